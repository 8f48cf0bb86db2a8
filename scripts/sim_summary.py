#!/usr/bin/python3
"""Summarize `clothcd simulate` output folders as a markdown table (one row per folder).

Usage: scripts/sim_summary.py DIR [DIR ...]
Reads each DIR/manifest.json: frames done, seconds per frame (median, mean), the share spent in
the collision stage, substeps per frame, intersecting pairs (frame 0, worst frame, last frame),
and unresolved / excluded CCD hits.
"""
import json
import statistics
import sys
from pathlib import Path


def row(folder: Path) -> str:
    m = json.loads((folder / "manifest.json").read_text())
    frames = m["frames"]
    if not frames:
        return f"| {m['scene']} | 0 | | | | | | |"
    sec = [f["seconds"] for f in frames]
    col = sum(f["collision_seconds"] for f in frames)
    sub = [f["substeps"] for f in frames]
    self_ = [f["self_intersections"] for f in frames]
    body = [f["body_intersections"] for f in frames]
    worst = max(range(len(frames)), key=lambda i: (self_[i] or 0) + (body[i] or 0))
    unresolved = sum(f["unresolved_ccd_hits"] for f in frames)
    frames_unresolved = sum(1 for f in frames if f["unresolved_ccd_hits"] > 0)
    zero = sum(1 for s, b in zip(self_, body) if s == 0 and (b or 0) == 0)
    return (
        f"| {m['scene']} | {m['complete_frames']} | {statistics.median(sec):.1f} / "
        f"{statistics.mean(sec):.1f} | {100 * col / sum(sec):.0f}% | {min(sub)}-{max(sub)} | "
        f"{m['initial_self_intersections']} / {m['initial_body_intersections']} | "
        f"{self_[worst]} / {body[worst]} (frame {frames[worst]['frame']}) | "
        f"{self_[-1]} / {body[-1]} | {zero} | {unresolved} in {frames_unresolved} frames |"
    )


def main() -> int:
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    print("| scene | frames | s/frame median / mean | collision share | substeps/frame | "
          "intersecting pairs self / body at frame 0 | worst frame | last frame | "
          "frames with 0 / 0 | unresolved CCD hits |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for d in sys.argv[1:]:
        try:
            print(row(Path(d)))
        except (OSError, KeyError, ValueError) as e:
            print(f"{d}: cannot read manifest.json: {e}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
