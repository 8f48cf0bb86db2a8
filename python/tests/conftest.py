"""Shared fixtures: the data folder, the C++ reference tool and the CLI (paths from ctest)."""

import json
import os
import subprocess
from pathlib import Path

import pytest

SOURCE_DIR = Path(os.environ.get("CLOTHCD_SOURCE_DIR", Path(__file__).resolve().parents[2]))


def data_root() -> Path:
    env = os.environ.get("CLOTHCD_DATA")
    if env:
        return Path(env)
    return Path(os.environ.get("CLOTHCD_DATA_DEFAULT", SOURCE_DIR.parent / "shared" / "data"))


def require_data(sub: str) -> Path:
    """The data folder `sub`, or a skip naming where it was looked for (as the C++ tests do)."""
    path = data_root() / sub
    if not path.exists():
        pytest.skip(f"test data {path} not found; set CLOTHCD_DATA to the shared data folder")
    return path


def tool(env_name: str) -> str:
    path = os.environ.get(env_name)
    if not path:
        pytest.fail(f"{env_name} is not set: run these tests through ctest (label python)")
    return path


def reference(**args) -> dict:
    """Runs the C++ reference tool (SelfDetector through the C++ API) and parses its JSON."""
    cmd = [tool("CLOTHCD_REFERENCE")] + [f"{k}={v}" for k, v in args.items()]
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([tool("CLOTHCD_CLI"), *args], capture_output=True, text=True)


TINY_SCENE = {
    "name": "tiny-drop",
    "frames": 4,
    "frame_dt": 0.04,
    "cloth": {
        "grid": {"origin": [-0.3, 0.32, -0.3], "u": [0.6, 0.0, 0.0], "v": [0.0, 0.0, 0.6],
                 "resolution": [12, 12]}
    },
    "material": {"area_density": 0.15, "stretch_stiffness": 260, "poisson": 0.25,
                 "bending_stiffness": 1e-7, "friction": 0.4},
    "body": {"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 0.25, "subdivisions": 2},
    "collisions": {"self": True, "body": True, "thickness": 0.001, "ccd_thickness": 1e-5},
    "output": {"format": "obj"},
}


@pytest.fixture
def tiny_scene(tmp_path) -> Path:
    """A 12 x 12 cloth dropping on a sphere, 4 frames: seconds to simulate."""
    path = tmp_path / "tiny.json"
    path.write_text(json.dumps(TINY_SCENE))
    return path
