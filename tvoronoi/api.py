"""The public entry for the engines: validate once, build, clip, and return a Diagram."""

from __future__ import annotations

import dataclasses
import math
import os

import numpy as np

from tvoronoi.diagram import Diagram
from tvoronoi.engines import scale_exponent
from tvoronoi.errors import CoordinateRangeError, EngineError, TvoronoiError
from tvoronoi.kernels.bounds import point_bounds
from tvoronoi.point_input import crs_of, explain_failure, foreign_points

ENGINES = ("incremental", "fortune")
INSERTION_ORDERS = ("brio", "random")
# The default box grows the sites' bounding box by this fraction of its larger side.
BBOX_MARGIN = 0.10
# The range rule of every diagram (batch, dynamic, traces): coordinates are scaled by a power of two
# 2^-e (exact) so that the largest magnitude in play is below 1 -- the sites' for a batch diagram or a
# trace, the box's and the first sites' for a dynamic one. The exact predicates multiply up to four
# coordinate differences; so that no product under- or overflows, a nonzero coordinate must lie within
# 2^170 (about 1.5e51) of 2^e either way.
RANGE_BITS = 170


def check_range(
    pts: np.ndarray, e: int, *, what: str = "point", scale_of: str | None = None, remedy: str | None = None
) -> None:
    """Refuse nonzero coordinates more than 2^170 from the scale 2^e (naming the first row at fault).

    ``what`` names the rows ("point" gives "point 3"; a name starting with "the " names a single one).
    ``scale_of`` names where the scale comes from when it is not these points' own ("the diagram" for a
    new site or a query point): the message then measures against it, not against the largest of them.
    ``remedy``: what the message advises instead of rounding tiny values or removing the outlier.

    Raises
    ------
    CoordinateRangeError
        Naming the first row at fault and the row of the largest coordinate.
    """
    pts = np.asarray(pts, np.float64)
    if pts.size == 0:
        return
    pts = pts.reshape(len(pts), -1)
    # 2^(e+170) may exceed the double range: then nothing is too large
    low = math.ldexp(1.0, e - RANGE_BITS)
    high = math.ldexp(1.0, e + RANGE_BITS) if e + RANGE_BITS < 1024 else math.inf
    # the common case in a few passes without a float temporary: nothing above the range, and
    # the values below it all zeros
    if max(float(pts.max()), -float(pts.min())) <= high:
        if np.count_nonzero((pts > -low) & (pts < low)) == np.count_nonzero(pts == 0):
            return
    mag = np.abs(pts)
    bad = (pts != 0) & ((mag < low) | (mag > high))
    if bad.any():
        row, col = (int(v) for v in np.argwhere(bad)[0])
        if scale_of is not None:
            top_row, top = -1, math.ldexp(1.0, e)
        else:
            top_row, top_col = (int(v) for v in np.unravel_index(int(np.argmax(mag)), mag.shape))
            top = float(pts[top_row, top_col])
        raise CoordinateRangeError(
            rows=(row, top_row),
            values=(float(pts[row, col]), top),
            small=bool(mag[row, col] < low),
            remedy=remedy,
            locate=lambda i: (
                (what if what.startswith("the ") else f"{what} {i}") if i >= 0 else f"the scale of {scale_of}"
            ),
        )


def as_points(points) -> np.ndarray:
    """Check and convert points to a C-contiguous (n, 2) float64 array.

    Besides (n, 2) arrays and sequences of pairs, takes shapely Points (a MultiPoint, a sequence or
    array of Points), a geopandas GeoSeries or GeoDataFrame of points, and a pandas DataFrame with
    x/y (lon/lat, easting/northing...) columns: see ``point_input.foreign_points``.

    Raises
    ------
    TvoronoiError
        Wrong shape, non-numeric values, NaN or infinity, a geometry that is not a point or an empty
        point (naming the row).

    Examples
    --------
    >>> import shapely
    >>> as_points([shapely.Point(0, 1), shapely.Point(2, 3)]).tolist()
    [[0.0, 1.0], [2.0, 3.0]]
    """
    return checked_points(points)[0]


