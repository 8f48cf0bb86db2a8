#!/usr/bin/env python3
"""Detects collisions over one step between two frames with every culling mode and cone policy,
prints the counts and plots the triangle pairs each mode leaves to the narrow phase.

    python3 examples/python/culling_counts.py                    # cloth_ball 92 -> 93
    python3 examples/python/culling_counts.py --t0 a.ply --t1 b.ply --out counts.png

Without --t0/--t1 it reads cloth-ball/frames/cloth_ball{92,93}.ply from $CLOTHCD_DATA (default
../shared/data beside the repository). Writes a PNG (matplotlib, Agg backend).
"""

import argparse
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import clothcd  # noqa: E402

CULLINGS = ["none", "cone", "gated", "sound"]
POLICIES = ["provot", "proposed", "exact"]


def default_frames():
    root = Path(os.environ.get("CLOTHCD_DATA", Path(__file__).resolve().parents[2].parent / "shared" / "data"))
    frames = root / "cloth-ball" / "frames"
    return frames / "cloth_ball92.ply", frames / "cloth_ball93.ply"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--t0", type=Path, help="frame at the start of the step (OBJ or PLY)")
    p.add_argument("--t1", type=Path, help="frame at the end of the step (same faces)")
    p.add_argument("--bvh", default="patch", choices=["spatial", "patch"])
    p.add_argument("--out", type=Path, default=Path("culling_counts.png"))
    a = p.parse_args()
    t0, t1 = (a.t0, a.t1) if a.t0 else default_frames()
    V0, F = clothcd.read_mesh(t0)
    V1, F1 = clothcd.read_mesh(t1)
    if not np.array_equal(F, F1):
        raise SystemExit(f"{t0} and {t1} have different faces")

    det = clothcd.SelfDetector(F, V0, bvh=a.bvh, culling="none")
    reference = det.detect(V0, V1)
    found = {"vf": set(map(tuple, reference.vf.tolist())), "ee": set(map(tuple, reference.ee.tolist()))}
    print(f"{len(F)} triangles, bvh {a.bvh}: {len(reference.vf)} VF and {len(reference.ee)} EE collisions")
    print(f"{'culling':8} {'policy':9} {'tri pairs':>10} {'nodes culled':>13} {'collisions':>11} {'missed':>7}")
    pairs = {}
    for culling in CULLINGS:
        for policy in POLICIES if culling != "none" else ["proposed"]:
            det.set_options(culling=culling, policy=policy)
            r = det.detect(V0, V1)
            missed = len(found["vf"] - set(map(tuple, r.vf.tolist()))) + len(
                found["ee"] - set(map(tuple, r.ee.tolist())))
            pairs[culling, policy] = r.stats["triangle_pairs"]
            print(f"{culling:8} {policy:9} {r.stats['triangle_pairs']:10d} {r.stats['nodes_culled']:13d} "
                  f"{len(r.vf) + len(r.ee):11d} {missed:7d}")

    fig, ax = plt.subplots(figsize=(7, 4))
    width = 0.25
    x = np.arange(len(CULLINGS))
    for i, policy in enumerate(POLICIES):
        counts = [pairs.get((c, policy), pairs[("none", "proposed")]) for c in CULLINGS]
        ax.bar(x + (i - 1) * width, counts, width, label=policy.upper())
    ax.set_xticks(x, CULLINGS)
    ax.set_ylabel("triangle pairs to the narrow phase")
    ax.set_title(f"{t0.name} -> {t1.name} ({a.bvh} BVH)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
