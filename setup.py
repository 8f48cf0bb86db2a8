"""Builds the clothcd extension module with the project's CMake build (-DCLOTHCD_PYTHON=ON).

The module is built for the interpreter running this script (sys.executable), passed to CMake as
Python3_EXECUTABLE. Environment: CLOTHCD_BUILD_TYPE (default Release), CMAKE_BUILD_PARALLEL_LEVEL
(default: the CPU count), CMAKE_CXX_COMPILER_LAUNCHER (e.g. ccache), CLOTHCD_CMAKE_ARGS (extra
configure arguments, split on spaces), CLOTHCD_BUILD_DIR (the CMake build folder; default
build/pip-<interpreter tag> in the repository, kept between installs so that a rebuild is
incremental).
"""

import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(clothcd VERSION ([0-9.]+)", f.read())
    if not match:
        raise RuntimeError("CMakeLists.txt: no project(clothcd VERSION ...)")
    return match.group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        tag = f"{sys.implementation.name}{sys.version_info[0]}{sys.version_info[1]}"
        build = os.environ.get("CLOTHCD_BUILD_DIR") or os.path.join(ROOT, "build", f"pip-{tag}")
        os.makedirs(build, exist_ok=True)
        configure = [
            "cmake", "-S", ROOT, "-B", build,
            f"-DCMAKE_BUILD_TYPE={os.environ.get('CLOTHCD_BUILD_TYPE', 'Release')}",
            "-DCLOTHCD_PYTHON=ON",
            "-DCLOTHCD_BUILD_TESTS=OFF",
            "-DCLOTHCD_BUILD_APPS=OFF",
            "-DCLOTHCD_BUILD_BENCH=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
        ] + os.environ.get("CLOTHCD_CMAKE_ARGS", "").split()
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", build, "--target", "_clothcd", "-j", jobs], check=True)
        built = glob.glob(os.path.join(build, "python", "clothcd", "_clothcd*.so")) + glob.glob(
            os.path.join(build, "python", "clothcd", "_clothcd*.pyd"))
        if len(built) != 1:
            raise RuntimeError(f"expected one built _clothcd module in {build}, found {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built[0], target)


setup(
    version=project_version(),
    ext_modules=[CMakeExtension("clothcd._clothcd")],
    cmdclass={"build_ext": CMakeBuild},
)
