"""GeoParquet 1.1 out: cells and triangles as WKB polygons, bbox covering columns, typed properties."""

from __future__ import annotations

import numpy as np

from tvoronoi.arrow_arrays import fixed_width, null_count, validity_bitmap
from tvoronoi.errors import TvoronoiError
from tvoronoi.readers.text_column import TextColumn

from .targets import open_output

__all__ = [
    "write_cells_parquet",
    "write_delaunay_parquet",
    "require_pyarrow",
    "projjson",
    "crs_name",
    "is_crs84",
    "CRS84_PROJJSON",
]

GEOPARQUET_VERSION = "1.1.0"
# bytes before the points of a one-ring polygon's WKB: byte order, type, ring count, point count
WKB_HEADER = 13
# cells per row group of a GeoParquet file: a row group's polygons are laid out at a time
ROW_GROUP = 1 << 17
# polygons laid out per numpy pass (bounds the temporary masks to a few megabytes)
WKB_CHUNK = 1 << 15
# zstd's level for the WKB geometry: a fast level (negative: less searching for matches), for
# a column of doubles that compresses by a quarter at best; at 10^6 cells its encoding takes
# 0.37 s of CPU for 133 MB where level 1 takes 0.56 s for 127 MB
GEOMETRY_ZSTD_LEVEL = -3
# values of a property looked at to choose a dictionary for it
DICTIONARY_SAMPLE = 1 << 14
# a cell's WKB is laid out in 16-byte slots (see _padded_cells): its header takes the first
# slot after this many bytes of padding, each point a slot of its own
WKB_PAD = 16 - WKB_HEADER
# the first 9 bytes of a one-ring polygon's WKB: little-endian, type 3 (Polygon), 1 ring
WKB_POLYGON_RING = b"\x01\x03\x00\x00\x00\x01\x00\x00\x00"
INSTALL_HINT = "pip install 'tvoronoi[parquet]' (or pip install pyarrow pyproj)"
# OGC:CRS84, lon/lat on WGS 84, as the GeoParquet specification spells it
CRS84_PROJJSON = {
    "$schema": "https://proj.org/schemas/v0.7/projjson.schema.json",
    "type": "GeographicCRS",
    "name": "WGS 84 (CRS84)",
    "datum_ensemble": {
        "name": "World Geodetic System 1984 ensemble",
        "members": [
            {"name": "World Geodetic System 1984 (Transit)"},
            {"name": "World Geodetic System 1984 (G730)"},
            {"name": "World Geodetic System 1984 (G873)"},
            {"name": "World Geodetic System 1984 (G1150)"},
            {"name": "World Geodetic System 1984 (G1674)"},
            {"name": "World Geodetic System 1984 (G1762)"},
            {"name": "World Geodetic System 1984 (G2139)"},
        ],
        "ellipsoid": {"name": "WGS 84", "semi_major_axis": 6378137, "inverse_flattening": 298.257223563},
        "accuracy": "2.0",
        "id": {"authority": "EPSG", "code": 6326},
    },
    "coordinate_system": {
        "subtype": "ellipsoidal",
        "axis": [
            {"name": "Geodetic longitude", "abbreviation": "Lon", "direction": "east", "unit": "degree"},
            {"name": "Geodetic latitude", "abbreviation": "Lat", "direction": "north", "unit": "degree"},
        ],
    },
    "scope": "Not known.",
    "area": "World.",
    "bbox": {"south_latitude": -90, "west_longitude": -180, "north_latitude": 90, "east_longitude": 180},
    "id": {"authority": "OGC", "code": "CRS84"},
}


def require_pyarrow():
    """Import pyarrow and pyarrow.parquet, or say how to install them."""
    try:
        import pyarrow
        import pyarrow.parquet  # noqa: F401
    except ImportError:
        raise TvoronoiError(f"GeoParquet needs pyarrow, which is not installed: {INSTALL_HINT}") from None
    return pyarrow


def is_crs84(crs) -> bool:
    """Whether a CRS (a name or PROJJSON) is WGS 84 longitude/latitude: OGC:CRS84 or EPSG:4326."""
    return crs_name(crs) in ("OGC:CRS84", "EPSG:4326")


