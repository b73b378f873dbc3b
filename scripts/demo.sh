#!/usr/bin/env bash
# README command 1: install what is missing, build, and run the main job,
# `collide report` with its default settings (docs/report.md): the speed and
# the error of every variant on 4,000,000 random pairs and a debris scene of
# 1,000,000 contacts, as a table on stdout, build/report.json and
# build/report.png (a few minutes on a 2-core machine; REPORT_ARGS adds
# options, e.g. REPORT_ARGS="--n 1000000").
#
# Then the file workflow on its built-in default: `collide gen` writes a random
# scene of 1,000,000 pairs (PAIRS=N changes it, PAIRS=0 skips it) and
# `collide solve --stats --check` resolves it in float and double against the
# long-double reference (--check fails if an impulse is outside the bound).
#
# A report whose kernel rows exceed the documented error bound (exit 3) does
# not stop the rest; the script exits with the first failure's status.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"

status=0
# shellcheck disable=SC2086  # REPORT_ARGS is a list of options
"$root/build/collide" report --json "$root/build/report.json" --plot "$root/build/report.png" ${REPORT_ARGS:-} ||
  status=$?

pairs="${PAIRS:-1000000}"
if [ "$pairs" != 0 ]; then
  out="$root/build/demo"
  mkdir -p "$out"
  "$root/build/collide" gen --pairs "$pairs" --out "$out/scene" --seed 1
  for precision in float double; do
    "$root/build/collide" solve --bodies "$out/scene/bodies.csv" --contacts "$out/scene/contacts.csv" \
      --out-bodies "$out/bodies-$precision.csv" --out-impulses "$out/impulses-$precision.csv" \
      --precision "$precision" --stats --check || {
      rc=$?
      [ "$status" -ne 0 ] || status=$rc
    }
  done
fi
exit "$status"
