"""Type stub of sweep_order.pyx: the event order of Fortune's sweep (by y, then x, then row)."""

import numpy as np
import numpy.typing as npt

def sweep_keys(ys: npt.NDArray[np.float64], key: npt.NDArray[np.uint64]) -> int: ...
def sweep_rows(
    key: npt.NDArray[np.uint64],
    row_bits: int,
    xs: npt.NDArray[np.float64],
    ys: npt.NDArray[np.float64],
    perm: npt.NDArray[np.int32],
) -> int: ...
