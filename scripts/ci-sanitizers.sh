#!/usr/bin/env bash
# CI, after the README's test command (.ci/run): the sanitized and fuzzed runs
# (sanitizers, fuzzers, the race detector). Any finding fails the run (non-zero exit).
#
#   1. ASan + UBSan: one Clang build (no Python module: a sanitized extension
#      cannot load into an unsanitized interpreter; Debug, so the kernels' asserts are on,
#      at -O1; see cmake/sanitizers.cmake) of the library, the CLI, every test
#      and the fuzzers, then ctest, one ctest test per test program (each
#      runs all its cases in one sanitized process: COLLIDE_TESTS_PER_CASE,
#      decision 0049). The `objects` test (test_isa_objects: it
#      inspects the optimised objects the project ships) and the `package`
#      tests are left out; the latter
#      install the library and build consumers without sanitizer flags (which
#      cannot link a sanitized archive) and recompile the library, and the
#      Release stage has run them already. So are the `report` tests (two
#      whole `collide report` runs, minutes under the sanitizers; the Release
#      stage runs them, and the report's code runs here in
#      CliNpzTest.ReportMeasuresAScenesFiles and the eval tests).
#      The sanitized builds compile one kernel, the baseline's
#      (COLLIDE_KERNEL_ISAS=sse2: 4 float and 2 double lanes, and the
#      one-lane kernel of every path): the kernel is one body over the lane
#      type (core/src/kernel/loops.hpp), so a wider copy adds minutes of compile time
#      and no code of its own, and the Release stage runs every ISA's. The
#      libraries and the tool compile in unity batches (CMAKE_UNITY_BUILD,
#      as README command 1 builds them), so two sources of a batch that
#      define one name fail here. Test code compiles at -O0 and without
#      libFuzzer's coverage (tests/CMakeLists.txt: the libraries keep both),
#      and the sweeps that repeat a solve over every path, thread count and
#      layout run a quarter of their scene (tests/support/sanitized.hpp;
#      decision 0051).
#   2. Fuzzing: each libFuzzer target of fuzz/ for FUZZ_SECONDS (default 45),
#      the targets side by side on the available cores, from a scratch copy of
#      fuzz/corpus/<target>/ (the committed seeds stay as they are). A crash,
#      UB, a leak, an input over 10 s (-timeout) or over 2 GB (-rss_limit_mb)
#      stops the target with a non-zero exit; the input is kept under
#      build-asan/fuzz-artifacts/.
#   3. TSan: a Clang build of only what the parallel kernel tests need
#      (determinism, schedule, the islands' lock-free union-find, the
#      caller's-arena solver, the shared-body hard cases) and ctest on those.
#      TBB's hand-overs reach TSan through the ITT
#      bridge (tests/tsan/itt_tsan_bridge.cpp); tests/tsan/tbb.supp hides
#      TBB's own task-memory recycling and nothing else. Last, race_canary
#      must produce a TSan report in the kernel: proof that the bridge and the
#      suppressions cannot hide a race on the kernel's data.
#
# The configurations, builds and test runs are the `asan` and `tsan` presets
# of CMakePresets.json (Clang 14); build directories: build-asan/ and
# build-tsan/ next to build/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/install-deps.sh"
# The presets are read from the source directory's CMakePresets.json.
cd "$root"

jobs="$(nproc)"
fuzz_seconds="${FUZZ_SECONDS:-45}"
# The presets' compiler is clang++-14; where only another clang++ exists, that one.
compiler=()
if ! command -v clang++-14 >/dev/null; then
  compiler=(-DCMAKE_CXX_COMPILER="$(command -v clang++)")
fi
# Through ccache when present, as scripts/build.sh does: a re-run after a
# change recompiles only what changed.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"
fi
stage() { printf '\n== %s (%ss since start)\n' "$1" "$SECONDS"; }
# A build directory that Make configured (before the presets named Ninja)
# loses its cache: CMake does not switch generators in place.
for dir in "$root/build-asan" "$root/build-tsan"; do
  if [ -f "$dir/CMakeCache.txt" ] && ! grep -qx 'CMAKE_GENERATOR:INTERNAL=Ninja' "$dir/CMakeCache.txt"; then
    rm -rf "$dir/CMakeCache.txt" "$dir/CMakeFiles"
  fi
done

# --- 1. ASan + UBSan --------------------------------------------------------
asan="$root/build-asan"
stage "ASan+UBSan build"
cmake --preset asan "${compiler[@]}" "${launcher[@]}" >/dev/null
cmake --build --preset asan -j"$jobs"
stage "ASan+UBSan tests"
# The sanitizer options of the `asan` test preset, for the fuzzers too.
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:check_initialization_order=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest --preset asan -j"$jobs"

# --- 2. Fuzzing -------------------------------------------------------------
stage "fuzzing, ${fuzz_seconds}s per target"
targets=(scene_io kernel entry npz routes)
pids=()
for t in "${targets[@]}"; do
  work="$asan/fuzz-work/$t"
  rm -rf "$work" && mkdir -p "$work/corpus" "$asan/fuzz-artifacts"
  cp "$root/fuzz/corpus/$t/"* "$work/corpus/"
  "$asan/fuzz/fuzz_$t" -max_total_time="$fuzz_seconds" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$asan/fuzz-artifacts/$t-" "$work/corpus" >"$work/log" 2>&1 &
  pids+=($!)
done
failed=0
for i in "${!targets[@]}"; do
  if wait "${pids[$i]}"; then
    grep -E "^stat::number_of_executed_units|^Done" "$asan/fuzz-work/${targets[$i]}/log" | tr '\n' ' '
    echo "(fuzz_${targets[$i]}: clean)"
  else
    echo "fuzz_${targets[$i]} FAILED:" >&2
    tail -n 60 "$asan/fuzz-work/${targets[$i]}/log" >&2
    failed=1
  fi
done
[ "$failed" -eq 0 ]

# --- 3. TSan on the parallel kernel -------------------------------------------
tsan="$root/build-tsan"
stage "TSan build"
cmake --preset tsan "${compiler[@]}" "${launcher[@]}" >/dev/null
# The build preset's targets: the tests below and the race detector's helpers.
cmake --build --preset tsan -j"$jobs"
stage "TSan tests"
# The environment of the `tsan` test preset, for the canary too.
export INTEL_LIBITTNOTIFY64="$tsan/libcollide_itt_tsan.so"
export INTEL_ITTNOTIFY_GROUPS=sync
export TSAN_OPTIONS="suppressions=$root/tests/tsan/tbb.supp"
ctest --preset tsan -j"$jobs"
# The negative control: TSan must see the canary's race, in the kernel.
set +e
"$tsan/collide_race_canary" >"$tsan/race_canary.log" 2>&1
canary=$?
set -e
if [ "$canary" -ne 66 ] || ! grep -q "WARNING: ThreadSanitizer: data race" "$tsan/race_canary.log" ||
  ! grep -q "core/src/" "$tsan/race_canary.log"; then
  echo "race_canary: TSan did not report the deliberate race in the kernel (exit $canary); the TSan run proves nothing" >&2
  tail -n 40 "$tsan/race_canary.log" >&2
  exit 1
fi
echo "race_canary: TSan reported the deliberate race, as it must"
stage "sanitizers and fuzzing passed"
