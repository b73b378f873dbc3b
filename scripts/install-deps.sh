#!/usr/bin/env bash
# Installs, from Debian's packages, whatever the build needs and is missing.
# Downloads nothing else. Run as root, or with sudo available.
set -euo pipefail

# libdeflate-dev: the CRC-32 of the .npz scene writer.
# gnuplot-nox draws the report's plot and the debris example's picture;
# libbullet-dev gives `collide report` its peer row (optional in CMake).
# pybind11-dev and the python3-* packages: the Python extension (python/), its
# tests (pytest) and examples (matplotlib), and `pip install .` in a venv with
# no network (venv, setuptools, pip).
# python3-dask, python3-distributed, python3-pandas: collide.dask (python/collide/dask),
# the solve split across Dask workers by islands and solve_scenes' table, and its
# tests on a LocalCluster (tests/python/test_dask.py); `import collide` does not need them.
# ccache: scripts/build.sh and setup.py compile through it when present, so the
# pip install test reuses the normal build's objects (python/CMakeLists.txt).
# clang-14 and its runtimes: the ASan/UBSan, TSan and libFuzzer builds of
# scripts/ci-sanitizers.sh; clang-tidy-14: scripts/clang-tidy.sh.
packages=(g++ cmake make ccache pkg-config libeigen3-dev libtbb-dev libdeflate-dev libbenchmark-dev libgtest-dev gnuplot-nox libbullet-dev
  clang-14 libclang-rt-14-dev clang-tidy-14
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib python3-venv python3-setuptools python3-pip
  python3-dask python3-distributed python3-pandas)

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
