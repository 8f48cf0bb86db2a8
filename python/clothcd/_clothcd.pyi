"""Type stubs of the clothcd extension module (see the docstrings for the contracts)."""

import os
from typing import Any, Callable, Dict, List, Optional, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Floats = npt.ArrayLike
_Ints = npt.ArrayLike
_F64 = npt.NDArray[np.float64]
_I32 = npt.NDArray[np.int32]
_Bool = npt.NDArray[np.bool_]

__version__: str
SATURATED_HALF_ANGLE: float

class InputError(ValueError): ...

def read_mesh(path: _Path) -> Tuple[_F64, _I32]: ...
def write_mesh(path: _Path, V: _Floats, F: _Ints) -> None: ...
def mesh_edges(F: _Ints, num_vertices: Optional[int] = None) -> _I32: ...

class DetectResult:
    @property
    def vf(self) -> _I32: ...
    @property
    def vf_toi(self) -> _F64: ...
    @property
    def ee(self) -> _I32: ...
    @property
    def ee_toi(self) -> _F64: ...
    @property
    def stats(self) -> Dict[str, Union[int, float]]: ...
    @property
    def missed_vf(self) -> Optional[_I32]: ...
    @property
    def missed_ee(self) -> Optional[_I32]: ...

class ProximityResult:
    @property
    def vf(self) -> _I32: ...
    @property
    def vf_distance(self) -> _F64: ...
    @property
    def ee(self) -> _I32: ...
    @property
    def ee_distance(self) -> _F64: ...
    @property
    def reused_pairs(self) -> int: ...

class PairDetectResult:
    @property
    def vf_a_on_b(self) -> _I32: ...
    @property
    def vf_a_on_b_toi(self) -> _F64: ...
    @property
    def vf_b_on_a(self) -> _I32: ...
    @property
    def vf_b_on_a_toi(self) -> _F64: ...
    @property
    def ee(self) -> _I32: ...
    @property
    def ee_toi(self) -> _F64: ...
    @property
    def stats(self) -> Dict[str, Union[int, float]]: ...

class SelfDetector:
    def __init__(
        self,
        F: _Ints,
        V_rest: _Floats,
        *,
        policy: str = "proposed",
        culling: str = "sound",
        bvh: str = "patch",
        thickness: float = 0.0,
        threads: int = 0,
        linked_vertices: Optional[_Ints] = None,
        np_filter: bool = True,
        fast_path: bool = True,
        toi_tolerance: float = 1e-4,
        distance_filter_depth: int = 0,
        reuse_distance: float = 0.0,
        cull_min_triangles: int = 0,
        reuse_front: bool = False,
        distance_filter: bool = True,
    ) -> None: ...
    def detect(self, V0: _Floats, V1: _Floats) -> DetectResult: ...
    def earliest_impact(
        self, V0: _Floats, V1: _Floats, *, toi_tolerance: float = 1e-6, first_window: float = 0.0
    ) -> tuple[float, str, tuple[int, int]]: ...
    def proximity(self, V: _Floats, h: float) -> ProximityResult: ...
    def set_active_vertices(self, ids: _Ints) -> None: ...
    def set_active_faces(self, ids: _Ints) -> None: ...
    def clear_active(self) -> None: ...
    def rebuild(self, V: _Floats) -> None: ...
    def set_options(
        self,
        *,
        policy: Optional[str] = None,
        culling: Optional[str] = None,
        thickness: Optional[float] = None,
        np_filter: Optional[bool] = None,
        fast_path: Optional[bool] = None,
        toi_tolerance: Optional[float] = None,
        distance_filter_depth: Optional[int] = None,
        reuse_distance: Optional[float] = None,
        verify: Optional[bool] = None,
        cull_min_triangles: Optional[int] = None,
        reuse_front: Optional[bool] = None,
        distance_filter: Optional[bool] = None,
    ) -> None: ...
    @property
    def edges(self) -> _I32: ...
    @property
    def faces(self) -> _I32: ...
    @property
    def num_vertices(self) -> int: ...
    @property
    def options(self) -> Dict[str, Any]: ...