def crs_name(crs) -> str | None:
    """ "EPSG:3857" for a name or a PROJJSON with that id; a PROJJSON's name without one; None if unknown."""
    if crs is None:
        return None
    if isinstance(crs, dict):
        ident = crs.get("id")
        if isinstance(ident, dict):
            return f"{ident.get('authority')}:{ident.get('code')}".upper()
        return str(crs.get("name", "a CRS without an id"))
    return crs.upper()


def projjson(crs) -> dict | None:
    """The PROJJSON of a CRS ("OGC:CRS84", "EPSG:3857" or a PROJJSON dict); None when unknown.

    An authority code other than OGC:CRS84 is spelled out by pyproj (part of the
    ``parquet`` extra): a PROJJSON with only an id is not readable by PROJ.

    Raises
    ------
    TvoronoiError
        pyproj is missing, or does not know the code.
    """
    if crs is None or isinstance(crs, dict):
        return crs
    if crs.upper() == "OGC:CRS84":
        return CRS84_PROJJSON
    try:
        from pyproj import CRS
        from pyproj.exceptions import CRSError
    except ImportError:
        raise TvoronoiError(
            f"recording {crs} in GeoParquet needs pyproj, which is not installed: {INSTALL_HINT}"
        ) from None
    try:
        return CRS.from_user_input(crs).to_json_dict()
    except CRSError as e:
        raise TvoronoiError(f"{crs}: not a CRS pyproj knows ({e}); give one like EPSG:3857") from None


def _typed_column(pa, values: list, name: str = "a property"):
    """An Arrow array of one property: its own type when the values share one, else text (see
    :func:`_mixed_column`)."""
    if isinstance(values, TextColumn):
        return values.to_arrow()
    numbers = _number_column(pa, values)
    if numbers is not None:
        return numbers
    try:
        return pa.array(values)
    except (pa.ArrowInvalid, pa.ArrowTypeError, OverflowError):
        return _mixed_column(pa, values, name)


def _mixed_column(pa, values: list, name: str = "a property"):
    """A string array of a property whose values mix types (``1``, ``"01"``, ``2.5``): a string
    as it is (``"01"``, never ``'"01"'``), any other value as the JSON text the GeoJSON output
    writes for it (``"1"``, ``"2.5"``, ``"[1,2]"``), null for None.

    Raises
    ------
    TvoronoiError
        A value has no JSON form.
    """
    import orjson

    out = []
    for v in values:
        if v is not None and not isinstance(v, str):
            try:
                v = orjson.dumps(v, option=orjson.OPT_SERIALIZE_NUMPY).decode()
            except orjson.JSONEncodeError as e:
                raise TvoronoiError(f"{name}: the value {v!r} cannot be written as JSON text ({e})") from None
        out.append(v)
    return pa.array(out, pa.string())


def _number_column(pa, values: list):
    """An int64 or float64 Arrow array of a list of ints or of floats (None for null), made from
    numpy's buffer (``pa.array`` would import pandas to look at them); None for other lists."""
    kinds = set(map(type, values))
    valid = None
    if type(None) in kinds:
        kinds.discard(type(None))
        valid = np.fromiter((v is not None for v in values), bool, count=len(values))
        values = [0 if v is None else v for v in values]
    if kinds == {float}:
        return fixed_width(pa, np.array(values, np.float64), pa.float64(), valid)
    if kinds == {int}:
        try:
            return fixed_width(pa, np.array(values, np.int64), pa.int64(), valid)
        except OverflowError:
            return None
    return None


def geo_metadata(column_bbox, geometry_types: list[str], crs) -> bytes:
    import orjson

    meta = {
        "encoding": "WKB",
        "geometry_types": geometry_types,
        "covering": {"bbox": {k: ["bbox", k] for k in ("xmin", "ymin", "xmax", "ymax")}},
    }
    if column_bbox is not None:
        meta["bbox"] = [float(v) for v in column_bbox]
    # without a crs member GeoParquet means OGC:CRS84; coordinates of unknown meaning say null
    meta["crs"] = projjson(crs)
    return orjson.dumps({"version": GEOPARQUET_VERSION, "primary_column": "geometry", "columns": {"geometry": meta}})


