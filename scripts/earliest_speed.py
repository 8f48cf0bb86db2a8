#!/usr/bin/env python3
"""The earliest-impact query against a full detection of the same step, back to back.

For each case, thickness and thread count, runs `clothcd detect` (every collision) and
`clothcd detect --earliest` alternately REPS times and writes a markdown table of the medians
(min-max) of the detection time (refit + traversal + narrow phase, from the JSON), their ratio,
the earliest time of impact and its pair, and the windows searched. A full detection that takes
longer than 20 s is repeated SLOW_REPS times only.

Usage: scripts/earliest_speed.py [--bin BIN] [--reps N] [--slow-reps N] [--repeat N] [--threads 1,2]
                                 [--frames OUT/frames] [--out FILE]
  defaults: --bin build/release/apps/clothcd, 3 reps, 1 slow rep, 3 repeated calls per run
  (`clothcd detect --earliest --repeat`), threads 1,2, output
  docs/results/earliest.md. Data: $CLOTHCD_DATA or ../shared/data. --frames: the frames folder
  of a `scripts/results.sh OUT` run (or any folder of <scene>/frame_NNNN.obj): adds the
  simulated garment steps dress-rumba and multilayer-rumba 60 -> 61 (sewn at 1e-3, patch
  build), at zero thickness and at 1e-3, and the same steps unsewn at zero thickness (their
  seams' edges nearly touching).
"""

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SIMULATED = [("dress-rumba", 60), ("multilayer-rumba", 60)]


def data_dir():
    return Path(os.environ.get("CLOTHCD_DATA", ROOT.parent / "shared" / "data")).resolve()


def cases(frames):
    ball = data_dir() / "cloth-ball" / "frames"
    out = [("cloth_ball 92 -> 93", 0.0,
            ["--t0", str(ball / "cloth_ball92.ply"), "--t1", str(ball / "cloth_ball93.ply")])]
    for scene, k in SIMULATED if frames else []:
        f0, f1 = (Path(frames) / scene / f"frame_{i:04d}.obj" for i in (k, k + 1))
        if not (f0.is_file() and f1.is_file()):
            sys.exit(f"earliest_speed.py: --frames {frames}: {f0} or {f1} is missing")
        args = ["--t0", str(f0), "--t1", str(f1), "--sew", "1e-3", "--bvh", "patch"]
        for h in (0.0, 1e-3):
            out.append((f"{scene} {k} -> {k + 1}", h, args))
        # The same step with the seams left as the frames have them: the stitched panels' edges
        # a fraction of a micrometre apart, sliding along each other (near-touching pairs).
        out.append((f"{scene} {k} -> {k + 1}, seams unsewn", 0.0, args[:4] + ["--bvh", "patch"]))
    return out


def run(binary, args, h, threads, earliest, json_path, repeat=0):
    cmd = [binary, "detect", *args, "--culling", "sound", "--policy", "proposed", "--thickness",
           str(h), "--threads", str(threads), "--json", json_path]
    if earliest:
        cmd += ["--earliest", "--repeat", str(repeat)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(json_path) as f:
        res = json.load(f)
    s = res["stats"]
    return s["time_refit"] + s["time_traverse"] + s["time_narrow"], res


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def cpu_flags():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("flags"):
                f = line.split()
                return "AVX-512" if "avx512f" in f else "AVX2" if "avx2" in f else "no AVX2"
    except OSError:
        pass
    return "unknown ISA"


def spread(v):
    return f"{1e3 * statistics.median(v):.1f} ({1e3 * min(v):.1f}-{1e3 * max(v):.1f})"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=str(ROOT / "build" / "release" / "apps" / "clothcd"))
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--slow-reps", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--frames")
    ap.add_argument("--out", default=str(ROOT / "docs" / "results" / "earliest.md"))
    a = ap.parse_args()
    load_before = os.getloadavg()[0]
    lines = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, h, args in cases(a.frames):
            for threads in [int(t) for t in a.threads.split(",")]:
                full, early, warm, answers = [], [], [], set()
                for rep in range(a.reps):
                    if rep < a.slow_reps or not full or max(full) < 20:
                        full.append(run(a.bin, args, h, threads, False, f"{tmp}/f.json")[0])
                    t, res = run(a.bin, args, h, threads, True, f"{tmp}/e.json", a.repeat)
                    early.append(t)
                    warm += [sum(c.values()) for c in res.get("repeat", [])]
                    e = res["earliest"]
                    answers.add((e["toi"], e["kind"], json.dumps(e["ids"]),
                                 res["stats"]["windows"], res["stats"]["first_window"]))
                    print(f"{name} h={h} T={threads} rep {rep}: full {full[-1]:.3f} s, "
                          f"earliest {t:.3f} s", file=sys.stderr)
                if len(answers) != 1:
                    sys.exit(f"{name}, h {h}, {threads} threads: the answer changed between runs")
                toi, kind, ids, windows, first = answers.pop()
                again = warm or early
                ratio = statistics.median(again) / statistics.median(full)
                lines.append(f"| {name} | {h:g} | {threads} | {spread(full)} | {spread(early)} | "
                             f"{spread(again)} | {ratio:.3f} | {toi:.10g} | {kind} {ids} | "
                             f"{windows} (first [0, {first:g}]) |")
    load_after = os.getloadavg()[0]
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    out = [
        "# Earliest impact against a full detection (generated)",
        "",
        f"Generated by `scripts/earliest_speed.py --reps {a.reps} --slow-reps {a.slow_reps} "
        f"--repeat {a.repeat} "
        f"--threads {a.threads}{' --frames OUT/frames' if a.frames else ''}` on "
        f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, commit {commit}; {cpu_name()} "
        f"({cpu_flags()}), {os.cpu_count()} cores; load average {load_before:.1f} before, "
        f"{load_after:.1f} after.",
        "",
        "Detection time: refit + traversal + narrow phase as the JSON reports them (for the "
        "earliest impact, the whole query: every window, and the timing and refinement of its "
        "candidates), ms, median (min-max) over the runs, `clothcd detect ... --culling sound "
        "--policy proposed` without and with `--earliest` (default tolerance 1e-6), run "
        "alternately. First call: the query's first call on a new detector (as the full detection "
        "is timed), which also allocates the detector's buffers; repeated calls: the "
        f"`--repeat {a.repeat}` calls on the same detector that follow it, each after a call on 3/4 "
        "of the step, as a line search makes them. Ratio: repeated calls / full detection. The "
        "pair as vertex ids of the input (vf: vertex, face corners; ee: the two edges). Every "
        "call of a case gave the same answer.",
        "",
        "| case | thickness | threads | full detection ms | earliest impact, first call ms | "
        "earliest impact, repeated calls ms | ratio | toi | pair | windows |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---|---|",
        *lines,
        "",
    ]
    Path(a.out).write_text("\n".join(out))
    print("\n".join(out))


if __name__ == "__main__":
    main()
