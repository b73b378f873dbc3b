# cmake/options.cmake - every option and cache setting of the build, with the
# checks of their combinations, included by the top-level CMakeLists.txt
# before anything is found or built.
#
#   COLLIDE_KERNEL_ISAS     the SIMD kernels to build (see "Instruction sets")
#   COLLIDE_PREFETCH_AHEAD  how far ahead the kernel requests contacts
#   COLLIDE_BUILD_IO        collide::io (scene files, generators)
#   COLLIDE_BUILD_EVAL      collide::eval (reference, error measures)
#   COLLIDE_BUILD_TESTS     the tests (tests/)
#   COLLIDE_TESTS_PER_CASE  one ctest test per GoogleTest case, or per program
#   COLLIDE_USE_LLD         link with lld where the compiler can (cmake/flags.cmake)
#   COLLIDE_BUILD_BENCH     the benchmarks (bench/)
#   COLLIDE_BUILD_CLI       the `collide` tool (cli/)
#   COLLIDE_BUILD_PYTHON    the Python extension (python/; needs pybind11)
#   COLLIDE_BUILD_EXAMPLES  the examples (examples/)
#   COLLIDE_BUILD_FUZZ      the libFuzzer targets (fuzz/; needs clang)
#   COLLIDE_SANITIZE        sanitizers of every target (cmake/sanitizers.cmake)
#   COLLIDE_SANITIZE_OPT    optimisation level of a sanitizer build
#   COLLIDE_INSTALL         install rules and package files (cmake/install.cmake)
#
# The tools (tests, bench, CLI, Python, examples) are on by default when
# collide is the top-level project and io and eval are built, off when a
# project embeds it with add_subdirectory.

