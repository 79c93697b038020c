"""Type stub of dual.pyx: the Voronoi DCEL from a Delaunay triangulation, circumcentres, collinear strips."""

from typing import Any

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I32 = npt.NDArray[np.int32]

# The DCEL dict: vertices (m, 2) float64; he_origin, he_twin, he_next, he_prev, he_face (h,) int32;
# face_edge (n,) int32 (and triangles where the caller adds them).
def voronoi_from_delaunay(
    xs: F64,
    ys: F64,
    tv: I32,
    opp: I32,
    exponent: int = 0,
    threads: int = 1,
    parallel_min: int = ...,
    clip_room: bool = False,
    walk_chunk: int = ...,
    check: bool = False,
    give_triangulation: bool = False,
    he_room: tuple[I32, I32, I32] | None = None,
) -> dict[str, Any]: ...

TRI_BLOCK_SIZE: int

def circumcentres(xs: F64, ys: F64, tri: I32, e: int = 0, by_blocks: bool = True) -> F64: ...
def voronoi_collinear(xs: F64, ys: F64) -> dict[str, Any]: ...
