"""GeoParquet and Parquet point files: Point geometries (WKB) with their columns, or x/y columns."""

from __future__ import annotations

import io

import numpy as np

from ..errors import InputFileError, TvoronoiError
from .columns import LAT_NAMES, LON_NAMES, check_distinct, describe_choice, is_id_like, resolve_column
from .pointset import PointSet

PARQUET_MAGIC = b"PAR1"
INSTALL_HINT = "pip install 'tvoronoi[parquet]' (or pip install pyarrow)"


def read_parquet(data: bytes, source: str, x, y) -> PointSet:
    """The sites of a GeoParquet file (its primary geometry column of points) or a Parquet table."""
    try:
        import orjson
        import pyarrow.parquet as pq
    except ImportError:
        raise TvoronoiError(
            f"{source}: reading Parquet needs pyarrow, which is not installed: {INSTALL_HINT}"
        ) from None
    if not data:
        raise InputFileError(f"{source}: no points found (the file is empty)")
    try:
        table = pq.read_table(io.BytesIO(data))
    except Exception as e:  # pyarrow's ArrowInvalid and friends
        raise InputFileError(f"{source}: broken Parquet file: {e}") from None
    geo = (table.schema.metadata or {}).get(b"geo")
    if geo is not None and x is None and y is None:
        meta = orjson.loads(geo)
        column = meta.get("primary_column", "geometry")
        # no crs member means OGC:CRS84; null means unknown; else PROJJSON, carried as it is
        crs = meta.get("columns", {}).get(column, {}).get("crs", "OGC:CRS84")
        return _geometry_table(table, column, source, crs)
    return _xy_table(table, source, x, y)


def _geometry_table(table, column: str, source: str, crs) -> PointSet:
    import shapely

    if column not in table.column_names:
        raise InputFileError(f'{source}: the GeoParquet metadata names a geometry column "{column}" it lacks')
    wkb = table.column(column).to_numpy(zero_copy_only=False)
    try:
        geometries = shapely.from_wkb(wkb)
    except Exception as e:
        raise InputFileError(f'{source}: column "{column}" is not WKB: {e}') from None
    kinds = shapely.get_type_id(geometries)
    bad = np.flatnonzero(kinds != shapely.GeometryType.POINT)
    if len(bad):
        i = int(bad[0])
        what = "null" if geometries[i] is None else shapely.get_type_id(geometries[i])
        kind = "a null geometry" if what == "null" else f"a {geometries[i].geom_type}"
        raise InputFileError(
            f"{source}, row {i} (0-based): {kind}; tvoronoi reads Point geometries: convert it (e.g. to "
            f"its centroid) or remove it"
        )
    xy = np.ascontiguousarray(shapely.get_coordinates(geometries), dtype=np.float64)
    if len(xy) == 0:
        raise InputFileError(f"{source}: no points found (the table has 0 rows)")
    _check_finite(xy, source)
    others = [j for j, name in enumerate(table.column_names) if name not in (column, "bbox")]
    columns = _properties(table, others)
    ident = crs.get("id") if isinstance(crs, dict) else None
    name = f"{ident.get('authority')}:{ident.get('code')}".upper() if isinstance(ident, dict) else crs
    lonlat = name in ("OGC:CRS84", "EPSG:4326")
    return PointSet(xy, source, columns, crs=crs, lonlat=lonlat, where=lambda i: f"row {i} (0-based)")


def _xy_table(table, source: str, x, y) -> PointSet:
    import pyarrow.types as pt

    names = table.column_names
    numeric = [
        j
        for j, name in enumerate(names)
        if pt.is_integer(table.schema.field(name).type) or pt.is_floating(table.schema.field(name).type)
    ]
    ix = resolve_column(x, "x", names, True, source)
    iy = resolve_column(y, "y", names, True, source)
    how, skipped = "by name", []
    if ix is None or iy is None:
        skipped = [names[j] for j in numeric if j not in (ix, iy) and is_id_like(names[j])]
        free = [j for j in numeric if j not in (ix, iy) and names[j] not in skipped]
        ix = free.pop(0) if ix is None and free else ix
        iy = free.pop(0) if iy is None and free else iy
        how = "the first numeric columns"
    if ix is None or iy is None:
        ids = f" (id-like columns are not taken: {', '.join(skipped)})" if skipped else ""
        raise InputFileError(
            f"{source}: no geo metadata and no x and y columns among {', '.join(names)}{ids}; choose them with --x/--y"
        )
    check_distinct(ix, iy, names, source)
    for j in (ix, iy):
        if j not in numeric:
            raise InputFileError(
                f'{source}: column "{names[j]}" has type {table.schema.field(names[j]).type}, not a number; '
                f"choose numeric columns with --x/--y"
            )
    if table.num_rows == 0:
        raise InputFileError(f"{source}: no points found (the table has 0 rows)")
    xy = np.empty((table.num_rows, 2), dtype=np.float64)
    for k, j in enumerate((ix, iy)):
        values = table.column(j)
        if values.null_count:
            i = int(np.flatnonzero(values.is_null().to_numpy(zero_copy_only=False))[0])
            raise InputFileError(
                f'{source}, row {i} (0-based): column "{names[j]}" is null; tvoronoi needs finite coordinates'
            )
        xy[:, k] = values.to_numpy()
    _check_finite(xy, source)
    columns = _properties(table, [j for j in range(len(names)) if j not in (ix, iy)])
    lonlat = names[ix].lower() in LON_NAMES and names[iy].lower() in LAT_NAMES
    choice = describe_choice(names, ix, iy, how, skipped) if x is None or y is None else None
    ambiguous = x is None and y is None and how != "by name" and len(numeric) > 2
    return PointSet(
        xy,
        source,
        columns,
        lonlat=lonlat,
        choice=choice,
        xy_columns=(names[ix], names[iy]),
        candidates=tuple(names[j] for j in numeric) if ambiguous else (),
        where=lambda i: f"row {i} (0-based)",
    )


def _check_finite(xy: np.ndarray, source: str) -> None:
    finite = np.isfinite(xy)
    if not finite.all():
        i, k = (int(v) for v in np.argwhere(~finite)[0])
        raise InputFileError(f"{source}, row {i} (0-based): {'xy'[k]} is {xy[i, k]}; tvoronoi needs finite coordinates")


def _properties(table, indices: list[int]) -> dict[str, list]:
    """The columns that travel as properties, as Python values: decimals become floats, and
    binary columns (another geometry, raw bytes) are left out, having no JSON form."""
    import pyarrow as pa
    import pyarrow.types as pt

    out = {}
    for j in indices:
        field = table.schema.field(j)
        values = table.column(j)
        if pt.is_binary(field.type) or pt.is_large_binary(field.type) or pt.is_fixed_size_binary(field.type):
            continue
        if pt.is_decimal(field.type):
            values = values.cast(pa.float64())
        out[field.name] = values.to_pylist()
    return out
