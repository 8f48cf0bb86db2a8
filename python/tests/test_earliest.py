"""earliest_impact through Python: the earliest of the detection's own hits (at the query's
tolerance), the same for any thread count, between two meshes, and errors for bad settings."""

import numpy as np
import pytest

import clothcd


def earliest_of(r):
    """(toi, kind, ids) of the earliest hit of a DetectResult, ties by (kind, ids)."""
    cands = [(float(t), "vf", tuple(map(int, p))) for p, t in zip(r.vf, r.vf_toi)]
    cands += [(float(t), "ee", tuple(map(int, p))) for p, t in zip(r.ee, r.ee_toi)]
    return min(cands, key=lambda c: (c[0], c[1] != "vf", c[2]))


@pytest.mark.parametrize("thickness", [0.0, 1e-3])
def test_earliest_is_no_later_than_any_hit_and_names_a_colliding_pair(thickness):
    F, V0, V1 = clothcd.procedural.stacked_sheets(12)
    det = clothcd.SelfDetector(F, V0, thickness=thickness, toi_tolerance=1e-6)
    toi, kind, ids = det.earliest_impact(V0, V1)
    assert kind in ("vf", "ee") and 0 <= toi < 1
    full = det.detect(V0, V1)
    first = earliest_of(full)
    # Never earlier than the detection's earliest hit by more than the tolerance (the detection's
    # own time may be earlier still, never later than the contact either).
    assert toi >= first[0] - 1e-6
    hit_pairs = {("vf", tuple(map(int, p))) for p in full.vf}
    hit_pairs |= {("ee", tuple(map(int, p))) for p in full.ee}
    assert (kind, ids) in hit_pairs
    # Moving most of the way there is free of contacts; a little further is not.
    short = det.detect(V0, V0 + 0.9 * toi * (V1 - V0))
    assert len(short.vf) == 0 and len(short.ee) == 0
    longer = det.detect(V0, V0 + min(1.0, toi + 1e-3) * (V1 - V0))
    assert len(longer.vf) + len(longer.ee) > 0


def test_same_answer_for_any_thread_count_and_window():
    F, V0, V1 = clothcd.procedural.crumpled_sheet(16, 3)
    answers = {clothcd.SelfDetector(F, V0, threads=t).earliest_impact(V0, V1) for t in (1, 2, 4)}
    assert len(answers) == 1
    det = clothcd.SelfDetector(F, V0)
    whole = det.earliest_impact(V0, V1, first_window=1.0)
    auto = det.earliest_impact(V0, V1)
    assert abs(whole[0] - auto[0]) <= 1e-6


def test_nothing_near_gives_none():
    F, V0, _ = clothcd.procedural.stacked_sheets(6)
    det = clothcd.SelfDetector(F, V0)
    assert det.earliest_impact(V0, V0 + 1e-6) == (1.0, "none", (-1, -1))


def test_pair_detector_kinds_and_sides():
    F, V0, V1 = clothcd.procedural.stacked_sheets(10)
    n, m = len(V0) // 2, len(F) // 2
    Fa, Fb = F[:m], F[m:] - n
    pd = clothcd.PairDetector(Fa, V0[:n], Fb, V0[n:], toi_tolerance=1e-6)
    toi, kind, ids = pd.earliest_impact(V0[:n], V1[:n], V0[n:], V1[n:])
    assert kind in ("vf_a_on_b", "vf_b_on_a", "ee") and 0 <= toi < 1
    r = pd.detect(V0[:n], V1[:n], V0[n:], V1[n:])
    lists = {"vf_a_on_b": (r.vf_a_on_b, r.vf_a_on_b_toi), "vf_b_on_a": (r.vf_b_on_a, r.vf_b_on_a_toi),
             "ee": (r.ee, r.ee_toi)}
    pairs, tois = lists[kind]
    assert ids in {tuple(map(int, p)) for p in pairs}
    first = min(float(t) for _, ts in lists.values() for t in ts)
    assert toi >= first - 1e-6


def test_bad_settings():
    F, V0, V1 = clothcd.procedural.stacked_sheets(6)
    det = clothcd.SelfDetector(F, V0)
    with pytest.raises(ValueError, match="toi_tolerance must be finite and > 0"):
        det.earliest_impact(V0, V1, toi_tolerance=0)
    with pytest.raises(ValueError, match="first_window must be 0"):
        det.earliest_impact(V0, V1, first_window=0.3)
    with pytest.raises(ValueError):
        det.earliest_impact(V0, V1[:-1])
