"""cloth_ball frames 92 -> 93 (CLOTHCD_DATA/cloth-ball) through Python: every ground-truth-positive
VF and EE pair is reported by the unculled and the sound detector for each cone policy and both
BVH builds (as tests/detect/cloth_ball_test.cpp checks through C++), and one configuration
returns exactly what the C++ API returns."""

import json

import numpy as np
import pytest

import clothcd
from conftest import reference, require_data


@pytest.fixture(scope="module")
def ball():
    root = require_data("cloth-ball")
    V0, F = clothcd.read_mesh(root / "frames/cloth_ball92.ply")
    V1, F1 = clothcd.read_mesh(root / "frames/cloth_ball93.ply")
    assert np.array_equal(F, F1)
    nv, ne = len(V0), len(clothcd.mesh_edges(F))

    def load(name):
        return json.loads((root / name).read_text())

    vf, vf_truth = load("boxes/92vf.json"), load("mma_bool/92vf_mma_bool.json")
    ee, ee_truth = load("boxes/92ee.json"), load("mma_bool/92ee_mma_bool.json")
    assert len(vf) == len(vf_truth) and len(ee) == len(ee_truth)
    gt_vf = {(v, f - nv - ne) for (v, f), t in zip(vf, vf_truth) if t}
    gt_ee = {tuple(sorted((a - nv, b - nv))) for (a, b), t in zip(ee, ee_truth) if t}
    assert (len(gt_vf), len(gt_ee)) == (19032, 94822)
    return root, F, V0, V1, gt_vf, gt_ee


CONFIGS = [
    ("spatial", "none", "proposed"),
    ("spatial", "sound", "provot"),
    ("spatial", "sound", "proposed"),
    ("spatial", "sound", "exact"),
    ("patch", "none", "exact"),
    ("patch", "sound", "proposed"),
]


def test_no_false_negatives(ball):
    _, F, V0, V1, gt_vf, gt_ee = ball
    det = None
    built = None
    for bvh, culling, policy in CONFIGS:
        if built != bvh:
            det = clothcd.SelfDetector(F, V0, bvh=bvh)
            built = bvh
        det.set_options(culling=culling, policy=policy)
        r = det.detect(V0, V1)
        vf = set(map(tuple, r.vf.tolist()))
        ee = set(map(tuple, r.ee.tolist()))
        assert len(gt_vf - vf) == 0, (bvh, culling, policy)
        assert len(gt_ee - ee) == 0, (bvh, culling, policy)


def test_same_results_as_the_cpp_api(ball):
    root, F, V0, V1, _, _ = ball
    ref = reference(t0=root / "frames/cloth_ball92.ply", t1=root / "frames/cloth_ball93.ply",
                    bvh="patch", culling="sound", policy="proposed")
    r = clothcd.SelfDetector(F, V0, bvh="patch", culling="sound", policy="proposed").detect(V0, V1)
    ref_vf = np.array(ref["vf"]).reshape(-1, 3)
    ref_ee = np.array(ref["ee"]).reshape(-1, 3)
    assert np.array_equal(r.vf, ref_vf[:, :2].astype(np.int32))
    assert np.array_equal(r.vf_toi, ref_vf[:, 2])
    assert np.array_equal(r.ee, ref_ee[:, :2].astype(np.int32))
    assert np.array_equal(r.ee_toi, ref_ee[:, 2])
    for key, value in ref["stats"].items():
        assert r.stats[key] == value, key
