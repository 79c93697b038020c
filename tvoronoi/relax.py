"""Lloyd relaxation (tvoronoi.lloyd): move each site to the centroid of its cell, a given number of times."""

from __future__ import annotations

import operator

import numpy as np

from tvoronoi.errors import TvoronoiError

# A cut cell whose centroid lies outside it (in a hole, a notch, between its parts) sends its site to the
# point of the cell nearest the centroid, moved into the cell by this fraction of its distance to a point
# inside (the point_on_surface of the cell's part that holds it; see lloyd_targets). The nearest point
# lies on the cell's boundary (on the region's, perhaps, where rounding may put it outside): the move is
# small enough to stay near that best place, large enough that two sites moved from one boundary point
# end far more than a rounding error apart.
INWARD_PULL = 1e-3


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


def lloyd_targets(diagram) -> tuple[np.ndarray, np.ndarray]:
    """Where one Lloyd step moves each site: the centroid of its cell, kept inside the cell.

    Without a clip region, these are :func:`cell_centroids`. In a clipped
    diagram, the centroid of a cell cut to a concave region, or to a region
    with holes or several parts, can lie outside the cell and the region; a
    site moved there would lose its cell for good. So a site goes to its
    cell's centroid only where the centroid lies strictly inside the cell
    (``shapely.contains_xy``) and inside the region by the clip's own test
    (:func:`tvoronoi.region.sites_inside`). Elsewhere it goes, in this order,
    to the first of these that passes the same tests:

    1. the point of the cell nearest the centroid (the best place within the
       cell, on its boundary; in a MultiPolygon, on the part nearest the
       centroid) moved into the cell, away from the centroid (along the
       inward normal of the edge it lies on), by ``INWARD_PULL`` of its
       distance to the ``shapely.point_on_surface`` of that part;
    2. the same point moved ``INWARD_PULL`` of the way toward that point on
       surface instead (where the first left the cell: an acute corner);
    3. that point on surface (GEOS: inside the part, a degenerate one aside);
    4. where it is (inside the region, since it has a cell).

    Every moved site then lies inside the region and inside its own former
    cell, apart from every other site: it has a cell at the next step.

    Returns
    -------
    targets : (n, 2) float64
        Row i is where site i moves (NaN where ``has_cell`` is False).
    has_cell : (n,) bool
        As in :func:`cell_centroids`: the sites that move.

    >>> import shapely, tvoronoi
    >>> ring = shapely.box(0, 0, 4, 4).difference(shapely.box(1, 1, 3, 3))  # a square with a square hole
    >>> d = tvoronoi.voronoi([[0.5, 2.0]], clip=ring)  # one site: its cell is the whole ring
    >>> cell_centroids(d)[0].tolist()  # the centroid, in the hole
    [[2.0, 2.0]]
    >>> lloyd_targets(d)[0].round(4).tolist()  # on the hole's nearest edge, pulled just inside the ring
    [[2.0, 3.0018]]
    """
    targets, has_cell = cell_centroids(diagram)
    reshaped = getattr(diagram, "reshaped", None)
    if reshaped is None:
        return targets, has_cell
    import shapely

    from tvoronoi.region import sites_inside

    def kept_inside(rows: np.ndarray, xy: np.ndarray) -> np.ndarray:
        """Whether each point xy[k] lies strictly inside cell rows[k] and inside the region by the clip's test."""
        inside = shapely.contains_xy(diagram.clipped[rows], xy[:, 0], xy[:, 1])
        inside[inside] = sites_inside(xy[inside], diagram.region)
        return inside

    # only a cut cell can miss its centroid: a cell the region holds whole is a convex Voronoi cell
    cut = np.flatnonzero(reshaped & has_cell)
    rows = cut[~kept_inside(cut, targets[cut])]
    if len(rows) == 0:
        return targets, has_cell
    # the centroid lies outside its cell (in a hole, a notch, between two parts): the part of the cell
    # nearest to it (the first of equals), the point of that part nearest to it (on the part's boundary)
    # and a point inside that part
    centroids = shapely.points(targets[rows])
    parts, owner = shapely.get_parts(diagram.clipped[rows], return_index=True)
    by_row = np.lexsort((shapely.distance(parts, centroids[owner]), owner))
    nearest_part = parts[by_row[np.r_[True, owner[by_row][1:] != owner[by_row][:-1]]]]
    nearest = shapely.get_coordinates(shapely.shortest_line(nearest_part, centroids))[0::2]
    surface = shapely.get_coordinates(shapely.point_on_surface(nearest_part))
    # the nearest point pulled into the part: away from the centroid (along the inward normal of the edge
    # it lies on), else toward the point on surface; both by INWARD_PULL of the way to that point
    reach = INWARD_PULL * np.hypot(*(surface - nearest).T)[:, None]
    away = nearest - targets[rows]
    with np.errstate(divide="ignore", invalid="ignore"):
        # NaN where the centroid lies on the cell's boundary: no direction, and no point inside
        inward = nearest + reach * away / np.hypot(*away.T)[:, None]
    toward = nearest + INWARD_PULL * (surface - nearest)
    # a candidate outside the cell (an acute corner, a sliver) gives way to the next; the last: the point on surface
    left = np.arange(len(rows))  # the rows still without a target, as positions in rows
    for candidate in (inward, toward, surface):
        ok = kept_inside(rows[left], candidate[left])
        targets[rows[left[ok]]] = candidate[left[ok]]
        left = left[~ok]
    # no point passed (a cell thinner than rounding): the site stays where it is, inside the region
    targets[rows[left]] = diagram.sites[rows[left]]
    return targets, has_cell


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
        Relax within a region: centroids of the cells cut to the region. A
        site inside the region stays inside: where its cut cell's centroid
        falls outside the cell (a hole, a notch, between parts), the site
        moves to the cell's point nearest the centroid, just inside the cell
        (see :func:`lloyd_targets`).
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
        targets, has_cell = lloyd_targets(diagram)
        pts[has_cell] = targets[has_cell]
    return pts
