"""The examples in examples/python run on small data and print what the library computes."""

import os
import re
import subprocess
import sys

import numpy as np

import clothcd
from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "examples" / "python"


def run(script, *args, cwd):
    done = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr
    return done.stdout


def is_png(path):
    return path.exists() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_culling_counts(tmp_path):
    F, V0, V1 = clothcd.procedural.winding_strip()
    clothcd.write_mesh(tmp_path / "t0.ply", V0, F)
    clothcd.write_mesh(tmp_path / "t1.ply", V1, F)
    out = run("culling_counts.py", "--t0", tmp_path / "t0.ply", "--t1", tmp_path / "t1.ply",
              "--out", tmp_path / "counts.png", cwd=tmp_path)
    assert is_png(tmp_path / "counts.png")
    rows = {(m[1], m[2]): (int(m[3]), int(m[4])) for m in
            re.finditer(r"^(\w+)\s+(\w+)\s+(\d+)\s+\d+\s+\d+\s+(\d+)$", out, re.M)}
    assert len(rows) == 1 + 3 * 3
    det = clothcd.SelfDetector(F, V0, culling="sound", policy="provot")
    assert rows["sound", "provot"][0] == det.detect(V0, V1).stats["triangle_pairs"]
    assert all(rows["sound", p][1] == 0 for p in ("provot", "proposed", "exact"))
    # The winding strip is where the gated rule misses collisions.
    assert rows["gated", "proposed"][1] > 0


def test_spread_angles_and_meshio_frames(tmp_path, tiny_scene):
    work = tmp_path / "sim"
    out = run("spread_angles.py", "--scene", tiny_scene, "--frames", 2, "--work", work,
              "--out", tmp_path / "spread.png", cwd=tmp_path)
    assert is_png(tmp_path / "spread.png")
    F, V = clothcd.read_frames(work)
    lines = re.findall(r"^\s+(\d+) (provot|proposed)\s+([\d.]+)°", out, re.M)
    assert len(lines) == 4
    for step, policy, median in lines:
        k = int(step)
        _, angles = clothcd.ccd_leaf_cone(V[k - 1][F], V[k][F], policy="tang" if policy == "provot" else policy)
        want = np.median(np.degrees(angles[angles < clothcd.SATURATED_HALF_ANGLE]))
        assert float(median) == float(f"{want:.4f}")
    # PROPOSED's leaf cones are never wider than PROVOT's.
    medians = {(int(s), p): float(m) for s, p, m in lines}
    assert all(medians[k, "proposed"] <= medians[k, "provot"] for k in (1, 2))

    out = run("read_frames_meshio.py", work, "--vtu", tmp_path / "vtu", cwd=tmp_path)
    lowest = [float(x) for x in re.findall(r"lowest y ([-+\d.]+)", out)]
    assert lowest == [float(f"{v:+.5f}") for v in V[:, :, 1].min(axis=1)]
    assert sorted(p.name for p in (tmp_path / "vtu").iterdir()) == [f"frame_{k:04d}.vtu" for k in range(3)]


def test_line_search_stops_short_of_contact(tmp_path):
    out = run("line_search.py", cwd=tmp_path)
    steps = [float(m[1]) for m in re.finditer(r"step (\S+)", out)]
    assert len(steps) == 4 and all(0 < s < 1 for s in steps)
    # The path the example took, as one motion from V0: nothing comes within the thickness.
    F, V0, V1 = clothcd.procedural.stacked_sheets(12)
    x = V0 + sum(steps) * (V1 - V0)
    r = clothcd.SelfDetector(F, V0, thickness=1e-3).detect(V0, x)
    assert len(r.vf) == 0 and len(r.ee) == 0
    full = clothcd.SelfDetector(F, V0, thickness=1e-3).detect(V0, V1)
    assert len(full.vf) + len(full.ee) > 0  # the full step would have collided
