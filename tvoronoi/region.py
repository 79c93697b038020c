"""Diagrams clipped to a region: the cells of the sites inside a (Multi)Polygon, each cut to the region."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tvoronoi.diagram import Diagram
from tvoronoi.errors import TvoronoiError

# The default box of a clipped diagram grows the region's bounds by this fraction of their larger side
# on every side: any margin keeps the region strictly inside the box; a small one keeps the outer
# cells (which are cut anyway) small.
REGION_MARGIN = 0.01
# Sites and cells are first placed in a grid of GRID_TILES x GRID_TILES tiles over the region, for
# diagrams of at least GRID_MIN_SITES sites (below that, testing each against the region is as fast)
GRID_TILES = 128
GRID_MIN_SITES = 20_000
# Cells that cross a region's boundary are cut against pieces of the region with at most this many
# vertices (see local_intersection): an overlay costs about the size of both inputs, a piece about
# as many vertices as a few cells keeps it local without making too many pieces.
PIECE_VERTICES = 64
# fewer cells than this are cut against their piece directly, without splitting it further
LOCAL_MIN_CELLS = 8
# the margin of the pieces' boxes: 1.5 times the size of the largest cell of a tier; a tier holds
# cells whose sizes (the larger side of their bounds) are within this factor, from the median size
TIER_RATIO = 2.0
# an outline's edges longer than this many times its median edge (a coast's spikes) are split before
# the cut, so that pieces need not reach far beyond their cells
EDGE_SPLIT = 4.0
# a piece's box reaches this fraction beyond the edges it must hold whole, so that the cut (its new
# vertices, rounded) stays clear of them
PIECE_BOX_GROWTH = 0.01


@dataclass(frozen=True, eq=False)
class ClippedDiagram(Diagram):
    """A Diagram whose cells are cut to a region.

    Everything a :class:`Diagram` holds describes the Voronoi diagram of the
    sites inside the region, bounded by the box: the half-edges, the
    triangles, and the CSR cells (``cell_polygon``) before the cut. The rows
    of sites outside the region have no cell at all (``face_edge`` -1, an
    empty ``cell_polygon``) and are never answers of ``locate``.

    :meth:`to_shapely`, :meth:`to_geopandas` and the writers give the cells
    cut to the region: Polygons or MultiPolygons, possibly with holes, that
    tile the region.

    Attributes
    ----------
    region : shapely Polygon or MultiPolygon
        The region, as given (checked valid).
    inside : (n,) bool
        Rows whose site the region covers (boundary included).
    clipped : (n,) object
        Cell i cut to the region (counter-clockwise exteriors, clockwise
        holes), or None for a row without a cell: a site outside the region,
        a repeated point.
    reshaped : (n,) bool
        Rows whose clipped cell differs from their CSR ring: cells that cross
        the region's boundary, and rows without a clipped cell. Elsewhere
        ``clipped[i]`` is exactly the Polygon of ``cell_polygon(i)``.
    """

    region: object = None
    inside: np.ndarray | None = None
    clipped: np.ndarray | None = None
    reshaped: np.ndarray | None = None

    @property
    def n_outside(self) -> int:
        """Number of rows whose site lies outside the region (they have no cell)."""
        return int(self.n_sites - np.count_nonzero(self.inside))

    def to_shapely(self) -> np.ndarray:
        """The cells cut to the region, one per input row (None for a row without a cell).

        >>> import shapely, tvoronoi
        >>> square = shapely.box(0, 0, 2, 2)
        >>> d = tvoronoi.voronoi([[0.5, 1], [1.5, 1], [5, 5]], clip=square)
        >>> [None if g is None else g.area for g in d.to_shapely()]
        [2.0, 2.0, None]
        """
        return self.clipped.copy()


def as_region(clip, *, what: str = "clip"):
    """Check a clip region: a non-empty, valid shapely Polygon or MultiPolygon with finite coordinates
    (a GeoSeries or GeoDataFrame stands for the union of its geometries).

    Raises
    ------
    TvoronoiError
        Naming what is wrong (``what`` names the region in the message) and how to fix it.
    """
    import shapely

    if type(clip).__name__ in ("GeoSeries", "GeoDataFrame") and hasattr(clip, "union_all"):
        # geopandas: read_file(...) gives a frame; its union is the region
        clip = clip.union_all()
    if not isinstance(clip, (shapely.Polygon, shapely.MultiPolygon)):
        raise TvoronoiError(f"{what} must be a shapely Polygon or MultiPolygon, got {type(clip).__name__}")
    if clip.is_empty:
        raise TvoronoiError(f"{what} is an empty {clip.geom_type}: it has no area to clip to")
    if not np.isfinite(shapely.get_coordinates(clip)).all():
        raise TvoronoiError(f"{what} has a coordinate that is not finite")
    if not clip.is_valid:
        raise TvoronoiError(
            f"{what} is not a valid {clip.geom_type} ({shapely.is_valid_reason(clip)}); "
            f"repair it first, e.g. with shapely.make_valid"
        )
    if not clip.area > 0:
        raise TvoronoiError(f"{what} has no area to clip to")
    _check_region_range(clip, what)
    return clip


def _check_region_range(clip, what: str) -> None:
    """Refuse a region whose coordinates spread over more than the points may (2^170 around the
    largest): the overlays that cut the cells lose their way among subnormal or tiny values."""
    import shapely

    from tvoronoi.api import check_range
    from tvoronoi.engines import scale_exponent
    from tvoronoi.errors import CoordinateRangeError

    coords = shapely.get_coordinates(clip)
    try:
        check_range(coords, scale_exponent(coords), what="vertex")
    except CoordinateRangeError as e:
        raise TvoronoiError(f"{what}: {e.explain(lambda i: f'vertex {i}')}") from None


def region_box(region) -> tuple[float, float, float, float]:
    """The region's bounds grown by 1% of their larger side on every side (at least one double each way)."""
    xmin, ymin, xmax, ymax = (float(v) for v in region.bounds)
    margin = REGION_MARGIN * max(xmax - xmin, ymax - ymin)
    return (
        min(xmin - margin, math.nextafter(xmin, -math.inf)),
        min(ymin - margin, math.nextafter(ymin, -math.inf)),
        max(xmax + margin, math.nextafter(xmax, math.inf)),
        max(ymax + margin, math.nextafter(ymax, math.inf)),
    )


