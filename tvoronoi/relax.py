"""Lloyd relaxation (tvoronoi.lloyd): move each site to the centroid of its cell, a given number of times."""

from __future__ import annotations

import operator

import numpy as np

from tvoronoi.errors import TvoronoiError


def cell_centroids(diagram) -> tuple[np.ndarray, np.ndarray]:
    """The centroid of every cell, by the shoelace formula over the CSR cell arrays.

    For a diagram clipped to a region, the centroids of the cut cells (those
    crossing the region's boundary) come from shapely.

    Returns
    -------
    centroids : (n, 2) float64
        Row i is the centroid of cell i (NaN where ``has_cell`` is False).
    has_cell : (n,) bool
        Rows with a cell of positive area: not a repeated point, a site
        outside a clip region, or a cell that misses the box.

    >>> import tvoronoi
    >>> d = tvoronoi.voronoi([[0, 0], [2, 0]], bbox=(-1, -1, 3, 1))
    >>> cell_centroids(d)[0].tolist()
    [[0.0, 0.0], [2.0, 0.0]]
    """
    n = diagram.n_sites
    offsets = np.asarray(diagram.cell_offsets, np.int64)
    lengths = np.diff(offsets)
    row = np.repeat(np.arange(n), lengths)
    # each ring's points relative to its own site, so that far-off cells keep their digits
    xy = np.take(diagram.cell_points, diagram.cell_vertices, axis=0) - np.take(diagram.sites, row, axis=0)
    after = np.arange(1, len(row) + 1)
    rings = lengths > 0
    after[offsets[1:][rings] - 1] = offsets[:-1][rings]  # the last point of a ring is followed by its first
    x, y = xy[:, 0], xy[:, 1]
    x1, y1 = x[after], y[after]
    cross = x * y1 - x1 * y
    twice_area = np.bincount(row, cross, minlength=n)
    with np.errstate(divide="ignore", invalid="ignore"):
        cx = np.bincount(row, (x + x1) * cross, minlength=n) / (3 * twice_area)
        cy = np.bincount(row, (y + y1) * cross, minlength=n) / (3 * twice_area)
    centroids = np.column_stack([cx, cy]) + diagram.sites
    has_cell = (lengths >= 3) & (twice_area > 0)
    reshaped = getattr(diagram, "reshaped", None)
    if reshaped is not None:
        import shapely

        # cells cut by a clip region: shapely's centroids; rows without a cut cell have none
        cut = np.flatnonzero(reshaped & (diagram.clipped != None))  # noqa: E711 (elementwise)
        has_cell &= ~reshaped
        centroids[cut] = shapely.get_coordinates(shapely.centroid(diagram.clipped[cut]))
        has_cell[cut] = shapely.area(diagram.clipped[cut]) > 0
    centroids[~has_cell] = np.nan
    return centroids, has_cell


def lloyd(
    points,
    iterations: int,
    *,
    bbox=None,
    clip=None,
    engine: str = "incremental",
    insertion: str = "brio",
    seed: int = 0,
) -> np.ndarray:
    """Lloyd relaxation: move each site to the centroid of its cell, ``iterations`` times.

    The sites tend to a centroidal Voronoi tessellation: evenly spread, each
    at the centre of its cell. Each step rebuilds the diagram. Moving sites
    through a DynamicVoronoi instead was measured (benchmarks/lloyd.py,
    results/lloyd.md): at 100,000 sites a move costs about 20 us, a rebuild
    with every centroid about 0.13 s, so moves win only when fewer than about
    6% of the sites move, and reading the moved cells' neighbourhoods back
    for their centroids costs as much again. A Lloyd step never moves that
    few: late in the relaxation the median site still moves 3% of a cell's
    size and 90% move over 1%, every one of them changing its neighbours'
    centroids. Freezing the sites that move less would change the result,
    so every step rebuilds.

    Parameters
    ----------
    points : array_like, shape (n, 2), or shapely / geopandas / pandas points
        As :func:`tvoronoi.voronoi` takes them.
    iterations : int
        Number of steps (0 returns the points as given).
    bbox : (xmin, ymin, xmax, ymax), optional
        The box of every step; by default that of the first step (the
        points' bounding box grown by 10%, or the clip region's grown by 1%).
    clip : shapely Polygon or MultiPolygon, optional
        Relax within a region: centroids of the cells cut to the region.
    engine, insertion, seed
        As in :func:`tvoronoi.voronoi`.

    Returns
    -------
    (n, 2) float64
        The relaxed points, row for row. A site without a cell stays where
        it is: a site outside the clip region or the box, and the later
        copies of a repeated point (which have cells of their own from the
        next step on, as the first copy moves away).

    Raises
    ------
    TvoronoiError
        Bad points, iterations, box, engine or region; no point inside the region.

    >>> import tvoronoi
    >>> tvoronoi.lloyd([[0.1, 0.5], [0.3, 0.5]], 1, bbox=(0, 0, 1, 1)).tolist()
    [[0.1, 0.5], [0.6, 0.5]]
    """
    from tvoronoi.api import as_bbox, as_points, default_bbox, voronoi

    try:
        steps = operator.index(iterations)
    except TypeError:
        raise TvoronoiError(f"iterations must be a whole number, got {iterations!r}") from None
    if steps < 0:
        raise TvoronoiError(f"iterations must be 0 or more, got {steps}")
    pts = as_points(points).copy()
    region = None
    if clip is not None:
        from tvoronoi.region import as_region, region_box

        region = as_region(clip)
        box = region_box(region) if bbox is None else as_bbox(bbox)
    else:
        box = default_bbox(pts) if bbox is None else as_bbox(bbox)
    for _ in range(steps):
        # every site moves (see the measurement above): rebuild the diagram
        diagram = voronoi(pts, engine=engine, bbox=box, insertion=insertion, seed=seed, clip=region)
        centroids, has_cell = cell_centroids(diagram)
        pts[has_cell] = centroids[has_cell]
    return pts
