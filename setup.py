"""Builds the extension collide._collide with CMake for `pip install .`.

Only the library and the module are built (no tests, benchmarks, CLI or
examples), in Release, for the interpreter running pip. The build directory
is build-pip-<python tag> under the source tree (kept between installs, so a
second install recompiles only what changed); COLLIDE_PIP_BUILD_DIR
overrides it.

With ccache on PATH every compile goes through it, with CCACHE_BASEDIR set
to the source tree unless the environment sets one: paths are then hashed
relative to the build directory, and since build-pip-<tag> sits one level
under the root like the normal build/, the library's objects (the kernel
objects take minutes each) are the ones the normal build already compiled,
even for a copy of the checkout elsewhere (scripts/build.sh uses ccache the
same way).
"""

import os
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        tag = sysconfig.get_config_var("SOABI") or "py"
        build_dir = os.environ.get("COLLIDE_PIP_BUILD_DIR", os.path.join(ROOT, "build-pip-" + tag))
        configure = [
            "cmake", "-S", ROOT, "-B", build_dir,
            "-DCMAKE_BUILD_TYPE=Release",
            "-DCOLLIDE_BUILD_TESTS=OFF", "-DCOLLIDE_BUILD_BENCH=OFF", "-DCOLLIDE_BUILD_CLI=OFF",
            "-DCOLLIDE_BUILD_EXAMPLES=OFF", "-DCOLLIDE_INSTALL=OFF", "-DCOLLIDE_BUILD_PYTHON=ON",
            "-DPython3_EXECUTABLE=" + sys.executable,
        ]
        # Ninja where it is installed, as the presets build (CMakePresets.json):
        # the same generator lays the objects out as the normal build does, so
        # ccache finds them. A build directory another generator made keeps it.
        cache = os.path.join(build_dir, "CMakeCache.txt")
        if shutil.which("ninja") and not os.path.exists(cache):
            configure += ["-G", "Ninja"]
        env = dict(os.environ)
        if shutil.which("ccache"):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
            env.setdefault("CCACHE_BASEDIR", ROOT)
        subprocess.check_call(configure, env=env)
        jobs = str(os.cpu_count() or 1)
        subprocess.check_call(["cmake", "--build", build_dir, "--target", "_collide", "-j", jobs], env=env)
        built = os.path.join(build_dir, "python", "collide", os.path.basename(self.get_ext_filename(ext.name)))
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)
        # The interpreter the extension is for (python/collide/_build.py.in),
        # which `import collide` names when it cannot run.
        shutil.copyfile(os.path.join(os.path.dirname(built), "_build.py"),
                        os.path.join(os.path.dirname(target), "_build.py"))


setup(ext_modules=[CMakeExtension("collide._collide")], cmdclass={"build_ext": CMakeBuild})
