"""Signatures of renumber.pyx: a triangulation renumbered in a spatial order."""

import numpy as np

def grid_bits(n: int) -> int: ...
def spatial_order(
    xs: np.ndarray, ys: np.ndarray, tv: np.ndarray, opp: np.ndarray, threads: int = 1
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]: ...
def site_order(xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...
def triangle_order(
    tv: np.ndarray, opp: np.ndarray, old_to_new: np.ndarray, threads: int = 1
) -> tuple[np.ndarray, np.ndarray]: ...
def triangle_order_into(
    tv: np.ndarray,
    opp: np.ndarray,
    old_to_new: np.ndarray | None,
    tv2: np.ndarray,
    opp2: np.ndarray,
    site_base: int,
    tri_base: int,
    inf_out: int,
    threads: int = 1,
    n_sites: int = -1,
) -> None: ...
def take_sites(xs: np.ndarray, ys: np.ndarray, idx: np.ndarray, exponent: int = 0) -> tuple[np.ndarray, np.ndarray]: ...
def split_sites(
    xs: np.ndarray,
    ys: np.ndarray,
    axis: int,
    split: float,
    exponent: int = 0,
    least: int = 0,
    threads: int = 1,
) -> (
    tuple[
        tuple[np.ndarray, np.ndarray, np.ndarray],
        tuple[np.ndarray, np.ndarray, np.ndarray],
        tuple[float, float, float, float],
        tuple[float, float, float, float],
    ]
    | None
): ...
def sites_into(
    xs: np.ndarray,
    ys: np.ndarray,
    rows: np.ndarray,
    perm: np.ndarray | None,
    new_to_old: np.ndarray,
    out_x: np.ndarray,
    out_y: np.ndarray,
    out_rows: np.ndarray,
) -> None: ...
