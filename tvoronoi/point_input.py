"""Points from the geospatial ecosystem (shapely, geopandas, pandas) as plain coordinate arrays.

``api.as_points`` calls :func:`foreign_points` first; it recognises a container by the module of its
type, so neither pandas nor geopandas is imported unless the caller already holds one of their objects.
"""

from __future__ import annotations

import numpy as np

from tvoronoi.coordinate_names import named_column
from tvoronoi.errors import TvoronoiError


def _module(obj) -> str:
    return type(obj).__module__ or ""


def _is_shapely(obj) -> bool:
    return _module(obj).startswith("shapely")


def _is_geopandas(obj) -> bool:
    return _module(obj).startswith("geopandas")


def _is_pandas(obj) -> bool:
    return _module(obj).startswith("pandas")


def foreign_points(points):
    """Coordinates of shapely, geopandas or pandas points as an (n, 2) array; None for anything else.

    Accepted: a shapely Point, MultiPoint or GeometryCollection of points; a sequence or object array of
    shapely Points; a geopandas GeoSeries, or a GeoDataFrame (its active geometry); a pandas Series of
    shapely Points; a pandas DataFrame, whose columns are chosen by name (x/y, lon/lat, lng/lat,
    longitude/latitude, easting/northing, e/n, in any case), or failing names its column of shapely
    Points (the one named "geometry" first), or else taken when there are exactly two. A z coordinate
    is dropped.

    Returns
    -------
    ndarray of shape (n, 2), float64, or None
        None when ``points`` is none of these (a list of numbers, an ndarray...).

    Raises
    ------
    TvoronoiError
        A geometry that is not a point, an empty point, a value that is not a geometry among geometries
        (naming the row, and the index label of a pandas object), or a DataFrame without recognisable
        coordinate columns.

    Examples
    --------
    >>> import shapely
    >>> foreign_points(shapely.MultiPoint([(0, 0), (2, 1)])).tolist()
    [[0.0, 0.0], [2.0, 1.0]]
    >>> foreign_points([[0, 0], [1, 1]]) is None
    True
    """
    if _is_geopandas(points):
        geometry = getattr(points, "geometry", points)  # a GeoDataFrame's active geometry column
        return _geometry_points(geometry.to_numpy(), labels=geometry.index)
    if _is_pandas(points):
        if hasattr(points, "columns"):
            return _frame_points(points)
        values = points.to_numpy()
        if values.dtype == object and len(values) and _is_shapely(values[0]):
            return _geometry_points(values, labels=points.index)
        return None
    if _is_shapely(points):
        return _geometry_points(_parts(points))
    if isinstance(points, (list, tuple)) and len(points) and _is_shapely(points[0]):
        return _geometry_points(_object_array(points))
    if isinstance(points, np.ndarray) and points.dtype == object and points.size and _is_shapely(points.flat[0]):
        return _geometry_points(points.ravel())
    return None


def crs_of(points):
    """The CRS a geopandas GeoSeries or GeoDataFrame carries (None for it without one, or for anything else)."""
    return getattr(points, "crs", None) if _is_geopandas(points) else None


def explain_failure(points) -> str | None:
    """Why a sequence that numpy could not read as numbers failed, when a shapely geometry is in it."""
    if not isinstance(points, (list, tuple)):
        return None
    for i, value in enumerate(points):
        if _is_shapely(value):
            return (
                f"point {i} is a shapely {value.geom_type} among other values: give only shapely Points, "
                f"or only coordinate pairs"
            )
    return None


def _object_array(values) -> np.ndarray:
    # np.asarray would try to read each geometry as a sequence: fill an object array instead
    out = np.empty(len(values), dtype=object)
    out[:] = list(values)
    return out


def _parts(geom) -> np.ndarray:
    """A single shapely geometry as an array of candidate points: itself, or the parts of a collection."""
    import shapely

    if shapely.get_type_id(geom) in (4, 7):  # MultiPoint, GeometryCollection
        return shapely.get_parts(geom)
    return np.array([geom], dtype=object)


def _label(labels, i: int) -> str:
    """' (index label)' when a pandas index names row i otherwise than by its position."""
    if labels is None:
        return ""
    label = labels[i]
    return "" if isinstance(label, (int, np.integer)) and label == i else f" (index {label!r})"


def _geometry_points(geoms: np.ndarray, labels=None) -> np.ndarray:
    """Coordinates of an array of shapely Points, refusing anything else by row."""
    import shapely

    if len(geoms) == 0:
        return np.empty((0, 2), np.float64)
    not_geometry = ~shapely.is_geometry(geoms)
    if not_geometry.any():
        i = int(np.flatnonzero(not_geometry)[0])
        raise TvoronoiError(
            f"point {i}{_label(labels, i)} is {geoms[i]!r}, not a shapely Point: give a Point for every row "
            f"(drop missing geometries first)"
        )
    not_point = shapely.get_type_id(geoms) != 0
    if not_point.any():
        i = int(np.flatnonzero(not_point)[0])
        raise TvoronoiError(
            f"point {i}{_label(labels, i)} is a {geoms[i].geom_type}, not a Point ({int(not_point.sum())} such "
            f"geometries): take their centroids or representative points first"
        )
    empty = shapely.is_empty(geoms)
    if empty.any():
        i = int(np.flatnonzero(empty)[0])
        raise TvoronoiError(
            f"point {i}{_label(labels, i)} is an empty Point ({int(empty.sum())} such points): drop them first"
        )
    return shapely.get_coordinates(geoms)


def _geometry_column(frame, names: list[str]) -> int | None:
    """The index of a column holding shapely geometries (its first non-null value one), "geometry" first."""
    order = sorted(range(len(names)), key=lambda j: names[j].lower() != "geometry")
    for j in order:
        column = frame[frame.columns[j]]
        if column.dtype != object:
            continue
        present = column.dropna()
        if len(present) and _is_shapely(present.iloc[0]):
            return j
    return None


def _frame_points(frame) -> np.ndarray:
    """The x and y columns of a pandas DataFrame, chosen by name; else its column of shapely points
    (one named "geometry" first); else its only two columns."""
    names = [str(c) for c in frame.columns]
    ix, iy = named_column(names, "x"), named_column(names, "y")
    if ix is None or iy is None:
        geometry = _geometry_column(frame, names)
        if geometry is not None:
            column = frame[frame.columns[geometry]]
            try:
                return _geometry_points(column.to_numpy(), labels=column.index)
            except TvoronoiError as exc:
                raise TvoronoiError(f"DataFrame column {names[geometry]!r}: {exc}") from None
        if len(names) != 2:
            raise TvoronoiError(
                f"cannot tell which DataFrame columns are x and y among {names}: name them x and y "
                f"(or lon/lat, easting/northing), or pass frame[[xcol, ycol]]"
            )
        ix, iy = 0, 1
    columns = [frame.columns[ix], frame.columns[iy]]
    try:
        return frame[columns].to_numpy(dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TvoronoiError(f"DataFrame columns {names[ix]!r} and {names[iy]!r} must be numbers: {exc}") from None
