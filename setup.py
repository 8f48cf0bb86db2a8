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
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(clothcd VERSION ([0-9.]+)", f.read())
    if not match:
        raise RuntimeError("CMakeLists.txt: no project(clothcd VERSION ...)")
    return match.group(1)


def missing_build_needs():
    """What the build needs and this machine lacks, as (what, Debian package) pairs."""
    missing = []
    for tool, package in (("cmake", "cmake"), ("c++", "g++"), ("node", "nodejs")):
        if shutil.which(tool) is None:
            missing.append((f"the `{tool}` command", package))
    if not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")):
        missing.append((f"the headers of Python {sys.version_info[0]}.{sys.version_info[1]}",
                        "python3-dev"))
    try:
        import numpy  # noqa: F401
    except ImportError:
        missing.append((f"NumPy for {sys.executable} (Debian's is for /usr/bin/python3 and the "
                        "venvs made from it with --system-site-packages)", "python3-numpy"))
    pybind11_dirs = [os.path.join(prefix, sub, "cmake", "pybind11")
                     for prefix in ("/usr", "/usr/local", sys.prefix)
                     for sub in ("lib", "share", os.path.join("lib", "x86_64-linux-gnu"))]
    try:
        import pybind11
        pybind11_dirs.append(pybind11.get_cmake_dir())
    except ImportError:
        pass
    if not any(os.path.exists(os.path.join(d, "pybind11Config.cmake")) for d in pybind11_dirs):
        missing.append(("pybind11's CMake package", "pybind11-dev"))
    for package in ("three", "esbuild"):
        if not os.path.exists(os.path.join(ROOT, "apps", "viewer", "node_modules", package,
                                           "package.json")):
            missing.append((f"the viewer's npm package {package} (apps/viewer/node_modules)",
                            "npm ci in apps/viewer"))
    return missing


SETUP_HINT = ("Install them with `scripts/setup.sh full` (as root or with sudo): it installs the "
              "Debian packages and the viewer's npm packages, and does nothing when all are "
              "there. Then run `pip install . --no-build-isolation` again.")


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
        missing = missing_build_needs()
        if missing:
            lines = "\n".join(f"  - {what} (Debian: {pkg})" for what, pkg in missing)
            raise SystemExit(f"clothcd: cannot build the Python module; missing:\n{lines}\n"
                             f"{SETUP_HINT}")
        if subprocess.run(configure).returncode != 0:
            raise SystemExit(f"clothcd: CMake could not configure the build (see above). "
                             f"{SETUP_HINT}")
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
