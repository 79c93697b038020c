"""Type stub of rings.pyx: the cells' rings gathered for the writers."""

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]

def gather_slotted_rings(
    offsets: npt.NDArray[np.int64],
    vertices: npt.NDArray[np.int32],
    points: F64,
    ra: int,
    rb: int,
    keep: npt.NDArray[np.uint8],
    slots: F64,
    mins: F64,
    maxs: F64,
) -> None: ...
