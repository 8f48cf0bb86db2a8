#!/usr/bin/env python3
"""Reads a simulation's frames (`clothcd simulate` or clothcd.simulate output) with meshio and
prints how the cloth moves; optionally converts them to VTU files for ParaView.

    python3 examples/python/read_frames_meshio.py OUT_FOLDER [--vtu VTU_FOLDER]
"""

import argparse
import json
from pathlib import Path

import meshio
import numpy as np


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folder", type=Path, help="simulation output folder (with manifest.json)")
    p.add_argument("--vtu", type=Path, help="also write frame_NNNN.vtu files here")
    a = p.parse_args()
    manifest = json.loads((a.folder / "manifest.json").read_text())
    ext = manifest.get("mesh_format", "obj")
    print(f"scene {manifest['scene']}: {manifest['vertices']} vertices, {manifest['faces']} faces, "
          f"{manifest['complete_frames']} frames after frame 0")
    if a.vtu:
        a.vtu.mkdir(parents=True, exist_ok=True)
    previous = None
    for k in range(manifest["complete_frames"] + 1):
        mesh = meshio.read(a.folder / f"frame_{k:04d}.{ext}")
        points = mesh.points
        moved = 0.0 if previous is None else float(np.max(np.linalg.norm(points - previous, axis=1)))
        lo, hi = points.min(axis=0), points.max(axis=0)
        print(f"frame {k:4d}: lowest y {lo[1]:+.5f}, box {np.round(hi - lo, 5).tolist()}, "
              f"largest move {moved:.6f}")
        if a.vtu:
            meshio.write(a.vtu / f"frame_{k:04d}.vtu", mesh)
        previous = points


if __name__ == "__main__":
    main()
