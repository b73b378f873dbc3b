#!/usr/bin/env bash
# Configures and builds collide (Release) into build/, after installing what is missing.
#   scripts/build.sh [--target T]... [CMAKE_OPTION]...
# builds every target, or only the targets named (README command 1 builds
# only the `collide` tool: --target collide_cli); other arguments go to the
# configure step.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
targets=()
configure=()
while [ $# -gt 0 ]; do
  if [ "$1" = --target ] && [ $# -ge 2 ]; then
    targets+=(--target "$2")
    shift 2
  else
    configure+=("$1")
    shift
  fi
done
"$root/scripts/install-deps.sh"
# With ccache, paths hashed relative to the build directory (CCACHE_BASEDIR),
# so that the pip install test (setup.py, same layout) reuses these objects.
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$root}"
fi
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" "${configure[@]}" >/dev/null
cmake --build "$root/build" -j"$(nproc)" "${targets[@]}"
