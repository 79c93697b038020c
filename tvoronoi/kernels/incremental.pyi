"""Type stub of incremental.pyx: the randomized incremental engine (the insertion loop)."""

from typing import Any

import numpy as np
import numpy.typing as npt

I32 = npt.NDArray[np.int32]

STATUS_OK: int
STATUS_COLLINEAR: int

# (status, tv, opp, dup), and with stop_after >= 0 a fifth item: the trace dict (order, cavity, fan)
def permutation_copy(order: npt.NDArray[np.int32], n: int) -> npt.NDArray[np.int32]: ...
def triangulate(
    xs: npt.NDArray[np.float64],
    ys: npt.NDArray[np.float64],
    conflict_lists: bool = False,
    stop_after: int = -1,
    order: npt.NDArray[np.int32] | None = None,
) -> tuple[Any, ...]: ...
