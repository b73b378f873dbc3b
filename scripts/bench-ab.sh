#!/usr/bin/env bash
# Alternated rounds of several collide_bench builds on the same rows: each
# round runs every build once, so that the machine's drift over the rounds
# falls on all of them alike, and the order turns by one build a round
# (A B, then B A; A B C, B C A, C A B), so that each build runs first as
# often as the others when the rounds are a multiple of the builds: a build
# that ran first in every round came out faster than the same code run
# second (docs/decisions/0053-builds-take-turns-at-running-first.md).
# Prints one line per build, round and row: `round label row median_us`
# (the median of REPETITIONS repetitions, default 3, at least 2: Google
# Benchmark's aggregate), then, per row, each build's median over the
# rounds and its ratio to the first build's.
#
#   scripts/bench-ab.sh ROUNDS FILTER LABEL=BENCH [LABEL=BENCH]...
#
# A null pair is the same binary under two labels. The ISA is the row's
# (isa/... rows name it) or COLLIDE_ISA's, which the environment passes on.
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 ROUNDS FILTER LABEL=BENCH [LABEL=BENCH]..." >&2
  exit 2
fi
rounds=$1
filter=$2
shift 2
out=$(mktemp)
trap 'rm -f "$out"' EXIT
builds=("$@")
for r in $(seq 1 "$rounds"); do
  for k in $(seq 0 $(($# - 1))); do
    build=${builds[$(((r - 1 + k) % $#))]}
    label=${build%%=*}
    bench=${build#*=}
    "$bench" --benchmark_filter="$filter" --benchmark_repetitions="${REPETITIONS:-3}" \
      --benchmark_report_aggregates_only=true --benchmark_format=csv 2>/dev/null |
      awk -F, -v r="$r" -v b="$label" '/_median"/ { gsub(/"/, "", $1); sub(/\/manual_time_median$|_median$/, "", $1); print r, b, $1, $3 }' |
      tee -a "$out"
  done
done
first=${1%%=*}
echo
awk -v first="$first" '
  { t[$3, $2, $1] = $4; rows[$3] = 1; if (!($2 in seen)) { seen[$2] = 1; order[++n] = $2 } if ($1 > R) R = $1 }
  function median(row, b,   i, k, v, tmp) {
    k = 0
    for (i = 1; i <= R; ++i) if ((row, b, i) in t) v[++k] = t[row, b, i]
    for (i = 1; i <= k; ++i) for (j = i + 1; j <= k; ++j) if (v[j] < v[i]) { tmp = v[i]; v[i] = v[j]; v[j] = tmp }
    return k % 2 ? v[(k + 1) / 2] : (v[k / 2] + v[k / 2 + 1]) / 2
  }
  END {
    for (row in rows) {
      line = row; base = median(row, first)
      for (i = 1; i <= n; ++i) { m = median(row, order[i]); line = line sprintf("  %s %.1f us (%.3f)", order[i], m, m / base) }
      print line
    }
  }' "$out" | sort
