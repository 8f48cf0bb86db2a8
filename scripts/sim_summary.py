#!/usr/bin/python3
"""Summarize `clothcd simulate` output folders as a markdown table (one row per folder).

Usage: scripts/sim_summary.py [--parts] DIR [DIR ...]
Reads each DIR/manifest.json: frames done, seconds per frame (median, mean), the share spent in
the collision stage, substeps per frame, intersecting pairs (frame 0, worst frame, last frame),
and unresolved / excluded CCD hits. With --parts, a second table says where the collision stage's
time went (the manifest's collision_parts, summed over frames; runs that predate them are
skipped), and a third splits the self detector's part: its full CCD passes' phases and its
proximity query. A strain table follows when the manifests have the per-frame `strain` figures:
the worst frame's median, p99, p99.9 and largest strain, where the largest sat (the count of
frames per site), and the limiter's share of the time.
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


PARTS = [
    ("proximity_s", "proximity"),
    ("ccd_self_s", "CCD self detector"),
    ("ccd_body_s", "CCD body detector"),
    ("ccd_hits_s", "hits to contacts"),
    ("response_s", "response"),
    ("zones_s", "impact zones"),
    ("crossings_s", "crossings"),
    ("setup_s", "setup"),
]


def with_parts(folder: Path) -> tuple[dict, list]:
    """The manifest and its frames that have collision_parts."""
    m = json.loads((folder / "manifest.json").read_text())
    return m, [f for f in m["frames"] if "collision_parts" in f]


def parts_row(folder: Path) -> str | None:
    m, frames = with_parts(folder)
    if not frames:
        return None
    col = sum(f["collision_seconds"] for f in frames)
    sums = {k: sum(f["collision_parts"][k] for f in frames) for k, _ in PARTS}
    ms = 1000 * col / sum(f["substeps"] for f in frames)
    cells = [f"{100 * sums[k] / col:.0f}%" if col > 0 else "" for k, _ in PARTS]
    other = 100 * (col - sum(sums.values())) / col if col > 0 else 0
    return f"| {m['scene']} | {len(frames)} | {ms:.1f} | " + " | ".join(cells) + f" | {other:.0f}% |"


def self_row(folder: Path) -> str | None:
    m, frames = with_parts(folder)
    if not frames:
        return None
    ccd = [f["self_ccd"] for f in frames]
    prox = [f["self_proximity"] for f in frames]
    calls = sum(c["calls"] for c in ccd)
    pcalls = sum(p["calls"] for p in prox)
    if calls == 0 or pcalls == 0:
        return None

    def per_call(key: str) -> str:
        return f"{1000 * sum(c[key] for c in ccd) / calls:.1f}"

    full = sum(c["refit_s"] + c["traversal_s"] + c["narrow_s"] for c in ccd)
    self_ccd = sum(f["collision_parts"]["ccd_self_s"] for f in frames)
    query = sum(p["query_s"] for p in prox)
    proximity = sum(f["collision_parts"]["proximity_s"] for f in frames)
    return (
        f"| {m['scene']} | {calls} | {sum(c['triangle_pairs'] for c in ccd) // calls} | "
        f"{per_call('refit_s')} | {per_call('traversal_s')} | {per_call('narrow_s')} | "
        f"{100 * full / self_ccd:.0f}% | {1000 * query / pcalls:.1f} | "
        f"{100 * query / proximity:.0f}% |"
    )


SITES = ["seam", "sliver", "body_contact", "elsewhere"]


def strain_row(folder: Path) -> str | None:
    m = json.loads((folder / "manifest.json").read_text())
    frames = [f for f in m["frames"] if "strain" in f]
    if not frames:
        return None
    st = [f["strain"] for f in frames]

    def worst(key: str) -> str:
        i = max(range(len(st)), key=lambda k: st[k][key])
        return f"{100 * st[i][key]:.1f}% ({frames[i]['frame']})"

    sites = {s: sum(1 for x in st if x["max_site"] == s) for s in SITES}
    limit = m.get("strain_limit", {})
    secs = sum(f["seconds"] for f in frames)
    share = sum(f.get("strain_seconds", 0.0) for f in frames) / secs if secs else 0
    return (
        f"| {m['scene']} | {limit.get('stretch', '')} | {len(frames)} | "
        f"{100 * max(x['median'] for x in st):.2f}% | {worst('p99')} | {worst('p999')} | "
        f"{worst('max')} | " + " / ".join(str(sites[s]) for s in SITES) + f" | {100 * share:.1f}% |"
    )


def tables(folders: list[Path], parts: bool) -> list[str]:
    """Every line of the output; raises on the first folder that cannot be read."""
    out = ["| scene | frames | s/frame median / mean | collision share | substeps/frame | "
           "intersecting pairs self / body at frame 0 | worst frame | last frame | "
           "frames with 0 / 0 | unresolved CCD hits |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    out += [row(d) for d in folders]
    strain = [r for r in (strain_row(d) for d in folders) if r is not None]
    if strain:
        out += ["",
                "| scene | strain limit | frames | largest median | worst p99 (frame) | "
                "worst p99.9 (frame) | largest (frame) | frames whose largest sits at seam / "
                "sliver / body contact / elsewhere | limiter time share |",
                "|---|---|---:|---:|---:|---:|---:|---|---:|"] + strain
    if parts:
        out += ["",
                "| scene | frames | collision ms / substep | "
                + " | ".join(name for _, name in PARTS) + " | between parts |",
                "|---|---:|---:|" + "---:|" * (len(PARTS) + 1)]
        out += [r for r in (parts_row(d) for d in folders) if r is not None]
        out += ["",
                "Self detector: its full CCD passes (the first of each substep) per call, their "
                "share of all its CCD calls' time, and its proximity query per call and share of "
                "the proximity part (the rest: the cloth-body query and the contacts built).",
                "",
                "| scene | full passes | triangle pairs / pass | refit ms | traversal ms | "
                "narrow ms | share of CCD self | proximity query ms | share of proximity |",
                "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
        out += [r for r in (self_row(d) for d in folders) if r is not None]
    return out


def main() -> int:
    args = sys.argv[1:]
    parts = "--parts" in args
    args = [a for a in args if a != "--parts"]
    if not args:
        print(__doc__, file=sys.stderr)
        return 2
    # Every folder is read (once) before anything is printed: no partial table on an error.
    folders = [Path(d) for d in args]
    errors = (OSError, KeyError, ValueError, TypeError, ZeroDivisionError)
    try:
        out = tables(folders, parts)
    except errors:
        # Name the first folder that fails on its own, with its own error.
        for d in folders:
            try:
                tables([d], parts)
            except errors as e:
                what = f"no {e.args[0]!r} in it" if isinstance(e, KeyError) else str(e)
                print(f"{d}: cannot read manifest.json: {what}", file=sys.stderr)
                return 1
        raise
    print("\n".join(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
