#!/usr/bin/python3
"""How far the stitches of a `clothcd simulate` folder stand open, measured from its frame files.

Usage: scripts/stitch_gaps.py [--first N] [--last N] DIR [DIR ...]

A stitch ties vertex a to the point (1 - r) x_b + r x_c of another panel's edge (the pattern
file's `stitch a b c r` lines, which the scene names with `"stitches": "pattern"`); its gap is
the distance between the two in a frame. A closed seam has gaps of a fraction of a millimetre
(the dress's drape: median 0.002 mm, p90 0.05 mm). Prints one markdown row per folder: the range
over the frames first..last (all by default) of the per-frame median, p90 and largest gap in
millimetres, and the last frame's figures. Quantiles are nearest rank.
"""
import argparse
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from frame_strain import data_file, frames_of, quantile, read_manifest, scene_cloth  # noqa: E402


def read_stitches(path: Path):
    out = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            if not line.startswith("stitch "):
                continue
            p = line.split()
            try:
                if len(p) != 5:
                    raise ValueError
                a, b, c, r = int(p[1]), int(p[2]), int(p[3]), float(p[4])
                if min(a, b, c) < 0 or not 0.0 <= r <= 1.0:
                    raise ValueError
            except ValueError:
                raise SystemExit(f"{path}:{number}: expected 'stitch a b c r' (vertex ids >= 0, "
                                 f"0 <= r <= 1), got {line.strip()!r}") from None
            out.append((a, b, c, r))
    return out


def stitches_of(folder: Path):
    m = read_manifest(folder)
    scene_file, cloth = scene_cloth(m, folder)
    if cloth.get("stitches", "none") != "pattern":
        raise SystemExit(f"{scene_file}: only stitches read from the pattern file are measured "
                         f"(cloth.stitches is {cloth.get('stitches', 'none')!r})")
    if m.get("mesh_format", "obj") != "obj":
        raise SystemExit(f"{folder}: only OBJ frames are read, this run wrote {m['mesh_format']}")
    stitches = read_stitches(data_file(scene_file, cloth, "pattern"))
    if not stitches:
        raise SystemExit(f"{scene_file}: its pattern file has no stitch lines")
    return m, stitches


def gaps(x, stitches):
    out = []
    for a, b, c, r in stitches:
        d = [x[a][k] - ((1.0 - r) * x[b][k] + r * x[c][k]) for k in range(3)]
        out.append(math.sqrt(sum(t * t for t in d)))
    return sorted(out)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--first", type=int, default=1, help="first frame (default 1)")
    ap.add_argument("--last", type=int, default=10**9, help="last frame (default: the run's last)")
    ap.add_argument("folders", nargs="+", type=Path, metavar="DIR")
    args = ap.parse_args(argv)
    first, last, folders = args.first, args.last, args.folders
    out = []  # every folder measured before anything is printed: no partial table on an error
    for folder in folders:
        m, stitches = stitches_of(folder)
        rows = {}
        for k, frame, x in frames_of(folder, m, first, last):
            if max(max(s[:3]) for s in stitches) >= len(x):
                raise SystemExit(f"{frame}: {len(x)} vertices, fewer than "
                                 "the stitches refer to")
            g = gaps(x, stitches)
            rows[k] = [1e3 * quantile(g, 0.5), 1e3 * quantile(g, 0.9), 1e3 * g[-1]]
        if not rows:
            continue
        span = [f"{min(r[i] for r in rows.values()):.2f}-{max(r[i] for r in rows.values()):.2f}"
                for i in range(3)]
        tail = " / ".join(f"{v:.2f}" for v in rows[max(rows)])
        out.append(f"| {m['scene']} | {min(rows)}-{max(rows)} | {len(stitches)} | " +
                   " | ".join(span) + f" | {tail} |")
    print("| run | frames | stitches | median mm | p90 mm | largest mm |"
          " last frame: median / p90 / largest mm |")
    print("|---|---|---|---|---|---|---|")
    for line in out:
        print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
