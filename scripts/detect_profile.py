#!/usr/bin/env python3
"""Where one `clothcd detect` step spends its instructions, stage by stage (callgrind).

For each case of scripts/detect_speed.py (cloth_ball and the garment steps; with --frames the
simulated garment frame pairs too), runs the binary once under callgrind on one thread with
`--culling sound --policy proposed` and writes a markdown table: each stage's inclusive
instruction count, its share of the detection, and instructions per triangle pair and per
feature test (the counts `clothcd detect --json` reports). Instruction counts are exact and
repeatable where times are not, but they do not see memory waits: docs/results/detect_speed.md
has the times.

Usage: scripts/detect_profile.py [--bin BIN] [--frames OUT/frames] [--out FILE]
  defaults: --bin build/release/apps/clothcd, output docs/results/detect_profile.md.
  Needs valgrind (Debian package `valgrind`). Data: $CLOTHCD_DATA or ../shared/data.
"""

import argparse
import datetime
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import detect_speed  # noqa: E402  (its cases and data folder)

ROOT = detect_speed.ROOT

# (label, depth, function-name patterns): a stage's count is the largest inclusive count of a
# function matching its pattern (callgrind_annotate lists a function once per source file its
# code came from; the largest is the whole function), summed over the patterns.
STAGES = [
    ("whole process", 0, [r"^PROGRAM TOTALS$"]),
    ("reading the frames", 1, [r"clothcd::read_mesh\("]),
    ("building the detector (topology, tree, orphans, ownership)", 1,
     [r"clothcd::SelfDetector::SelfDetector\("]),
    ("detection", 1, [r"clothcd::detail::SelfCore::detect\("]),
    ("refit (boxes and cones)", 2, [r"clothcd::detail::SelfCore::refit\("]),
    ("traversal (box and cone tests, triangle pairs)", 2,
     [r"clothcd::detail::SelfCore::traverse\("]),
    # The pair loop over each round of the traversal's pairs, the orphans, and the step's
    # feature boxes (brought up to date before the first round, timed as narrow phase).
    ("narrow phase", 2, [r"clothcd::detail::SelfCore::narrow_pairs\(",
                         r"clothcd::detail::SelfCore::narrow_orphans\(",
                         r"clothcd::detail::FeatureBoxes::update\("]),
    ("whole-triangle distance filter (vectorised)", 3,
     [r"clothcd::ccd_detail::triangles_filter_batch\("]),
    ("NP filter (vectorised)", 3, [r"clothcd::ccd_detail::np_filter_batch\("]),
    ("feature distance filter (vectorised)", 3, [r"clothcd::ccd_detail::distance_filter_batch\("]),
    ("fast-path settle (vectorised)", 3, [r"clothcd::ccd_detail::fast_path_settle\("]),
    ("scalar kernels (the pairs left undecided)", 3,
     [r"clothcd::ccd_detail::vertex_face_ccd_np_kept\(",
      r"clothcd::ccd_detail::edge_edge_ccd_np_kept\(", r"^clothcd::vertex_face_ccd\(",
      r"^clothcd::edge_edge_ccd\("]),
]
# The narrow phase's remainder: R-triangle ownership, feature boxes, gathering coordinates into
# the batches, orphans.
REST = "the pair loop: ownership, feature boxes, gathering into batches, orphans"
LINE = re.compile(r"^\s*([\d,]+)\s+\([\s\d.]+%\)\s+(.*)$")


def inclusive_counts(callgrind_out):
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100",
                           str(callgrind_out)], check=True, capture_output=True,
                          text=True).stdout
    counts = []
    for line in text.splitlines():
        m = LINE.match(line)
        if not m:
            continue
        name = m.group(2)
        # "file:function [object]": keep the function (file is ??? without debug info).
        if name != "PROGRAM TOTALS":
            name = re.sub(r"\s+\[[^\]]*\]$", "", name).split(":", 1)[-1]
        counts.append((name, int(m.group(1).replace(",", ""))))
    return counts


def stage_count(counts, patterns):
    """The stage's count, or None where no function of the profile matches (a renamed function
    would otherwise read as a stage that costs nothing)."""
    found = False
    total = 0
    for p in patterns:
        rx = re.compile(p)
        matches = [n for name, n in counts if rx.search(name)]
        found = found or bool(matches)
        total += max(matches, default=0)
    return total if found else None


