"""The batch CCD kernels on the Sample-Queries set (CLOTHCD_DATA/ccd-queries): no false negatives,
the same true/false positive counts per file as `clothcd ccd-queries --json`, and a CSV reader
that agrees with an independent exact parse."""

import json
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import clothcd
from conftest import cli, require_data


def files(root):
    return sorted(p for p in root.rglob("*.csv") if p.parent.name in ("vertex-face", "edge-edge"))


def parse_exact(path):
    """(k, 8, 3) coordinates as exact fractions rounded once to double, and the truth bits."""
    rows = [line.split(",") for line in Path(path).read_text().splitlines() if line.strip()]
    coords = np.array([[float(Fraction(int(r[2 * c]), int(r[2 * c + 1]))) for c in range(3)] for r in rows])
    truth = np.array([r[6].strip() == "1" for r in rows])
    return coords.reshape(-1, 8, 3), truth[::8]


def kernel(kind):
    return clothcd.vertex_face_ccd if kind == "vertex-face" else clothcd.edge_edge_ccd


@pytest.mark.parametrize("fast_path", [True, False])
def test_no_false_negatives_and_the_cli_counts(tmp_path, fast_path):
    root = require_data("ccd-queries")
    out = tmp_path / "cli.json"
    args = ["ccd-queries", str(root), "--json", str(out)] + ([] if fast_path else ["--no-fast-path"])
    done = cli(*args)
    assert done.returncode == 0, done.stderr
    report = json.loads(out.read_text())
    per_file = {Path(f["path"]).resolve(): f for f in report["files"]}
    checked = 0
    for path in files(root):
        q, truth, kind = clothcd.read_query_csv(path)
        assert kind == path.parent.name
        hit, toi = kernel(kind)(q, fast_path=fast_path)
        assert hit.dtype == np.bool_ and toi.shape == (len(q),)
        assert not np.any(truth & ~hit), f"{path}: false negatives"
        assert np.all((toi >= 0) & (toi <= 1)) and np.all(toi[~hit] == 1.0)
        row = per_file[path.resolve()]
        assert row["queries"] == len(q)
        assert row["true_positives"] == int(np.sum(truth & hit)), path
        assert row["false_positives"] == int(np.sum(~truth & hit)), path
        assert row["false_negatives"] == 0
        checked += 1
    assert checked == len(per_file) > 0


def test_reader_agrees_with_an_exact_parse_and_kinds_can_be_forced():
    root = require_data("ccd-queries")
    for path in files(root):
        q, truth, _ = clothcd.read_query_csv(path)
        want_q, want_truth = parse_exact(path)
        assert np.array_equal(q, want_q), path
        assert np.array_equal(truth, want_truth), path
    path = files(root)[0]
    q_forced, _, kind = clothcd.read_query_csv(path, kind="edge-edge")
    assert kind == "edge-edge" and np.array_equal(q_forced, clothcd.read_query_csv(path)[0])


def test_batch_equals_one_query_at_a_time_and_threads_agree():
    root = require_data("ccd-queries")
    path = next(p for p in files(root) if p.parent.name == "edge-edge")
    q, _, kind = clothcd.read_query_csv(path)
    hit, toi = clothcd.edge_edge_ccd(q, threads=1)
    for i in range(0, len(q), max(1, len(q) // 40)):
        h1, t1 = clothcd.edge_edge_ccd(q[i : i + 1])
        assert h1[0] == hit[i] and t1[0] == toi[i]
    hit2, toi2 = clothcd.edge_edge_ccd(q, threads=2)
    assert np.array_equal(hit, hit2) and np.array_equal(toi, toi2)
