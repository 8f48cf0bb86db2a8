"""`clothcd view` in a real browser: for every scene in scenes/ a short simulation, and for the
detection results of cloth_ball (frames 92 -> 93) and of a garment frame pair (the dress's first
two simulated frames), the page is written and opened in headless Chromium, whose DevTools
protocol plays the page's own check (#test): the cloth's colour must be on screen (counted in the
page and again in a screenshot), play must advance the frame counter, a hit chosen from the list
must be selected, and the strain the page computes must match the manifest's max_stretch.

Usage: browser_test.py --clothcd BIN --scenes DIR [--data DIR] --work DIR [--screenshots DIR]
Exit code 77 (ctest's skip) when no Chromium or no data is there.
"""

import argparse
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from chromium import Chromium, find_chromium  # noqa: E402
from png_pixels import count_pixels  # noqa: E402

PANEL = 320  # the side panel's width: screenshots count cloth pixels left of it
failures = []
# The page's state (main.js), {} while the page is not there yet.
STATE = ("(document.getElementById('clothcd-state') ? "
         "JSON.parse(document.getElementById('clothcd-state').textContent) : {})")


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def run(args):
    print("$ " + " ".join(args), flush=True)
    done = subprocess.run(args, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"{args[0]} failed ({done.returncode}):\n{done.stdout}\n{done.stderr}")
    return done.stdout


def bluish(r, g, b):
    return b > r + 30 and b > g + 10


def open_page(browser, page, fragment, screenshot):
    """Opens page#fragment, waits for the page's check and returns its state."""
    started = time.monotonic()
    browser.open("file://" + os.path.abspath(page) + "#" + fragment)
    state = browser.wait_for(STATE + ".done ? " + STATE + " : null", timeout=120)
    check(state is not None, f"{page}: the page's check finished")
    if state is None:
        return {}
    print(f"     {page}: {json.dumps(state)[:300]} ({time.monotonic() - started:.1f} s)")
    check("error" not in state, f"{page}: no error ({state.get('error', '')})")
    check(not browser.console_errors(), f"{page}: no console errors {browser.console_errors()}")
    check(state.get("clothPixels", 0) > 0.002 * state.get("pixels", 1),
          f"{page}: the cloth's colour on screen ({state.get('clothPixels')} pixels)")
    browser.screenshot(screenshot)
    seen = count_pixels(screenshot, bluish, right_margin=PANEL)
    check(seen > 1000, f"{screenshot}: the cloth's colour in the screenshot ({seen} pixels)")
    return state


def check_sequence(state, page, manifest_path):
    check(state.get("kind") == "sequence", f"{page}: a sequence page")
    check(state.get("playedTo", 0) != state.get("playedFrom", 0),
          f"{page}: play advanced the frame counter ({state.get('playedFrom')} -> "
          f"{state.get('playedTo')})")
    with open(manifest_path) as f:
        manifest = json.load(f)
    page_strain = state.get("maxStrain")
    if page_strain is None:
        check(False, f"{page}: strain colouring available")
        return
    for entry in manifest["frames"]:
        k = entry["frame"]
        want, got = entry["max_stretch"], page_strain[k]
        check(abs(got - want) <= 0.02 + 0.05 * abs(want),
              f"{page}: frame {k} strain {got:.4f} matches the manifest's max_stretch {want:.4f}")


def check_detection(state, page, result_path):
    with open(result_path) as f:
        result = json.load(f)
    hits = len(result.get("vf", [])) + len(result.get("ee", []))
    check(state.get("kind") == "detection", f"{page}: a detection page")
    check(state.get("hits") == hits, f"{page}: lists all {hits} hits ({state.get('hits')})")
    check(hits > 0 and state.get("listedHit") == 0 and state.get("selectedHit") == 0 and
          state.get("selectedText", "").startswith("selected: #0 "),
          f"{page}: the first hit of the list selected ({state.get('selectedText')})")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--clothcd", required=True)
    ap.add_argument("--scenes", required=True)
    ap.add_argument("--data", help="the shared data (default: CLOTHCD_DATA, else --data-default)")
    ap.add_argument("--data-default", default="../shared/data")
    ap.add_argument("--work", required=True)
    ap.add_argument("--screenshots", help="also keep the screenshots of the docs here")
    ap.add_argument("--frames", type=int, default=1, help="frames simulated per scene")
    a = ap.parse_args()
    a.data = a.data or os.environ.get("CLOTHCD_DATA") or a.data_default
    if not os.path.isdir(os.path.join(a.data, "cloth-ball")):
        print(f"SKIP: no shared data in {a.data} (set CLOTHCD_DATA)")
        return 77
    chromium = find_chromium()
    if chromium is None:
        print("SKIP: no chromium installed (scripts/setup.sh full installs it)")
        return 77
    os.makedirs(a.work, exist_ok=True)
    shots = {}
    with Chromium(chromium) as browser:
        for name in sorted(os.listdir(a.scenes)):
            if not name.endswith(".json"):
                continue
            scene = name[:-5]
            out = os.path.join(a.work, scene)
            run([a.clothcd, "simulate", os.path.join(a.scenes, name), "--out", out,
                 "--frames", str(a.frames)])
            page = os.path.join(a.work, scene + ".html")
            print("     " + run([a.clothcd, "view", out, "--out", page]).strip())
            shot = os.path.join(a.work, scene + ".png")
            state = open_page(browser, page, "test&colour=none", shot)
            if state:
                check_sequence(state, page, os.path.join(out, "manifest.json"))
            shots[scene] = page
        steps = [("cloth_ball", os.path.join(a.data, "cloth-ball/frames/cloth_ball92.ply"),
                  os.path.join(a.data, "cloth-ball/frames/cloth_ball93.ply"),
                  ["--culling", "sound", "--policy", "proposed"]),
                 ("dress_step", os.path.join(a.work, "dress-rumba/frame_0000.obj"),
                  os.path.join(a.work, "dress-rumba/frame_0001.obj"), ["--thickness", "0.001"])]
        for label, t0, t1, extra in steps:
            result = os.path.join(a.work, label + ".json")
            run([a.clothcd, "detect", "--t0", t0, "--t1", t1, "--json", result] + extra)
            page = os.path.join(a.work, label + ".html")
            print("     " + run([a.clothcd, "view", "--t0", t0, "--t1", t1, "--json", result,
                                 "--out", page]).strip())
            state = open_page(browser, page, "test", os.path.join(a.work, label + ".png"))
            if state:
                check_detection(state, page, result)
            shots[label] = page
        if a.screenshots:
            os.makedirs(a.screenshots, exist_ok=True)
            for page, fragment, png in [
                    (shots["multilayer-kick"], "colour=strain&frame=1", "viewer-simulation.png"),
                    (shots["cloth_ball"], "hit=0", "viewer-detection.png")]:
                browser.open("file://" + os.path.abspath(page) + "#" + fragment)
                browser.wait_for(STATE + ".ready", timeout=120)
                browser.screenshot(os.path.join(a.screenshots, png))
                print(f"     wrote {os.path.join(a.screenshots, png)}")
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