def checked_points(points, threads: int = 1) -> tuple[np.ndarray, tuple[float, float, float, float] | None]:
    """as_points, and the points' bounds (xmin, ymin, xmax, ymax), None when there are none: one
    compiled pass (kernels/bounds.pyx, on ``threads`` threads) checks them and gives what the scale, the
    default box and the halves' cut read (default_bbox and build.build_diagram take it as ``bounds``)."""
    pts = foreign_points(points)
    if pts is None:
        try:
            pts = np.asarray(points, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            why = explain_failure(points)
            raise TvoronoiError(why or f"points must be numbers in an (n, 2) array: {exc}") from None
    if pts.size == 0:
        return np.empty((0, 2), np.float64), None
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise TvoronoiError(f"points must have shape (n, 2), got {pts.shape}")
    pts = np.ascontiguousarray(pts)
    n_bad, xmin, ymin, xmax, ymax, smallest = point_bounds(pts, threads)
    if n_bad:
        bad = ~np.isfinite(pts).all(axis=1)
        row = int(np.flatnonzero(bad)[0])
        more = "" if bad.sum() == 1 else f" ({int(bad.sum())} such points)"
        raise TvoronoiError(
            f"point {row} is ({float(pts[row, 0])!r}, {float(pts[row, 1])!r}): coordinates must be finite{more}"
        )
    box = (xmin, ymin, xmax, ymax)
    e = scale_exponent(box)
    if smallest < math.ldexp(1.0, e - RANGE_BITS):  # (the largest is within range: it sets e)
        check_range(pts, e)
    return pts, box


def default_bbox(
    pts: np.ndarray, bounds: tuple[float, float, float, float] | None = None
) -> tuple[float, float, float, float]:
    """The sites' bounding box grown by 10% of its larger side on every side.

    A single site, or sites that all coincide, get a margin of 10% of their
    largest coordinate (1 at the origin). Where the margin is below the
    coordinates' rounding (sites a few ulps apart, subnormal sites), each side
    still moves out by at least one double, so the box always has area.
    ``bounds``: the sites' own box (xmin, ymin, xmax, ymax) when known (checked_points).
    """
    if len(pts) == 0:
        return (0.0, 0.0, 1.0, 1.0)
    if bounds is None:
        # a column at a time: numpy reduces an (n, 2) array along axis 0 row by row, 30 times slower
        bounds = (pts[:, 0].min(), pts[:, 1].min(), pts[:, 0].max(), pts[:, 1].max())
    lo = np.array(bounds[:2], np.float64)
    hi = np.array(bounds[2:], np.float64)
    side = float(max(hi[0] - lo[0], hi[1] - lo[1]))
    if side > 0:
        margin = BBOX_MARGIN * side
    else:
        top = float(np.abs(np.concatenate([lo, hi])).max())
        margin = BBOX_MARGIN * top if top > 0 else 1.0
    low = np.minimum(lo - margin, np.nextafter(lo, -np.inf))
    high = np.maximum(hi + margin, np.nextafter(hi, np.inf))
    return (float(low[0]), float(low[1]), float(high[0]), float(high[1]))


def as_bbox(
    bbox,
    *,
    what: str | None = None,
    names: tuple[str, str, str, str] = ("xmin", "ymin", "xmax", "ymax"),
    sep: str = ", ",
) -> tuple[float, float, float, float]:
    """Check a box: four finite numbers (xmin, ymin, xmax, ymax) with xmin < xmax and ymin < ymax.

    The one box check of the package: ``voronoi``, dynamic diagrams, traces and the CLI's
    ``--bbox`` all use it. ``what`` names the box in messages (default: ``bbox`` and the value
    given), ``names`` and ``sep`` spell its four values (the CLI: ``XMIN,YMIN,XMAX,YMAX``).

    Raises
    ------
    TvoronoiError
        Not four values, a value that is not a number or not finite, an empty box; the message
        names the value at fault.

    Examples
    --------
    >>> as_bbox([0, -1, 2.5, 1e3])
    (0.0, -1.0, 2.5, 1000.0)
    >>> as_bbox((1, 0, 0, 1))
    Traceback (most recent call last):
    ...
    tvoronoi.errors.TvoronoiError: bbox (1, 0, 0, 1): the box is empty; it needs xmin < xmax and ymin < ymax
    """
    what = f"bbox {bbox!r}" if what is None else what
    order = sep.join(names)
    try:
        parts = list(bbox)
    except TypeError:
        raise TvoronoiError(f"{what}: expected four numbers {order}") from None
    if len(parts) != 4:
        raise TvoronoiError(f"{what}: expected four numbers {order}, got {len(parts)}")
    values = []
    for part in parts:
        try:
            value = float(part)
        except (TypeError, ValueError):
            raise TvoronoiError(f"{what}: {part!r} is not a number; expected {order}") from None
        if not math.isfinite(value):
            raise TvoronoiError(f"{what}: {part!r} is not a finite number")
        values.append(value)
    xmin, ymin, xmax, ymax = values
    if not (xmin < xmax and ymin < ymax):
        raise TvoronoiError(f"{what}: the box is empty; it needs {names[0]} < {names[2]} and {names[1]} < {names[3]}")
    return xmin, ymin, xmax, ymax


def check_engine(engine: str, insertion: str = "brio") -> None:
    """Refuse an unknown engine or insertion order (``voronoi``, traces and the CLI).

    Raises
    ------
    EngineError
        Naming the value given and the choices.
    """
    if engine not in ENGINES:
        raise EngineError(f"unknown engine {engine!r}: choose one of {', '.join(ENGINES)}")
    if insertion not in INSERTION_ORDERS:
        raise EngineError(f"unknown insertion order {insertion!r}: choose one of {', '.join(INSERTION_ORDERS)}")


def voronoi(
    points,
    *,
    engine: str = "incremental",
    bbox=None,
    insertion: str = "brio",
    seed: int = 0,
    clip=None,
    threads: int | None = None,
) -> Diagram:
    """The Voronoi diagram of a set of points, with its cells clipped to a box or to a region.

    Parameters
    ----------
    points : array_like, shape (n, 2), or shapely / geopandas / pandas points
        Finite coordinates. Repeated points are allowed: they share one cell.
        Also a shapely MultiPoint or sequence of Points, a GeoSeries or
        GeoDataFrame of points, or a DataFrame with x/y (lon/lat,
        easting/northing...) columns; cell i is then the row i.
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
    clip : shapely Polygon or MultiPolygon, or a GeoSeries / GeoDataFrame (their union), optional
        A region (concave, with holes, in several parts): the diagram is
        that of the points the region covers, each cell cut to the region,
        so that the cells tile it. Points outside get no cell (None in
        ``to_shapely``). The box defaults to the region's bounds grown by 1%;
        a ``bbox`` that does not hold the region cuts it too.
    threads : int, optional
        Threads for the phases that split (the Voronoi vertices, the cells' clipping); by default
        every core this process may use. The Diagram is the same, bit for bit, for any count.

    Returns
    -------
    Diagram
        A :class:`tvoronoi.region.ClippedDiagram` (a Diagram) with ``clip``.

    Raises
    ------
    TvoronoiError
        Bad points, box, engine, option or region; no point inside the region.

    Examples
    --------
    >>> import tvoronoi
    >>> d = tvoronoi.voronoi([[0, 0], [1, 0], [0, 1], [1, 1]])
    >>> d.n_vertices, len(d.delaunay_triangles())
    (1, 2)
    """
    from tvoronoi.build import build_arrays, build_diagram

    with build_arrays():  # its checks' temporaries too
        threads = as_threads(threads)
        pts, bounds = checked_points(points, threads)
        check_engine(engine, insertion)
        if clip is not None:
            from tvoronoi.region import as_region, clip_to_region, region_box

            region = as_region(clip)
            box = region_box(region) if bbox is None else as_bbox(bbox)
            d: Diagram = clip_to_region(
                pts,
                region,
                lambda inside: build_diagram(
                    inside, box, engine=engine, insertion=insertion, seed=seed, threads=threads
                ),
            )
        else:
            box = default_bbox(pts, bounds) if bbox is None else as_bbox(bbox)
            d = build_diagram(pts, box, engine=engine, insertion=insertion, seed=seed, threads=threads, bounds=bounds)
    crs = crs_of(points)
    return d if crs is None else dataclasses.replace(d, crs=crs)


def as_threads(threads) -> int:
    """The thread count of a build: a positive integer, or None for every core this process may use."""
    if threads is None:
        try:
            return max(1, len(os.sched_getaffinity(0)))
        except AttributeError:  # no affinity on this platform
            return max(1, os.cpu_count() or 1)
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise TvoronoiError(f"threads must be a positive integer, got {threads!r}")
    return int(threads)
