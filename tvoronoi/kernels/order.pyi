"""Type stub of order.pyx: the biased randomized insertion order along a Hilbert curve."""

import numpy as np
import numpy.typing as npt

def brio_order(
    xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64], seed: int = 0, threads: int = 1
) -> npt.NDArray[np.int32]: ...