# ---------------------------------------------------------------------------
# Instruction sets. One library runs on every x86-64 and uses what the CPU
# has: the SIMD kernel (core/src/kernel/loops.hpp, in units: kernel/units.hpp)
# is compiled once per ISA, each copy in its own namespace, and a Solver picks
# one at run time (collide/isa.hpp; docs/embedding.md, "One binary, every
# x86-64"):
#   sse2    4 float / 2 double lanes, the x86-64 baseline (also the scalar path)
#   avx2    8 float / 4 double lanes
#   avx512  16 float / 8 double lanes (AVX-512 F, BW, DQ, VL)
# Their compiler flags are in cmake/flags.cmake. On other processors there is
# one kernel, for the target's own lanes, and it answers to every name.
# ---------------------------------------------------------------------------
set(_collide_isas_here "")
if(CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
  set(_collide_isas_here sse2 avx2 avx512)
  if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    # libstdc++'s std::experimental::simd computes wrong results when clang 14
    # compiles it with AVX-512 enabled (test_isa in the clang sanitizer build:
    # J = 0 on every scene, at 16 lanes and at 8), so a clang build has no
    # AVX-512 kernel, and isa_supported(avx512) says so. GCC builds have all three.
    set(_collide_isas_here sse2 avx2)
  endif()
endif()
# COLLIDE_KERNEL_ISAS: which of them to build. Every ISA's kernel costs a few
# minutes of compile time (in units of under a minute each,
# core/src/kernel/units.hpp); a project that embeds collide for known machines
# (or a test that needs only the library's packaging, tests/package) may
# build fewer, e.g. -DCOLLIDE_KERNEL_ISAS="sse2;avx2". sse2 cannot be left
# out: it is the baseline every x86-64 has and holds the scalar path.
set(COLLIDE_KERNEL_ISAS "${_collide_isas_here}" CACHE STRING
    "SIMD kernels to build, a subset of the ones this compiler and target have (x86-64: sse2;avx2;avx512)")
foreach(isa IN LISTS COLLIDE_KERNEL_ISAS)
  if(NOT isa IN_LIST _collide_isas_here)
    message(FATAL_ERROR "COLLIDE_KERNEL_ISAS: '${isa}' cannot be built with this compiler and target (they have: '${_collide_isas_here}')")
  endif()
endforeach()
if(_collide_isas_here AND NOT "sse2" IN_LIST COLLIDE_KERNEL_ISAS)
  message(FATAL_ERROR "COLLIDE_KERNEL_ISAS must contain sse2, the baseline that holds the scalar path (it is '${COLLIDE_KERNEL_ISAS}')")
endif()
# The kernels form a ladder (isa_supported() answers "up to the best"): no
# AVX-512 kernel without the AVX2 one.
if("avx512" IN_LIST COLLIDE_KERNEL_ISAS AND NOT "avx2" IN_LIST COLLIDE_KERNEL_ISAS)
  message(FATAL_ERROR "COLLIDE_KERNEL_ISAS: avx512 needs avx2 too (it is '${COLLIDE_KERNEL_ISAS}')")
endif()

# COLLIDE_PREFETCH_AHEAD: how many contacts ahead of the group it solves the
# kernel requests the packed records of a batch (twice as far for a scattered
# batch's own contact lines): kPrefetchAhead in core/src/kernel/loops.hpp, and
# the same distance in the benchmark's packed twin (bench/packed_twin.cpp).
# Far enough that the misses of a few groups overlap, near enough that the
# lines are still in L1 when the group reads them (64 measured the same as 32:
# docs/decisions/0005-packed-records-for-scattered-contacts.md). A tuning
# knob for another CPU: it changes speed only, never a bit of the results.
set(COLLIDE_PREFETCH_AHEAD 32 CACHE STRING "Contacts ahead of the solved group whose records the kernel requests")
if(NOT COLLIDE_PREFETCH_AHEAD MATCHES "^[1-9][0-9]*$")
  message(FATAL_ERROR "COLLIDE_PREFETCH_AHEAD must be a positive number of contacts (it is '${COLLIDE_PREFETCH_AHEAD}')")
endif()

# ---------------------------------------------------------------------------
# The architecture, one folder and one library each:
#   core/  collide::collide  the solver: bodies, contacts, packed records, the
#                            schedule, the kernels, validation (TBB only)
#   io/    collide::io       scene files (CSV, .npz), result files, generators
#   eval/  collide::eval     the reference, error measures, --check, the
#                            bandwidth bound, hard scenes; and the report
#                            engine of the tools (not installed)
#   cli/                     the `collide` tool; bench/, python/: the other shells
# An embedding project that needs only the solver turns io and eval off
# (-DCOLLIDE_BUILD_IO=OFF): the core builds and links alone, and the tools,
# which need all three, are then off too.
# ---------------------------------------------------------------------------
option(COLLIDE_BUILD_IO "Build collide::io (scene files, generators)" ON)
include(CMakeDependentOption)
cmake_dependent_option(COLLIDE_BUILD_EVAL "Build collide::eval (reference, error measures)" ON "COLLIDE_BUILD_IO" OFF)
set(_collide_tools_default OFF)
if(PROJECT_IS_TOP_LEVEL AND COLLIDE_BUILD_EVAL)
  set(_collide_tools_default ON)
endif()
option(COLLIDE_BUILD_TESTS "Build the tests" ${_collide_tools_default})
option(COLLIDE_BUILD_BENCH "Build the benchmarks" ${_collide_tools_default})
option(COLLIDE_BUILD_CLI "Build the collide command-line tool" ${_collide_tools_default})
option(COLLIDE_BUILD_PYTHON "Build the Python extension (needs pybind11)" ${_collide_tools_default})
option(COLLIDE_BUILD_EXAMPLES "Build the examples" ${_collide_tools_default})
option(COLLIDE_BUILD_FUZZ "Build the libFuzzer targets (needs clang)" OFF)
# How the GoogleTest programs reach ctest (tests/CMakeLists.txt): ON, each
# case its own ctest test in its own process (gtest_discover_tests), so ctest
# names, filters and times every case; OFF, each program one ctest test
# running all its cases in one process. The `asan` preset turns it off: a
# sanitized process spends a large part of a short case starting (mapping
# its shadow memory and loading a large program), and one start per program
# instead of one per case shortens the sanitized test run (decision 0049).
option(COLLIDE_TESTS_PER_CASE "Register each GoogleTest case as its own ctest test (OFF: one test per program)" ON)
# The linker of collide's own programs: lld where the compiler can use it,
# else the compiler's default (cmake/flags.cmake says why).
option(COLLIDE_USE_LLD "Link collide's programs with lld where the compiler can use it" ON)
# Unity batches are CMake's own: -DCMAKE_UNITY_BUILD=ON (UNITY_BUILD of every
# target, 8 sources a batch; the kernel objects, one source each, and the
# tests stay out: core/CMakeLists.txt, tests/CMakeLists.txt). The libraries'
# and the tool's sources parse the same standard and TBB headers, so in
# batches they compile in much less compiler time, which suits a build that
# only runs the tool (the `tool` preset of CMakePresets.json: scripts/build.sh
# --tool, README command 1). Off by default: a per-source build keeps
# compile_commands.json per source for clang-tidy and rebuilds one source per
# edit. The `asan` preset (scripts/ci-sanitizers.sh) builds with it on, so a
# name that two sources of a batch define twice fails CI.
foreach(tool TESTS BENCH CLI PYTHON)
  if(COLLIDE_BUILD_${tool} AND NOT COLLIDE_BUILD_EVAL)
    message(FATAL_ERROR "COLLIDE_BUILD_${tool} needs the io and eval libraries (COLLIDE_BUILD_IO and COLLIDE_BUILD_EVAL ON)")
  endif()
endforeach()
if(COLLIDE_BUILD_FUZZ AND NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "COLLIDE_BUILD_FUZZ needs Clang (libFuzzer); configure with -DCMAKE_CXX_COMPILER=clang++")
endif()
if(COLLIDE_BUILD_FUZZ AND NOT COLLIDE_BUILD_EVAL)
  message(FATAL_ERROR "COLLIDE_BUILD_FUZZ needs the io and eval libraries (COLLIDE_BUILD_IO and COLLIDE_BUILD_EVAL ON)")
endif()

# Sanitizer builds: what the flags do and why is in cmake/sanitizers.cmake.
set(COLLIDE_SANITIZE "" CACHE STRING "Sanitizers for every target: address,undefined or thread (empty: none)")
set(COLLIDE_SANITIZE_OPT "-O1" CACHE STRING "Optimisation level of sanitizer builds")
# A fuzzing build without an explicit choice fuzzes under ASan and UBSan.
if(COLLIDE_BUILD_FUZZ AND NOT COLLIDE_SANITIZE)
  set(COLLIDE_SANITIZE "address,undefined")
endif()
string(REPLACE ";" "," _collide_sanitize "${COLLIDE_SANITIZE}")
if(_collide_sanitize MATCHES "thread" AND _collide_sanitize MATCHES "address")
  message(FATAL_ERROR "COLLIDE_SANITIZE: thread and address sanitizers cannot be combined")
endif()
unset(_collide_sanitize)

# Install rules are generated when collide is the top-level project, or when
# an embedding project asks for them.
option(COLLIDE_INSTALL "Generate the install rules for collide" ${PROJECT_IS_TOP_LEVEL})
