"""The simulator through Python: the same frames as `clothcd simulate`, progress after every
frame, an exception from the callback stops the run, frames read back from the folder."""

import filecmp

import numpy as np
import pytest

import clothcd
from conftest import cli


def test_simulate_writes_the_frames_the_cli_writes(tmp_path, tiny_scene):
    seen = []
    stats = clothcd.simulate(tiny_scene, tmp_path / "py", frames=3,
                             progress=lambda s, total: seen.append((s["frame"], total)))
    assert seen == [(1, 3), (2, 3), (3, 3)]
    assert [s["frame"] for s in stats] == [1, 2, 3]
    assert all(s["substeps"] >= 4 and s["finite"] for s in stats)
    done = cli("simulate", str(tiny_scene), "--out", str(tmp_path / "cli"), "--frames", "3")
    assert done.returncode == 0, done.stderr
    for k in range(4):
        name = f"frame_{k:04d}.obj"
        assert filecmp.cmp(tmp_path / "py" / name, tmp_path / "cli" / name, shallow=False), name

    F, V = clothcd.read_frames(tmp_path / "py")
    manifest = clothcd.read_manifest(tmp_path / "py")
    assert V.shape == (4, manifest["vertices"], 3) and F.shape == (manifest["faces"], 3)
    for k in range(4):
        Vk, Fk = clothcd.read_mesh(tmp_path / "py" / f"frame_{k:04d}.obj")
        assert np.array_equal(V[k], Vk) and np.array_equal(F, Fk)
    # The cloth falls: its lowest point moves down.
    assert V[3, :, 1].min() < V[0, :, 1].min()
    F2, V2 = clothcd.read_frames(tmp_path / "py", frames=[3, 1])
    assert np.array_equal(V2, V[[3, 1]])
    with pytest.raises(ValueError, match="frame 4 is not complete"):
        clothcd.read_frames(tmp_path / "py", frames=[4])

    # Resume continues from the last complete frame.
    more = clothcd.simulate(tiny_scene, tmp_path / "py", frames=4, resume=True)
    assert [s["frame"] for s in more] == [4]
    assert clothcd.read_manifest(tmp_path / "py")["complete_frames"] == 4


def test_an_exception_in_progress_stops_the_run(tmp_path, tiny_scene):
    class Stop(Exception):
        pass

    def progress(stats, total):
        if stats["frame"] == 2:
            raise Stop("enough")

    with pytest.raises(Stop, match="enough"):
        clothcd.simulate(tiny_scene, tmp_path / "out", progress=progress, threads=1)
    # The frames written before it stay readable.
    F, V = clothcd.read_frames(tmp_path / "out")
    assert len(V) >= 2
