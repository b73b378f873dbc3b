// collide/isa.hpp - the kernel's two paths (one lane, or SIMD lanes), the
// instruction sets the SIMD kernel is compiled for, and which one runs.
//
// One library holds the kernel compiled three times: for SSE2 (every x86-64),
// AVX2 and AVX-512 (F, BW, DQ, VL). A Solver runs the one named in
// SolverOptions::isa, else the one named by the environment variable
// COLLIDE_ISA, else, per solve, the one that ran fastest on this CPU for the
// solve's model, precision, accuracy and scene kind: measured once per process
// at first use (fastest_isa() below). All three give bitwise
// identical results (no FMA, the same IEEE operations in the same order): the
// ISA changes speed, never answers, so the choice is made on speed alone.
// Which ISAs the CPU has comes from CPUID, and XGETBV for the OS's register
// state.
//
// The header is C++17 so that C++17 programs can embed the kernel.
#pragma once

#include <cstddef>
#include <string_view>

#include "collide/accuracy.hpp"
#include "collide/model.hpp"

namespace collide {

/// Which implementation of the kernel runs.
enum class Path {
  scalar,  ///< one contact at a time (lane width 1)
  simd,    ///< SIMD lanes: 16 float / 8 double with AVX-512, 8 / 4 with AVX2, 4 / 2 with SSE2
};

const char* to_string(Path path);

/// An instruction set of the SIMD path (the scalar path is the same kernel at
/// one lane and is compiled for the baseline).
enum class Isa {
  automatic,  ///< COLLIDE_ISA if set, else the fastest on this CPU, measured (fastest_isa() below)
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
/// unset does not use it: it measures (fastest_isa() below).
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
  measured,     ///< automatic with COLLIDE_ISA unset: fastest_isa() for the solve (below)
  baseline,     ///< the scalar path, which runs the baseline's (sse2) one-lane kernel whatever was asked
};

/// "forced", "environment", "measured" or "baseline".
const char* to_string(IsaChoice choice);

/// Lanes of the SIMD path for T (float or double) under a concrete ISA.
template <class T>
std::size_t simd_width(Isa isa);

/// The ISA whose SIMD kernel ran fastest on this CPU for `model` in precision
/// T (float or double) and `accuracy`, on a streaming scene (scattered =
/// false: contact k joins bodies 2k and 2k+1, the SoA arrays in order) or a
/// scattered one (scattered = true: contacts reach packed bodies at random,
/// as in the debris scene). It is what a Solver with Isa::automatic and
/// COLLIDE_ISA unset runs; a solve counts as scattered when most of its
/// schedule's contacts reach their bodies at random: those in non-contiguous
/// batches, and those of consecutive batches whose bodies, sampled, do not
/// follow one another (contacts handed over grouped by level).
///
/// Measured once per process at the first call for each key (thread-safe;
/// later calls return the cached answer): every ISA the CPU has runs its
/// kernel on one thread over a small synthetic scene in cache, round by
/// round, and the fastest best time wins: a short pause for the first solve
/// of a kind (isa_measurement() says how long). With one ISA, nothing is measured.
/// COLLIDE_ISA does not affect it.
template <class T>
Isa fastest_isa(Model model, Accuracy accuracy, bool scattered);

/// What the measurement behind fastest_isa() found for one key.
struct IsaMeasurement {
  Isa fastest = Isa::sse2;  ///< fastest_isa() for the key
  /// Contacts of each timed pass over the synthetic scene: up to 1024, fewer
  /// for slow kernels (0: nothing was measured).
  std::size_t contacts = 0;
  int rounds = 0;                  ///< timed passes per ISA (after one warm-up pass)
  double calibration_seconds = 0;  ///< wall time of the whole measurement [s]
  /// The best time of one timed pass for sse2, avx2 and avx512 in that order
  /// [s]; 0 for an ISA not measured (the CPU lacks it).
  double seconds[3] = {0, 0, 0};
};

/// The measurement of fastest_isa(model, accuracy, scattered), run first if
/// it has not run in this process yet.
template <class T>
IsaMeasurement isa_measurement(Model model, Accuracy accuracy, bool scattered);

}  // namespace collide
