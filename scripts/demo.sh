#!/usr/bin/env bash
# README command 1: install the packages the tool needs (install-deps.sh
# --tool), build the `collide` tool (only it: not the tests, benchmarks,
# examples or the Python module, which are configured off), and run the
# main job, `collide report` with its default settings (docs/report.md): the
# speed and the error of every variant on 1,000,000 random pairs, a debris
# scene of 1,000,000 contacts and a pile of 976,005, as a summary on stdout
# (the speed-against-error frontier of each scene), every row in
# build/report.json and the plot build/report.png (REPORT_ARGS adds options,
# e.g. REPORT_ARGS="--all" prints every row).
#
# Then the file workflow on its built-in default: `collide gen` writes a
# random scene of 1,000,000 pairs as binary scene files (.npz; PAIRS=N
# changes it, PAIRS=0 skips it), in float and in double, and `collide solve
# --stats --check` resolves each, its files mapped in place, so that --stats
# shows the kernel's time beside the files', and checks it against the
# long-double reference (--check fails if an impulse is outside the bound).
#
# A report whose kernel rows exceed the documented error bound (exit 3) does
# not stop the rest; the script exits with the first failure's status.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh" --tool

status=0
# shellcheck disable=SC2086  # REPORT_ARGS is a list of options
"$root/build/collide" report --json "$root/build/report.json" --plot "$root/build/report.png" ${REPORT_ARGS:-} ||
  status=$?

pairs="${PAIRS:-1000000}"
if [ "$pairs" != 0 ]; then
  for precision in float double; do
    scene="$root/build/demo/$precision"
    echo
    echo "collide gen --pairs $pairs --format npz --precision $precision, then collide solve --stats --check:"
    "$root/build/collide" gen --pairs "$pairs" --out "$scene" --seed 1 --format npz --precision "$precision"
    "$root/build/collide" solve --bodies "$scene/bodies.npz" --contacts "$scene/contacts.npz" \
      --out-bodies "$scene/solved-bodies.npz" --out-impulses "$scene/impulses.npz" --stats --check || {
      rc=$?
      [ "$status" -ne 0 ] || status=$rc
    }
  done
fi
exit "$status"
