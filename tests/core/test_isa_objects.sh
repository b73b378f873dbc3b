#!/usr/bin/env bash
# test_isa_objects.sh - proves the one-binary guarantee (collide/isa.hpp) on the
# compiled objects (run by ctest, see tests/core/CMakeLists.txt).
#
# The kernel is compiled once per ISA into the same library. If an object
# compiled for AVX2 or AVX-512 defined a function with vague linkage (an
# inline function or a template instantiation, emitted as a weak symbol) that
# another object also uses, the linker could keep the wide copy for every
# caller, and the baseline path would execute AVX instructions on a CPU
# without them. So:
#   1. no weak function (nm type W) that a wide object defines is defined or
#      referenced by any other object of the library (in an optimised build
#      the wide objects define no weak function at all; in a debug build the
#      ones they define carry the ISA's namespace in their names, and this
#      checks it). Weak data (type V: typeinfo that the sanitizers emit) is
#      the same bytes whatever the ISA and is not code;
#   2. the baseline objects (the SSE2 kernel and every other object of the
#      library) contain no ymm or zmm register outside target_clones' AVX2
#      clones (dispatched on CPUID by their resolver), and the AVX2 object no
#      zmm;
#   3. no fused multiply-add instruction in any object (the floating-point
#      policy: AVX-512 includes FMA, and only -ffp-contract=off keeps the
#      compiler from using it);
#   4. the checks can fail: the AVX2 object does use ymm and the AVX-512
#      object zmm (otherwise the grep would prove nothing).
#
# Usage: test_isa_objects.sh NM OBJDUMP AVX2_OBJECT AVX512_OBJECT BASELINE_OBJECT...
set -euo pipefail
nm_tool=$1 objdump_tool=$2 avx2=$3 avx512=$4
shift 4
baseline=("$@")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0

# 1. Weak symbols of each wide object against every other object's symbols.
weak() { "$nm_tool" --defined-only "$1" | awk '$2 ~ /^[Ww]$/ {print $3}' | sort -u; }
names() { "$nm_tool" "$@" 2>/dev/null | awk 'NF >= 2 {print $NF}' | sort -u; }
for wide in "$avx2" "$avx512"; do
  others=()
  for o in "$avx2" "$avx512" "${baseline[@]}"; do [ "$o" != "$wide" ] && others+=("$o"); done
  weak "$wide" >"$tmp/weak"
  names "${others[@]}" >"$tmp/others"
  shared=$(comm -12 "$tmp/weak" "$tmp/others")
  echo "$(basename "$(dirname "$(dirname "$wide")")"): $(wc -l <"$tmp/weak") weak functions, $(printf '%s' "$shared" | grep -c . || true) shared with other objects"
  if [ -n "$shared" ]; then
    echo "FAIL: weak symbols of $wide that other objects also define or use:" >&2
    printf '%s\n' "$shared" | head -20 >&2
    failed=1
  fi
done

# 2. No wide registers in the baseline objects, no zmm in the AVX2 object.
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
"$objdump_tool" -d --no-show-raw-insn "$avx2" >"$tmp/avx2.asm"
"$objdump_tool" -d --no-show-raw-insn "$avx512" >"$tmp/avx512.asm"
if grep -q -E '%zmm[0-9]' "$tmp/avx2.asm"; then
  echo "FAIL: the AVX2 object uses zmm registers" >&2
  failed=1
fi

# 3. No FMA anywhere.
for o in "$avx2" "$avx512" "${baseline[@]}"; do
  "$objdump_tool" -d --no-show-raw-insn "$o" >"$tmp/asm"
  if grep -m1 -E 'vf(n)?m(add|sub)[0-9]{3}' "$tmp/asm" >"$tmp/hit"; then
    echo "FAIL: $o contains a fused multiply-add: $(cat "$tmp/hit")" >&2
    failed=1
  fi
done

# 4. The wide objects do use their registers.
if ! grep -q -E '%ymm[0-9]' "$tmp/avx2.asm"; then
  echo "FAIL: the AVX2 object has no ymm register: is it compiled for AVX2?" >&2
  failed=1
fi
if ! grep -q -E '%zmm[0-9]' "$tmp/avx512.asm"; then
  echo "FAIL: the AVX-512 object has no zmm register: is it compiled for AVX-512?" >&2
  failed=1
fi

[ "$failed" -eq 0 ] && echo "test_isa_objects: passed"
exit "$failed"
