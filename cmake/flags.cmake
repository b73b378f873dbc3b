# cmake/flags.cmake - the compiler flags of collide's own code, included by
# the top-level CMakeLists.txt after cmake/options.cmake.
#
#   collide_build_flags      an INTERFACE target every target of the project
#                            links (PRIVATE, and only in the build: it is never
#                            installed or exported): the floating-point policy
#                            and the warnings
#   collide_isa_<isa>        an INTERFACE target per kernel ISA (sse2, avx2,
#                            avx512; native elsewhere) with that ISA's flags,
#                            linked by the per-ISA kernel objects (core/) and
#                            the per-ISA tests of the lane layer (tests/)
#   collide_kernel_placement an INTERFACE target with the code alignment of
#                            every kernel object
# All of them are build-only: no installed or exported target links them.
#
# Everything outside the per-ISA kernels is compiled for the target's
# baseline: no -march=native anywhere.

# ---------------------------------------------------------------------------
# Floating-point policy (tested per ISA in tests/core/test_fp_policy.cpp):
#   * -ffp-contract=off: a*b+c is never fused, so the scalar path, the SSE2
#     path and the AVX2 path perform the same IEEE operations in the same
#     order and agree bit for bit (docs/collision-law.md, "Precision and the
#     error bound").
#   * no -ffast-math, -fno-finite-math etc.: NaN and inf keep their meaning,
#     divisions and square roots are correctly rounded.
# ---------------------------------------------------------------------------
set(COLLIDE_FP_FLAGS -ffp-contract=off -fno-fast-math)

add_library(collide_build_flags INTERFACE)
target_compile_options(collide_build_flags INTERFACE ${COLLIDE_FP_FLAGS} -Wall -Wextra -Wpedantic)
# In unity batches (CMAKE_UNITY_BUILD, cmake/options.cmake) each source is
# included into a batch file, so GCC's -Wsubobject-linkage, which is meant
# for headers, reports every lambda of a source that captures a type of the
# source's anonymous namespace. A source is included once, so no such type
# can meet its namesake; the per-source build keeps the warning and shows
# one that would be real.
if(CMAKE_UNITY_BUILD AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(collide_build_flags INTERFACE -Wno-subobject-linkage)
endif()

# ---------------------------------------------------------------------------
# The kernel ISAs (which ones are built: COLLIDE_KERNEL_ISAS, cmake/options.cmake).
# The results are bitwise identical across all of them (the floating-point
# policy above): the ISA changes speed, never answers.
# ---------------------------------------------------------------------------
if(CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
  add_library(collide_isa_sse2 INTERFACE)
  target_compile_options(collide_isa_sse2 INTERFACE -msse2)
  # -mno-fma on AVX2, on purpose: no fused multiply-add instruction exists
  # there to appear.
  add_library(collide_isa_avx2 INTERFACE)
  target_compile_options(collide_isa_avx2 INTERFACE -mavx2 -mno-fma)
  # No -mno-fma here: AVX-512F includes FMA, and clang drops AVX-512 altogether
  # under -mno-fma (its 16-lane "AVX-512" object was then AVX2 code). No FMA
  # can appear anyway: -ffp-contract=off forbids contraction and the code
  # never calls an fma. -mprefer-vector-width=512: clang would otherwise split
  # 16-lane vectors into two ymm halves.
  add_library(collide_isa_avx512 INTERFACE)
  target_compile_options(collide_isa_avx512 INTERFACE -mavx512f -mavx512bw -mavx512dq -mavx512vl
                                                      -mprefer-vector-width=512)
  # GCC 12's _mm512_sqrt_ps starts from _mm512_undefined_ps(), a deliberate
  # self-initialisation that -W(maybe-)uninitialized reports once inlined.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(collide_isa_avx512 INTERFACE -Wno-maybe-uninitialized -Wno-uninitialized)
  endif()
else()
  # One kernel for the target's own lanes, compiled for the target's baseline.
  add_library(collide_isa_native INTERFACE)
endif()

# ---------------------------------------------------------------------------
# Code placement of the kernel objects (core/CMakeLists.txt): every function
# and every loop starts on a 64-byte boundary (a cache line, and a whole
# number of the front end's fetch blocks). The speed of a kernel loop moved
# with where it landed: a change to one loop moved the code after it, and
# an unchanged loop's speed with it
# (docs/decisions/0036-the-avx512-gather-instruction-measured.md). Each loop
# is its own function (core/src/kernel_table.hpp); aligned, a function's
# start and its hot loops sit at the same offsets in their lines whatever
# precedes them in the object, so placing or changing one variant does not
# move another's speed. What it costs is padding: the gaps before each
# function and hot loop, in the kernel objects only. Clang 14 accepts both
# flags too (the sanitizer build).
# ---------------------------------------------------------------------------
add_library(collide_kernel_placement INTERFACE)
target_compile_options(collide_kernel_placement INTERFACE -falign-functions=64 -falign-loops=64)

# ---------------------------------------------------------------------------
# The linker: LLVM's lld (Debian lld) where the compiler can use it, GNU ld
# otherwise. The tests are some fifty programs, each linking the static
# libraries with every kernel unit, and lld links them several times faster
# than GNU ld where the programs are largest, in the sanitized builds
# (decision 0049 has the times). The program is the same: the linker places the
# objects' code, it does not change it. COLLIDE_USE_LLD=OFF keeps the
# compiler's default. Only collide's own build: an embedding project
# (add_subdirectory) keeps its linker.
# ---------------------------------------------------------------------------
if(COLLIDE_USE_LLD AND PROJECT_IS_TOP_LEVEL)
  include(CheckLinkerFlag)
  check_linker_flag(CXX -fuse-ld=lld COLLIDE_LINKER_LLD)
  if(COLLIDE_LINKER_LLD)
    add_link_options(-fuse-ld=lld)
  endif()
endif()