def _wkb_polygons(pa, xy: np.ndarray, ring_offsets: np.ndarray, present: np.ndarray | None = None):
    """Closed single-ring polygons as an Arrow binary array of little-endian WKB, built in bulk.

    Each polygon is ``01 | 03000000 | 01000000 | n (uint32) | n points (2 float64)``, the
    bytes shapely.to_wkb writes for it, laid out with numpy instead of one GEOS geometry and
    one Python bytes object per cell (three times faster, and no per-cell objects in memory).
    ``present``: a row per True, the polygons in order, and a null row per False.
    """
    counts = np.diff(ring_offsets)
    sizes = WKB_HEADER + 16 * counts
    offsets = np.zeros(len(counts) + 1, np.int64)
    np.cumsum(sizes, out=offsets[1:])
    rows = len(counts) if present is None else len(present)
    total = int(offsets[-1])
    data = np.empty(total, np.uint8)
    points = np.ascontiguousarray(xy, "<f8").view(np.uint8).ravel()
    # a run of polygons at a time: the masks below stay a few megabytes
    for a in range(0, len(counts), WKB_CHUNK):
        b = min(a + WKB_CHUNK, len(counts))
        chunk = data[offsets[a] : offsets[b]]
        header = np.empty((b - a, WKB_HEADER), np.uint8)
        header[:, :9] = np.frombuffer(WKB_POLYGON_RING, np.uint8)
        header[:, 9:] = counts[a:b].astype("<u4").view(np.uint8).reshape(-1, 4)
        positions = ((offsets[a:b] - offsets[a])[:, None] + np.arange(WKB_HEADER)).ravel()
        chunk[positions] = header.ravel()
        # every byte that is not a header's holds the points, in order
        in_points = np.ones(len(chunk), bool)
        in_points[positions] = False
        chunk[in_points] = points[16 * ring_offsets[a] : 16 * ring_offsets[b]]
    if rows != len(counts):
        # a null row is an empty value where the row's offset repeats
        assert present is not None
        offsets = offsets[np.concatenate([[0], np.cumsum(present)])]
    return _binary_column(pa, offsets, data, None if present is None else present)


def _binary_column(pa, offsets: np.ndarray, data: np.ndarray, valid: np.ndarray | None):
    """A binary Arrow array (large_binary past 2 GiB) of the values ``data[offsets[i]:offsets[i + 1]]``."""
    kind, index = (pa.binary(), np.int32) if int(offsets[-1]) < 2**31 else (pa.large_binary(), np.int64)
    if valid is not None and valid.all():
        valid = None
    return pa.Array.from_buffers(
        kind,
        len(offsets) - 1,
        [validity_bitmap(pa, valid), pa.py_buffer(offsets.astype(index)), pa.py_buffer(data)],
        null_count=null_count(valid),
    )


def _bbox_column(pa, mins: np.ndarray, maxs: np.ndarray, present: np.ndarray):
    """The bbox covering column (struct of xmin, ymin, xmax, ymax), null where ``present`` is False."""
    valid = None if present.all() else present
    return pa.StructArray.from_arrays(
        [fixed_width(pa, v, pa.float64(), valid) for v in (mins[:, 0], mins[:, 1], maxs[:, 0], maxs[:, 1])],
        names=["xmin", "ymin", "xmax", "ymax"],
    )


