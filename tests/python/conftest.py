"""Shared fixtures of the collide pytest suite.

COLLIDE_CLI names the `collide` executable of the same build (set by CTest);
COLLIDE_TEST_TMP a scratch directory under the build tree.
"""

import os
import shutil
import subprocess
import tempfile

import pytest


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("COLLIDE_CLI") or shutil.which("collide")
    if not path:
        pytest.fail("COLLIDE_CLI is not set and no collide on PATH: run the suite through ctest")
    return path


@pytest.fixture()
def workdir():
    base = os.environ.get("COLLIDE_TEST_TMP")
    if base:
        os.makedirs(base, exist_ok=True)
    d = tempfile.mkdtemp(prefix="pytest-", dir=base)
    yield d
    shutil.rmtree(d, ignore_errors=True)


def run(args):
    r = subprocess.run(args, capture_output=True, text=True)
    assert r.returncode == 0, f"{args}: exit {r.returncode}\n{r.stderr}"
    return r
