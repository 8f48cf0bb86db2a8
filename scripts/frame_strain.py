#!/usr/bin/python3
"""Strain of the frames of a `clothcd simulate` folder, measured from its mesh files alone.

Usage: scripts/frame_strain.py [--first N] [--last N] [--json OUT] [--manifest]
                               [--over P99,P999,MAX] DIR [DIR ...]

Strain is a triangle's largest principal stretch against its rest shape, minus 1 (the manifest's
`strain`). The rest shape comes from the scene the folder's manifest names: the `vt` pattern of
`cloth.pattern` for `"rest": "pattern"`, else the cloth's initial OBJ shape. Every triangle with a
non-degenerate rest shape counts, slivers included; quantiles are nearest rank, as the simulator's.
Prints one markdown row per folder with the range of the per-frame median, p90, p99, p99.9,
largest strain and share over 10%, over the frames first..last (all by default); --json writes
the per-frame figures. Runs of any version can be measured, so figures of runs made before the
manifest had them are comparable with those after. --manifest takes the figures from the
manifest's per-frame `strain` instead (the simulator's own, from the same formula; fast).
--over adds a column with the number of frames whose p99, p99.9 and largest strain exceed the
three given fractions, e.g. --over 0.05,0.1,0.2.
"""
import argparse
import json
import math
import os
import sys
from pathlib import Path


def data_path(text: str, scene_file: Path) -> Path:
    root = os.environ.get("CLOTHCD_DATA") or str(scene_file.resolve().parent.parent / ".." / "shared" / "data")
    p = Path(text.replace("${CLOTHCD_DATA}", root))
    return p if p.is_absolute() else scene_file.parent / p


def data_file(scene_file: Path, cloth: dict, key: str) -> Path:
    """The existing file that the scene's cloth.<key> names (as the simulator resolves it)."""
    if key not in cloth:
        raise SystemExit(f"{scene_file}: cloth.{key} is not set")
    p = data_path(cloth[key], scene_file)
    if not p.is_file():
        hint = " (set CLOTHCD_DATA to the shared data folder)" if "${CLOTHCD_DATA}" in cloth[key] else ""
        raise SystemExit(f"{scene_file}: cloth.{key} names {p}, which is missing{hint}")
    return p


def read_manifest(folder: Path):
    manifest = folder / "manifest.json"
    if not manifest.is_file():
        raise SystemExit(f"{folder}: no manifest.json (not a clothcd simulate folder)")
    try:
        return json.loads(manifest.read_text())
    except json.JSONDecodeError as e:
        raise SystemExit(f"{manifest}: invalid JSON ({e})") from None


def scene_cloth(m: dict, folder: Path):
    """The scene file a manifest names and its cloth section."""
    scene_file = Path(m.get("scene_file", ""))
    if not scene_file.is_file():
        raise SystemExit(f"{folder}: the scene file its manifest names, {scene_file}, is missing")
    try:
        return scene_file, json.loads(scene_file.read_text())["cloth"]
    except (json.JSONDecodeError, KeyError, TypeError):
        raise SystemExit(f"{scene_file}: not a scene (no cloth section)") from None


def read_obj(path: Path, want_vt: bool = False):
    v, vt, faces, face_vt = [], [], [], []
    if not path.is_file():
        raise SystemExit(f"{path}: missing")
    with open(path) as f:
        for number, line in enumerate(f, 1):
            try:
                if line.startswith("v "):
                    _, x, y, z = line.split()[:4]
                    v.append((float(x), float(y), float(z)))
                elif want_vt and line.startswith("vt "):
                    p = line.split()
                    vt.append((float(p[1]), float(p[2])))
                elif line.startswith("f "):
                    idx = [t.split("/") for t in line.split()[1:4]]
                    if len(idx) != 3:
                        raise ValueError
                    faces.append(tuple(int(t[0]) - 1 for t in idx))
                    if min(faces[-1]) < 0:
                        raise ValueError
                    if want_vt:
                        face_vt.append(tuple(int(t[1]) - 1 if len(t) > 1 and t[1] else -1
                                             for t in idx))
            except (ValueError, IndexError):
                raise SystemExit(f"{path}:{number}: expected 'v x y z', 'vt u v' or a triangle "
                                 f"'f a b c', got {line.strip()!r}") from None
    return v, vt, faces, face_vt


def frames_of(folder: Path, m: dict, first: int, last: int):
    """(k, frame file, positions) of the folder's frames first..last that its manifest counts
    complete."""
    for k in range(first, min(last, m.get("complete_frames", 0)) + 1):
        frame = folder / f"frame_{k:04d}.obj"
        if not frame.is_file():
            raise SystemExit(f"{frame}: missing, though the manifest counts "
                             f"{m['complete_frames']} complete frames")
        yield k, frame, read_obj(frame)[0]


def rest_grams(scene_file: Path, cloth: dict):
    """Faces of the scene's cloth and each face's rest Gram matrix (r11, r12, r22, det), or None
    if degenerate."""
    obj = data_file(scene_file, cloth, "obj")
    v, _, faces, _ = read_obj(obj)
    nv = cloth.get("vertices", len(v))
    faces = [f for f in faces if max(f) < nv][: cloth.get("faces", len(faces))]
    if cloth.get("rest", "initial") == "pattern":
        pattern = data_file(scene_file, cloth, "pattern")
        _, vt, pfaces, pvt = read_obj(pattern, want_vt=True)
        rest = [None] * nv
        for f, t in zip(pfaces, pvt):
            for a, b in zip(f, t):
                if not 0 <= b < len(vt):
                    raise SystemExit(f"{pattern}: a face corner without a 'vt' pattern point")
                rest[a] = (vt[b][0], vt[b][1], 0.0)
        if any(rest[a] is None for f in faces for a in f):
            raise SystemExit(f"{pattern}: a vertex of the cloth's faces has no pattern point")
    else:
        rest = v[:nv]
    grams = []
    for a, b, c in faces:
        e1 = [rest[b][k] - rest[a][k] for k in range(3)]
        e2 = [rest[c][k] - rest[a][k] for k in range(3)]
        r11 = sum(x * x for x in e1)
        r12 = sum(x * y for x, y in zip(e1, e2))
        r22 = sum(x * x for x in e2)
        det = r11 * r22 - r12 * r12
        grams.append((r11, r12, r22, det) if det > 0.0 and math.isfinite(det) else None)
    return faces, grams


