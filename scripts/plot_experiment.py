#!/usr/bin/python3
"""Figures of `clothcd experiment` (the paper's Figures 5 and 6) from OUT/steps.csv and
OUT/spread.csv.

    /usr/bin/python3 scripts/plot_experiment.py OUT

fig5.png: spread angle of the tracked BVH node over the steps, PROVOT / PROPOSED / EXACT / OPTIMAL,
and beside it the mean half-angle over all internal nodes (those with a non-saturated OPTIMAL cone)
relative to OPTIMAL's (one row per scene, two columns per BVH build). fig6.png: triangle pair tests per step, one row per
scene, one column per culling rule, one line per policy and build (the unculled reference dashed).
Needs Debian's python3-matplotlib (call /usr/bin/python3, not another python3 on the PATH).
"""
import csv
import os
import sys
from collections import defaultdict

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write(
        "plot_experiment.py: matplotlib is missing for %s; install python3-matplotlib "
        "(apt-get install python3-matplotlib) and run it with /usr/bin/python3\n" % sys.executable)
    sys.exit(3)

COLORS = {"PROVOT": "tab:red", "PROPOSED": "tab:blue", "EXACT": "tab:green", "OPTIMAL": "0.45"}
STYLES = {"spatial": "-", "patch": ":"}


def read(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def save(fig, path):
    # Atomic: a reader never sees a half-written PNG.
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, path)
    plt.close(fig)


def ordered(values, preferred):
    out = [v for v in preferred if v in values]
    return out + sorted(v for v in values if v not in out)


