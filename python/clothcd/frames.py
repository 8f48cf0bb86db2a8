"""Reading a simulation's output folder (what clothcd.simulate and `clothcd simulate` write)."""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Optional, Sequence, Tuple

import numpy as np

from ._clothcd import read_mesh


def read_manifest(folder: "os.PathLike[str] | str") -> Dict[str, Any]:
    """The folder's manifest.json as a dict (scene, vertex and face counts, per-frame stats)."""
    path = os.path.join(os.fspath(folder), "manifest.json")
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except FileNotFoundError:
        raise ValueError(f"{path}: no manifest (not a simulation output folder?)") from None
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: unreadable manifest: {e}") from None


def frame_path(folder: "os.PathLike[str] | str", frame: int, mesh_format: str = "obj") -> str:
    """The mesh file of one frame: frame_NNNN.obj or .ply."""
    return os.path.join(os.fspath(folder), f"frame_{frame:04d}.{mesh_format}")


def read_frames(
    folder: "os.PathLike[str] | str", frames: Optional[Sequence[int]] = None
) -> Tuple[np.ndarray, np.ndarray]:
    """The complete frames of a simulation output folder.

    frames: which frames to read (default: 0 .. the manifest's last complete frame).
    Returns (F, V): F int32 (m, 3) faces, V float64 (k, n, 3) positions, V[i] of frames[i].
    Raises ValueError for a missing manifest, a frame that is not complete, or a frame file whose
    faces differ from the first one's.
    """
    manifest = read_manifest(folder)
    complete = int(manifest["complete_frames"])
    fmt = manifest.get("mesh_format", "obj")
    wanted = list(range(complete + 1)) if frames is None else [int(k) for k in frames]
    for k in wanted:
        if not 0 <= k <= complete:
            raise ValueError(f"{folder}: frame {k} is not complete (frames 0..{complete} are)")
    faces = None
    positions = np.empty((len(wanted), int(manifest["vertices"]), 3))
    for i, k in enumerate(wanted):
        path = frame_path(folder, k, fmt)
        V, F = read_mesh(path)
        if faces is None:
            faces = F
        elif not np.array_equal(F, faces):
            raise ValueError(f"{path}: faces differ from frame {wanted[0]}'s")
        if V.shape != positions.shape[1:]:
            raise ValueError(f"{path}: {V.shape[0]} vertices, the manifest says {positions.shape[1]}")
        positions[i] = V
    if faces is None:
        faces = np.empty((0, 3), dtype=np.int32)
    return faces, positions
