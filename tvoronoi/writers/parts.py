"""Partitioned outputs: one part per task (GeoParquet or GeoJSONSeq) in a directory, and the dataset's metadata files."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import orjson

from tvoronoi.errors import TvoronoiError
from tvoronoi.writers.targets import open_output

# the dataset's metadata files, as Dask and Spark write them: pyarrow and geopandas read the directory
# (or ``_metadata`` alone) as one table
METADATA, COMMON_METADATA = "_metadata", "_common_metadata"
SUFFIXES = {"parquet": ".parquet", "geojsonseq": ".geojsonseq"}
RS = b"\x1e"


def prepare_directory(path) -> Path:
    """Create the output directory; refuse one that already holds files (nothing is overwritten)."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise TvoronoiError(f"{out}: exists and is not a directory; a distributed build writes a directory of parts")
    if out.is_dir() and any(out.iterdir()):
        raise TvoronoiError(f"{out}: the directory is not empty; choose a new directory or remove this one")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise TvoronoiError(f"{out}: cannot create the output directory ({exc.strerror})") from None
    return out


def remove_directory(path) -> None:
    """Remove what a failed build wrote: its parts and metadata files, then the directory if it is empty."""
    out = Path(path)
    for name in os.listdir(out) if out.is_dir() else ():
        if name.startswith("part-") or name in (METADATA, COMMON_METADATA):
            try:
                os.remove(out / name)
            except OSError:
                pass
    try:
        out.rmdir()
    except OSError:
        pass


def write_part(frame, geoms, directory, stem: str, format: str, crs=None) -> str:
    """Write one task's cells (a frame of ``site`` and properties, and the cells: shapely geometries or
    None); return the part's name.

    Returns "" for a task without rows (no empty part is written).
    """
    if len(frame) == 0:
        return ""
    name = stem + SUFFIXES[format]
    path = os.path.join(str(directory), name)
    if format == "parquet":
        _write_parquet_part(frame, geoms, path, crs)
    else:
        _write_geojsonseq_part(frame, geoms, path)
    return name


def write_cells_part(frame, diagram, rows: np.ndarray, directory, stem: str, crs=None) -> str:
    """Write one task's cells straight from its diagram as a GeoParquet part; return the part's name.

    ``frame`` holds ``site`` and the properties of the diagram's ``rows`` (ascending), a row each; a
    cell of fewer than three points (it misses the box, or a repeated point's) is a null geometry. The
    rings go to WKB a row group at a time (``writers.geoparquet.write_cell_rows``, as one process writes
    a whole diagram), never all at once. Returns "" for a task without rows (no empty part is written).
    """
    if len(frame) == 0:
        return ""
    from tvoronoi.writers.geojson_diagram import MIN_RING_POINTS
    from tvoronoi.writers.geoparquet import require_pyarrow, write_cell_rows

    pa = require_pyarrow()
    name = stem + SUFFIXES["parquet"]
    table = pa.Table.from_pandas(frame, preserve_index=False)
    columns = dict(zip(table.column_names, table.columns))
    present = np.diff(diagram.cell_offsets)[rows] >= MIN_RING_POINTS
    write_cell_rows(pa, os.path.join(str(directory), name), columns, diagram, rows, present, crs=crs, overwrite=False)
    return name


