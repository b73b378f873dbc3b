// collide/isa.hpp - the instruction sets the SIMD kernel is compiled for, and
// which one runs.
//
// One library holds the kernel compiled three times: for SSE2 (every x86-64),
// AVX2 and AVX-512 (F, BW, DQ, VL). A Solver picks one when it is built: the
// one named in SolverOptions::isa, else the environment variable COLLIDE_ISA,
// else the best the CPU supports (CPUID, and XGETBV for the OS's register
// state). All three give bitwise identical results (no FMA, the same IEEE
// operations in the same order): the ISA changes speed, never answers.
//
// The header is C++17 so that C++17 programs can embed the kernel.
#pragma once

#include <cstddef>
#include <string_view>

namespace collide {

/// An instruction set of the SIMD path (the scalar path is the same kernel at
/// one lane and is compiled for the baseline).
enum class Isa {
  automatic,  ///< COLLIDE_ISA if set, else the best the CPU supports
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

/// The widest ISA this CPU supports, detected once.
Isa best_isa();

/// What Isa::automatic means here: COLLIDE_ISA when set (throws
/// std::invalid_argument when it names an unknown ISA or one the CPU lacks),
/// else best_isa().
Isa default_isa();

/// Resolves `requested` to a concrete ISA (never automatic). Throws
/// std::invalid_argument when the CPU lacks it, naming the ISA and what the
/// CPU has.
Isa resolve_isa(Isa requested);

/// Lanes of the SIMD path for T (float or double) under a concrete ISA.
template <class T>
std::size_t simd_width(Isa isa);

}  // namespace collide