def _padded_cells(pa, diagram, ra: int, rb: int, keep: np.ndarray, present: np.ndarray):
    """The cells of rows ra..rb-1 where ``keep`` holds as WKB Polygons with WKB_PAD bytes of padding
    before each, and their bboxes: (padded binary array, mins, maxs), a row per ``present`` entry
    (null where False). ``pyarrow.compute.binary_slice(padded, WKB_PAD)`` is their WKB.

    With the padding, the header and every point of a cell fill 16-byte slots::

        | pad(3) 01 03000000 01000000 n | x0 y0 | x1 y1 | ... | x0 y0 | pad(3) 01 ...

    so the points go from the diagram's positions straight into the slots, with each ring's bounding
    box, in one compiled pass (``kernels.rings``), and a header's slot then gets its header, where
    unpadded WKB would need each byte placed on its own.
    """
    from tvoronoi.kernels.rings import gather_slotted_rings

    offsets = diagram.cell_offsets
    lengths = np.diff(offsets[ra : rb + 1])[keep]
    k = len(lengths)
    # before each ring a header slot, after it its first point again
    header_at = np.zeros(k, np.int64)
    np.cumsum(lengths[:-1] + 2, out=header_at[1:])
    slots = np.empty(int(lengths.sum()) + 2 * k, "<c16")
    kept_mins, kept_maxs = np.empty((k, 2)), np.empty((k, 2))
    gather_slotted_rings(
        offsets,
        diagram.cell_vertices,
        np.ascontiguousarray(diagram.cell_points, "<f8"),
        ra,
        rb,
        np.ascontiguousarray(keep, np.uint8),
        slots.view("<f8").reshape(-1, 2),
        kept_mins,
        kept_maxs,
    )
    # the headers: the point count includes the closing point
    headers = np.zeros((k, 16), np.uint8)
    headers[:, WKB_PAD : WKB_PAD + 9] = np.frombuffer(WKB_POLYGON_RING, np.uint8)
    headers[:, WKB_PAD + 9 :] = (lengths + 1).astype("<u4").view(np.uint8).reshape(-1, 4)
    slots[header_at] = headers.view("<c16").ravel()
    mins = np.full((len(present), 2), np.nan)
    maxs = np.full((len(present), 2), np.nan)
    mins[present] = kept_mins
    maxs[present] = kept_maxs
    sizes = np.zeros(len(present), np.int64)
    sizes[present] = 16 * (lengths + 2)
    value_offsets = np.zeros(len(present) + 1, np.int64)
    np.cumsum(sizes, out=value_offsets[1:])
    padded = _binary_column(pa, value_offsets, slots.view(np.uint8), present)
    return padded, mins, maxs


def unpadded(padded):
    """The WKB of the values of :func:`_padded_cells`: each without its first WKB_PAD bytes (Arrow's
    own slicing, without the GIL)."""
    import pyarrow.compute as pc

    # stop: past any value (a larger one overflows in Arrow's size estimate)
    return pc.binary_slice(padded, WKB_PAD, 1 << 31)


def polygon_columns(pa, xy: np.ndarray, ring_offsets: np.ndarray, present: np.ndarray):
    """WKB and bbox columns of closed single-ring polygons; rows where ``present`` is False are null."""
    n_rings = len(ring_offsets) - 1
    mins = np.full((len(present), 2), np.nan)
    maxs = np.full((len(present), 2), np.nan)
    wkb = _wkb_polygons(pa, xy, ring_offsets, present)
    if n_rings:
        starts = ring_offsets[:-1]
        mins[present] = np.minimum.reduceat(xy, starts, axis=0)
        maxs[present] = np.maximum.reduceat(xy, starts, axis=0)
    bbox = _bbox_column(pa, mins, maxs, present)
    extent = None
    if n_rings:
        kept_mins, kept_maxs = mins[present], maxs[present]
        extent = [kept_mins[:, 0].min(), kept_mins[:, 1].min(), kept_maxs[:, 0].max(), kept_maxs[:, 1].max()]
    return wkb, bbox, extent


def shapely_cell_columns(pa, geoms: np.ndarray):
    """WKB and bbox columns, the extent and the geometry types of shapely cells (None: a null row)."""
    import shapely

    present = geoms != None  # noqa: E711 (elementwise)
    wkb = pa.array(shapely.to_wkb(geoms), pa.binary())
    bounds = shapely.bounds(geoms)
    mask = ~present
    bbox = pa.StructArray.from_arrays(
        [pa.array(bounds[:, k], pa.float64(), mask=mask) for k in range(4)],
        names=["xmin", "ymin", "xmax", "ymax"],
    )
    extent = [float(v) for v in shapely.total_bounds(geoms)] if present.any() else None
    names = {shapely.GeometryType.POLYGON: "Polygon", shapely.GeometryType.MULTIPOLYGON: "MultiPolygon"}
    types = sorted({names[int(t)] for t in np.unique(shapely.get_type_id(geoms[present]))})
    return wkb, bbox, extent, types


def _duplicates_column(pa, diagram, kept: np.ndarray):
    """The later rows at each kept site's place (list of int64), null where the site does not repeat."""
    repeats = diagram.duplicates()
    kind = pa.list_(pa.int64())
    if not repeats:
        return pa.nulls(len(kept), kind)
    return pa.array([repeats.get(i) for i in kept.tolist()], kind)


def write_table(pa, table, out, overwrite: bool) -> None:
    import pyarrow.parquet as pq

    with open_output(out, overwrite=overwrite) as stream:
        options = _parquet_options(table.schema, {name: table.column(name) for name in table.schema.names})
        pq.write_table(table, pa.PythonFile(stream, mode="w"), **options)