def fig5(spread, out):
    # A one-step scene makes no curve: the tables carry it.
    scenes = [s for s in dict.fromkeys(r["scene"] for r in spread)
              if len({r["step"] for r in spread if r["scene"] == s}) >= 2]
    builds = ordered({r["build"] for r in spread}, ["spatial", "patch"])
    if not scenes:
        return False
    # Per build: the tracked node's angle, then the all-node ratio to OPTIMAL.
    fig, axes = plt.subplots(len(scenes), 2 * len(builds),
                             figsize=(5.0 * 2 * len(builds), 3.0 * len(scenes)), squeeze=False)
    for i, scene in enumerate(scenes):
        for j, build in enumerate(builds):
            ax = axes[i][2 * j]
            rax = axes[i][2 * j + 1]
            rows = [r for r in spread if r["scene"] == scene and r["build"] == build]
            node = rows[0]["node"] if rows else "?"
            depth = rows[0]["node_depth"] if rows else "?"
            opt = {int(r["step"]): float(r["opt_domain_mean_deg"]) for r in rows
                   if r["policy"] == "OPTIMAL"}
            for policy in ordered({r["policy"] for r in rows}, ["PROVOT", "PROPOSED", "EXACT", "OPTIMAL"]):
                # Saturated cones (>= 90 deg, stored larger by older runs) are drawn at 90.
                pts = sorted((int(r["step"]), min(90.0, float(r["node_angle_deg"])))
                             for r in rows if r["policy"] == policy)
                if not pts:
                    continue
                xs, ys = zip(*pts)
                # EXACT dashed so PROPOSED stays visible where they coincide.
                style = {"EXACT": "--", "OPTIMAL": ":"}.get(policy, "-")
                sparse = len(xs) < 12 or (policy == "OPTIMAL" and len(xs) < len(
                    {int(r["step"]) for r in rows}))
                ax.plot(xs, ys, style, color=COLORS.get(policy, "k"), label=policy,
                        marker="o" if sparse else None, markersize=3.5,
                        linewidth=2.0 if policy == "OPTIMAL" else 1.4)
                if policy == "OPTIMAL" or not opt:
                    continue
                rpts = sorted((int(r["step"]), float(r["opt_domain_mean_deg"]) / opt[int(r["step"])])
                              for r in rows if r["policy"] == policy and int(r["step"]) in opt
                              and opt[int(r["step"])] > 0
                              and r["opt_domain_mean_deg"] not in ("nan", ""))
                if rpts:
                    rx, ry = zip(*rpts)
                    rax.plot(rx, ry, style, color=COLORS.get(policy, "k"), label=policy,
                             marker="o" if len(rx) < 12 else None, markersize=3.5, linewidth=1.4)
            ax.set_title("%s, %s build: node %s (depth %s)" % (scene, build, node, depth), fontsize=9)
            rax.set_title("%s, %s build: all nodes, mean / OPTIMAL's" % (scene, build), fontsize=9)
            rax.axhline(1.0, color=COLORS["OPTIMAL"], linestyle=":", linewidth=1.2)
            for a, ylabel in ((ax, "spread angle (deg)"), (rax, "mean half-angle / OPTIMAL")):
                a.xaxis.get_major_locator().set_params(integer=True)
                a.set_xlabel("CD call (step)")
                a.set_ylabel(ylabel)
                a.grid(alpha=0.3)
                a.legend(fontsize=7, loc="best")
    fig.suptitle("Spread angle of one BVH node over the steps (cf. the paper's Figure 5), 90 = "
                 "saturated; and the mean over the internal nodes whose OPTIMAL cone is not "
                 "saturated, relative to OPTIMAL", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    save(fig, os.path.join(out, "fig5.png"))
    return True


def fig6(steps, out):
    scenes = [s for s in dict.fromkeys(r["scene"] for r in steps)
              if len({r["step"] for r in steps if r["scene"] == s}) >= 2]
    cullings = ordered({r["culling"] for r in steps if r["culling"] != "none"}, ["cone", "gated", "sound"])
    if not scenes or not cullings:
        return False
    fig, axes = plt.subplots(len(scenes), len(cullings), figsize=(5.2 * len(cullings), 3.0 * len(scenes)),
                             squeeze=False)
    for i, scene in enumerate(scenes):
        rows = [r for r in steps if r["scene"] == scene]
        builds = ordered({r["build"] for r in rows}, ["spatial", "patch"])
        for j, culling in enumerate(cullings):
            ax = axes[i][j]
            series = defaultdict(list)
            for r in rows:
                if r["culling"] in (culling, "none"):
                    key = ("none", r["build"]) if r["culling"] == "none" else (r["policy"], r["build"])
                    series[key].append((int(r["step"]), float(r["triangle_pairs"])))
            for bi, build in enumerate(builds):
                # EXACT first, wide and pale, so PROPOSED stays visible on top where they coincide;
                # the reference does not depend on the build: drawn once.
                for policy in ["none", "EXACT", "PROVOT", "PROPOSED"]:
                    if policy == "none" and bi > 0:
                        continue
                    pts = sorted(series.get((policy, build), []))
                    if not pts:
                        continue
                    xs, ys = zip(*pts)
                    ax.plot(xs, ys, "--" if policy == "none" else STYLES.get(build, "-"),
                            color="0.6" if policy == "none" else COLORS[policy],
                            label="none (reference)" if policy == "none" else "%s %s" % (policy, build),
                            marker="o" if len(xs) < 12 else None, markersize=3,
                            linewidth=3.2 if policy == "EXACT" else 1.3,
                            alpha=0.45 if policy == "EXACT" else 1.0)
            ax.xaxis.get_major_locator().set_params(integer=True)
            ax.set_title("%s, culling %s" % (scene, culling), fontsize=9)
            ax.set_xlabel("CD call (step)")
            ax.set_ylabel("triangle pair tests")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=6, loc="best", ncol=2)
    fig.suptitle("Triangle pair tests per CD call (cf. the paper's Figure 6); solid: spatial build, "
                 "dotted: patch build", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    save(fig, os.path.join(out, "fig6.png"))
    return True


def main():
    if len(sys.argv) != 2:
        sys.stderr.write("usage: /usr/bin/python3 plot_experiment.py OUT\n")
        return 2
    out = sys.argv[1]
    steps = read(os.path.join(out, "steps.csv"))
    spread = read(os.path.join(out, "spread.csv"))
    if not steps:
        sys.stderr.write("plot_experiment.py: %s has no rows\n" % os.path.join(out, "steps.csv"))
        return 2
    made = []
    if fig5(spread, out):
        made.append("fig5.png")
    if fig6(steps, out):
        made.append("fig6.png")
    print("plot_experiment.py: wrote %s in %s" % (", ".join(made), out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
