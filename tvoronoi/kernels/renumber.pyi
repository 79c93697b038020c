"""Signatures of renumber.pyx: a triangulation renumbered in a spatial order."""

import numpy as np

def grid_bits(n: int) -> int: ...
def spatial_order(
    xs: np.ndarray, ys: np.ndarray, tv: np.ndarray, opp: np.ndarray, threads: int = 1
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]: ...
