#!/usr/bin/env python3
"""Simulates a short sequence and compares the normal-cone spread angles of PROVOT and PROPOSED
on every step: the leaf cones of all triangles (C_Tang vs C_Proposed) and what the detector's
cone test culls with each policy.

    python3 examples/python/spread_angles.py --scene scenes/sphere-drop.json --frames 5

Writes a PNG (matplotlib, Agg backend) and prints one line per step.
"""

import argparse
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import clothcd  # noqa: E402

POLICIES = {"provot": "tang", "proposed": "proposed"}  # detector policy -> its leaf cone


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", type=Path, default=Path(__file__).resolve().parents[2] / "scenes" / "sphere-drop.json")
    p.add_argument("--frames", type=int, default=5)
    p.add_argument("--work", type=Path, help="simulation output folder (default: a temporary one)")
    p.add_argument("--out", type=Path, default=Path("spread_angles.png"))
    a = p.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        work = a.work or Path(tmp)
        clothcd.simulate(a.scene, work, frames=a.frames,
                         progress=lambda s, total: print(f"simulated frame {s['frame']}/{total}"))
        F, V = clothcd.read_frames(work)

    det = clothcd.SelfDetector(F, V[0], culling="cone")
    rows = []
    print(f"{'step':>4} {'policy':9} {'median leaf':>12} {'p90 leaf':>9} {'saturated':>10} {'nodes culled':>13}")
    for k in range(len(V) - 1):
        T0, T1 = V[k][F], V[k + 1][F]  # (m, 3, 3): each triangle's corners at both ends
        for policy, leaf in POLICIES.items():
            _, angles = clothcd.ccd_leaf_cone(T0, T1, policy=leaf)
            det.set_options(policy=policy)
            stats = det.detect(V[k], V[k + 1]).stats
            deg = np.degrees(angles[angles < clothcd.SATURATED_HALF_ANGLE])
            row = dict(step=k + 1, policy=policy, median=float(np.median(deg)),
                       p90=float(np.percentile(deg, 90)),
                       saturated=float(np.mean(angles >= clothcd.SATURATED_HALF_ANGLE)),
                       culled=stats["nodes_culled"])
            rows.append(row)
            print(f"{row['step']:4d} {policy:9} {row['median']:11.4f}° {row['p90']:8.4f}° "
                  f"{100 * row['saturated']:9.3f}% {row['culled']:13d}")

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for policy in POLICIES:
        mine = [r for r in rows if r["policy"] == policy]
        steps = [r["step"] for r in mine]
        left.plot(steps, [r["median"] for r in mine], "o-", label=f"{policy.upper()} median")
        left.plot(steps, [r["p90"] for r in mine], "s--", label=f"{policy.upper()} 90th percentile")
        right.plot(steps, [r["culled"] for r in mine], "o-", label=policy.upper())
    left.set_xlabel("step")
    left.set_ylabel("leaf cone half-angle (degrees)")
    left.set_yscale("log")
    left.legend()
    right.set_xlabel("step")
    right.set_ylabel("BVH nodes culled (culling 'cone')")
    right.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