class PairDetector:
    def __init__(
        self,
        F_a: _Ints,
        V_a: _Floats,
        F_b: _Ints,
        V_b: _Floats,
        *,
        policy: str = "proposed",
        culling: str = "none",
        bvh: str = "spatial",
        thickness: float = 0.0,
        threads: int = 0,
        np_filter: bool = True,
        fast_path: bool = True,
        toi_tolerance: float = 1e-4,
        distance_filter_depth: int = 0,
        reuse_front: bool = False,
        distance_filter: bool = True,
    ) -> None: ...
    def detect(self, Va0: _Floats, Va1: _Floats, Vb0: _Floats, Vb1: _Floats) -> PairDetectResult: ...
    def earliest_impact(
        self,
        Va0: _Floats,
        Va1: _Floats,
        Vb0: _Floats,
        Vb1: _Floats,
        *,
        toi_tolerance: float = 1e-6,
        first_window: float = 0.0,
    ) -> tuple[float, str, tuple[int, int]]: ...
    @property
    def edges_a(self) -> _I32: ...
    @property
    def edges_b(self) -> _I32: ...

class procedural:
    @staticmethod
    def stacked_sheets(n: int = 12) -> Tuple[_I32, _F64, _F64]: ...
    @staticmethod
    def winding_strip(segments: int = 96, rings: int = 3) -> Tuple[_I32, _F64, _F64]: ...
    @staticmethod
    def crumpled_sheet(n: int, seed: int) -> Tuple[_I32, _F64, _F64]: ...
    @staticmethod
    def twisted_strip(segments: int = 80, width: int = 4) -> Tuple[_I32, _F64, _F64]: ...
    @staticmethod
    def smooth_perturbation(V: _Floats, amplitude: float, wavelength: float, seed: int) -> _F64: ...

def vertex_face_ccd(
    q: _Floats,
    *,
    thickness: float = 0.0,
    fast_path: bool = True,
    tolerance: float = 1e-6,
    toi_tolerance: float = 1e-4,
    max_boxes: int = 65536,
    threads: int = 0,
) -> Tuple[_Bool, _F64]: ...
def edge_edge_ccd(
    q: _Floats,
    *,
    thickness: float = 0.0,
    fast_path: bool = True,
    tolerance: float = 1e-6,
    toi_tolerance: float = 1e-4,
    max_boxes: int = 65536,
    threads: int = 0,
) -> Tuple[_Bool, _F64]: ...
def read_query_csv(path: _Path, kind: Optional[str] = None) -> Tuple[_F64, _Bool, str]: ...

@overload
def merge_provot(
    axis_a: _Floats, half_angle_a: float, axis_b: _Floats, half_angle_b: float
) -> Tuple[_F64, float]: ...
@overload
def merge_provot(
    axis_a: _Floats, half_angle_a: _Floats, axis_b: _Floats, half_angle_b: _Floats
) -> Tuple[_F64, _F64]: ...
@overload
def merge_tight(
    axis_a: _Floats, half_angle_a: float, axis_b: _Floats, half_angle_b: float
) -> Tuple[_F64, float]: ...
@overload
def merge_tight(
    axis_a: _Floats, half_angle_a: _Floats, axis_b: _Floats, half_angle_b: _Floats
) -> Tuple[_F64, _F64]: ...
def ccd_leaf_cone(
    T0: _Floats, T1: _Floats, policy: str = "proposed"
) -> Tuple[_F64, Union[float, _F64]]: ...
def optimal_cone(vectors: _Floats) -> Tuple[_F64, float]: ...
def simulate(
    scene_path: _Path,
    out: _Path,
    frames: Optional[int] = None,
    progress: Optional[Callable[[Dict[str, Any], int], None]] = None,
    *,
    threads: int = 0,
    resume: bool = False,
    keep_states: int = 0,
) -> List[Dict[str, Any]]: ...
def view(
    dir: Optional[_Path] = None,
    *,
    out: _Path,
    t0: Optional[_Path] = None,
    t1: Optional[_Path] = None,
    json: Optional[_Path] = None,
    first: int = 0,
    last: Optional[int] = None,
    step: int = 1,
    contact_distance: float = 0.0,
    no_body: bool = False,
    no_contact: bool = False,
) -> Dict[str, Any]: ...
