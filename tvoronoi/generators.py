"""Seeded point generators shared by the terminal UI, the tests and the benchmarks."""

from __future__ import annotations

import inspect
import math
import numbers
from typing import Callable

import numpy as np

from .errors import TvoronoiError

__all__ = ["DISTRIBUTIONS", "clustered", "gaussian", "generate", "uniform"]

UNIT_SQUARE = (0.0, 0.0, 1.0, 1.0)


def uniform(
    n: int,
    *,
    seed: int | None = 0,
    bounds: tuple[float, float, float, float] = UNIT_SQUARE,
) -> np.ndarray:
    """Points drawn uniformly from an axis-aligned box.

    Parameters
    ----------
    n : int
        Number of points, ``n >= 0``.
    seed : int or None
        Seed of ``numpy.random.default_rng``; the same seed gives the same points.
    bounds : (xmin, ymin, xmax, ymax)
        The box, with ``xmin < xmax`` and ``ymin < ymax``.

    Returns
    -------
    numpy.ndarray
        C-contiguous float64 array of shape ``(n, 2)``.

    Raises
    ------
    TvoronoiError
        If ``n`` is negative or not an integer, or the box is empty or not finite.
    """
    n = _check_count(n)
    xmin, ymin, xmax, ymax = _check_bounds(bounds)
    rng = np.random.default_rng(seed)
    points = rng.uniform((xmin, ymin), (xmax, ymax), size=(n, 2))
    return np.ascontiguousarray(points, dtype=np.float64)


def gaussian(
    n: int,
    *,
    seed: int | None = 0,
    center: tuple[float, float] = (0.5, 0.5),
    sigma: float = 0.15,
) -> np.ndarray:
    """Points from an isotropic normal distribution (not clipped to any box).

    Parameters
    ----------
    n : int
        Number of points, ``n >= 0``.
    seed : int or None
        Seed of ``numpy.random.default_rng``.
    center : (x, y)
        Mean of the distribution.
    sigma : float
        Standard deviation along each axis, ``sigma > 0``.

    Returns
    -------
    numpy.ndarray
        C-contiguous float64 array of shape ``(n, 2)``.

    Raises
    ------
    TvoronoiError
        If ``n`` is negative, ``sigma`` is not positive or ``center`` is not two finite numbers.
    """
    n = _check_count(n)
    cx, cy = _check_pair(center, "center")
    sigma = _check_positive(sigma, "sigma")
    rng = np.random.default_rng(seed)
    points = rng.normal((cx, cy), sigma, size=(n, 2))
    return np.ascontiguousarray(points, dtype=np.float64)


def clustered(
    n: int,
    *,
    seed: int | None = 0,
    clusters: int = 10,
    spread: float = 0.02,
) -> np.ndarray:
    """Points in gaussian clusters whose centres are uniform in the unit square.

    Cluster sizes are multinomial (each point picks a cluster with equal
    probability); each point is normal about its centre with standard
    deviation ``spread`` and is not clipped. The points come in random order,
    not grouped by cluster.

    Parameters
    ----------
    n : int
        Number of points, ``n >= 0``.
    seed : int or None
        Seed of ``numpy.random.default_rng``.
    clusters : int
        Number of cluster centres, ``clusters >= 1``.
    spread : float
        Standard deviation of a cluster along each axis, ``spread > 0``.

    Returns
    -------
    numpy.ndarray
        C-contiguous float64 array of shape ``(n, 2)``.

    Raises
    ------
    TvoronoiError
        If ``n`` is negative, ``clusters`` is not a positive integer or ``spread`` is not positive.
    """
    n = _check_count(n)
    clusters = _check_count(clusters, "clusters", minimum=1)
    spread = _check_positive(spread, "spread")
    rng = np.random.default_rng(seed)
    centres = rng.random((clusters, 2))
    sizes = rng.multinomial(n, np.full(clusters, 1.0 / clusters))
    # shuffle the labels so that the order of the points says nothing about the clusters
    labels = rng.permutation(np.repeat(np.arange(clusters), sizes))
    points = centres[labels] + rng.normal(0.0, spread, size=(n, 2))
    return np.ascontiguousarray(points, dtype=np.float64)


DISTRIBUTIONS: dict[str, Callable[..., np.ndarray]] = {
    "uniform": uniform,
    "gaussian": gaussian,
    "clustered": clustered,
}


