#!/usr/bin/env python3
"""Per-phase speed of `clothcd detect`, against a reference binary, back to back.

For each case and thread count, runs the reference and the current binary alternately REPS times,
checks that both report exactly the same VF and EE collisions (pairs and times of impact), and
writes a markdown table of medians: refit, traversal, narrow phase, detection (their sum), setup
(reading and building the detector), whole-process wall and CPU time, and the detection's
nanoseconds per triangle pair and per feature test.

Usage: scripts/detect_speed.py [--ref BIN] [--bin BIN] [--reps N] [--threads 1,2] [--out FILE]
                               [--frames OUT/frames]
  defaults: --bin build/release/apps/clothcd, no reference (current binary only), 5 reps,
  threads 1,2, output docs/results/detect_speed.md. Data: $CLOTHCD_DATA or ../shared/data.
  --frames: the frames folder of a `scripts/results.sh OUT` run; adds simulated garment frame
  pairs (dress-rumba and multilayer-rumba, frames 60 -> 61, sewn at 1e-3, patch build).
  --steady-ref TOOL: also time repeated calls on one detector, as a simulator makes them, with
  build/release/python/tests/clothcd_py_reference against TOOL (the same program built from the
  reference): one untimed detect(), then 5 timed ones, 3 rounds alternating; cloth_ball and,
  with --frames, the same garment frames unsewn.
"""

import argparse
import json
import os
import platform
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def data_dir():
    return Path(os.environ.get("CLOTHCD_DATA", ROOT.parent / "shared" / "data")).resolve()


# Simulated garment steps: (scene, first frame). Frame 60 is mid-sequence, the body in motion.
SIMULATED = [("dress-rumba", 60), ("multilayer-rumba", 60)]


def cases(data, frames=None):
    ball = data / "cloth-ball" / "frames"
    garments = data / "garments"
    # The garments' drape shapes (the body's vertices dropped), moved by a smooth 1 cm
    # perturbation: a garment-sized step without a simulation run first.
    garment = ["--perturb", "0.01", "--sew", "1e-3", "--bvh", "patch", "--garment-vertices"]
    out = [
        ("cloth_ball 92 -> 93",
         ["--t0", str(ball / "cloth_ball92.ply"), "--t1", str(ball / "cloth_ball93.ply")]),
        ("dress drape + 1 cm",
         ["--t0", str(garments / "dress_knife" / "drape.obj"), *garment, "15656"]),
        ("multilayer drape + 1 cm",
         ["--t0", str(garments / "multilayer" / "drape.obj"), *garment, "30464"]),
    ]
    for scene, k in SIMULATED if frames else []:
        f0, f1 = (Path(frames) / scene / f"frame_{i:04d}.obj" for i in (k, k + 1))
        if not (f0.is_file() and f1.is_file()):
            sys.exit(f"detect_speed.py: --frames {frames}: {f0} or {f1} is missing "
                     "(expected the frames folder of a scripts/results.sh run)")
        out.append((f"{scene} {k} -> {k + 1}",
                    ["--t0", str(f0), "--t1", str(f1), "--sew", "1e-3", "--bvh", "patch"]))
    return out


def run(binary, args, threads, json_path):
    """Wall time, CPU time (user + system) and setup time of one process, and its JSON."""
    cmd = [binary, "detect", *args, "--culling", "sound", "--policy", "proposed", "--threads",
           str(threads), "--json", json_path]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    out = subprocess.run(cmd, check=True, stdout=subprocess.PIPE, text=True).stdout
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    # "setup: reading X s, detector Y s" (binaries older than that line: nan).
    m = re.search(r"setup: reading ([0-9.]+) s, detector ([0-9.]+) s", out)
    setup = float(m.group(1)) + float(m.group(2)) if m else float("nan")
    with open(json_path) as f:
        res = json.load(f)
    return wall, res, cpu, setup


def vector_width():
    """The widest vector instructions the batched filters use on this processor."""
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("flags"):
                f = line.split()
                if "avx512f" in f and "fma" in f:
                    return "AVX-512: 8 doubles a vector"
                return "AVX2: 4 doubles a vector" if "avx2" in f else "SSE2: 2 doubles a vector"
    except OSError:
        pass
    return "vector width unknown"