def write_triangles_part(triangles: np.ndarray, xy: np.ndarray, directory, stem: str, format: str, crs=None) -> str:
    """Write one task's Delaunay triangles ((k, 3) input rows, their places (k, 3, 2)); return the part's name.

    The columns are those of the whole-diagram writers: GeoParquet ``sites`` (three input rows),
    ``geometry``, ``bbox``; GeoJSONSeq features with ``"sites"``. Returns "" for a task without triangles.
    """
    if len(triangles) == 0:
        return ""
    name = stem + SUFFIXES[format]
    path = os.path.join(str(directory), name)
    closed = np.concatenate([xy, xy[:, :1]], axis=1)
    if format == "parquet":
        from tvoronoi.writers.geoparquet import geo_metadata, polygon_columns, require_pyarrow, write_table

        pa = require_pyarrow()
        ring_offsets = np.arange(0, 4 * len(triangles) + 1, 4, dtype=np.int64)
        geometry, bbox, extent = polygon_columns(
            pa, np.ascontiguousarray(closed.reshape(-1, 2)), ring_offsets, np.ones(len(triangles), bool)
        )
        sites = pa.FixedSizeListArray.from_arrays(pa.array(np.asarray(triangles, np.int64).ravel(), pa.int64()), 3)
        table = pa.table({"sites": sites, "geometry": geometry, "bbox": bbox})
        table = table.replace_schema_metadata({b"geo": geo_metadata(extent, ["Polygon"], crs)})
        write_table(pa, table, path, overwrite=False)
        return name
    with open_output(path, overwrite=False) as stream:
        for tri, ring in zip(np.asarray(triangles).tolist(), closed.tolist()):
            feature = {
                "type": "Feature",
                "geometry": {"type": "Polygon", "coordinates": [ring]},
                "properties": {"sites": tri},
            }
            stream.write(RS + orjson.dumps(feature) + b"\n")
    return name


def _write_parquet_part(frame, geoms, path: str, crs) -> None:
    from tvoronoi.writers.geoparquet import geo_metadata, require_pyarrow, shapely_cell_columns, write_table

    pa = require_pyarrow()
    geometry, bbox, extent, types = shapely_cell_columns(pa, geoms)
    table = pa.Table.from_pandas(frame, preserve_index=False)
    table = table.append_column("geometry", geometry).append_column("bbox", bbox)
    table = table.replace_schema_metadata({b"geo": geo_metadata(extent, types or ["Polygon"], crs)})
    write_table(pa, table, path, overwrite=False)


def _write_geojsonseq_part(frame, geoms: np.ndarray, path: str) -> None:
    names = list(frame.columns)
    columns = [frame[c].to_numpy() for c in names]
    with open_output(path, overwrite=False) as stream:
        for k, geom in enumerate(geoms):
            properties = {name: values[k] for name, values in zip(names, columns)}
            feature = {
                "type": "Feature",
                "geometry": None if geom is None else geom.__geo_interface__,
                "properties": properties,
            }
            try:
                stream.write(RS + orjson.dumps(feature, option=orjson.OPT_SERIALIZE_NUMPY) + b"\n")
            except orjson.JSONEncodeError as exc:
                raise TvoronoiError(
                    f"the properties of site {properties['site']} cannot be written as JSON: {exc}"
                ) from None


def finish_directory(directory, names: list[str], format: str, crs=None) -> None:
    """Write ``_metadata`` and ``_common_metadata`` over the GeoParquet parts (nothing for GeoJSONSeq).

    ``_common_metadata`` holds the schema with the ``geo`` metadata of the whole dataset (its bbox the
    union of the parts', its geometry types theirs); ``_metadata`` adds every part's row groups. Parts whose
    property columns came out with different types (a column all null in one part) cannot share one
    ``_metadata``: then only ``_common_metadata`` is written, and readers open the parts themselves.
    """
    if format != "parquet" or not names:
        return
    import pyarrow.parquet as pq

    from tvoronoi.writers.geoparquet import geo_metadata

    directory = str(directory)
    metas = [pq.read_metadata(os.path.join(directory, name)) for name in names]
    extent = None
    types: set[str] = set()
    for meta in metas:
        geo = orjson.loads(meta.metadata[b"geo"])["columns"]["geometry"]
        types.update(geo["geometry_types"])
        if "bbox" in geo:
            box = geo["bbox"]
            extent = (
                box
                if extent is None
                else [min(extent[0], box[0]), min(extent[1], box[1]), max(extent[2], box[2]), max(extent[3], box[3])]
            )
    schema = metas[0].schema.to_arrow_schema()
    schema = schema.with_metadata({b"geo": geo_metadata(extent, sorted(types), crs)})
    pq.write_metadata(schema, os.path.join(directory, COMMON_METADATA))
    if any(not meta.schema.equals(metas[0].schema) for meta in metas[1:]):
        return
    combined = None
    for name, meta in zip(names, metas):
        meta.set_file_path(name)
        if combined is None:
            combined = meta
        else:
            combined.append_row_groups(meta)
    pq.write_metadata(schema, os.path.join(directory, METADATA), metadata_collector=[combined])
