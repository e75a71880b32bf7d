// The ISA choice: names, the widest one that runs, and refusals of an ISA that cannot run —
// on made-up processors (a CPU without AVX-512, one without AVX2, a build without the kernels),
// since the machine running the tests has only one.
#include "glint/core/isa.h"

#include <gtest/gtest.h>

#include <string>

namespace glint {
namespace {

IsaSupport support(bool avx2Cpu, bool avx512Cpu, bool compiled = true) {
  IsaSupport s;
  s.compiled[1] = s.compiled[2] = compiled;
  s.cpu[1] = avx2Cpu;
  s.cpu[2] = avx512Cpu;
  return s;
}

std::string refusal(std::string_view request, const IsaSupport& s) {
  try {
    resolveIsa(request, "--isa", s);
  } catch (const IsaError& error) {
    return error.what();
  }
  return "(accepted)";
}

TEST(IsaTest, NamesRoundTrip) {
  for (const Isa isa : kAllIsas) EXPECT_EQ(parseIsa(isaName(isa)), isa);
  EXPECT_EQ(isaName(Isa::Avx512), "avx512");
  EXPECT_FALSE(parseIsa("auto"));
  EXPECT_FALSE(parseIsa("AVX2"));
  EXPECT_FALSE(parseIsa(""));
}

TEST(IsaTest, AutoIsTheWidestThatRuns) {
  EXPECT_EQ(bestIsa(support(true, true)), Isa::Avx512);
  EXPECT_EQ(bestIsa(support(true, false)), Isa::Avx2);  // a CPU without AVX-512 falls back
  EXPECT_EQ(bestIsa(support(false, false)), Isa::Baseline);
  EXPECT_EQ(bestIsa(support(true, true, false)), Isa::Baseline);  // kernels not built
  EXPECT_EQ(resolveIsa("auto", "--isa", support(true, false)), Isa::Avx2);
  EXPECT_EQ(resolveIsa("auto", "--isa", support(false, false)), Isa::Baseline);
}

TEST(IsaTest, ForcingAnIsaThatCannotRunIsRefusedNamingIt) {
  EXPECT_EQ(resolveIsa("avx2", "--isa", support(true, false)), Isa::Avx2);
  EXPECT_EQ(resolveIsa("baseline", "--isa", support(false, false)), Isa::Baseline);
  EXPECT_EQ(refusal("avx512", support(true, false)),
            "--isa avx512: this processor lacks AVX-512 (x86-64-v4); it runs avx2");
  EXPECT_EQ(refusal("avx2", support(false, false)),
            "--isa avx2: this processor lacks AVX2 (x86-64-v3); it runs baseline");
  EXPECT_EQ(refusal("avx2", support(true, true, false)),
            "--isa avx2: this glint was built without AVX2 (x86-64-v3) kernels (baseline only)");
  EXPECT_EQ(refusal("sse4", support(true, true)),
            "--isa expects baseline, avx2, avx512 or auto, got 'sse4'");
}

TEST(IsaTest, TheDefaultRunsHere) {
  const IsaSupport here = isaSupportHere();
  EXPECT_TRUE(here.runs(Isa::Baseline));
  EXPECT_TRUE(here.runs(defaultIsa()));  // GLINT_ISA (ctest sets it for some runs) or the best
  EXPECT_NO_THROW(requireIsa(Isa::Baseline));
  for (const Isa isa : kAllIsas) {
    if (!here.runs(isa)) {
      EXPECT_THROW(requireIsa(isa), IsaError) << isaName(isa);
    }
  }
}

}  // namespace
}  // namespace glint
