"""A Diagram's cells as shapely Polygons and as a geopandas GeoDataFrame, built in bulk."""

from __future__ import annotations

import numpy as np

from tvoronoi.errors import TvoronoiError


def cell_polygons(diagram) -> np.ndarray:
    """One shapely Polygon per input row, from the CSR cell arrays in one call.

    Returns
    -------
    ndarray of shape (n,), dtype object
        Element i is cell i as a Polygon whose exterior ring runs
        counter-clockwise through ``diagram.cell_polygon(i)`` and back to its
        first point; None for a row without a cell (a repeated point, a cell
        that misses the box).

    Examples
    --------
    >>> import tvoronoi
    >>> d = tvoronoi.voronoi([[0, 0], [2, 0], [0, 0]], bbox=(-1, -1, 3, 1))
    >>> [p.wkt if p is not None else None for p in cell_polygons(d)]
    ['POLYGON ((-1 -1, 1 -1, 1 1, -1 1, -1 -1))', 'POLYGON ((1 -1, 3 -1, 3 1, 1 1, 1 -1))', None]
    """
    import shapely

    n = diagram.n_sites
    offsets = np.asarray(diagram.cell_offsets, np.int64)
    lengths = np.diff(offsets)
    # a ring needs three points; the kernels give a cell either none or at least three
    has_cell = lengths >= 3
    out = np.full(n, None, dtype=object)
    if not has_cell.any():
        return out
    # copy each ring's vertex indices and repeat its first one at its end (closed rings, as GeoArrow wants)
    kept = np.repeat(has_cell, lengths)
    vertex_ids = np.asarray(diagram.cell_vertices)[kept]
    ring_lengths = lengths[has_cell]
    closed_offsets = np.zeros(len(ring_lengths) + 1, np.int64)
    np.cumsum(ring_lengths + 1, out=closed_offsets[1:])
    ids = np.empty(closed_offsets[-1], np.int64)
    ring_of_vertex = np.repeat(np.arange(len(ring_lengths)), ring_lengths)
    ids[np.arange(len(vertex_ids)) + ring_of_vertex] = vertex_ids
    ids[closed_offsets[1:] - 1] = ids[closed_offsets[:-1]]
    # np.take gathers whole rows several times faster than fancy indexing
    coords = np.take(np.ascontiguousarray(diagram.cell_points, np.float64), ids, axis=0)
    polygon_offsets = np.arange(len(ring_lengths) + 1, dtype=np.int64)
    out[has_cell] = shapely.from_ragged_array(shapely.GeometryType.POLYGON, coords, (closed_offsets, polygon_offsets))
    return out


def cells_frame(diagram, properties=None, crs=None):
    """The cells as a geopandas GeoDataFrame: one row per input point, in input order.

    Parameters
    ----------
    properties : mapping or DataFrame, optional
        Columns to carry, each with one value per input point (taken by
        position: a DataFrame's own index is dropped).
    crs : optional
        Anything geopandas accepts as a CRS ("EPSG:3857", a pyproj CRS...).

    Returns
    -------
    geopandas.GeoDataFrame
        Columns ``site`` (the input row, int64), the properties, and
        ``geometry`` (the cells; missing for a row without a cell).

    Raises
    ------
    TvoronoiError
        geopandas is not installed, or the properties do not have one value per point or use the
        names ``site`` or ``geometry``.
    """
    try:
        import geopandas
        import pandas
    except ImportError:
        raise TvoronoiError(
            "Diagram.to_geopandas needs geopandas: pip install geopandas "
            "(or use Diagram.to_shapely, which needs only shapely)"
        ) from None
    n = diagram.n_sites
    columns = pandas.DataFrame({} if properties is None else properties)
    if properties is not None and len(columns) != n:
        raise TvoronoiError(f"properties have {len(columns)} rows for {n} points: give one row per point")
    taken = [name for name in ("site", "geometry") if name in columns.columns]
    if taken:
        raise TvoronoiError(f"properties may not have a column named {taken[0]!r}: tvoronoi writes it; rename it")
    columns = columns.reset_index(drop=True)
    columns.insert(0, "site", np.arange(n, dtype=np.int64))
    return geopandas.GeoDataFrame(columns, geometry=geopandas.array.from_shapely(diagram.to_shapely()), crs=crs)
