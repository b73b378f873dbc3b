# cmake/sanitizers.cmake - sanitizer builds, included from the top-level
# CMakeLists.txt before any target exists, so the options reach every target
# of the project: the library, the CLI, the tests, the benchmarks and the
# fuzzers.
#
#   COLLIDE_SANITIZE      comma- or semicolon-separated -fsanitize= list, e.g.
#                         "address,undefined" or "thread"; empty = no sanitizer.
#   COLLIDE_SANITIZE_OPT  optimisation level of a sanitizer build (default -O1).
# (Both are declared and checked with the other options, cmake/options.cmake.)
#
# Why these flags:
#   * -fno-sanitize-recover=all: UBSan otherwise prints a report and carries
#     on, and the test passes; with it the first UB aborts the process, so a
#     ctest run or a fuzzer fails on it.
#   * -fno-omit-frame-pointer and, under ASan and UBSan, line tables only
#     (Clang's -gline-tables-only, GCC's -g1): readable stacks in the
#     reports, file and line of every frame. Full debug information adds the
#     types and variables, which no report prints, and costs a sixth of the
#     compile time of a test or kernel unit besides much larger objects to
#     link (decision 0047). TSan keeps -g: its suppressions
#     (tests/tsan/tbb.supp) match TBB's frames by their qualified names,
#     which the line tables do not hold for inlined functions.
#   * -O1: the kernel units (core/src/kernel/) instantiate the kernel for
#     3 models x 2 paths x 2 precisions x friction; at -O0 with
#     instrumentation the tests run many times slower and at -O2/-O3 the
#     build takes longer, for no extra findings. The level is applied after the build type's flags, so it wins.
#     Configure sanitizer builds as Debug: NDEBUG stays undefined and the
#     kernels' debug asserts (index range, a != b, view sizes) run too.
#   * The kernel units (core/src/kernel/) leave out UBSan's pointer-overflow
#     check (COLLIDE_KERNEL_SANITIZE_OPTIONS): it guards every address the
#     inlined lane loads and stores form, and half of those units' compile
#     time under the sanitizers goes to it (decision 0044). What it would
#     catch there, an address that wraps, needs an index beyond the arrays,
#     and ASan checks every access against its allocation; the kernels'
#     indices are checked against the counts before a solve (Schedule::build,
#     validate_indices) and asserted in these Debug builds.
#   * float-divide-by-zero is not part of "undefined" in GCC or Clang, and is
#     not enabled: IEEE division by zero is defined, and the kernel divides by
#     zero in lanes whose result it discards (see contact_kernel.hpp).
#
# A fuzzing build (COLLIDE_BUILD_FUZZ=ON, Clang) also compiles every target
# with -fsanitize=fuzzer-no-link, so libFuzzer sees coverage inside the
# library, not only in the fuzz drivers; the drivers link -fsanitize=fuzzer
# (fuzz/CMakeLists.txt). The same build directory then runs the ASan+UBSan
# test suite and the fuzzers (see scripts/ci-sanitizers.sh). Two kinds of
# code go without the coverage: the tests (no fuzzer runs them,
# tests/CMakeLists.txt) and the kernel units (COLLIDE_KERNEL_SANITIZE_OPTIONS).
# The units are the law in lanes, with no branch on a contact's values, and
# the branches of their loops (a tail, a gathered or a contiguous group)
# follow the schedule, whose code keeps its coverage; instrumenting them
# cost much of the sanitized build's compile time (decision 0051).
if(COLLIDE_SANITIZE)
  string(REPLACE ";" "," _collide_sanitize "${COLLIDE_SANITIZE}")
  message(STATUS "collide: sanitizers ${_collide_sanitize} (${COLLIDE_SANITIZE_OPT})")
  if(_collide_sanitize MATCHES "thread")
    set(_collide_line_tables -g)
  elseif(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    set(_collide_line_tables -gline-tables-only)
  else()
    set(_collide_line_tables -g1)
  endif()
  add_compile_options(-fsanitize=${_collide_sanitize} -fno-sanitize-recover=all -fno-omit-frame-pointer
                      ${_collide_line_tables} ${COLLIDE_SANITIZE_OPT})
  add_link_options(-fsanitize=${_collide_sanitize} -fno-sanitize-recover=all)
  if(_collide_sanitize MATCHES "undefined")
    set(COLLIDE_KERNEL_SANITIZE_OPTIONS -fno-sanitize=pointer-overflow)
  endif()
  if(_collide_sanitize MATCHES "thread")
    # TBB's hand-overs become visible to TSan through the ITT bridge (tests/tsan/,
    # built there with the race canary): the TBB headers notify spawn, join and
    # wait only when compiled with TBB_USE_PROFILING_TOOLS=2, and libtbb loads
    # the bridge named by INTEL_LIBITTNOTIFY64.
    add_compile_definitions(TBB_USE_PROFILING_TOOLS=2)
  endif()
  unset(_collide_sanitize)
  unset(_collide_line_tables)
endif()

if(COLLIDE_BUILD_FUZZ)
  add_compile_options(-fsanitize=fuzzer-no-link)
  list(APPEND COLLIDE_KERNEL_SANITIZE_OPTIONS -fno-sanitize=fuzzer-no-link)
endif()
