#!/usr/bin/env bash
# Installs, from Debian's packages, whatever the build needs and is missing.
# Downloads nothing else. Run as root, or with sudo available.
#   scripts/install-deps.sh          everything: the libraries, the tools, the
#                                    tests, the benchmarks, Python, sanitizers
#   scripts/install-deps.sh --tool   only what the `collide` tool's build and
#                                    its report need (README command 1)
set -euo pipefail

# The tool: the compiler and CMake; TBB (the threads), libdeflate-dev (the
# CRC-32 of the .npz scene writer), pkg-config (which finds libdeflate);
# gnuplot-nox draws the report's plot (and the debris example's picture);
# libbullet-dev gives `collide report` its peer row (optional in CMake).
# ccache: scripts/build.sh and setup.py compile through it when present, so the
# pip install test reuses the normal build's objects (python/CMakeLists.txt).
# ninja-build: the presets' generator (CMakePresets.json): it compiles a
# target's sources while the libraries it links are still compiling, where
# Make waits for each library, so both cores stay busy (decision 0050).
tool=(g++ cmake make ninja-build ccache pkg-config libtbb-dev libdeflate-dev gnuplot-nox libbullet-dev)
# The rest: Eigen (the tests' cross-check and the benchmarks' lane
# comparison), Google Benchmark and GoogleTest.
# clang-14 and its runtimes: the ASan/UBSan, TSan and libFuzzer builds of
# scripts/ci-sanitizers.sh; clang-tidy-14: scripts/clang-tidy.sh. lld: the
# linker of the tests' fifty programs, faster than GNU ld (cmake/flags.cmake;
# the build falls back to GNU ld without it).
# pybind11-dev and the python3-* packages: the Python extension (python/), its
# tests (pytest) and examples (matplotlib), and `pip install .` in a venv with
# no network (venv, setuptools, pip).
# python3-dask, python3-distributed, python3-pandas: collide.dask (python/collide/dask),
# the solve split across Dask workers by islands and solve_scenes' table, and its
# tests on a LocalCluster (tests/python/test_dask.py); `import collide` does not need them.
rest=(libeigen3-dev libbenchmark-dev libgtest-dev
  clang-14 libclang-rt-14-dev clang-tidy-14 lld
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib python3-venv python3-setuptools python3-pip
  python3-dask python3-distributed python3-pandas)

case "${1:-}" in
  "") packages=("${tool[@]}" "${rest[@]}") ;;
  --tool) packages=("${tool[@]}") ;;
  *)
    echo "usage: scripts/install-deps.sh [--tool]" >&2
    exit 2
    ;;
esac

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "installing: ${missing[*]}" >&2
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
