"""Type stub of certify.pyx: the tiles' certification of cells as final."""

import numpy as np
import numpy.typing as npt

def certify_rings(
    offsets: npt.NDArray[np.int64],
    vertices: npt.NDArray[np.int32],
    points: npt.NDArray[np.float64],
    sites: npt.NDArray[np.float64],
    rows: npt.NDArray[np.int64],
    region: tuple[float, float, float, float],
    relative: float,
    ulps: float,
    ok: npt.NDArray[np.uint8],
) -> None: ...