def strains(x, faces, grams):
    out = []
    for (a, b, c), g in zip(faces, grams):
        if g is None:
            continue
        xa, xb, xc = x[a], x[b], x[c]
        e1 = (xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2])
        e2 = (xc[0] - xa[0], xc[1] - xa[1], xc[2] - xa[2])
        g11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]
        g12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]
        g22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]
        r11, r12, r22, rdet = g
        # Eigenvalues of R^-1 G (the squared principal stretches): det(G - l R) = 0.
        tr = (g11 * r22 + g22 * r11 - 2.0 * g12 * r12) / rdet
        det = (g11 * g22 - g12 * g12) / rdet
        half = 0.5 * tr
        out.append(math.sqrt(max(0.0, half + math.sqrt(max(0.0, half * half - det)))) - 1.0)
    return out


def quantile(sorted_values, q):
    k = max(1, math.ceil(q * len(sorted_values)))
    return sorted_values[min(k, len(sorted_values)) - 1]


def figures(s):
    s = sorted(s)
    over = sum(1 for x in s if x > 0.1)
    return {"median": quantile(s, 0.5), "p90": quantile(s, 0.9), "p99": quantile(s, 0.99),
            "p999": quantile(s, 0.999), "max": s[-1], "over_10": over / len(s)}


def measure(folder: Path, first: int, last: int):
    m = read_manifest(folder)
    scene_file, cloth = scene_cloth(m, folder)
    ext = m.get("mesh_format", "obj")
    if ext != "obj":
        raise SystemExit(f"{folder}: only OBJ frames are read, this run wrote {ext}")
    faces, grams = rest_grams(scene_file, cloth)
    frames = {}
    for k, frame, x in frames_of(folder, m, first, last):
        if faces and max(max(f) for f in faces) >= len(x):
            raise SystemExit(f"{frame}: {len(x)} vertices, fewer than the cloth's faces use")
        s = strains(x, faces, grams)
        if not s:
            raise SystemExit(f"{scene_file}: no triangle with a non-degenerate rest shape")
        frames[k] = figures(s)
    return m["scene"], frames


def from_manifest(folder: Path, first: int, last: int):
    m = read_manifest(folder)
    keys = ("median", "p90", "p99", "p999", "max", "over_10")
    try:
        frames = {f["frame"]: {k: f["strain"][k] for k in keys} for f in m["frames"]
                  if "strain" in f and first <= f["frame"] <= last}
        return m["scene"], frames
    except (KeyError, TypeError) as e:
        raise SystemExit(f"{folder / 'manifest.json'}: no per-frame strain figures "
                         f"(missing {e})") from None


def span(values, scale=100.0):
    return f"{scale * min(values):.1f}-{scale * max(values):.1f}%"


def fractions(text: str):
    try:
        over = [float(t) for t in text.split(",")]
    except ValueError:
        over = []
    if len(over) != 3:
        raise argparse.ArgumentTypeError(f"expected three fractions P99,P999,MAX, got {text!r}")
    return over


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--first", type=int, default=1, help="first frame (default 1)")
    ap.add_argument("--last", type=int, default=10**9, help="last frame (default: the run's last)")
    ap.add_argument("--json", type=Path, help="also write the per-frame figures to this file")
    ap.add_argument("--manifest", action="store_true",
                    help="the simulator's own per-frame figures from the manifest (fast)")
    ap.add_argument("--over", type=fractions, metavar="P99,P999,MAX",
                    help="count the frames above these p99, p99.9 and largest strains")
    ap.add_argument("folders", nargs="+", type=Path, metavar="DIR")
    args = ap.parse_args(argv)
    over = args.over
    head = "| run | frames | median | p90 | p99 | p99.9 | max per frame | over 10% |"
    rule = "|---|---|---|---|---|---|---|---|"
    if over:
        head += (f" frames over p99 {100 * over[0]:g}% / p99.9 {100 * over[1]:g}% / "
                 f"max {100 * over[2]:g}% |")
        rule += "---|"
    rows, dump = [], {}  # every folder measured before anything is printed: no partial table
    for folder in args.folders:
        scene, frames = (from_manifest if args.manifest else measure)(folder, args.first, args.last)
        dump[str(folder)] = frames
        if not frames:
            continue
        f = list(frames.values())
        cells = [span([x[k] for x in f]) for k in ("median", "p90", "p99", "p999", "max", "over_10")]
        if over:
            cells.append(" / ".join(str(sum(1 for x in f if x[k] > t))
                                    for k, t in zip(("p99", "p999", "max"), over)))
        rows.append(f"| {scene} | {min(frames)}-{max(frames)} | " + " | ".join(cells) + " |")
    if args.json:
        args.json.write_text(json.dumps(dump, indent=1) + "\n")
    print(head)
    print(rule)
    for row in rows:
        print(row)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