class _Grid:
    """A grid of GRID_TILES x GRID_TILES tiles over a region's bounds, each tile known to lie in the
    region's interior, outside the region, or across its boundary (exact shapely predicates).

    Most sites and cells of a large diagram lie in a tile that is inside or outside: they are
    classified by arithmetic, and only those in boundary tiles are tested against the region.
    """

    def __init__(self, region):
        import shapely

        xmin, ymin, xmax, ymax = (float(v) for v in region.bounds)
        self.origin = (xmin, ymin)
        self.step = (max(xmax - xmin, 0.0) / GRID_TILES or 1.0, max(ymax - ymin, 0.0) / GRID_TILES or 1.0)
        i, j = np.divmod(np.arange(GRID_TILES * GRID_TILES), GRID_TILES)
        boxes = shapely.box(
            xmin + i * self.step[0],
            ymin + j * self.step[1],
            xmin + (i + 1) * self.step[0],
            ymin + (j + 1) * self.step[1],
        )
        shapely.prepare(region)
        # inside: the closed tile lies in the region's interior; outside: they share no point
        self.inside = shapely.contains_properly(region, boxes).reshape(GRID_TILES, GRID_TILES)
        self.outside = shapely.disjoint(region, boxes).reshape(GRID_TILES, GRID_TILES)

    def tiles(self, xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(i, j, within): the tile of each point, and whether the point lies in the grid
        (the tile's exact bounds are rechecked, so a rounded division cannot misplace it)."""
        x0, y0 = self.origin
        dx, dy = self.step
        i = np.clip(np.floor((xs - x0) / dx), 0, GRID_TILES - 1).astype(np.int64)
        j = np.clip(np.floor((ys - y0) / dy), 0, GRID_TILES - 1).astype(np.int64)
        within = (xs >= x0 + i * dx) & (xs <= x0 + (i + 1) * dx) & (ys >= y0 + j * dy) & (ys <= y0 + (j + 1) * dy)
        return i, j, within


def sites_inside(pts: np.ndarray, region, grid: _Grid | None = None) -> np.ndarray:
    """(n,) bool: the sites the region covers (its boundary included)."""
    import shapely

    shapely.prepare(region)
    if len(pts) < GRID_MIN_SITES:
        # a point that intersects a polygon is covered by it
        return shapely.intersects_xy(region, pts[:, 0], pts[:, 1])
    grid = grid or _Grid(region)
    i, j, within = grid.tiles(pts[:, 0], pts[:, 1])
    # a point in a tile inside the region is inside; in a tile outside, outside; the rest is tested
    inside = within & grid.inside[i, j]
    unknown = np.flatnonzero(~(inside | (within & grid.outside[i, j])))
    inside[unknown] = shapely.intersects_xy(region, pts[unknown, 0], pts[unknown, 1])
    return inside


def clip_to_region(pts: np.ndarray, region, build) -> ClippedDiagram:
    """The diagram of the sites inside ``region``, built by ``build(points)``, with its cells cut to the region.

    Parameters
    ----------
    pts : (n, 2) float64, checked
    region : a checked shapely Polygon or MultiPolygon
    build : callable taking (m, 2) points and returning their Diagram (in the clip's box)

    Raises
    ------
    TvoronoiError
        No site lies inside the region.
    """
    grid = _Grid(region) if len(pts) >= GRID_MIN_SITES else None
    inside = sites_inside(pts, region, grid)
    rows = np.flatnonzero(inside)
    if len(rows) == 0:
        raise TvoronoiError(
            f"none of the {len(pts)} points lies inside the clip region (bounds {tuple(region.bounds)}): "
            f"check that the points and the region use the same coordinates (x, y order, CRS)"
        )
    inner = build(pts[rows])
    fields = _rows_of(inner, pts, rows)
    clipped, reshaped = _cut_cells(Diagram(**fields), region, grid)
    return ClippedDiagram(**fields, region=region, inside=inside, clipped=clipped, reshaped=reshaped)


def _rows_of(inner: Diagram, pts: np.ndarray, rows: np.ndarray) -> dict:
    """The fields of ``inner`` (a diagram of ``pts[rows]``) with its sites renumbered as rows of ``pts``."""
    n = len(pts)
    fields = {name: getattr(inner, name) for name in Diagram.__dataclass_fields__}
    if len(rows) == n:
        return fields
    rows32 = rows.astype(np.int32)
    site_of = np.arange(n, dtype=np.int32)
    site_of[rows] = rows32[inner.site_of]
    face_edge = np.full(n, -1, np.int32)
    face_edge[rows] = inner.face_edge
    lengths = np.zeros(n, np.int64)
    lengths[rows] = np.diff(inner.cell_offsets)
    cell_offsets = np.zeros(n + 1, np.int64)
    np.cumsum(lengths, out=cell_offsets[1:])
    he_face = np.asarray(inner.he_face)
    fields.update(
        sites=pts,
        site_of=site_of,
        he_face=np.where(he_face >= 0, rows32[np.maximum(he_face, 0)], -1).astype(np.int32),
        face_edge=face_edge,
        triangles=rows32[inner.triangles].reshape(-1, 3),
        cell_offsets=cell_offsets,
    )
    return fields


def _cut_cells(diagram: Diagram, region, grid: _Grid | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Each cell cut to the region: (clipped, reshaped) as in ClippedDiagram."""
    from tvoronoi.shapes import cell_polygons

    return cut_polygons(cell_polygons(diagram), region, grid)


def cut_polygons(cells: np.ndarray, region, grid: _Grid | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Cells (shapely Polygons, None for no cell) cut to the region: (clipped, reshaped) as in ClippedDiagram.

    A cell inside the region is kept as it is, and a crossing cell's cut depends on that cell and the
    region alone, never on the other cells: tiles on a cluster (tvoronoi.distributed) cut their cells
    to the same geometries as one process. ``grid`` (a _Grid of the region) only makes it faster.
    """
    import shapely

    has = cells != None  # noqa: E711 (elementwise on an object array)
    shapely.prepare(region)
    # cells inside the region are kept as they are; only those crossing its boundary are cut
    crossing = np.flatnonzero(has)
    if grid is not None:
        # a cell within one tile that lies inside the region is inside
        b = shapely.bounds(cells[crossing])
        i0, j0, in0 = grid.tiles(b[:, 0], b[:, 1])
        i1, j1, in1 = grid.tiles(b[:, 2], b[:, 3])
        crossing = crossing[~(in0 & in1 & (i0 == i1) & (j0 == j1) & grid.inside[i0, j0])]
    crossing = crossing[~shapely.contains_properly(region, cells[crossing])]
    clipped = cells.copy()
    if len(crossing):
        clipped[crossing] = _polygonal(local_intersection(cells[crossing], region))
    reshaped = ~has
    reshaped[crossing] = True
    return clipped, reshaped


def local_intersection(cells: np.ndarray, region) -> np.ndarray:
    """Each cell intersected with the region, each against only the part of the region near it.

    A detailed outline (thousands of vertices) is cut into pieces along a
    quadtree of boxes. A cell goes to the smallest box that holds it, with a
    margin a little above its size, strictly inside; the piece of that box is
    the region cut to the box grown by the length of the region's longest
    edge, so that it holds every region edge that can touch the cell whole. A
    cell's overlay with its piece meets the same region edges, with the same
    end points, as its overlay with the whole region, and gives the same
    points where they cross the cell: two neighbours cut against different
    pieces share their boundary exactly. Cells come in tiers of similar size,
    so that a few large cells do not make the pieces of the many small ones
    large.

    Edges longer than the smallest margin are first split (``shapely.segmentize``)
    into edges no longer than it, for every cell alike: the new vertices lie on
    the edges up to rounding (the cells' union is then the region up to
    rounding, as for the crossing points of any cut); an outline without such
    long edges is used as it is.

    Parameters
    ----------
    cells : (k,) object array of shapely Polygons
    region : shapely Polygon or MultiPolygon

    Returns
    -------
    (k,) object array: ``shapely.intersection(cells[i], region)`` for each i.
    """
    import shapely

    if shapely.get_num_coordinates(region) <= PIECE_VERTICES:
        return shapely.intersection(cells, region)
    # the outline's long edges split by a length of its own (never one taken from the cells, so that
    # any subset of cells is cut as in the whole set): the pieces' reach
    region, reach = _short_edged(region)
    if len(cells) < LOCAL_MIN_CELLS:
        return shapely.intersection(cells, region)
    bounds = shapely.bounds(cells)
    sizes = np.maximum(bounds[:, 2] - bounds[:, 0], bounds[:, 3] - bounds[:, 1])
    # cells in tiers of similar sizes (a factor TIER_RATIO apart), each tier with a margin a little
    # above its largest cell: which piece a cell is cut against, not what the cut gives
    tier = np.floor(np.log(np.maximum(sizes / np.median(sizes), 1.0)) / np.log(TIER_RATIO)).astype(np.int64)
    tiers = [np.flatnonzero(tier == k) for k in np.unique(tier).tolist()]
    margins = [1.5 * float(sizes[rows].max()) for rows in tiers]
    out = np.empty(len(cells), dtype=object)
    for rows, margin in zip(tiers, margins):
        out[rows] = _cut_locally(cells[rows], bounds[rows], region, margin, reach)
    return out


def _cut_locally(cells: np.ndarray, bounds: np.ndarray, region, margin: float, reach: float) -> np.ndarray:
    """local_intersection of cells no larger than ``margin`` with a region of edges no longer than ``reach``."""
    import shapely

    out = np.empty(len(cells), dtype=object)
    # (piece, the box it serves, the cells it holds)
    stack = [(region, tuple(float(v) for v in region.bounds), np.arange(len(cells)))]
    while stack:
        piece, (x0, y0, x1, y1), held = stack.pop()
        xm, ym = (x0 + x1) / 2, (y0 + y1) / 2
        if (
            shapely.get_num_coordinates(piece) <= PIECE_VERTICES
            or len(held) < LOCAL_MIN_CELLS
            or max(x1 - x0, y1 - y0) < 2 * margin
        ):
            out[held] = shapely.intersection(cells[held], piece)
            continue
        quadrants = [(x0, y0, xm, ym), (xm, y0, x1, ym), (x0, ym, xm, y1), (xm, ym, x1, y1)]
        left = np.ones(len(held), bool)
        children = []
        b = bounds[held]
        for qx0, qy0, qx1, qy1 in quadrants:
            fit = (qx0 - margin, qy0 - margin, qx1 + margin, qy1 + margin)
            fits = left & (b[:, 0] > fit[0]) & (b[:, 1] > fit[1]) & (b[:, 2] < fit[2]) & (b[:, 3] < fit[3])
            if fits.any():
                left &= ~fits
                # every region edge that touches the fit box lies in this box, whole
                grow = reach * (1 + PIECE_BOX_GROWTH)
                box = (fit[0] - grow, fit[1] - grow, fit[2] + grow, fit[3] + grow)
                children.append(((qx0, qy0, qx1, qy1), box, held[fits]))
        if left.any():
            out[held[left]] = shapely.intersection(cells[held[left]], piece)
        if children:
            # a quadrant's box lies in its parent's, and so do the edges it must hold whole
            boxes = shapely.box(*np.array([box for _, box, _ in children]).T)
            pieces = _polygonal(shapely.intersection(piece, boxes))
            for (quadrant, _, cells_in), child in zip(children, pieces):
                stack.append((shapely.Polygon() if child is None else child, quadrant, cells_in))
    return out


def _edge_extents(region) -> np.ndarray:
    """The extent (the larger side of its bounds) of each edge of the region's rings."""
    import shapely

    rings = shapely.get_rings(shapely.get_parts(region))
    coords, index = shapely.get_coordinates(rings, return_index=True)
    same_ring = index[1:] == index[:-1]
    return np.abs(coords[1:] - coords[:-1])[same_ring].max(axis=1)


def _short_edged(region):
    """(region, reach): the region with its edges longer than EDGE_SPLIT times its median edge split
    (``shapely.segmentize``), and its longest edge's extent then. A function of the region alone."""
    import shapely

    extents = _edge_extents(region)
    if len(extents) == 0:
        return region, 0.0
    longest, length = float(extents.max()), EDGE_SPLIT * float(np.median(extents))
    if length > 0 and longest > length:
        region = shapely.segmentize(region, length)
        extents = _edge_extents(region)
        longest = float(extents.max())
    return region, longest


def _polygonal(geoms: np.ndarray) -> np.ndarray:
    """Overlay results as Polygons or MultiPolygons (stray points and lines dropped; None if no area is left),
    exteriors counter-clockwise."""
    import shapely

    types = shapely.get_type_id(geoms)
    odd = np.flatnonzero((types != shapely.GeometryType.POLYGON) & (types != shapely.GeometryType.MULTIPOLYGON))
    out = geoms.copy()
    for k in odd.tolist():
        # a collection from a degenerate overlay (a cell touching the region at a point or along a line)
        parts = shapely.get_parts(geoms[k])
        parts = parts[shapely.get_type_id(parts) == shapely.GeometryType.POLYGON]
        out[k] = None if len(parts) == 0 else parts[0] if len(parts) == 1 else shapely.multipolygons(parts)
    present = out != None  # noqa: E711
    present[present] = ~shapely.is_empty(out[present])
    out[~present] = None
    out[present] = shapely.orient_polygons(out[present], exterior_cw=False)
    return out
