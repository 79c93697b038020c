"""Type stub of order.pyx: the biased randomized insertion order along a Hilbert curve."""

from typing import Literal, overload

import numpy as np
import numpy.typing as npt

@overload
def brio_order(
    xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64], seed: int = 0, along_curve: Literal[False] = False
) -> npt.NDArray[np.int32]: ...
@overload
def brio_order(
    xs: npt.NDArray[np.float64], ys: npt.NDArray[np.float64], seed: int, along_curve: Literal[True]
) -> tuple[npt.NDArray[np.int32], npt.NDArray[np.int32]]: ...
def hilbert_indices(x: npt.NDArray[np.uint32], y: npt.NDArray[np.uint32], bits: int) -> npt.NDArray[np.uint32]: ...
