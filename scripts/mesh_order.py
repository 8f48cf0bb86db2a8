#!/usr/bin/env python3
"""How the order of a mesh's faces and vertices affects `clothcd detect`.

Writes one frame pair in three orders and times `clothcd detect` on each, alternating runs:
  given     the files' own order;
  morton    faces sorted along a Morton (Z-order) curve of their centroids at t0, vertices
            numbered in the order the sorted faces first use them;
  shuffled  faces and vertices in a random order (seeded).
The three are the same geometry (each face keeps its corner order), so every order must report
the same collisions once its ids are mapped back: the script checks that (vertex-face pairs by
vertex and face corners, edge-edge pairs by their vertices; times of impact within the kernel's
tolerance, 1e-4: an edge's vertices reach the kernel smaller id first, so a new order may hand
it an edge-edge query's points in another order), then writes
a markdown table of medians and spreads: setup (reading and building the detector), refit,
traversal, narrow phase and whole-process wall time, with how scattered each order is (the
median over faces of the largest minus the smallest corner id).

Usage: scripts/mesh_order.py [--bin BIN] [--python-module DIR] [--reps N] [--threads 1,2]
                             [--out FILE] [--t0 A --t1 B] [-- extra detect options]
  defaults: build/release/apps/clothcd, the module under build/release/python, 7 reps,
  threads 1,2, cloth_ball 92 -> 93 from $CLOTHCD_DATA (or ../shared/data), `--culling sound
  --policy proposed`, output docs/results/mesh_order.md. Needs numpy and the Python module
  (configure with -DCLOTHCD_PYTHON=ON) to read and write the meshes.
"""

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def morton_order(V, F):
    """Face order along a Morton curve of the face centroids (21 bits per axis)."""
    c = V[F].mean(axis=1)
    lo = c.min(axis=0)
    span = max(float((c.max(axis=0) - lo).max()), np.finfo(float).tiny)
    q = ((c - lo) / span * ((1 << 21) - 1)).astype(np.uint64)
    code = np.zeros(len(F), dtype=np.uint64)
    for bit in range(21):
        for axis in range(3):
            code |= ((q[:, axis] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(3 * bit + axis)
    return np.argsort(code, kind="stable")


def first_use_order(F, nv):
    """New vertex ids: in the order the faces (in their order) first use them; unused ones last."""
    seen = np.full(nv, -1, dtype=np.int64)
    flat = F.reshape(-1)
    _, first = np.unique(flat, return_index=True)
    used = flat[np.sort(first)]
    seen[used] = np.arange(len(used))
    rest = np.flatnonzero(seen < 0)
    seen[rest] = len(used) + np.arange(len(rest))
    return seen  # seen[old] = new


def reorder(V0, V1, F, mode, rng):
    if mode == "given":
        face_order, new_id = np.arange(len(F)), np.arange(len(V0))
    elif mode == "morton":
        face_order = morton_order(V0, F)
        new_id = first_use_order(F[face_order], len(V0))
    else:
        face_order, new_id = rng.permutation(len(F)), rng.permutation(len(V0))
    old_id = np.empty_like(new_id)
    old_id[new_id] = np.arange(len(new_id))
    return V0[old_id], V1[old_id], new_id[F[face_order]].astype(np.int32), old_id


TOI_TOLERANCE = 1e-4  # CcdOptions::toi_tolerance


def collisions(report, old_id):
    """The report's collisions in the given order's ids: {pair: time of impact} for VF and EE."""
    vf = {(int(old_id[c["vertex"]]), tuple(int(old_id[x]) for x in c["face"])): c["toi"]
          for c in report["vf"]}
    ee = {frozenset((tuple(sorted(int(old_id[x]) for x in c["edge_a"])),
                     tuple(sorted(int(old_id[x]) for x in c["edge_b"])))): c["toi"]
          for c in report["ee"]}
    return vf, ee


def same_collisions(a, b):
    return all(x.keys() == y.keys() and all(abs(x[k] - y[k]) <= TOI_TOLERANCE for k in x)
               for x, y in zip(a, b))


SETUP = re.compile(r"setup: reading ([0-9.e-]+) s, detector ([0-9.e-]+) s")


def run(binary, t0, t1, extra, threads, json_path):
    cmd = [str(binary), "detect", "--t0", str(t0), "--t1", str(t1), *extra, "--threads",
           str(threads), "--json", str(json_path)]
    start = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stderr}")
    m = SETUP.search(p.stdout + p.stderr)
    if m is None:
        sys.exit(f"no setup line in the output of {' '.join(cmd)}")
    report = json.loads(Path(json_path).read_text())
    s = report["stats"]
    return report, {"setup": float(m.group(1)) + float(m.group(2)), "refit": s["time_refit"],
                    "traversal": s["time_traverse"], "narrow": s["time_narrow"], "wall": wall}


def main():
    data = Path(os.environ.get("CLOTHCD_DATA", ROOT.parent / "shared" / "data")).resolve()
    ball = data / "cloth-ball" / "frames"
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=ROOT / "build" / "release" / "apps" / "clothcd", type=Path)
    ap.add_argument("--python-module", default=ROOT / "build" / "release" / "python", type=Path)
    ap.add_argument("--t0", default=ball / "cloth_ball92.ply", type=Path)
    ap.add_argument("--t1", default=ball / "cloth_ball93.ply", type=Path)
    ap.add_argument("--reps", default=7, type=int)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--out", default=ROOT / "docs" / "results" / "mesh_order.md", type=Path)
    ap.add_argument("extra", nargs="*", default=["--culling", "sound", "--policy", "proposed"])
    a = ap.parse_args()
    sys.path.insert(0, str(a.python_module))
    import clothcd  # noqa: E402  (found through --python-module)

    V0, F = clothcd.read_mesh(a.t0)
    V1, F1 = clothcd.read_mesh(a.t1)
    if not np.array_equal(F, F1):
        sys.exit(f"{a.t0} and {a.t1} have different faces")
    rng = np.random.default_rng(1)
    orders = ["given", "morton", "shuffled"]
    with tempfile.TemporaryDirectory() as tmp:
        files, old_ids, spread = {}, {}, {}
        for mode in orders:  # every order written by the same writer, so reading costs compare
            W0, W1, G, old_id = reorder(V0, V1, F, mode, rng)
            files[mode] = (Path(tmp) / f"{mode}0.ply", Path(tmp) / f"{mode}1.ply")
            clothcd.write_mesh(files[mode][0], W0, G)
            clothcd.write_mesh(files[mode][1], W1, G)
            old_ids[mode] = old_id
            spread[mode] = int(np.median(G.max(axis=1) - G.min(axis=1)))
        threads = [int(t) for t in a.threads.split(",")]
        times = {(t, m): [] for t in threads for m in orders}
        expected = None
        for t in threads:
            for _ in range(a.reps):
                for mode in orders:
                    report, tm = run(a.bin, *files[mode], a.extra, t, Path(tmp) / "out.json")
                    found = collisions(report, old_ids[mode])
                    if expected is None:
                        expected = found
                    elif not same_collisions(found, expected):
                        sys.exit(f"order '{mode}' ({t} threads) reports other collisions")
                    times[(t, mode)].append(tm)
    load = os.getloadavg()
    cols = ["setup", "refit", "traversal", "narrow", "wall"]
    lines = [
        "# Mesh order and detection time",
        "",
        "Generated by `scripts/mesh_order.py`; do not edit. One frame pair written in three orders",
        "(the files' own; faces along a Morton curve of their centroids at t0, vertices numbered by",
        "first use; shuffled) and detected alternately. Every run reported the same collisions",
        f"({len(expected[0])} VF, {len(expected[1])} EE) once mapped back to the given ids, times",
        "of impact within the kernel's tolerance. Seconds, medians of",
        f"{a.reps} runs [min-max]; setup = reading both files + building the detector; id spread =",
        "median over faces of the largest minus the smallest corner id.",
        "",
        f"- pair: `{a.t0.name}` -> `{a.t1.name}` ({len(V0)} vertices, {len(F)} faces), "
        f"options `{' '.join(a.extra)}`",
        f"- machine: {platform.machine()}, {os.cpu_count()} logical CPUs; load after the runs "
        f"{load[0]:.2f} / {load[1]:.2f}",
        "",
        "| threads | order | id spread | " + " | ".join(cols) + " |",
        "|---|---|---|" + "---|" * len(cols),
    ]
    for t in threads:
        for mode in orders:
            rows = times[(t, mode)]
            cells = []
            for c in cols:
                v = [r[c] for r in rows]
                cells.append(f"{statistics.median(v):.3f} [{min(v):.3f}-{max(v):.3f}]")
            lines.append(f"| {t} | {mode} | {spread[mode]} | " + " | ".join(cells) + " |")
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
