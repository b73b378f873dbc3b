#!/usr/bin/env bash
# test_isa_objects.sh - proves the one-binary guarantee (collide/isa.hpp) on the
# compiled objects (run by ctest, see tests/core/CMakeLists.txt).
#
# The kernel is compiled once per ISA into the same library, each ISA's as
# objects of its own (one per body model, and its table: core/src/kernel/).
# If an object compiled for AVX2 or AVX-512 defined a function with vague
# linkage (an inline function or a template instantiation, emitted as a weak
# symbol) that an object of another ISA also uses, the linker could keep the
# wide copy for every caller, and the baseline path would execute AVX
# instructions on a CPU without them. So:
#   1. no weak function (nm type W) that a wide ISA's objects define is
#      defined or referenced by any object outside that ISA's (in an
#      optimised build the wide objects define no weak function at all; in a
#      debug build the ones they define carry the ISA's namespace in their
#      names, and this checks it). Weak data (type V: typeinfo that the
#      sanitizers emit) is the same bytes whatever the ISA and is not code;
#   2. the baseline objects (the SSE2 kernel's, the one-lane loops', and
#      every other object of the library) contain no ymm or zmm register
#      outside target_clones' AVX2 clones (dispatched on CPUID by their
#      resolver), and the AVX2 objects no zmm;
#   3. no fused multiply-add instruction in any object (the floating-point
#      policy: AVX-512 includes FMA, and only -ffp-contract=off keeps the
#      compiler from using it);
#   4. the checks can fail: every AVX2 object of kernel loops does use ymm
#      and every AVX-512 one zmm (otherwise the grep would prove nothing).
#
# Usage: test_isa_objects.sh NM OBJDUMP --avx2 OBJECT... --avx512 OBJECT... --baseline OBJECT...
set -euo pipefail
nm_tool=$1 objdump_tool=$2
shift 2
usage() {
  echo "usage: $0 NM OBJDUMP --avx2 OBJECT... --avx512 OBJECT... --baseline OBJECT..." >&2
  exit 2
}
avx2=() avx512=() baseline=()
group=
for arg in "$@"; do
  case "$group:$arg" in
    *:--avx2 | *:--avx512 | *:--baseline) group=${arg#--} ;;
    avx2:*) avx2+=("$arg") ;;
    avx512:*) avx512+=("$arg") ;;
    baseline:*) baseline+=("$arg") ;;
    *) usage ;;
  esac
done
[ ${#avx2[@]} -gt 0 ] && [ ${#avx512[@]} -gt 0 ] && [ ${#baseline[@]} -gt 0 ] || usage
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0

# 1. Weak symbols of each wide ISA's objects against every other object's symbols.
weak() { "$nm_tool" --defined-only "$@" 2>/dev/null | awk '$2 ~ /^[Ww]$/ {print $3}' | sort -u; }
names() { "$nm_tool" "$@" 2>/dev/null | awk 'NF >= 2 {print $NF}' | sort -u; }
for isa in avx2 avx512; do
  if [ "$isa" = avx2 ]; then
    mine=("${avx2[@]}") others=("${avx512[@]}" "${baseline[@]}")
  else
    mine=("${avx512[@]}") others=("${avx2[@]}" "${baseline[@]}")
  fi
  weak "${mine[@]}" >"$tmp/weak"
  names "${others[@]}" >"$tmp/others"
  shared=$(comm -12 "$tmp/weak" "$tmp/others")
  echo "$isa: ${#mine[@]} objects, $(wc -l <"$tmp/weak") weak functions, $(printf '%s' "$shared" | grep -c . || true) shared with other objects"
  if [ -n "$shared" ]; then
    echo "FAIL: weak symbols of the $isa objects that other objects also define or use:" >&2
    printf '%s\n' "$shared" | head -20 >&2
    failed=1
  fi
done

# 2. No wide registers in the baseline objects, no zmm in the AVX2 objects.
#    (Disassembly to a file first: grep -q closing the pipe early would make
#    objdump fail under pipefail.)
#    The one exception: a function clone that GCC's target_clones made for
#    AVX2 (symbol suffix .avx2), which runs only when its ifunc resolver has
#    asked the CPU; its zmm use is still refused.
wide_outside_clones() {
  awk '/^[0-9a-f]+ <.*>:$/ { clone = ($0 ~ /\.avx2>:$/) }
       /%zmm[0-9]/ || (!clone && /%ymm[0-9]/) { print; exit }' "$1"
}
for o in "${baseline[@]}"; do
  "$objdump_tool" -d --no-show-raw-insn "$o" >"$tmp/asm"
  wide_outside_clones "$tmp/asm" >"$tmp/hit"
  if [ -s "$tmp/hit" ]; then
    echo "FAIL: baseline object $o uses a wide register: $(cat "$tmp/hit")" >&2
    failed=1
  fi
done
echo "baseline: ${#baseline[@]} objects checked for ymm/zmm"
for o in "${avx2[@]}"; do
  "$objdump_tool" -d --no-show-raw-insn "$o" >"$tmp/asm"
  if grep -m1 -E '%zmm[0-9]' "$tmp/asm" >"$tmp/hit"; then
    echo "FAIL: the AVX2 object $o uses zmm registers: $(cat "$tmp/hit")" >&2
    failed=1
  fi
done

# 3. No FMA anywhere.
for o in "${avx2[@]}" "${avx512[@]}" "${baseline[@]}"; do
  "$objdump_tool" -d --no-show-raw-insn "$o" >"$tmp/asm"
  if grep -m1 -E 'vf(n)?m(add|sub)[0-9]{3}' "$tmp/asm" >"$tmp/hit"; then
    echo "FAIL: $o contains a fused multiply-add: $(cat "$tmp/hit")" >&2
    failed=1
  fi
done

# 4. The wide objects of kernel loops (all but the ISA's table, table.cpp's
#    object) do use their registers.
used=0
for isa in avx2 avx512; do
  if [ "$isa" = avx2 ]; then mine=("${avx2[@]}") reg=ymm; else mine=("${avx512[@]}") reg=zmm; fi
  for o in "${mine[@]}"; do
    case "$(basename "$o")" in table.*) continue ;; esac
    "$objdump_tool" -d --no-show-raw-insn "$o" >"$tmp/asm"
    if ! grep -q -E "%$reg[0-9]" "$tmp/asm"; then
      echo "FAIL: the $isa object $o has no $reg register: is it compiled for $isa?" >&2
      failed=1
    fi
    used=$((used + 1))
  done
done
if [ "$used" -lt 2 ]; then
  echo "FAIL: no wide object of kernel loops was checked for its registers" >&2
  failed=1
fi
echo "wide: $used objects of kernel loops checked for their registers"

[ "$failed" -eq 0 ] && echo "test_isa_objects: passed"
exit "$failed"
