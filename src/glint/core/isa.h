// The instruction sets glint's hot kernels (the Aggregate's two queries) are compiled for, which
// of them this processor runs, and which one a process uses: the widest by default, or the one
// GLINT_ISA names. Every ISA computes the same arithmetic (the build uses -ffp-contract=off), so
// the choice changes the speed, never a hit or a pixel.
#pragma once

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace glint {

enum class Isa {
  Baseline,  // x86-64 (SSE2), or whatever the target architecture's default is
  Avx2,      // x86-64-v3: AVX, AVX2, FMA (not used for contraction), BMI1/2, F16C, LZCNT, MOVBE
  Avx512,    // x86-64-v4: x86-64-v3 plus AVX-512 F, BW, CD, DQ, VL
};
inline constexpr std::array<Isa, 3> kAllIsas = {Isa::Baseline, Isa::Avx2, Isa::Avx512};

// A requested ISA that cannot run here, or a name that is none: the message names both.
class IsaError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

std::string_view isaName(Isa isa);  // "baseline", "avx2", "avx512"
// baseline, avx2 or avx512 (no "auto"); std::nullopt for anything else.
std::optional<Isa> parseIsa(std::string_view name);

// Which ISAs could run: what this binary holds kernels for and what the processor supports.
struct IsaSupport {
  bool compiled[3] = {true, false, false};  // kernels built into this binary (x86-64 g++ builds)
  bool cpu[3] = {true, false, false};       // the processor and the OS run them
  bool runs(Isa isa) const { return compiled[static_cast<int>(isa)] && cpu[static_cast<int>(isa)]; }
};
IsaSupport isaSupportHere();  // this binary on this processor (CPUID, once)

// The widest ISA that runs under `support`: the `auto` choice.
Isa bestIsa(const IsaSupport& support);
// What a request ("baseline", "avx2", "avx512" or "auto"; `where` names its source in messages,
// e.g. "--isa" or "GLINT_ISA") resolves to under `support`. Throws IsaError for an unknown name and
// for an ISA that cannot run there ("--isa avx512: this processor lacks AVX-512 (x86-64-v4)").
Isa resolveIsa(std::string_view request, std::string_view where, const IsaSupport& support);
// Throws IsaError unless `isa` runs here.
void requireIsa(Isa isa);

// The process's ISA when nothing chose one: GLINT_ISA resolved as above if it is set and not
// empty, else the best that runs here. Read once; throws IsaError (every time) when GLINT_ISA is
// bad.
Isa defaultIsa();

}  // namespace glint
