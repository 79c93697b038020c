"""Type stub of order.pyx: the biased randomized insertion order along a Hilbert curve."""

import numpy as np
import numpy.typing as npt

def brio_order(xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64], seed: int = 0) -> npt.NDArray[np.int32]: ...
def hilbert_indices(x: npt.NDArray[np.uint32], y: npt.NDArray[np.uint32], bits: int) -> npt.NDArray[np.uint32]: ...
