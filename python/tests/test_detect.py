"""SelfDetector and PairDetector through Python: the same pairs, times of impact and counters as
the C++ API (the reference tool) on the procedural scenes, the brute-force oracle's pairs where
the culling is sound, and the documented meaning of edges, restrictions and proximity."""

import itertools

import numpy as np
import pytest

import clothcd
from conftest import reference

SCENES = {
    "stacked_sheets": (lambda: clothcd.procedural.stacked_sheets(12), {"n": 12}),
    "winding_strip": (lambda: clothcd.procedural.winding_strip(96, 3), {"segments": 96, "rings": 3}),
    "crumpled_sheet": (lambda: clothcd.procedural.crumpled_sheet(16, 3), {"n": 16, "seed": 3}),
    "twisted_strip": (lambda: clothcd.procedural.twisted_strip(40, 3), {"segments": 40, "width": 3}),
}
CONFIGS = [
    dict(culling=c, policy=p, bvh=b)
    for c, p, b in itertools.product(
        ["none", "cone", "gated", "sound"], ["provot", "proposed"], ["spatial", "patch"]
    )
] + [dict(culling="sound", policy="exact", bvh="patch"), dict(culling="sound", policy="optimal", bvh="patch")]


def pairs(ids, toi):
    return [(int(a), int(b), float(t)) for (a, b), t in zip(ids, toi)]


@pytest.mark.parametrize("name", SCENES)
def test_same_results_as_the_cpp_api(name):
    make, scene_args = SCENES[name]
    F, V0, V1 = make()
    # Thickness makes the kernels costly on the sheets' deep crossings: one scene is enough.
    thick = [dict(culling="none", policy="proposed", bvh="spatial", thickness=1e-3)]
    for config in CONFIGS + (thick if name == "crumpled_sheet" else []):
        ref = reference(scene=name, **scene_args, **config)
        det = clothcd.SelfDetector(F, V0, **config)
        r = det.detect(V0, V1)
        assert pairs(r.vf, r.vf_toi) == [tuple(x) for x in ref["vf"]], config
        assert pairs(r.ee, r.ee_toi) == [tuple(x) for x in ref["ee"]], config
        for key, value in ref["stats"].items():
            assert r.stats[key] == value, (config, key)
        assert r.vf.dtype == np.int32 and r.vf.shape == (len(ref["vf"]), 2)
        assert r.ee_toi.dtype == np.float64


@pytest.mark.parametrize("name", SCENES)
def test_sound_culling_finds_what_brute_force_finds(name):
    make, scene_args = SCENES[name]
    F, V0, V1 = make()
    oracle = reference(scene=name, **scene_args, culling="none", oracle=1)["oracle"]
    want_vf = {(a, b) for a, b, _ in oracle["vf"]}
    want_ee = {(a, b) for a, b, _ in oracle["ee"]}
    assert want_vf or want_ee  # every scene collides
    for bvh in ["spatial", "patch"]:
        det = clothcd.SelfDetector(F, V0, culling="sound", bvh=bvh)
        r = det.detect(V0, V1)
        assert {tuple(p) for p in r.vf.tolist()} == want_vf
        assert {tuple(p) for p in r.ee.tolist()} == want_ee


def test_thread_count_does_not_change_results():
    F, V0, V1 = clothcd.procedural.crumpled_sheet(24, 5)
    one = clothcd.SelfDetector(F, V0, threads=1).detect(V0, V1)
    two = clothcd.SelfDetector(F, V0, threads=2).detect(V0, V1)
    every = clothcd.SelfDetector(F, V0).detect(V0, V1)
    for r in (two, every):
        assert np.array_equal(r.vf, one.vf) and np.array_equal(r.vf_toi, one.vf_toi)
        assert np.array_equal(r.ee, one.ee) and np.array_equal(r.ee_toi, one.ee_toi)


def test_edges_are_the_ee_numbering():
    F, V0, V1 = clothcd.procedural.twisted_strip()
    det = clothcd.SelfDetector(F, V0)
    edges = det.edges
    # Unique undirected edges, smaller id first, sorted by (larger id, smaller id).
    want = sorted({tuple(sorted((int(f[i]), int(f[(i + 1) % 3])))) for f in F for i in range(3)},
                  key=lambda e: (e[1], e[0]))
    assert edges.tolist() == [list(e) for e in want]
    assert np.array_equal(clothcd.mesh_edges(F), edges)
    r = det.detect(V0, V1)
    assert len(r.ee) > 0
    assert np.all(r.ee[:, 0] < r.ee[:, 1])
    # EE pairs never share a vertex (such pairs are adjacent, not collisions).
    a, b = edges[r.ee[:, 0]], edges[r.ee[:, 1]]
    assert not np.any((a[:, :, None] == b[:, None, :]).any(axis=(1, 2)))