def generate(distribution: str, n: int, *, seed: int | None = 0, **params) -> np.ndarray:
    """Generate ``n`` points from the distribution named ``distribution``.

    Parameters
    ----------
    distribution : str
        A key of ``DISTRIBUTIONS``: ``"uniform"``, ``"gaussian"`` or ``"clustered"``.
    n : int
        Number of points, ``n >= 0``.
    seed : int or None
        Seed of ``numpy.random.default_rng``.
    **params
        Keyword parameters of that distribution (``bounds``; ``center``, ``sigma``;
        ``clusters``, ``spread``).

    Returns
    -------
    numpy.ndarray
        C-contiguous float64 array of shape ``(n, 2)``.

    Raises
    ------
    TvoronoiError
        For an unknown distribution or parameter, or a value out of range.

    Examples
    --------
    >>> points = generate("clustered", 1000, seed=7, clusters=5)
    >>> points.shape, points.dtype.name, points.flags.c_contiguous
    ((1000, 2), 'float64', True)
    >>> bool((generate("uniform", 3, seed=1) == generate("uniform", 3, seed=1)).all())
    True
    >>> generate("poisson", 10)
    Traceback (most recent call last):
        ...
    tvoronoi.errors.TvoronoiError: unknown distribution 'poisson'; choose one of: uniform, gaussian, clustered
    """
    try:
        func = DISTRIBUTIONS[distribution]
    except (KeyError, TypeError):
        raise TvoronoiError(
            f"unknown distribution {distribution!r}; choose one of: {', '.join(DISTRIBUTIONS)}"
        ) from None
    accepted = [
        name
        for name, p in inspect.signature(func).parameters.items()
        if p.kind is inspect.Parameter.KEYWORD_ONLY and name != "seed"
    ]
    unknown = sorted(set(params) - set(accepted))
    if unknown:
        raise TvoronoiError(
            f"{distribution} has no parameter {unknown[0]!r}; its parameters are: {', '.join(accepted)}"
        )
    return func(n, seed=seed, **params)


def _check_count(value, name: str = "n", *, minimum: int = 0) -> int:
    """Return ``value`` as an int if it is an integer ``>= minimum``, else raise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TvoronoiError(f"{name} must be an integer, got {value!r}")
    if value < minimum:
        raise TvoronoiError(f"{name} must be >= {minimum}, got {value}")
    return int(value)


def _check_positive(value, name: str) -> float:
    """Return ``value`` as a float if it is a finite number ``> 0``, else raise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TvoronoiError(f"{name} must be a positive number, got {value!r}")
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        raise TvoronoiError(f"{name} must be a positive finite number, got {value}")
    return number


def _check_pair(value, name: str) -> tuple[float, float]:
    """Return ``value`` as two finite floats, else raise."""
    try:
        a, b = (float(v) for v in value)
    except (TypeError, ValueError):
        raise TvoronoiError(f"{name} must be two numbers (x, y), got {value!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise TvoronoiError(f"{name} must be finite, got {value!r}")
    return a, b


def _check_bounds(bounds) -> tuple[float, float, float, float]:
    """Return ``bounds`` as (xmin, ymin, xmax, ymax) floats of a non-empty finite box, else raise."""
    try:
        xmin, ymin, xmax, ymax = (float(v) for v in bounds)
    except (TypeError, ValueError):
        raise TvoronoiError(f"bounds must be four numbers (xmin, ymin, xmax, ymax), got {bounds!r}") from None
    if not all(math.isfinite(v) for v in (xmin, ymin, xmax, ymax)):
        raise TvoronoiError(f"bounds must be finite, got {bounds!r}")
    if not (xmin < xmax and ymin < ymax):
        raise TvoronoiError(
            f"bounds {bounds!r} is an empty box; give (xmin, ymin, xmax, ymax) with xmin < xmax and ymin < ymax"
        )
    return xmin, ymin, xmax, ymax


def coastline(n_vertices: int = 4000, *, spikes: int = 300, lakes: int = 6, islands: int = 10, seed: int | None = 0):
    """A country-like clip region: a wiggly coast with thin spikes (fjords and capes), lakes and islands.

    The coast is a star-shaped ring of ``n_vertices`` vertices around the origin (radius about 1,
    forty harmonics and some noise); ``spikes`` of its vertices are pushed 25% out or in, each
    making a spike one vertex wide. ``lakes`` small polygons are cut out of it as holes and
    ``islands`` small polygons lie off the coast. It exercises clipping at scale: a detailed,
    concave boundary with holes and several parts.

    Returns
    -------
    shapely.MultiPolygon or shapely.Polygon
        Valid (repaired with ``shapely.make_valid`` where the noise folds the ring).
    """
    import shapely

    n_vertices = _check_count(n_vertices, "n_vertices", minimum=3)
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, 2 * np.pi, n_vertices))
    r = 1.0 + sum(rng.normal(0, 0.12 / k) * np.cos(k * t + rng.uniform(0, 2 * np.pi)) for k in range(1, 40))
    r = r + rng.normal(0, 0.004, n_vertices)
    pushed = rng.choice(n_vertices, min(spikes, n_vertices), replace=False)
    r[pushed] *= rng.choice([0.75, 1.25], len(pushed))
    land = shapely.make_valid(shapely.Polygon(np.c_[r * np.cos(t), r * np.sin(t)]))

    def blob(centre, size, k=24):
        a = np.linspace(0, 2 * np.pi, k, endpoint=False)
        rr = size * (1 + 0.3 * rng.uniform(-1, 1, k))
        return shapely.Polygon(np.c_[centre[0] + rr * np.cos(a), centre[1] + rr * np.sin(a)])

    for _ in range(lakes):
        angle, dist = rng.uniform(0, 2 * np.pi), rng.uniform(0, 0.5)
        land = land.difference(blob((dist * np.cos(angle), dist * np.sin(angle)), rng.uniform(0.02, 0.06)))
    for _ in range(islands):
        angle, dist = rng.uniform(0, 2 * np.pi), rng.uniform(1.4, 1.6)
        land = land.union(blob((dist * np.cos(angle), dist * np.sin(angle)), rng.uniform(0.02, 0.08)))
    return shapely.make_valid(land)
