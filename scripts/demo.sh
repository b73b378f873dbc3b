#!/usr/bin/env bash
# README command 1: install what is missing, build, and run the main job on its
# built-in default: a random scene of 1,000,000 colliding pairs, resolved in
# float with --stats, and checked against the long-double reference (--check
# fails the run if any impulse is outside the documented error bound).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/scripts/build.sh"
pairs="${PAIRS:-1000000}"
out="$root/build/demo"
mkdir -p "$out"
"$root/build/collide" gen --pairs "$pairs" --out "$out/scene" --seed 1
for precision in float double; do
  "$root/build/collide" solve --bodies "$out/scene/bodies.csv" --contacts "$out/scene/contacts.csv" \
    --out-bodies "$out/bodies-$precision.csv" --out-impulses "$out/impulses-$precision.csv" \
    --precision "$precision" --stats --check
done