def profile(binary, args, tmp):
    out = tmp / "callgrind.out"
    js = tmp / "result.json"
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(binary), "detect",
           *args, "--culling", "sound", "--policy", "proposed", "--threads", "1", "--json",
           str(js)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    counts = inclusive_counts(out)
    stats = json.loads(js.read_text())["stats"]
    rows = []
    for label, depth, pats in STAGES:
        n = stage_count(counts, pats)
        if n is None and label.startswith("scalar kernels"):
            n = 0  # a step whose batches settle every pair calls no scalar kernel
        if n is None:
            sys.exit(f"detect_profile.py: no function of the profile matches the stage '{label}' "
                     f"({', '.join(pats)}): renamed, inlined, or a binary without symbols?")
        rows.append((label, depth, n))
    by = {label: n for label, _, n in rows}
    inner = sum(n for label, depth, n in rows if depth == 3)
    rows.append((REST, 3, by["narrow phase"] - inner))
    return rows, stats


def table(name, rows, stats):
    pairs = stats["triangle_pairs"]
    tests = stats["vf_tests"] + stats["ee_tests"]
    detection = dict((label, n) for label, _, n in rows)["detection"]
    out = [f"### {name}", "",
           f"{pairs:,} triangle pairs, {tests:,} feature tests, "
           f"{stats['vf_collisions'] + stats['ee_collisions']:,} collisions.", "",
           "| stage | instructions (M) | share of detection | per triangle pair "
           "| per feature test |",
           "|---|---:|---:|---:|---:|"]
    for label, depth, n in rows:
        # Reading and building come before the detection, which the deeper rows divide.
        share = f"{100 * n / detection:.1f}%" if label == "detection" or depth >= 2 else ""
        indent = "&nbsp;&nbsp;" * max(0, depth - 1)
        out.append(f"| {indent}{label} | {n / 1e6:,.0f} | {share} | "
                   f"{n / max(pairs, 1):,.0f} | {n / max(tests, 1):,.0f} |")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=str(ROOT / "build" / "release" / "apps" / "clothcd"))
    ap.add_argument("--frames", help="frames folder of a scripts/results.sh run")
    ap.add_argument("--out", default=str(ROOT / "docs" / "results" / "detect_profile.md"))
    a = ap.parse_args()
    for tool in ("valgrind", "callgrind_annotate"):
        if shutil.which(tool) is None:
            sys.exit(f"detect_profile.py: {tool} not found (apt-get install valgrind)")
    binary = Path(a.bin)
    if not binary.is_file():
        sys.exit(f"detect_profile.py: {binary} not found (build first, or pass --bin)")
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip() or "unknown"
    when = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    cmd = "scripts/detect_profile.py" + (" --frames OUT/frames" if a.frames else "")
    out = ["# Where a detection step's instructions go (generated)", "",
           f"Generated by `{cmd}` on {when}, commit {commit}; {platform.machine()}. valgrind "
           "runs the AVX2 bodies of the batched filters (it has no AVX-512), 4 doubles a "
           "vector, whatever the processor.", "",
           "`clothcd detect --culling sound --policy proposed --threads 1` under callgrind: "
           "each stage's instructions including everything it calls, in millions, its share "
           "of the detection (refit + traversal + narrow phase) and per candidate. The "
           "narrow phase's rows add up to it; the vectorised rows count one vector "
           "instruction per lane group (on this machine's widest unit). Instructions are "
           "exact and repeatable but do not show memory waits, which weigh most in the pair "
           "loop's scattered reads: `detect_speed.md` has the times.", ""]
    with tempfile.TemporaryDirectory() as tmp:
        for name, args in detect_speed.cases(detect_speed.data_dir(), a.frames):
            rows, stats = profile(binary, args, Path(tmp))
            out += table(name, rows, stats) + [""]
            detection = next(n for label, _, n in rows if label == "detection")
            print(f"{name}: detection {detection / 1e6:,.0f} M instructions", file=sys.stderr)
    Path(a.out).write_text("\n".join(out))


if __name__ == "__main__":
    main()
