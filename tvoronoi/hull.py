"""The convex hull's boundary with its collinear sites, by exact orientation: the hull edges a Delaunay triangulation has.

A Delaunay triangulation's hull edges join consecutive sites along the boundary of the convex hull,
sites in the middle of a straight stretch included. ``boundary_hull`` lists those sites counter-clockwise;
the hull of a union is the hull of the parts' hulls, so the hull of many partitions is found from theirs.
"""

from __future__ import annotations

import numpy as np

from tvoronoi.engines import scale_exponent
from tvoronoi.kernels.predicates import orient2d_many, orient2d_sign


def boundary_hull(xy: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """The ids of the sites on the boundary of the convex hull, counter-clockwise from the lowest (x, y).

    Sites in the middle of a hull side are kept (they are hull vertices of the Delaunay triangulation);
    a place held by several ids is listed once, by its lowest id. Fewer than three distinct places, or
    all of them on one line: the distinct places in (x, y) order (there is no hull edge).

    >>> boundary_hull(np.array([[0.0, 0], [2, 0], [1, 0], [1, 1], [0.5, 0.2]]), np.arange(5)).tolist()
    [0, 2, 1, 3]
    """
    xy = np.asarray(xy, np.float64).reshape(-1, 2)
    ids = np.asarray(ids, np.int64)
    # the predicates want coordinates near 1: scale by a power of two (exact for the sites voronoi accepts)
    xy = np.ldexp(xy, -scale_exponent(xy))
    # drop the sites strictly inside the polygon of a few extreme ones (Akl-Toussaint): a cheap exact filter
    xy, ids = _outside_extremes(xy, ids)
    order = np.lexsort((ids, xy[:, 1], xy[:, 0]))
    xy, ids = xy[order], ids[order]
    first = np.ones(len(xy), bool)
    first[1:] = (xy[1:, 0] != xy[:-1, 0]) | (xy[1:, 1] != xy[:-1, 1])
    xy, ids = xy[first], ids[first]
    if len(xy) < 3:
        return ids
    pts = xy.tolist()
    lower = _chain(pts, range(len(pts)))
    upper = _chain(pts, range(len(pts) - 1, -1, -1))
    if len(lower) == len(pts) and len(upper) == len(pts):  # every site on one line
        return ids
    return ids[np.array(lower[:-1] + upper[:-1], np.int64)]


def hull_edges(hull: np.ndarray) -> np.ndarray:
    """(h, 2) int64: the directed edges (p, q) of a counter-clockwise hull (the inside on their left); none
    for fewer than three sites."""
    hull = np.asarray(hull, np.int64)
    if len(hull) < 3:
        return np.empty((0, 2), np.int64)
    return np.column_stack([hull, np.roll(hull, -1)])


def _chain(pts: list, indices) -> list[int]:
    """Andrew's monotone chain, one half: pop only on a strict right turn, so collinear sites stay."""
    chain: list[int] = []
    for k in indices:
        px, py = pts[k]
        while len(chain) >= 2:
            ax, ay = pts[chain[-2]]
            bx, by = pts[chain[-1]]
            if orient2d_sign(ax, ay, bx, by, px, py) >= 0:
                break
            chain.pop()
        chain.append(k)
    return chain


def _outside_extremes(xy: np.ndarray, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The sites not strictly inside the convex polygon of the extremes in eight directions."""
    if len(xy) < 64:
        return xy, ids
    x, y = xy[:, 0], xy[:, 1]
    picks = {int(np.argmin(v)) for v in (x, y, x + y, x - y)} | {int(np.argmax(v)) for v in (x, y, x + y, x - y)}
    corners = sorted(picks)
    order = np.lexsort((ids[corners], xy[corners, 1], xy[corners, 0]))
    cpts = xy[corners][order].tolist()
    lower = _chain(cpts, range(len(cpts)))
    upper = _chain(cpts, range(len(cpts) - 1, -1, -1))
    ring = lower[:-1] + upper[:-1]
    if len(ring) < 3 or (len(lower) == len(cpts) and len(upper) == len(cpts)):
        return xy, ids
    inside = np.ones(len(xy), bool)
    for k in range(len(ring)):
        a = np.broadcast_to(np.asarray(cpts[ring[k]]), xy.shape).copy()
        b = np.broadcast_to(np.asarray(cpts[ring[(k + 1) % len(ring)]]), xy.shape).copy()
        inside &= orient2d_many(a, b, np.ascontiguousarray(xy)) > 0
    return xy[~inside], ids[~inside]
