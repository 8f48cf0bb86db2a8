"""clothcd: continuous collision detection for cloth, from Python.

NumPy arrays in and out: positions are float arrays of shape (n, 3) (float64 C-contiguous ones
are read in place), faces integer arrays of shape (m, 3); results are float64 and int32 arrays.
Bad input raises ValueError with the C++ library's message (clothcd.InputError is the library's
own error type, a ValueError subclass).
"""

from ._clothcd import (
    SATURATED_HALF_ANGLE,
    DetectResult,
    InputError,
    PairDetectResult,
    PairDetector,
    ProximityResult,
    SelfDetector,
    __version__,
    ccd_leaf_cone,
    edge_edge_ccd,
    merge_provot,
    merge_tight,
    mesh_edges,
    optimal_cone,
    procedural,
    read_mesh,
    read_query_csv,
    simulate,
    vertex_face_ccd,
    view,
    write_mesh,
)
from .frames import read_frames, read_manifest

__all__ = [
    "SATURATED_HALF_ANGLE",
    "DetectResult",
    "InputError",
    "PairDetectResult",
    "PairDetector",
    "ProximityResult",
    "SelfDetector",
    "__version__",
    "ccd_leaf_cone",
    "edge_edge_ccd",
    "merge_provot",
    "merge_tight",
    "mesh_edges",
    "optimal_cone",
    "procedural",
    "read_frames",
    "read_manifest",
    "read_mesh",
    "read_query_csv",
    "simulate",
    "vertex_face_ccd",
    "view",
    "write_mesh",
]
