#include "glint/core/isa.h"

#include <cstdlib>
#include <string>
#include <variant>

namespace glint {

std::string_view isaName(Isa isa) {
  switch (isa) {
    case Isa::Avx2:
      return "avx2";
    case Isa::Avx512:
      return "avx512";
    case Isa::Baseline:
      break;
  }
  return "baseline";
}

std::optional<Isa> parseIsa(std::string_view name) {
  for (const Isa isa : kAllIsas) {
    if (name == isaName(isa)) return isa;
  }
  return std::nullopt;
}

IsaSupport isaSupportHere() {
  IsaSupport support;
  // GLINT_ISA_KERNELS: CMake compiled aggregate_avx2.cpp and aggregate_avx512.cpp with their ISA's
  // flags (x86-64 and g++; elsewhere they are baseline copies that are never chosen).
#if GLINT_ISA_KERNELS
  support.compiled[static_cast<int>(Isa::Avx2)] = true;
  support.compiled[static_cast<int>(Isa::Avx512)] = true;
  // The compiler's CPU model checks CPUID and that the OS saves the AVX and AVX-512 registers
  // (XGETBV).
  __builtin_cpu_init();
#if defined(__clang__)
  // clang 14 (Debian 12's, used by the fuzz build) cannot name the levels: their defining
  // features instead. Every processor with these also has the level's LZCNT, MOVBE and F16C
  // (Haswell, Excavator, Zen and later), which g++'s level names check too.
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                  __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                  __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512vl");
#else
  const bool v3 = __builtin_cpu_supports("x86-64-v3") != 0;
  const bool v4 = __builtin_cpu_supports("x86-64-v4") != 0;
#endif
  support.cpu[static_cast<int>(Isa::Avx2)] = v3;
  support.cpu[static_cast<int>(Isa::Avx512)] = v4;
#endif
  return support;
}

Isa bestIsa(const IsaSupport& support) {
  Isa best = Isa::Baseline;
  for (const Isa isa : kAllIsas) {
    if (support.runs(isa)) best = isa;
  }
  return best;
}

namespace {

std::string describe(Isa isa) {
  switch (isa) {
    case Isa::Avx2:
      return "AVX2 (x86-64-v3)";
    case Isa::Avx512:
      return "AVX-512 (x86-64-v4)";
    case Isa::Baseline:
      break;
  }
  return "the baseline";
}

}  // namespace

Isa resolveIsa(std::string_view request, std::string_view where, const IsaSupport& support) {
  if (request == "auto") return bestIsa(support);
  const std::optional<Isa> isa = parseIsa(request);
  if (!isa) {
    throw IsaError(std::string(where) + " expects baseline, avx2, avx512 or auto, got '" +
                   std::string(request) + "'");
  }
  if (!support.compiled[static_cast<int>(*isa)]) {
    throw IsaError(std::string(where) + " " + std::string(request) + ": this glint was built " +
                   "without " + describe(*isa) + " kernels (baseline only)");
  }
  if (!support.cpu[static_cast<int>(*isa)]) {
    throw IsaError(std::string(where) + " " + std::string(request) + ": this processor lacks " +
                   describe(*isa) + "; it runs " + std::string(isaName(bestIsa(support))));
  }
  return *isa;
}

void requireIsa(Isa isa) { resolveIsa(isaName(isa), "ISA", isaSupportHere()); }

Isa defaultIsa() {
  // Resolved once: a kernel choice per Aggregate must not cost a getenv and CPUID.
  static const std::variant<Isa, IsaError> chosen = []() -> std::variant<Isa, IsaError> {
    const IsaSupport support = isaSupportHere();
    const char* request = std::getenv("GLINT_ISA");
    if (request == nullptr || *request == '\0') return bestIsa(support);
    try {
      return resolveIsa(request, "GLINT_ISA", support);
    } catch (const IsaError& error) {
      return error;
    }
  }();
  if (const auto* error = std::get_if<IsaError>(&chosen)) throw *error;
  return std::get<Isa>(chosen);
}

}  // namespace glint
