// collide/isa.hpp - the instruction sets the SIMD kernel is compiled for, and
// which one runs.
//
// One library holds the kernel compiled three times: for SSE2 (every x86-64),
// AVX2 and AVX-512 (F, BW, DQ, VL). A Solver runs the one named in
// SolverOptions::isa, else the one named by the environment variable
// COLLIDE_ISA, else, per solve, the one that ran fastest on this CPU for the
// solve's model, precision, accuracy and scene kind: measured once per process
// at first use (collide/solve.hpp, fastest_isa()). All three give bitwise
// identical results (no FMA, the same IEEE operations in the same order): the
// ISA changes speed, never answers, so the choice is made on speed alone.
// Which ISAs the CPU has comes from CPUID, and XGETBV for the OS's register
// state.
//
// The header is C++17 so that C++17 programs can embed the kernel.
#pragma once

#include <cstddef>
#include <string_view>

namespace collide {

/// An instruction set of the SIMD path (the scalar path is the same kernel at
/// one lane and is compiled for the baseline).
enum class Isa {
  automatic,  ///< COLLIDE_ISA if set, else the fastest on this CPU, measured (fastest_isa() in solve.hpp)
  sse2,       ///< 4 float / 2 double lanes; every x86-64
  avx2,       ///< 8 float / 4 double lanes
  avx512,     ///< 16 float / 8 double lanes (AVX-512 F, BW, DQ, VL)
};

/// "auto", "sse2", "avx2" or "avx512".
const char* to_string(Isa isa);

/// Parses the names of to_string(); throws std::invalid_argument naming the
/// text and the accepted names otherwise.
Isa parse_isa(std::string_view name);

/// True when this CPU and OS can run `isa` and this build has a kernel for it
/// (automatic: always; a clang build has no AVX-512 kernel, CMakeLists.txt
/// says why; a build configured with COLLIDE_KERNEL_ISAS has only those). On a non-x86 build only sse2 and automatic
/// are "supported": there the lanes are the target's own and the name is nominal.
bool isa_supported(Isa isa);

/// The widest ISA this CPU supports, detected once. Not always the fastest:
/// on a CPU that splits 512-bit operations in two, AVX2 can beat AVX-512.
Isa best_isa();

/// The static answer for Isa::automatic, without measuring: COLLIDE_ISA when
/// set (throws std::invalid_argument when it names an unknown ISA or one the
/// CPU lacks), else best_isa(). A Solver with Isa::automatic and COLLIDE_ISA
/// unset does not use it: it measures (fastest_isa() in solve.hpp).
Isa default_isa();

/// Resolves `requested` to a concrete ISA (never automatic; automatic gives
/// default_isa()), checking that the CPU has it: throws
/// std::invalid_argument when it lacks it, naming the ISA and what the CPU
/// has.
Isa resolve_isa(Isa requested);

/// How the ISA of a solve was chosen (SolveStats::isa_choice).
enum class IsaChoice {
  forced,       ///< SolverOptions::isa named it
  environment,  ///< SolverOptions::isa was automatic and COLLIDE_ISA named it
  measured,     ///< automatic with COLLIDE_ISA unset: fastest_isa() for the solve (collide/solve.hpp)
  baseline,     ///< the scalar path, which runs the baseline's (sse2) one-lane kernel whatever was asked
};

/// "forced", "environment", "measured" or "baseline".
const char* to_string(IsaChoice choice);

/// Lanes of the SIMD path for T (float or double) under a concrete ISA.
template <class T>
std::size_t simd_width(Isa isa);

}  // namespace collide