def collisions(res):
    return (res["vf"], res["ee"])


def row(name, threads, label, runs):
    st = [r[1]["stats"] for r in runs]
    refit = statistics.median(s["time_refit"] for s in st)
    trav = statistics.median(s["time_traverse"] for s in st)
    narrow = statistics.median(s["time_narrow"] for s in st)
    dets = [s["time_refit"] + s["time_traverse"] + s["time_narrow"] for s in st]
    det = statistics.median(dets)
    wall = statistics.median(r[0] for r in runs)
    cpu = statistics.median(r[2] for r in runs)
    setup = statistics.median(r[3] for r in runs)
    s = st[0]
    pairs = s["triangle_pairs"]
    tests = s["vf_tests"] + s["ee_tests"]
    return {
        "case": name, "threads": threads, "binary": label, "refit": refit, "traverse": trav,
        "narrow": narrow, "detect": det, "det_min": min(dets), "det_max": max(dets), "wall": wall, "cpu": cpu, "setup": setup, "pairs": pairs,
        "tests": tests,
        "ns_pair": 1e9 * det * threads / max(pairs, 1),
        "ns_test": 1e9 * det * threads / max(tests, 1),
        "collisions": s["vf_collisions"] + s["ee_collisions"],
    }


def steady(ref_tool, frames, rounds=3, runs=5):
    """Markdown lines: median time of repeated detect() calls on one detector, both tools."""
    tool = ROOT / "build" / "release" / "python" / "tests" / "clothcd_py_reference"
    ball = data_dir() / "cloth-ball" / "frames"
    todo = [("cloth_ball 92 -> 93", [f"t0={ball / 'cloth_ball92.ply'}",
                                     f"t1={ball / 'cloth_ball93.ply'}", "bvh=spatial"])]
    for scene, k in SIMULATED if frames else []:
        f0, f1 = (Path(frames) / scene / f"frame_{i:04d}.obj" for i in (k, k + 1))
        todo.append((f"{scene} {k} -> {k + 1} (unsewn)", [f"t0={f0}", f"t1={f1}", "bvh=patch"]))
    lines = ["", "Repeated calls on one detector (a simulator's use): `clothcd_py_reference ... "
             f"culling=sound policy=proposed runs={runs}`, one untimed detect() and {runs} timed "
             f"ones per process, {rounds} rounds alternating with the reference; median (min-max) "
             "of the timed calls in ms. Both report the same VF and EE counts.", "",
             "| case | threads | reference | current | ratio |", "|---|---:|---:|---:|---:|"]
    for name, args in todo:
        for threads in (1, 2):
            times = {"ref": [], "cur": []}
            counts = set()
            for _ in range(rounds):
                for label, binary in (("ref", ref_tool), ("cur", str(tool))):
                    cmd = [binary, *args, "culling=sound", "policy=proposed", f"threads={threads}",
                           f"runs={runs}"]
                    res = json.loads(subprocess.run(cmd, check=True, capture_output=True,
                                                    text=True).stdout)
                    times[label] += res["seconds"]
                    counts.add((res["vf"], res["ee"]))
            if len(counts) != 1:
                sys.exit(f"{name}, {threads} threads: counts differ from the reference")
            r, c = (statistics.median(times[k]) for k in ("ref", "cur"))
            span = {k: f"{1e3 * min(v):.1f}-{1e3 * max(v):.1f}" for k, v in times.items()}
            lines.append(f"| {name} | {threads} | {1e3 * r:.1f} ({span['ref']}) | "
                         f"{1e3 * c:.1f} ({span['cur']}) | {r / c:.2f}x |")
    return lines


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ref")
    ap.add_argument("--bin", default=str(ROOT / "build" / "release" / "apps" / "clothcd"))
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--out", default=str(ROOT / "docs" / "results" / "detect_speed.md"))
    ap.add_argument("--frames", help="frames folder of a scripts/results.sh run (OUT/frames)")
    ap.add_argument("--steady-ref", help="clothcd_py_reference built from the reference")
    a = ap.parse_args()
    bins = [("current", a.bin)] + ([("reference", a.ref)] if a.ref else [])
    rows = []
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        for name, args in cases(data_dir(), a.frames):
            for threads in [int(t) for t in a.threads.split(",")]:
                runs = {label: [] for label, _ in bins}
                for rep in range(a.reps):
                    for label, b in bins:
                        runs[label].append(run(b, args, threads, f"{tmp}/{label}.json"))
                        print(f"{name} T={threads} {label} rep {rep}: "
                              f"{runs[label][-1][0]:.3f} s", file=sys.stderr)
                if a.ref:
                    for rep in range(a.reps):
                        if collisions(runs["current"][rep][1]) != collisions(
                                runs["reference"][rep][1]):
                            sys.exit(f"{name}, {threads} threads: collisions differ from the "
                                     "reference")
                for label, _ in bins:
                    rows.append(row(name, threads, label, runs[label]))
    load_after = os.getloadavg()[0]
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "-uno"],
                           capture_output=True, text=True).stdout.strip()
    cpu = platform.processor() or platform.machine()
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    cpu += f" ({vector_width()})"
    out = [
        "# Detection speed (generated)",
        "",
        f"Generated by `scripts/detect_speed.py{' --ref REF' if a.ref else ''} --reps {a.reps} "
        f"--threads {a.threads}{' --frames OUT/frames' if a.frames else ''}` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
        f"commit {commit}{' (modified)' if dirty else ''}; {cpu}, {os.cpu_count()} cores; "
        f"load average {load_before:.1f} before, {load_after:.1f} after.",
        "",
        "`clothcd detect --culling sound --policy proposed`, medians of "
        f"{a.reps} runs{', reference and current alternating' if a.ref else ''}. Detection = "
        "refit + traversal + narrow phase (times in seconds); ns per pair and per test are "
        "detection time x threads / count (CPU time per candidate). Setup: reading the frames "
        "and building the detector (topology, tree, orphans, ownership), as `clothcd detect` "
        "prints it (nan for binaries that do not). Wall and CPU: the whole process (reading, "
        "setup, detection, JSON output), CPU = user + system time of all its threads."
        + (" Every run of both binaries reported the same VF and EE collisions, times of impact "
           "included." if a.ref else ""),
        "",
        "| case | threads | binary | refit | traversal | narrow | detection | detection min-max "
        "| setup | wall | CPU | triangle pairs | feature tests | ns / pair | ns / test | "
        "collisions |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        out.append(
            f"| {r['case']} | {r['threads']} | {r['binary']} | {r['refit']:.3f} | "
            f"{r['traverse']:.3f} | {r['narrow']:.3f} | {r['detect']:.3f} | "
            f"{r['det_min']:.3f}-{r['det_max']:.3f} | {r['setup']:.3f} | {r['wall']:.3f} | "
            f"{r['cpu']:.3f} | "
            f"{r['pairs']:,} | {r['tests']:,} | {r['ns_pair']:.0f} | {r['ns_test']:.0f} | "
            f"{r['collisions']:,} |")
    if a.ref:
        out += ["", "Ratios reference / current (medians):", ""]
        out += ["| case | threads | detection | narrow | wall | CPU |",
                "|---|---:|---:|---:|---:|---:|"]
        for cur, ref in zip(rows[0::2], rows[1::2]):
            out.append(f"| {cur['case']} | {cur['threads']} | "
                       f"{ref['detect'] / cur['detect']:.2f}x | "
                       f"{ref['narrow'] / cur['narrow']:.2f}x | {ref['wall'] / cur['wall']:.2f}x | "
                       f"{ref['cpu'] / cur['cpu']:.2f}x |")
    if a.steady_ref:
        out += steady(a.steady_ref, a.frames)
    Path(a.out).write_text("\n".join(out) + "\n")
    print("\n".join(out))


if __name__ == "__main__":
    main()
