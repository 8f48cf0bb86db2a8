"""scripts/mesh_order.py on a procedural step: it renumbers the pair three ways, checks that every
order reports the same collisions once mapped back (it exits non-zero otherwise), and writes one
table row per order with the collision counts of the given order."""

import os
import re
import subprocess
import sys

import clothcd
from conftest import SOURCE_DIR, tool


def test_every_order_reports_the_same_collisions(tmp_path):
    F, V0, V1 = clothcd.procedural.crumpled_sheet(16, 3)
    t0, t1 = tmp_path / "t0.ply", tmp_path / "t1.ply"
    clothcd.write_mesh(t0, V0, F)
    clothcd.write_mesh(t1, V1, F)
    out = tmp_path / "mesh_order.md"
    done = subprocess.run(
        [sys.executable, str(SOURCE_DIR / "scripts" / "mesh_order.py"), "--bin",
         tool("CLOTHCD_CLI"), "--python-module", os.environ["PYTHONPATH"], "--t0", str(t0),
         "--t1", str(t1), "--reps", "1", "--threads", "1", "--out", str(out)],
        capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    table = out.read_text()
    rows = re.findall(r"^\| 1 \| (given|morton|shuffled) \| (\d+) \|", table, re.M)
    assert [r[0] for r in rows] == ["given", "morton", "shuffled"]
    # The given order is the generator's (a grid): its faces' corners lie close in id.
    assert int(rows[0][1]) < int(rows[2][1])
    found = clothcd.SelfDetector(F, V0, culling="sound").detect(V0, V1)
    assert len(found.vf) + len(found.ee) > 0
    assert f"({len(found.vf)} VF, {len(found.ee)} EE)" in table