def write_cells_parquet(diagram, points, out, *, overwrite: bool = True, crs=None) -> int:
    """Write the Voronoi cells as GeoParquet 1.1: one row per distinct site, in input order.

    Columns: ``site`` (int64, the 0-based input row), the site's properties as
    typed Arrow columns (a property whose values mix types is text: strings as they
    are, other values their JSON text),
    ``duplicates`` (list of later rows at the same place, null where none),
    ``geometry`` (WKB Polygon, null for a cell that misses the box) and ``bbox``
    (struct xmin, ymin, xmax, ymax: the covering columns of GeoParquet 1.1).
    The ``geo`` metadata records the CRS: ``crs`` (a CRS name or PROJJSON,
    see :func:`projjson`), or null when the coordinates have no known CRS.

    Returns
    -------
    int
        The number of rows written.

    Raises
    ------
    TvoronoiError
        pyarrow is not installed, or ``points`` does not match the diagram.
    OSError
        If writing fails (an existing file at ``out`` is then left untouched).
    """
    pa = require_pyarrow()
    from tvoronoi.writers.geojson_diagram import MIN_RING_POINTS, property_renames

    n_sites = diagram.n_sites
    rows = np.arange(n_sites)
    distinct = diagram.site_of == rows
    has_ring = distinct & (np.diff(diagram.cell_offsets) >= MIN_RING_POINTS)
    types = ["Polygon"]
    kept = rows[distinct]
    columns = {"site": fixed_width(pa, kept, pa.int64())}
    if points is not None:
        if len(points) != n_sites:
            raise TvoronoiError(
                f"the point set has {len(points)} rows but the diagram has {n_sites} sites; "
                f"pass the points the diagram was built from"
            )
        renames = property_renames(points.property_names)
        for name in points.property_names:
            if points.records is not None:
                values = [points.records[i].get(name) for i in kept.tolist()]
            else:
                values = points.columns[name]
                if len(kept) < n_sites:
                    values = [values[i] for i in kept.tolist()]
            columns[renames.get(name, name)] = _typed_column(pa, values, name)
    columns["duplicates"] = _duplicates_column(pa, diagram, kept)
    if getattr(diagram, "clipped", None) is not None:
        # cut to a clip region: Polygons with holes and MultiPolygons, written by shapely
        geometry, bbox, extent, types = shapely_cell_columns(pa, diagram.clipped[distinct])
        columns["geometry"] = geometry
        columns["bbox"] = bbox
        table = pa.table(columns).replace_schema_metadata({b"geo": geo_metadata(extent, types, crs)})
        write_table(pa, table, out, overwrite)
        return len(kept)
    write_cell_rows(pa, out, columns, diagram, kept, has_ring[distinct], crs=crs, overwrite=overwrite)
    return len(kept)


def write_cell_rows(
    pa, out, columns: dict, diagram, rows: np.ndarray, present: np.ndarray, *, crs=None, overwrite: bool = True
) -> None:
    """Write a GeoParquet table of ``columns`` (Arrow arrays, one value per row) and the cells of the
    diagram's ``rows`` (ascending) as ``geometry`` and ``bbox``: null where ``present`` is False.

    The polygons are laid out a row group at a time from the diagram (no whole copy of the rings or of
    their WKB), and a row group is encoded and compressed in a second thread while the next is made.
    """
    import pyarrow.parquet as pq

    has_ring = np.zeros(diagram.n_sites, bool)
    has_ring[rows[present]] = True
    schema = pa.schema(
        [pa.field(name, column.type) for name, column in columns.items()]
        + [pa.field("geometry", pa.binary()), pa.field("bbox", _BBOX_TYPE(pa))]
    )
    schema = schema.with_metadata({b"geo": geo_metadata(_rings_extent(diagram, has_ring), ["Polygon"], crs)})
    from concurrent.futures import ThreadPoolExecutor

    def row_group(a: int, b: int) -> dict:
        # diagram rows ra..rb-1 hold the rows a..b-1 and those between them (not written, no ring)
        ra, rb = int(rows[a]), int(rows[b - 1]) + 1
        padded, mins, maxs = _padded_cells(pa, diagram, ra, rb, has_ring[ra:rb], present[a:b])
        group = {name: column.slice(a, b - a) for name, column in columns.items()}
        group["geometry"], group["bbox"] = padded, _bbox_column(pa, mins, maxs, present[a:b])
        return group

    def write_group(group: dict) -> None:
        # in the writer's thread: the padding cut off (in Arrow, without the GIL), then encoded
        group["geometry"] = unpadded(group["geometry"])
        writer.write_table(pa.table(group, schema=schema))

    with open_output(out, overwrite=overwrite) as stream, ThreadPoolExecutor(1) as pool:
        options = _parquet_options(schema, columns, compress_bbox=False)
        with pq.ParquetWriter(pa.PythonFile(stream, mode="w"), schema, **options) as writer:
            if not len(rows):
                writer.write_table(schema.empty_table())
            # a row group is encoded and compressed (without the GIL) while the next one is made
            pending = None
            for a in range(0, len(rows), ROW_GROUP):
                group = row_group(a, min(a + ROW_GROUP, len(rows)))
                if pending is not None:
                    pending.result()
                pending = pool.submit(write_group, group)
                del group
            if pending is not None:
                pending.result()


