#!/usr/bin/env bash
# README command 2: install what is missing, build, and run every test but the
# opt-in timing checks. Those carry the ctest label perf (tests/bench: the
# instruments' agreement, collide_bench --timing-check): they take minutes and
# judge the machine's quiet as much as the code, so they run only when asked,
# on an idle machine: ctest --test-dir build -L perf --output-on-failure
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
ctest --test-dir "$root/build" --output-on-failure -j"$(nproc)" -LE perf
