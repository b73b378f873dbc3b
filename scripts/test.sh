#!/usr/bin/env bash
# README command 2: install what is missing, build everything
# (scripts/build.sh: the `release` configuration, which the `test` preset of
# CMakePresets.json is), and run every test but the opt-in timing checks
# (ctest's `test` preset). Those carry the ctest label perf (tests/bench: the
# instruments' agreement, collide_bench --timing-check): they take minutes and
# judge the machine's quiet as much as the code, so they run only when asked,
# on an idle machine: ctest --preset perf from the repository root (or
# ctest --test-dir build -L perf --output-on-failure).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
# A test preset is read from the source directory's CMakePresets.json.
cd "$root"
ctest --preset test -j"$(nproc)"