def _parquet_options(schema, columns: dict | None = None, *, compress_bbox: bool = True) -> dict:
    """How the columns are written.

    zstd, at level 1 (at the default level compressing takes twice as long for a file a few
    percent smaller), the geometry at GEOMETRY_ZSTD_LEVEL; the bbox columns uncompressed
    unless ``compress_bbox`` (the bounds of Voronoi cells shrink by 6%, for 0.07 s at 10^6
    cells; those of triangles, which share their corners, by 40%). Dictionaries for the
    Parquet columns of the properties (a nested property's leaves) whose values repeat
    (``columns``: the property arrays, a sample of each looked at; without them, every
    property): a column of distinct names would fill a dictionary in every row group only to
    fall back. Statistics for every column but the geometry (the bbox columns' let a reader
    skip row groups). The site numbers delta-encoded.
    """
    own = {"site", "duplicates", "geometry", "bbox", "sites"}
    properties = [field for field in schema if field.name not in own]
    if columns is None:
        dictionary = [path for field in properties for path, _ in _leaves(field.name, field.type)]
    else:
        dictionary = [
            path
            for field in properties
            for path, values in _leaves(field.name, field.type, _sample(columns[field.name]))
            if _repeats(values)
        ]
    # the options name Parquet's column paths: a nested column's are its leaves' ("duplicates.list.element")
    statistics = [path for path in _leaf_paths(schema) if path != "geometry"]
    bbox = [f"bbox.{k}" for k in ("xmin", "ymin", "xmax", "ymax")] if "bbox" in schema.names else []
    plain = [] if compress_bbox else bbox
    compressed = [path for path in _leaf_paths(schema) if path not in plain]
    options: dict = {}
    if "site" in schema.names:
        # the rows' numbers rise by one or a few: deltas bit-packed, 0.07 s less to encode at
        # 10^6 cells than zstd over the plain integers, and 1 MB smaller
        options["column_encoding"] = {"site": "DELTA_BINARY_PACKED"}
    return dict(
        options,
        compression={**{path: "zstd" for path in compressed}, **{path: "none" for path in plain}},
        compression_level={name: GEOMETRY_ZSTD_LEVEL if name == "geometry" else 1 for name in compressed},
        use_dictionary=dictionary or False,
        write_statistics=statistics,
    )


def _leaf_paths(schema) -> list[str]:
    """The Parquet column paths of an Arrow schema's fields, as per-column options name them
    ("bbox.xmin", "duplicates.list.element")."""
    return [path for field in schema for path, _ in _leaves(field.name, field.type)]


