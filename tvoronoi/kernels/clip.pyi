"""Type stub of clip.pyx: batch clipping of every cell to the box, and its exact helpers for tests."""

from typing import Any

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I32 = npt.NDArray[np.int32]

def clip_cells(
    xs: F64,
    ys: F64,
    vertices: F64,
    he_origin: I32,
    he_twin: I32,
    he_face: I32,
    face_edge: I32,
    active: npt.NDArray[np.int8],
    box_tuple: tuple[float, float, float, float],
    e: int,
    threads: int = 1,
    parallel_min: int = ...,
    room: F64 | None = None,
) -> tuple[F64, npt.NDArray[np.int64], I32, int]: ...
def rows_of_cells(
    owner: I32,
    perm: I32,
    dup: I32,
    first: npt.NDArray[np.int8],
    face_edge: I32,
    offsets: npt.NDArray[np.int64],
    ring: I32,
    threads: int = 1,
) -> tuple[I32, I32, npt.NDArray[np.int64], I32]: ...
def relabel(label: I32, ids: I32, threads: int = 1) -> I32: ...
def straighten(
    points: F64,
    offsets: npt.NDArray[Any],
    rings: npt.NDArray[Any],
    box_tuple: tuple[float, float, float, float],
    was_bent: npt.NDArray[np.int8] | None = None,
    candidates: npt.NDArray[np.int8] | None = None,
) -> Any: ...
def point_kinds(points: F64, box_tuple: tuple[float, float, float, float]) -> npt.NDArray[np.int8]: ...
def value_names(points: F64, keys: npt.ArrayLike | None = None) -> I32: ...
def finished_ring(points: F64, ring: Any) -> I32: ...
def bisector_crossing(ax: float, ay: float, bx: float, by: float, t: float, along_y: bool, e: int = 0) -> float: ...
def ring_turn(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> int: ...