def test_active_vertices_keep_exactly_the_pairs_touching_them():
    F, V0, V1 = clothcd.procedural.crumpled_sheet(20, 7)
    det = clothcd.SelfDetector(F, V0, culling="none")
    full = det.detect(V0, V1)
    active = np.arange(0, det.num_vertices, 3)
    det.set_active_vertices(active)
    part = det.detect(V0, V1)
    flag = np.zeros(det.num_vertices, bool)
    flag[active] = True
    vf_keep = flag[full.vf[:, 0]] | flag[F[full.vf[:, 1]]].any(axis=1)
    ee_keep = flag[det.edges[full.ee[:, 0]]].any(axis=1) | flag[det.edges[full.ee[:, 1]]].any(axis=1)
    assert 0 < vf_keep.sum() < len(full.vf) or 0 < ee_keep.sum() < len(full.ee)
    assert np.array_equal(part.vf, full.vf[vf_keep])
    assert np.array_equal(part.ee, full.ee[ee_keep])
    det.clear_active()
    again = det.detect(V0, V1)
    assert np.array_equal(again.vf, full.vf) and np.array_equal(again.ee, full.ee)


def point_triangle_distance(p, a, b, c):
    """Distance from p to triangle abc (closest point by regions, Ericson 5.1.5)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = ab @ ap, ac @ ap
    if d1 <= 0 and d2 <= 0:
        return np.linalg.norm(ap)
    bp = p - b
    d3, d4 = ab @ bp, ac @ bp
    if d3 >= 0 and d4 <= d3:
        return np.linalg.norm(bp)
    vc = d1 * d4 - d3 * d2
    if vc <= 0 and d1 >= 0 and d3 <= 0:
        return np.linalg.norm(p - (a + d1 / (d1 - d3) * ab))
    cp = p - c
    d5, d6 = ab @ cp, ac @ cp
    if d6 >= 0 and d5 <= d6:
        return np.linalg.norm(cp)
    vb = d5 * d2 - d1 * d6
    if vb <= 0 and d2 >= 0 and d6 <= 0:
        return np.linalg.norm(p - (a + d2 / (d2 - d6) * ac))
    va = d3 * d6 - d5 * d4
    if va <= 0 and d4 - d3 >= 0 and d5 - d6 >= 0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return np.linalg.norm(p - (b + w * (c - b)))
    denom = 1.0 / (va + vb + vc)
    v, w = vb * denom, vc * denom
    return np.linalg.norm(p - (a + ab * v + ac * w))


def test_proximity_vertex_face_pairs_match_brute_force():
    F, V0, V1 = clothcd.procedural.stacked_sheets(6)
    V = 0.5 * (V0 + V1) + np.array([0.0, 0.0, 0.0])
    h = 0.15
    det = clothcd.SelfDetector(F, V0)
    r = det.proximity(V, h)
    want = {}
    for v in range(len(V)):
        for f, tri in enumerate(F):
            if v in tri:
                continue
            d = point_triangle_distance(V[v], *V[tri])
            if d < h:
                want[(v, f)] = d
    got = {(int(a), int(b)): float(d) for (a, b), d in zip(r.vf, r.vf_distance)}
    # Pairs within rounding of h may go either way; everything else must agree.
    clear = {k: d for k, d in want.items() if d < h * (1 - 1e-9)}
    assert set(clear) <= set(got)
    assert set(got) <= set(want) | {k for k in got if abs(got[k] - h) < 1e-9 * h}
    for k, d in got.items():
        if k in want:
            assert d == pytest.approx(want[k], rel=1e-9, abs=1e-12)
    assert len(got) > 0 and r.ee.shape[1] == 2 and len(r.ee) == len(r.ee_distance)
    assert np.all(r.ee_distance < h)


def test_pair_detector_matches_the_self_detector_across_two_meshes():
    F, V0, V1 = clothcd.procedural.stacked_sheets(10)
    n = len(V0) // 2  # two sheets: vertices [0, n) and [n, 2n), faces in the same halves
    m = len(F) // 2
    assert F[:m].max() < n and F[m:].min() >= n
    Fa, Fb = F[:m], F[m:] - n
    pd = clothcd.PairDetector(Fa, V0[:n], Fb, V0[n:])
    r = pd.detect(V0[:n], V1[:n], V0[n:], V1[n:])
    whole = clothcd.SelfDetector(F, V0, culling="none").detect(V0, V1)
    a_on_b = {(v, f - m) for v, f in whole.vf.tolist() if v < n and f >= m}
    b_on_a = {(v - n, f) for v, f in whole.vf.tolist() if v >= n and f < m}
    assert a_on_b or b_on_a
    assert {tuple(p) for p in r.vf_a_on_b.tolist()} == a_on_b
    assert {tuple(p) for p in r.vf_b_on_a.tolist()} == b_on_a
    # EE: compare by vertex ids (the two numberings differ).
    edges = clothcd.SelfDetector(F, V0).edges
    ee_whole = set()
    for ea, eb in whole.ee.tolist():
        x, y = tuple(edges[ea]), tuple(edges[eb])
        if x[0] < n <= y[0]:
            ee_whole.add((x, tuple(v - n for v in y)))
        elif y[0] < n <= x[0]:
            ee_whole.add((y, tuple(v - n for v in x)))
    ee_pair = {(tuple(pd.edges_a[a]), tuple(pd.edges_b[b])) for a, b in r.ee.tolist()}
    assert ee_pair == ee_whole
    assert r.stats["vf_collisions"] == len(a_on_b) + len(b_on_a)


def test_options_round_trip_and_verify():
    F, V0, V1 = clothcd.procedural.winding_strip()
    det = clothcd.SelfDetector(F, V0, culling="gated", policy="provot", bvh="spatial", threads=1)
    o = det.options
    assert (o["culling"], o["policy"], o["bvh"], o["threads"]) == ("gated", "provot", "spatial", 1)
    det.set_options(verify=True)
    r = det.detect(V0, V1)
    # The winding strip is the case the gated rule gets wrong: verify reports what it missed.
    none = clothcd.SelfDetector(F, V0, culling="none").detect(V0, V1)
    missed_vf = {tuple(p) for p in none.vf.tolist()} - {tuple(p) for p in r.vf.tolist()}
    missed_ee = {tuple(p) for p in none.ee.tolist()} - {tuple(p) for p in r.ee.tolist()}
    assert {tuple(p) for p in r.missed_vf.tolist()} == missed_vf
    assert {tuple(p) for p in r.missed_ee.tolist()} == missed_ee
    assert missed_vf or missed_ee
    det.set_options(culling="sound", verify=False)
    assert det.options["culling"] == "sound"
    assert det.detect(V0, V1).missed_vf is None


def test_distance_filter_changes_the_work_not_the_results():
    F, V0, V1 = clothcd.procedural.crumpled_sheet(16, 3)
    on = clothcd.SelfDetector(F, V0, culling="sound")
    assert on.options["distance_filter"] is True
    off = clothcd.SelfDetector(F, V0, culling="sound", distance_filter=False)
    assert off.options["distance_filter"] is False
    a, b = on.detect(V0, V1), off.detect(V0, V1)
    assert np.array_equal(a.vf, b.vf) and np.array_equal(a.vf_toi, b.vf_toi)
    assert np.array_equal(a.ee, b.ee) and np.array_equal(a.ee_toi, b.ee_toi)
    # Off: every triangle pair's features are tested (none culled whole at zero thickness).
    assert b.stats["triangle_pairs_apart"] == 0 < a.stats["triangle_pairs_apart"]
    assert a.stats["ee_tests"] < b.stats["ee_tests"]
    off.set_options(distance_filter=True)
    assert off.detect(V0, V1).stats["triangle_pairs_apart"] == a.stats["triangle_pairs_apart"]


def test_cull_min_triangles_changes_the_work_not_the_results():
    F, V0, V1 = clothcd.procedural.crumpled_sheet(16, 3)
    every = clothcd.SelfDetector(F, V0, culling="sound").detect(V0, V1)
    det = clothcd.SelfDetector(F, V0, culling="sound", cull_min_triangles=16)
    assert det.options["cull_min_triangles"] == 16
    big = det.detect(V0, V1)
    assert np.array_equal(big.vf, every.vf) and np.array_equal(big.vf_toi, every.vf_toi)
    assert np.array_equal(big.ee, every.ee) and np.array_equal(big.ee_toi, every.ee_toi)
    # Only nodes of 16 or more triangles are tested: fewer cone tests than at 0.
    assert 0 < big.stats["cone_tests"] < every.stats["cone_tests"]
    det.set_options(cull_min_triangles=0)
    assert det.detect(V0, V1).stats["cone_tests"] == every.stats["cone_tests"]
    with pytest.raises(ValueError, match="cull_min_triangles must be >= 0"):
        det.set_options(cull_min_triangles=-1)


def test_reuse_front_changes_the_work_not_the_results():
    F, V0, V1 = clothcd.procedural.crumpled_sheet(16, 3)
    det = clothcd.SelfDetector(F, V0, culling="none", reuse_front=True)
    plain = clothcd.SelfDetector(F, V0, culling="none")
    assert det.options["reuse_front"] and not plain.options["reuse_front"]
    steps = [V0 + (V1 - V0) * (k / 4) for k in range(5)]
    for k in range(4):
        r, r0 = det.detect(steps[k], steps[k + 1]), plain.detect(steps[k], steps[k + 1])
        assert np.array_equal(r.vf, r0.vf) and np.array_equal(r.vf_toi, r0.vf_toi)
        assert np.array_equal(r.ee, r0.ee) and np.array_equal(r.ee_toi, r0.ee_toi)
        assert r.stats["front_pairs"] > 0 and r0.stats["front_pairs"] == 0
        # The first call starts at the root pairs; the later ones test fewer boxes from the front.
        if k == 0:
            assert r.stats["box_tests"] == r0.stats["box_tests"]
        else:
            assert r.stats["box_tests"] < r0.stats["box_tests"]
    det.set_options(reuse_front=False)
    assert det.detect(V0, V1).stats["front_pairs"] == 0


def test_float32_and_lists_are_accepted():
    F, V0, V1 = clothcd.procedural.stacked_sheets(6)
    det = clothcd.SelfDetector(F.tolist(), V0.tolist())
    want = det.detect(V0.astype(np.float32).astype(np.float64), V1.astype(np.float32).astype(np.float64))
    got = det.detect(V0.astype(np.float32), V1.astype(np.float32))
    assert np.array_equal(got.vf, want.vf) and np.array_equal(got.ee, want.ee)
    # Fortran order and strided views are read correctly (converted once).
    r1 = det.detect(np.asfortranarray(V0), np.asfortranarray(V1))
    r2 = det.detect(V0, V1)
    assert np.array_equal(r1.vf, r2.vf) and np.array_equal(r1.ee_toi, r2.ee_toi)


def test_every_array_layout_gives_the_same_results():
    # C-contiguous float64 is read in place; the other layouts are converted: all agree exactly.
    F, V0, V1 = clothcd.procedural.crumpled_sheet(10, 2)

    def layouts(V):
        wide = np.repeat(V, 2, axis=1)  # columns x x y y z z: [:, ::2] is a strided view of V
        frozen = V.copy()
        frozen.flags.writeable = False
        return [V, np.asfortranarray(V), wide[:, ::2], frozen]

    det = clothcd.SelfDetector(F, V0, culling="sound", thickness=1e-3)
    want = det.detect(V0, V1)
    near = det.proximity(V1, 0.05)
    assert len(want.vf) + len(want.ee) > 0 and len(near.vf) + len(near.ee) > 0
    for a, b in zip(layouts(V0), layouts(V1)):
        got = det.detect(a, b)
        assert np.array_equal(got.vf, want.vf) and np.array_equal(got.vf_toi, want.vf_toi)
        assert np.array_equal(got.ee, want.ee) and np.array_equal(got.ee_toi, want.ee_toi)
        p = det.proximity(b, 0.05)
        assert np.array_equal(p.vf, near.vf) and np.array_equal(p.vf_distance, near.vf_distance)
        assert np.array_equal(p.ee, near.ee) and np.array_equal(p.ee_distance, near.ee_distance)
        det.rebuild(b)
    n = len(V0) // 2
    m = np.nonzero(F.max(axis=1) < n)[0]
    pd = clothcd.PairDetector(F[m], V0[:n], F[m], V0[:n] + [0, 0, 0.02])
    pref = pd.detect(V0[:n], V1[:n], V0[:n] + [0, 0, 0.02], V1[:n] - [0, 0, 0.02])
    assert len(pref.vf_a_on_b) + len(pref.ee) > 0
    for a0, a1 in zip(layouts(V0[:n]), layouts(V1[:n])):
        got = pd.detect(a0, a1, V0[:n] + [0, 0, 0.02], V1[:n] - [0, 0, 0.02])
        assert np.array_equal(got.vf_a_on_b, pref.vf_a_on_b) and np.array_equal(got.ee, pref.ee)
        assert np.array_equal(got.ee_toi, pref.ee_toi)


def test_detect_releases_the_gil():
    import threading
    import time

    F, V0, V1 = clothcd.procedural.crumpled_sheet(48, 2)
    det = clothcd.SelfDetector(F, V0, culling="none", threads=1)
    span = {}

    def work():
        span["start"] = time.perf_counter()
        det.detect(V0, V1)
        span["end"] = time.perf_counter()

    worker = threading.Thread(target=work)
    ticks = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
    worker.join()
    # Had detect() kept the GIL, this thread could not have run while it was inside.
    inside = [t for t in ticks if span["start"] < t < span["end"]]
    assert span["end"] - span["start"] > 0.01
    assert len(inside) > 0