def _leaves(name: str, kind, values=None) -> list:
    """The Parquet column paths of a field (its name and Arrow type), each with its values in
    ``values`` (an Arrow array of the field, or None): [(path, values or None)]. A list's
    leaves are its elements', a map's its keys' and values', a struct's its fields'."""
    import pyarrow.types as pt

    if pt.is_map(kind):
        keys = items = None
        if values is not None:
            # the entries of the rows of ``values`` (``keys`` and ``items`` are the whole array's)
            start, stop = values.offsets[0].as_py(), values.offsets[-1].as_py()
            keys, items = values.keys.slice(start, stop - start), values.items.slice(start, stop - start)
        return [
            *_leaves(f"{name}.key_value.key", kind.key_type, keys),
            *_leaves(f"{name}.key_value.value", kind.item_type, items),
        ]
    if pt.is_list(kind) or pt.is_large_list(kind) or pt.is_fixed_size_list(kind):
        return _leaves(f"{name}.list.element", kind.value_type, None if values is None else values.flatten())
    if pt.is_struct(kind):
        fields = [None] * kind.num_fields if values is None else values.flatten()
        return [
            leaf
            for k in range(kind.num_fields)
            for leaf in _leaves(f"{name}.{kind.field(k).name}", kind.field(k).type, fields[k])
        ]
    return [(name, values)]


def _sample(values):
    """The first DICTIONARY_SAMPLE values of a column (an Arrow array or chunked array) as one array."""
    import pyarrow as pa

    sample = values.slice(0, DICTIONARY_SAMPLE)
    return sample.combine_chunks() if isinstance(sample, pa.ChunkedArray) else sample


def _repeats(values) -> bool:
    """Whether the values of a Parquet column (an array of one leaf of a property, from
    :func:`_sample`) repeat enough for a dictionary: at most half of them are distinct.

    Values of no type to count (all null: nothing to look up; a type Arrow cannot count) are
    written plain, as they always can be; a dictionary array's indices are counted.
    """
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.types as pt

    if pt.is_null(values.type):
        return False
    if pt.is_dictionary(values.type):
        values = values.indices
    try:
        distinct = pc.count_distinct(values, mode="all").as_py()
    except pa.ArrowNotImplementedError:
        return False
    return 2 * distinct <= max(len(values), 1)


def _BBOX_TYPE(pa):
    return pa.struct([pa.field(k, pa.float64()) for k in ("xmin", "ymin", "xmax", "ymax")])


def _rings_extent(diagram, has_ring: np.ndarray) -> list[float] | None:
    """(xmin, ymin, xmax, ymax) of the cells written from their rings; None when there is none.

    When every distinct site has a ring, it is the box: the cells clipped to the box cover it
    (a cell without area is only a side or a corner of others), and the clipper writes the
    box's own coordinates where a cell meets a side. Otherwise, from the rings' points.
    """
    distinct = diagram.site_of == np.arange(diagram.n_sites)
    if diagram.n_sites and np.array_equal(has_ring, distinct):
        return [float(v) for v in diagram.bbox]
    return _points_extent(diagram, has_ring)


def _points_extent(diagram, has_ring: np.ndarray) -> list[float] | None:
    """:func:`_rings_extent` from the points of the rings (each one looked at)."""
    offsets = diagram.cell_offsets
    lengths = np.diff(offsets)
    ring = diagram.cell_vertices[np.repeat(has_ring, lengths)] if not has_ring.all() else diagram.cell_vertices
    if not len(ring):
        return None
    used = np.zeros(len(diagram.cell_points), bool)
    used[ring] = True
    xy = diagram.cell_points if used.all() else diagram.cell_points[used]
    return [float(xy[:, 0].min()), float(xy[:, 1].min()), float(xy[:, 0].max()), float(xy[:, 1].max())]


def write_delaunay_parquet(diagram, out, *, overwrite: bool = True, crs=None) -> int:
    """Write the Delaunay triangles as GeoParquet 1.1: ``sites`` (three 0-based rows), ``geometry``, ``bbox``.

    Returns the number of triangles; raises as :func:`write_cells_parquet`.
    """
    pa = require_pyarrow()
    triangles = np.asarray(diagram.triangles, dtype=np.int64).reshape(-1, 3)
    xy = np.take(diagram.sites, triangles[:, [0, 1, 2, 0]].ravel(), axis=0)
    ring_offsets = np.arange(0, 4 * len(triangles) + 1, 4, dtype=np.int64)
    geometry, bbox, extent = polygon_columns(pa, xy, ring_offsets, np.ones(len(triangles), bool))
    sites = pa.FixedSizeListArray.from_arrays(pa.array(triangles.ravel(), pa.int64()), 3)
    table = pa.table({"sites": sites, "geometry": geometry, "bbox": bbox})
    table = table.replace_schema_metadata({b"geo": geo_metadata(extent, ["Polygon"], crs)})
    write_table(pa, table, out, overwrite)
    return len(triangles)
