"""Type stub of bounds.pyx: one pass over the input points."""

import numpy as np
import numpy.typing as npt

def point_bounds(pts: npt.NDArray[np.float64], threads: int = ...) -> tuple[int, float, float, float, float, float]: ...
