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
    """Check a clip region: a non-empty, valid shapely Polygon or MultiPolygon with finite coordinates.

    Raises
    ------
    TvoronoiError
        Naming what is wrong (``what`` names the region in the message) and how to fix it.
    """
    import shapely

    if not isinstance(clip, (shapely.Polygon, shapely.MultiPolygon)):
        raise TvoronoiError(
            f"{what} must be a shapely Polygon or MultiPolygon, got {type(clip).__name__}"
        )
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
    return clip


def region_box(region) -> tuple[float, float, float, float]:
    """The region's bounds grown by 1% of their larger side on every side (at least one double each way)."""
    xmin, ymin, xmax, ymax = (float(v) for v in region.bounds)
    margin = REGION_MARGIN * max(xmax - xmin, ymax - ymin)
    return (min(xmin - margin, math.nextafter(xmin, -math.inf)), min(ymin - margin, math.nextafter(ymin, -math.inf)),
            max(xmax + margin, math.nextafter(xmax, math.inf)), max(ymax + margin, math.nextafter(ymax, math.inf)))


def sites_inside(pts: np.ndarray, region) -> np.ndarray:
    """(n,) bool: the sites the region covers (its boundary included)."""
    import shapely

    shapely.prepare(region)
    # a point that intersects a polygon is covered by it
    return shapely.intersects_xy(region, pts[:, 0], pts[:, 1])


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
    inside = sites_inside(pts, region)
    rows = np.flatnonzero(inside)
    if len(rows) == 0:
        raise TvoronoiError(
            f"none of the {len(pts)} points lies inside the clip region (bounds {tuple(region.bounds)}): "
            f"check that the points and the region use the same coordinates (x, y order, CRS)"
        )
    inner = build(pts[rows])
    fields = _rows_of(inner, pts, rows)
    clipped, reshaped = _cut_cells(Diagram(**fields), region)
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


def _cut_cells(diagram: Diagram, region) -> tuple[np.ndarray, np.ndarray]:
    """Each cell cut to the region: (clipped, reshaped) as in ClippedDiagram."""
    from tvoronoi.shapes import cell_polygons

    return cut_polygons(cell_polygons(diagram), region)


def cut_polygons(cells: np.ndarray, region) -> tuple[np.ndarray, np.ndarray]:
    """Cells (shapely Polygons, None for no cell) cut to the region: (clipped, reshaped) as in ClippedDiagram.

    A cell inside the region is kept as it is, so the cut depends on the cell alone: tiles on a cluster
    (tvoronoi.distributed) cut their cells to the same geometries as one process.
    """
    import shapely

    has = cells != None  # noqa: E711 (elementwise on an object array)
    shapely.prepare(region)
    # cells inside the region are kept as they are; only those crossing its boundary are cut
    crossing = np.flatnonzero(has)
    crossing = crossing[~shapely.contains_properly(region, cells[crossing])]
    clipped = cells.copy()
    if len(crossing):
        clipped[crossing] = _polygonal(shapely.intersection(cells[crossing], region))
    reshaped = ~has
    reshaped[crossing] = True
    return clipped, reshaped


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
