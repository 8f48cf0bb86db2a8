#!/usr/bin/env python3
"""Simulates scenes with two clothcd binaries and checks that every frame file is byte-identical.

For each scene, runs the reference binary and the current one back to back (or side by side with
--parallel, on a machine with cores to spare), from the same start, then compares every frame
file and writes a markdown table: frames compared, the first frame that differs (if any), the
largest number of intersecting pairs in a frame, and the seconds per frame of both runs with
their ratio (the sum over the frames, and the median and quartiles of the per-frame ratios).

Usage: scripts/compare_frames.py --ref BIN [--bin BIN] [--threads N] [--frames N] [--parallel]
                                 [--out DIR] SCENE...
  SCENE: a name under scenes/ (dress-kick) or a scene file. --frames: simulate only the first N
  frames (default: the scene's own count). A run already in DIR is continued (--resume), so a
  long comparison can be done in pieces. The table goes to DIR/compare.md.
  Data: $CLOTHCD_DATA or ../shared/data.
"""

import argparse
import filecmp
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def scene_file(name):
    p = Path(name)
    return p if p.suffix == ".json" else ROOT / "scenes" / f"{name}.json"


def simulate(binary, scene, out, threads, frames):
    cmd = [str(binary), "simulate", str(scene), "--out", str(out), "--threads", str(threads),
           "--resume"]
    if frames is not None:
        cmd += ["--frames", str(frames)]
    log = open(out.parent / f"{out.name}.log", "a")
    return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)


def frames_of(manifest):
    return {f["frame"]: f for f in json.loads(manifest.read_text())["frames"]}


def compare(ref_dir, new_dir):
    """(frames compared, first differing frame file or None)."""
    names = sorted(p.name for p in ref_dir.glob("frame_*"))
    if names != sorted(p.name for p in new_dir.glob("frame_*")):
        return len(names), "the two runs wrote different frame files"
    for n in names:
        if not filecmp.cmp(ref_dir / n, new_dir / n, shallow=False):
            return len(names), n
    return len(names), None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ref", required=True, type=Path, help="reference clothcd binary")
    ap.add_argument("--bin", type=Path, default=ROOT / "build" / "release" / "apps" / "clothcd")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--frames", type=int)
    ap.add_argument("--parallel", action="store_true", help="run both binaries at once")
    ap.add_argument("--out", type=Path, default=Path("compare-frames"))
    ap.add_argument("scenes", nargs="+")
    args = ap.parse_args()
    os.environ.setdefault("CLOTHCD_DATA", str(ROOT.parent / "shared" / "data"))
    for b in (args.ref, args.bin):
        if not os.access(b, os.X_OK):
            sys.exit(f"compare_frames.py: {b} is not an executable")
    args.out.mkdir(parents=True, exist_ok=True)

    rows, failed = [], False
    load_before = os.getloadavg()
    for name in args.scenes:
        scene = scene_file(name)
        if not scene.is_file():
            sys.exit(f"compare_frames.py: no scene file {scene}")
        dirs = {k: args.out / k / scene.stem for k in ("ref", "new")}
        for d in dirs.values():
            d.parent.mkdir(parents=True, exist_ok=True)
        procs = []
        for k, b in (("ref", args.ref), ("new", args.bin)):
            procs.append(simulate(b, scene, dirs[k], args.threads, args.frames))
            if not args.parallel:
                procs[-1].wait()
        if any(p.wait() != 0 for p in procs):
            failed = True
            rows.append(f"| {scene.stem} | - | a run failed (see {args.out}/*/{scene.stem}.log) "
                        "| - | - | - | - | - |")
            continue
        count, diff = compare(dirs["ref"], dirs["new"])
        failed |= diff is not None
        ref_f, new_f = (frames_of(dirs[k] / "manifest.json") for k in ("ref", "new"))
        common = sorted(set(ref_f) & set(new_f))
        worst = max((f.get("self_intersections", 0) + f.get("body_intersections", 0)
                     for f in list(ref_f.values()) + list(new_f.values())), default=0)
        rs = sum(ref_f[k]["seconds"] for k in common)
        ns = sum(new_f[k]["seconds"] for k in common)
        ratios = [new_f[k]["seconds"] / ref_f[k]["seconds"] for k in common
                  if ref_f[k]["seconds"] > 0]
        q = statistics.quantiles(ratios, n=4) if len(ratios) >= 2 else [float("nan")] * 3
        rows.append(f"| {scene.stem} | {count} | {diff or 'none'} | {worst} | "
                    f"{rs / max(len(common), 1):.2f} | {ns / max(len(common), 1):.2f} | "
                    f"{ns / rs if rs > 0 else float('nan'):.3f} | "
                    f"{statistics.median(ratios) if ratios else float('nan'):.3f} "
                    f"({q[0]:.3f}-{q[2]:.3f}) |")

    mode = "side by side" if args.parallel else "back to back"
    text = "\n".join([
        "# Frames of two binaries compared",
        "",
        f"- reference: `{args.ref}`; current: `{args.bin}`",
        f"- {args.threads} threads each, run {mode}; frames: {args.frames or 'all'}",
        f"- date: {time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}; load average "
        f"before {' '.join(f'{x:.2f}' for x in load_before)}, after "
        f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}",
        "- seconds per frame are from each run's manifest (frames resumed from an earlier run "
        "count with the time they took then)",
        "",
        "| scene | frame files | first differing | most intersecting pairs in a frame | "
        "ref s/frame | new s/frame | ratio of sums | per-frame ratio median (quartiles) |",
        "|---|---|---|---|---|---|---|---|",
        *rows,
        "",
    ])
    (args.out / "compare.md").write_text(text)
    print(text)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
