#!/bin/sh
# The install step of the README for Python, as a test: a fresh venv with
# the system site packages (numpy), `pip install --no-build-isolation` of the
# checkout with no network, then import collide and solve a scene, import
# collide.dask and run its console script.
# usage: python-install-test.sh SOURCE_DIR WORK_DIR   (PYTHON: the interpreter, default /usr/bin/python3)
set -eu
src=$1
work=$2
python=${PYTHON:-/usr/bin/python3}
rm -rf "$work"
mkdir -p "$work"
"$python" -m venv --system-site-packages "$work/venv"
# A copy of the checkout, so the install's build directory is the test's own
# and nothing is written into the source tree.
mkdir -p "$work/src"
(cd "$src" && git ls-files -z --cached --others --exclude-standard | xargs -0 cp --parents -t "$work/src")
start=$(date +%s)
PIP_NO_INDEX=1 "$work/venv/bin/pip" install --no-build-isolation --no-deps -q "$work/src"
echo "pip install took $(($(date +%s) - start)) s"
cd "$work"
"$work/venv/bin/python" - <<'PY'
import numpy as np
import collide
assert collide.__file__.startswith(__import__("sys").prefix), collide.__file__
bodies, contacts = collide.generate("pairs", 10000, dtype=np.float32)
ref = collide.reference_solve(bodies, contacts)
J, stats = collide.solve(bodies, contacts)
err = collide.impulse_error(J, ref)
assert stats["collisions"] == 10000 and float(err.max()) <= collide.error_bound_eps
print("import collide and solve: ok,", stats["isa"], stats["collisions_per_second"], "collisions/s")
import os
from collide import _build
assert os.path.exists(_build.PYTHON), _build.PYTHON  # the interpreter `import collide` names when it cannot run
import collide.dask
assert collide.dask.__file__.startswith(__import__("sys").prefix), collide.dask.__file__
PY
# The command of collide.dask, installed as a console script.
"$work/venv/bin/collide-dask" --help >/dev/null
echo "collide-dask: ok"
