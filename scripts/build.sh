#!/usr/bin/env bash
# Configures and builds collide (Release) into build/, after installing what is missing.
#   scripts/build.sh [--target T]... [CMAKE_OPTION]...
#       everything (libraries, tool, tests, benchmarks, Python, examples), or
#       only the targets named: the `release` preset of CMakePresets.json;
#       README command 2
#   scripts/build.sh --tool [CMAKE_OPTION]...
#       the `collide` tool alone, with only its packages (install-deps.sh
#       --tool) and the tests, benchmarks, Python and examples configured
#       off, so none of their packages is needed, and its sources compiled
#       in unity batches (CMAKE_UNITY_BUILD): the `tool` preset; README
#       command 1
# Other arguments go to the configure step after the preset, so they win.
# Either preset names every part ON or OFF, so a build/ that one configured
# is reconfigured by the other.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
preset=release
deps=()
targets=()
configure=()
while [ $# -gt 0 ]; do
  if [ "$1" = --tool ]; then
    preset=tool
    deps=(--tool)
    targets=(--target collide_cli)
    shift
  elif [ "$1" = --target ] && [ $# -ge 2 ]; then
    targets+=(--target "$2")
    shift 2
  else
    configure+=("$1")
    shift
  fi
done
"$root/scripts/install-deps.sh" "${deps[@]}"
# With ccache, paths hashed relative to the build directory (CCACHE_BASEDIR),
# so that the pip install test (setup.py, same layout) reuses these objects.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"
fi
# CMake does not switch a build directory's generator in place: a build/
# that Make configured (before the presets named Ninja) loses its cache and
# is configured anew; ccache gives its objects back.
if [ -f "$root/build/CMakeCache.txt" ] && ! grep -qx 'CMAKE_GENERATOR:INTERNAL=Ninja' "$root/build/CMakeCache.txt"; then
  rm -rf "$root/build/CMakeCache.txt" "$root/build/CMakeFiles"
fi
cmake -S "$root" --preset "$preset" "${launcher[@]}" "${configure[@]}" >/dev/null
# A build preset is read from the source directory's CMakePresets.json.
(cd "$root" && cmake --build --preset "$preset" -j"$(nproc)" "${targets[@]}")
