#!/usr/bin/env python3
"""How long pages of `clothcd view` take to open: each page is opened in headless Chromium
(tests/view/chromium.py) `--repeat` times, and the times the page measures itself are printed as
a markdown table: decoding its data (base64, inflate, typed arrays) and the whole load up to the
first drawn frame (decoding every frame's positions and building the meshes included). Chromium
renders with its software GL (SwiftShader) here, so the load time is an upper bound for a
browser with a GPU.

Usage: scripts/view_load_time.py PAGE.html... [--repeat 3]
"""

import argparse
import json
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "view"))
from chromium import Chromium, find_chromium  # noqa: E402

STATE = ("(document.getElementById('clothcd-state') ? "
         "JSON.parse(document.getElementById('clothcd-state').textContent) : {})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pages", nargs="+")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    binary = find_chromium()
    if binary is None:
        sys.exit("no chromium installed (scripts/setup.sh full installs it)")
    print("| page | size (MB) | frames | decode (ms) | load (ms), median of", a.repeat, "| range |")
    print("|---|---|---|---|---|---|")
    for page in a.pages:
        decode, load, frames = [], [], 0
        for _ in range(a.repeat):
            with Chromium(binary) as browser:
                browser.open("file://" + os.path.abspath(page))
                deadline = time.monotonic() + 300
                state = None
                while time.monotonic() < deadline:
                    state = browser.evaluate(STATE)
                    if state.get("ready") or state.get("error"):
                        break
                    time.sleep(0.1)
                if not state or not state.get("ready"):
                    sys.exit(f"{page}: did not open: {json.dumps(state)}")
                decode.append(state["decodeMs"])
                load.append(state["loadMs"])
                frames = state.get("frames", 2)
        size = os.path.getsize(page) / 1e6
        print(f"| {os.path.basename(page)} | {size:.1f} | {frames} | {statistics.median(decode):.0f}"
              f" | {statistics.median(load):.0f} | {min(load)}-{max(load)} |")


if __name__ == "__main__":
    main()
