#!/usr/bin/env python3
"""SelfDetector.detect through Python against the C++ API (clothcd_py_reference), back to back.

    PYTHONPATH=build/py/python /usr/bin/python3 python/bench/detect_speed.py --build build/py

Both sides build one detector with the same options, run one untimed detect(), then time `runs`
detect() calls; the two alternate for `rounds` rounds. Prints each side's median over all timed
runs, their ratio, and the median of the per-round ratios (robust to load that drifts between
rounds on a shared machine). Defaults: cloth_ball 92 -> 93 from $CLOTHCD_DATA (../shared/data), bvh
patch, culling sound, policy proposed, all cores.
"""

import argparse
import json
import os
import statistics
import subprocess
import time
from pathlib import Path

import clothcd

ROOT = Path(__file__).resolve().parents[2]


def main():
    data = Path(os.environ.get("CLOTHCD_DATA", ROOT.parent / "shared" / "data"))
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", type=Path, default=ROOT / "build" / "py")
    p.add_argument("--t0", type=Path, default=data / "cloth-ball/frames/cloth_ball92.ply")
    p.add_argument("--t1", type=Path, default=data / "cloth-ball/frames/cloth_ball93.ply")
    p.add_argument("--bvh", default="patch")
    p.add_argument("--culling", default="sound")
    p.add_argument("--policy", default="proposed")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--rounds", type=int, default=3)
    a = p.parse_args()
    opts = dict(bvh=a.bvh, culling=a.culling, policy=a.policy, threads=a.threads)
    tool = a.build / "python" / "tests" / "clothcd_py_reference"

    V0, F = clothcd.read_mesh(a.t0)
    V1, _ = clothcd.read_mesh(a.t1)
    det = clothcd.SelfDetector(F, V0, **opts)
    counts = None
    cpp, py, ratios = [], [], []
    for _ in range(a.rounds):
        cmd = [str(tool), f"t0={a.t0}", f"t1={a.t1}", f"runs={a.runs}"] + [f"{k}={v}" for k, v in opts.items()]
        ref = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
        cpp += ref["seconds"]
        r = det.detect(V0, V1)  # untimed, as on the C++ side
        for _ in range(a.runs):
            start = time.perf_counter()
            r = det.detect(V0, V1)
            py.append(time.perf_counter() - start)
        ratios.append(statistics.median(py[-a.runs:]) / statistics.median(ref["seconds"]))
        counts = (len(r.vf), len(r.ee))
        assert counts == (ref["vf"], ref["ee"]), (counts, ref)
    mc, mp = statistics.median(cpp), statistics.median(py)
    print(f"{a.t0.name} -> {a.t1.name}, {opts}: {counts[0]} VF, {counts[1]} EE")
    print(f"C++ API  median {mc:.4f} s over {len(cpp)} runs: {' '.join(f'{x:.3f}' for x in cpp)}")
    print(f"Python   median {mp:.4f} s over {len(py)} runs: {' '.join(f'{x:.3f}' for x in py)}")
    print(f"Python / C++ = {mp / mc:.3f}; per round: {' '.join(f'{x:.3f}' for x in ratios)}, "
          f"median {statistics.median(ratios):.3f}")


if __name__ == "__main__":
    main()
