"""Signatures of seam.pyx: two halves' triangulations joined along the seam between them."""

import numpy as np

STATUS_OK: int

def kept_triangles(
    xs: np.ndarray,
    ys: np.ndarray,
    tv: np.ndarray,
    opp: np.ndarray,
    first: int,
    inf: int,
    split: float,
    axis: int,
    below: bool,
    ox0: float,
    oy0: float,
    ox1: float,
    oy1: float,
    keep: np.ndarray,
    seam: np.ndarray,
    threads: int = 1,
) -> None: ...
def join(
    tv: np.ndarray,
    opp: np.ndarray,
    keep: np.ndarray,
    holes: np.ndarray,
    gap_lo: int,
    gap_hi: int,
    n: int,
    tv_m: np.ndarray,
    opp_m: np.ndarray,
    sites_m: np.ndarray,
    expected: int,
) -> int: ...
