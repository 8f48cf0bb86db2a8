"""Normal cones on arrays: the merges' formulas and containment, leaf cones that contain the
moving normal, the optimal cone's minimality, batches equal to single calls."""

import numpy as np
import pytest

import clothcd

HALF_PI = np.pi / 2


def angle(u, v):
    u, v = np.asarray(u, float), np.asarray(v, float)
    c = u @ v / (np.linalg.norm(u) * np.linalg.norm(v))
    return float(np.arccos(np.clip(c, -1.0, 1.0)))


def random_cones(rng, k, max_angle=0.5):
    axes = rng.normal(size=(k, 3))
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    return axes, rng.uniform(0, max_angle, size=k)


def test_merge_provot_is_provots_formula():
    rng = np.random.default_rng(1)
    a, ta = random_cones(rng, 200)
    b, tb = random_cones(rng, 200)
    axes, angles = clothcd.merge_provot(a, ta, b, tb)
    assert axes.shape == (200, 3) and angles.shape == (200,)
    checked = 0
    for i in range(200):
        beta = angle(a[i], b[i])
        want = beta / 2 + max(ta[i], tb[i])
        if want >= HALF_PI - 1e-6 or beta > 3.0:
            assert angles[i] == pytest.approx(HALF_PI) or angles[i] >= want - 1e-9
            continue
        assert angles[i] == pytest.approx(want, abs=1e-9)
        s = a[i] + b[i]
        assert np.allclose(axes[i], s / np.linalg.norm(s), atol=1e-12)
        checked += 1
    assert checked > 50


def test_merge_tight_is_the_minimal_enclosing_cone():
    rng = np.random.default_rng(2)
    a, ta = random_cones(rng, 300)
    b, tb = random_cones(rng, 300)
    axes, angles = clothcd.merge_tight(a, ta, b, tb)
    checked = 0
    for i in range(300):
        if angles[i] >= HALF_PI:
            assert angles[i] == clothcd.SATURATED_HALF_ANGLE
            continue
        beta = angle(a[i], b[i])
        assert angles[i] == pytest.approx(max(ta[i], tb[i], (beta + ta[i] + tb[i]) / 2), abs=1e-9)
        # It contains both cones.
        assert angle(axes[i], a[i]) + ta[i] <= angles[i] + 1e-9
        assert angle(axes[i], b[i]) + tb[i] <= angles[i] + 1e-9
        assert np.linalg.norm(axes[i]) == pytest.approx(1.0)
        checked += 1
    assert checked > 100


def test_single_cones_and_batches_agree():
    rng = np.random.default_rng(3)
    a, ta = random_cones(rng, 20)
    b, tb = random_cones(rng, 20)
    for merge in (clothcd.merge_provot, clothcd.merge_tight):
        axes, angles = merge(a, ta, b, tb)
        for i in range(20):
            axis, t = merge(a[i], float(ta[i]), b[i], float(tb[i]))
            assert isinstance(t, float) and axis.shape == (3,)
            assert np.array_equal(axis, axes[i]) and t == angles[i]


def moving_triangles(rng, k, speed):
    t0 = rng.normal(size=(k, 3, 3))
    t1 = t0 + speed * rng.normal(size=(k, 3, 3))
    return t0, t1


def test_leaf_cones_contain_the_normal_over_the_step_and_nest():
    rng = np.random.default_rng(4)
    t0, t1 = moving_triangles(rng, 100, 0.1)
    cones = {p: clothcd.ccd_leaf_cone(t0, t1, policy=p) for p in ("tang", "proposed", "exact")}
    assert np.array_equal(clothcd.ccd_leaf_cone(t0, t1, policy="provot")[1], cones["tang"][1])
    ts = np.linspace(0, 1, 41)
    not_saturated = 0
    for i in range(100):
        for p, (axes, angles) in cones.items():
            if angles[i] >= HALF_PI:
                continue
            not_saturated += 1
            for t in ts:
                x = (1 - t) * t0[i] + t * t1[i]
                n = np.cross(x[1] - x[0], x[2] - x[0])
                assert angle(axes[i], n) <= angles[i] + 1e-9, (p, i, t)
        assert cones["exact"][1][i] <= cones["proposed"][1][i] + 1e-9
        assert cones["proposed"][1][i] <= cones["tang"][1][i] + 1e-9
    assert not_saturated > 200
    axis, t = clothcd.ccd_leaf_cone(t0[0], t1[0])
    assert axis.shape == (3,) and t == cones["proposed"][1][0]


def test_static_triangle_has_a_skinny_cone_and_degenerate_ones_saturate():
    tri = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    axis, t = clothcd.ccd_leaf_cone(tri, tri)
    assert t < 1e-9 and np.allclose(axis, [0, 0, 1])
    flat = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    assert clothcd.ccd_leaf_cone(flat, flat)[1] == clothcd.SATURATED_HALF_ANGLE


def test_optimal_cone_contains_every_vector_and_is_minimal():
    axis, t = clothcd.optimal_cone([[1.0, 0, 0], [0, 1.0, 0]])
    assert t == pytest.approx(np.pi / 4, abs=1e-9)
    assert np.allclose(axis, np.array([1, 1, 0]) / np.sqrt(2))
    rng = np.random.default_rng(5)
    for _ in range(20):
        center = rng.normal(size=3)
        v = center + 0.4 * np.linalg.norm(center) * rng.normal(size=(30, 3))
        axis, t = clothcd.optimal_cone(v)
        if t >= HALF_PI:
            continue
        worst = max(angle(axis, x) for x in v)
        assert worst <= t + 1e-9
        # Minimal: no cone around the vectors' mean direction is narrower.
        mean = (v / np.linalg.norm(v, axis=1)[:, None]).sum(axis=0)
        assert t <= max(angle(mean, x) for x in v) + 1e-9
    # All 6 axis directions: no cone below pi/2.
    assert clothcd.optimal_cone(np.vstack([np.eye(3), -np.eye(3)]))[1] == clothcd.SATURATED_HALF_ANGLE
