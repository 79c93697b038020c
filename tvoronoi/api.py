"""The public entry for the engines: validate once, build, clip, and return a Diagram."""

from __future__ import annotations

import math

import numpy as np

from tvoronoi.diagram import Diagram
from tvoronoi.errors import EngineError, TvoronoiError

ENGINES = ("incremental", "fortune")
INSERTION_ORDERS = ("brio", "random")
# The default box grows the sites' bounding box by this fraction of its larger side.
BBOX_MARGIN = 0.10
# The exact predicates multiply up to four coordinate differences; so that no
# product underflows, a nonzero coordinate may be at most this many times
# smaller than the largest one (2^170, about 1.5e51).
DYNAMIC_RANGE = 2.0 ** 170


def as_points(points) -> np.ndarray:
    """Check and convert points to a C-contiguous (n, 2) float64 array.

    Raises
    ------
    TvoronoiError
        Wrong shape, non-numeric values, NaN or infinity (naming the row).
    """
    try:
        pts = np.asarray(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TvoronoiError(f"points must be numbers in an (n, 2) array: {exc}") from None
    if pts.size == 0:
        return np.empty((0, 2), np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise TvoronoiError(f"points must have shape (n, 2), got {pts.shape}")
    bad = ~np.isfinite(pts).all(axis=1)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise TvoronoiError(
            f"point {row} is ({pts[row, 0]!r}, {pts[row, 1]!r}): coordinates must be finite "
            f"({int(bad.sum())} such point(s))"
        )
    top = float(np.abs(pts).max())
    tiny = (pts != 0) & (np.abs(pts) * DYNAMIC_RANGE < top)
    if tiny.any():
        row, col = (int(v) for v in np.argwhere(tiny)[0])
        raise TvoronoiError(
            f"point {row} has coordinate {pts[row, col]!r}, over 1e51 times smaller than the largest "
            f"({top!r}): exact arithmetic covers a range of 2^170 within one point set; "
            f"round such values to 0 or split the data"
        )
    return np.ascontiguousarray(pts)


def default_bbox(pts: np.ndarray) -> tuple[float, float, float, float]:
    """The sites' bounding box grown by 10% of its larger side on every side.

    A single site, or sites that all coincide, get a margin of 10% of their
    largest coordinate (1 at the origin), so the box always has area.
    """
    if len(pts) == 0:
        return (0.0, 0.0, 1.0, 1.0)
    lo = pts.min(axis=0)
    hi = pts.max(axis=0)
    side = float(max(hi[0] - lo[0], hi[1] - lo[1]))
    if side > 0:
        margin = BBOX_MARGIN * side
    else:
        margin = BBOX_MARGIN * float(np.abs(pts).max()) or 1.0
    return (float(lo[0] - margin), float(lo[1] - margin), float(hi[0] + margin), float(hi[1] + margin))


def as_bbox(bbox) -> tuple[float, float, float, float]:
    """Check a user box (xmin, ymin, xmax, ymax)."""
    try:
        values = tuple(float(v) for v in bbox)
    except (TypeError, ValueError):
        raise TvoronoiError(f"bbox must be four numbers (xmin, ymin, xmax, ymax), got {bbox!r}") from None
    if len(values) != 4 or not all(math.isfinite(v) for v in values):
        raise TvoronoiError(f"bbox must be four finite numbers (xmin, ymin, xmax, ymax), got {bbox!r}")
    xmin, ymin, xmax, ymax = values
    if not (xmin < xmax and ymin < ymax):
        raise TvoronoiError(f"bbox {values} is empty: it needs xmin < xmax and ymin < ymax")
    return values


def voronoi(points, *, engine: str = "incremental", bbox=None, insertion: str = "brio",
            seed: int = 0) -> Diagram:
    """The Voronoi diagram of a set of points, with its cells clipped to a box.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Finite coordinates. Repeated points are allowed: they share one cell.
    engine : {"incremental", "fortune"}
        The randomized incremental algorithm, or Fortune's sweepline.
    bbox : (xmin, ymin, xmax, ymax), optional
        The box that bounds the cells; by default the points' bounding box
        grown by 10% of its larger side on every side.
    insertion : {"brio", "random"}
        Incremental engine only: a biased randomized insertion order with
        walking point location (fast), or the textbook fully random order
        with conflict lists.
    seed : int
        Seed of the random insertion order.

    Returns
    -------
    Diagram

    Raises
    ------
    TvoronoiError
        Bad points, box, engine or option.

    Examples
    --------
    >>> import tvoronoi
    >>> d = tvoronoi.voronoi([[0, 0], [1, 0], [0, 1], [1, 1]])
    >>> d.n_vertices, len(d.delaunay_triangles())
    (1, 2)
    """
    pts = as_points(points)
    if engine not in ENGINES:
        raise EngineError(f"unknown engine {engine!r}: choose one of {', '.join(ENGINES)}")
    if insertion not in INSERTION_ORDERS:
        raise EngineError(f"unknown insertion order {insertion!r}: choose one of {', '.join(INSERTION_ORDERS)}")
    box = default_bbox(pts) if bbox is None else as_bbox(bbox)
    from tvoronoi.build import build_diagram

    return build_diagram(pts, box, engine=engine, insertion=insertion, seed=seed)
