"""Type stub of nearest.pyx: the nearest site of query points, by a walk on the Voronoi neighbours."""

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I32 = npt.NDArray[np.int32]

def nearest_sites(
    sites: F64,
    face_edge: I32,
    he_next: I32,
    he_twin: I32,
    he_face: I32,
    qx: F64,
    qy: F64,
    start: I32,
    first: int,
    out: I32,
    mark: npt.NDArray[np.int64],
    stack: I32,
) -> int: ...
