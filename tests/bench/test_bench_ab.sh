#!/usr/bin/env bash
# scripts/bench-ab.sh turns the order of its builds every round: two stand-in
# benchmarks (shell scripts that print one Google Benchmark CSV median and
# log that they ran) over four rounds run A B, B A, A B, B A, and the summary
# gives each build's median over its rounds and its ratio to the first
# build's. Three builds over three rounds: A B C, B C A, C A B.
set -euo pipefail
root=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
make_bench() {  # name, hundreds of its microseconds (plus its call's number, 1 up)
  cat >"$work/$1" <<SH
#!/bin/sh
echo $1 >>"$work/ran"
n=\$(grep -c . "$work/ran")
echo 'name,iterations,real_time,cpu_time,time_unit'
echo "\"row/x/manual_time_median\",10,\$((100 * $2 + n)),1,us"
SH
  chmod +x "$work/$1"
}
make_bench A 1
make_bench B 2
out=$("$root/scripts/bench-ab.sh" 4 x "A=$work/A" "B=$work/B")
order=$(tr '\n' ' ' <"$work/ran")
[ "$order" = "A B B A A B B A " ] || { echo "order of four rounds of two builds: $order"; exit 1; }
# Medians over the rounds: A ran as calls 1, 4, 5, 8 (101, 104, 105, 108:
# 104.5), B as 2, 3, 6, 7 (202, 203, 206, 207: 204.5).
summary=$(printf '%s\n' "$out" | grep '^row/x ')
[ "$summary" = "row/x  A 104.5 us (1.000)  B 204.5 us (1.957)" ] || { echo "summary: $summary"; exit 1; }
rm -f "$work/ran"
make_bench C 3
"$root/scripts/bench-ab.sh" 3 x "A=$work/A" "B=$work/B" "C=$work/C" >/dev/null
order=$(tr '\n' ' ' <"$work/ran")
[ "$order" = "A B C B C A C A B " ] || { echo "order of three rounds of three builds: $order"; exit 1; }
echo "bench-ab.sh: the builds take turns at running first"
