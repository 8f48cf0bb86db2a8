"""`cmake --install` puts the package where the configured interpreter imports it from."""

import os
import subprocess
import sys

from conftest import tool


def test_cmake_install_installs_an_importable_package(tmp_path):
    build = tool("CLOTHCD_BUILD_DIR")
    done = subprocess.run([tool("CLOTHCD_CMAKE"), "--install", build, "--prefix", str(tmp_path)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    packages = list(tmp_path.glob("lib/python3.*/*-packages/clothcd"))
    assert len(packages) == 1
    files = sorted(p.name for p in packages[0].iterdir())
    assert {"__init__.py", "frames.py", "_clothcd.pyi", "py.typed"} <= set(files)
    assert any(f.startswith("_clothcd") and f.endswith(".so") for f in files)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(packages[0].parent)
    check = "import clothcd; print(clothcd.__file__); print(len(clothcd.procedural.stacked_sheets(3)[0]))"
    out = subprocess.run([sys.executable, "-c", check], capture_output=True, text=True, env=env,
                         cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    path, faces = out.stdout.split()
    assert path.startswith(str(packages[0])) and int(faces) == 2 * 2 * 3 * 3
