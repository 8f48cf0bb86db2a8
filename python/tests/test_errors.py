"""Bad input raises ValueError with the library's own message (InputError and the kernels'
std::invalid_argument), or a message naming the argument for what only Python can get wrong
(rank, dtype, integer range)."""

import json

import numpy as np
import pytest

import clothcd


@pytest.fixture
def sheet():
    return clothcd.procedural.stacked_sheets(4)


def test_wrong_shapes_and_dtypes(sheet):
    F, V0, V1 = sheet
    det = clothcd.SelfDetector(F, V0)
    with pytest.raises(ValueError, match=r"positions at t1: expected a 50 x 3 position matrix, got 50 x 2"):
        det.detect(V0, V1[:, :2])
    with pytest.raises(ValueError, match=r"expected a \d+ x 3 position matrix, got 3 x 3"):
        det.detect(V0[:3], V1)
    with pytest.raises(ValueError, match=r"V0: expected a float array of shape \(n, 3\), got int64"):
        det.detect(V0.astype(np.int64), V1)
    with pytest.raises(ValueError, match=r"V0: expected a float array .* shape \(150,\)"):
        det.detect(V0.ravel(), V1)
    with pytest.raises(ValueError, match=r"F: expected an integer array of shape \(m, 3\), got float64"):
        clothcd.SelfDetector(F.astype(float), V0)
    with pytest.raises(ValueError, match=r"F: expected an integer array of shape \(m, 3\)"):
        clothcd.SelfDetector(F[:, :2], V0)
    with pytest.raises(ValueError, match="does not fit a 32-bit vertex id"):
        clothcd.SelfDetector(F.astype(np.int64) + 2**40, V0)


def test_non_finite_positions_name_the_vertex(sheet):
    F, V0, V1 = sheet
    det = clothcd.SelfDetector(F, V0)
    bad = V1.copy()
    bad[7, 2] = np.nan
    with pytest.raises(ValueError, match="vertex 7 has a non-finite coordinate"):
        det.detect(V0, bad)
    bad[7, 2] = np.inf
    with pytest.raises(clothcd.InputError, match="vertex 7"):
        det.proximity(bad, 0.1)
    with pytest.raises(ValueError, match="proximity distance must be finite and >= 0"):
        det.proximity(V0, -1.0)


def test_bad_faces_get_the_topology_message(sheet):
    F, V0, _ = sheet
    for bad_id in (len(V0), -1):
        F_bad = F.copy()
        F_bad[3, 1] = bad_id
        with pytest.raises(ValueError, match="face 3"):
            clothcd.SelfDetector(F_bad, V0)
    F_rep = F.copy()
    F_rep[2] = [1, 1, 2]
    with pytest.raises(ValueError, match="face 2"):
        clothcd.SelfDetector(F_rep, V0)


def test_bad_options_and_ids(sheet):
    F, V0, _ = sheet
    with pytest.raises(ValueError, match=r"policy: unknown value 'fast' \(one of"):
        clothcd.SelfDetector(F, V0, policy="fast")
    with pytest.raises(ValueError, match="culling: unknown value"):
        clothcd.SelfDetector(F, V0, culling="all")
    with pytest.raises(ValueError, match="bvh: unknown value"):
        clothcd.SelfDetector(F, V0, bvh="octree")
    with pytest.raises(ValueError, match="thickness must be finite and >= 0"):
        clothcd.SelfDetector(F, V0, thickness=-1)
    with pytest.raises(ValueError, match="threads must be >= 0"):
        clothcd.SelfDetector(F, V0, threads=-2)
    with pytest.raises(ValueError, match=r"linked_vertices: pair \(0, 999\) is out of range"):
        clothcd.SelfDetector(F, V0, linked_vertices=[[0, 999]])
    with pytest.raises(TypeError):
        clothcd.SelfDetector(F, V0, "proposed")  # options are keyword-only
    det = clothcd.SelfDetector(F, V0)
    with pytest.raises(ValueError, match=r"active vertex 500 is out of range \[0, 50\)"):
        det.set_active_vertices([1, 500])
    with pytest.raises(ValueError, match="active face"):
        det.set_active_faces([-3])
    with pytest.raises(ValueError, match="reuse distance must be finite"):
        det.set_options(reuse_distance=float("nan"))


def test_pair_detector_errors(sheet):
    F, V0, _ = sheet
    pd = clothcd.PairDetector(F, V0, F, V0 + 5)
    with pytest.raises(ValueError, match=r"x 3 position matrix"):
        pd.detect(V0, V0, V0[:4], V0)
    with pytest.raises(ValueError, match="Vb1: expected a float array"):
        pd.detect(V0, V0, V0, "abc")


def test_ccd_batches(sheet):
    q = np.zeros((3, 8, 3))
    q[:, :, 0] = np.arange(8)
    with pytest.raises(ValueError, match=r"q: expected a float array of shape \(k, 8, 3\)"):
        clothcd.vertex_face_ccd(q[:, :6])
    with pytest.raises(ValueError, match=r"q: expected a float array of shape \(k, 8, 3\), got int"):
        clothcd.edge_edge_ccd(q.astype(int))
    q[2, 5, 1] = np.nan
    with pytest.raises(ValueError, match=r"^query 2: .*(non-finite|NaN|finite)"):
        clothcd.vertex_face_ccd(q)
    with pytest.raises(ValueError, match="thickness must be finite"):
        clothcd.edge_edge_ccd(q[:2], thickness=-1.0)
    hit, toi = clothcd.vertex_face_ccd(np.empty((0, 8, 3)))
    assert hit.shape == (0,) and toi.shape == (0,)


def test_cones_reject_nan_and_bad_shapes():
    with pytest.raises(ValueError):
        clothcd.merge_tight([0, 0, 1], np.nan, [0, 1, 0], 0.1)
    with pytest.raises(ValueError, match="axis_a: expected a float array of shape"):
        clothcd.merge_provot([0, 1], 0.1, [0, 1, 0], 0.1)
    with pytest.raises(ValueError, match="batches of the same length"):
        clothcd.merge_tight(np.eye(3), [0.1, 0.2], np.eye(3), [0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="policy: unknown value"):
        clothcd.ccd_leaf_cone(np.eye(3), np.eye(3), policy="wide")
    with pytest.raises(ValueError):
        clothcd.optimal_cone(np.empty((0, 3)))


def test_bad_scene_names_the_file_and_key(tmp_path):
    scene = tmp_path / "bad.json"
    scene.write_text(json.dumps({"name": "x", "frames": 2, "cloth": {"grid": {}}, "unknown_key": 1}))
    with pytest.raises(ValueError, match="bad.json"):
        clothcd.simulate(scene, tmp_path / "out")
    with pytest.raises(ValueError, match="frames must be >= 0"):
        clothcd.simulate(scene, tmp_path / "out", frames=-3)
    with pytest.raises(ValueError, match="no manifest"):
        clothcd.read_frames(tmp_path)
