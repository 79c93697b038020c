"""Point files in: CSV, whitespace text, GeoJSON and .npy, read fast and checked line by line."""

from __future__ import annotations

import codecs
import os
import sys
from pathlib import Path

import orjson

from ..errors import InputFileError, TvoronoiError
from ..fileio import STDIO

# the column names recognised and the steps of a table read, reached through the
# package by the tests that hold the fast path of a table to the slow one
from .columns import X_NAMES, Y_NAMES  # noqa: F401
from .geojson_points import read_geojson
from .npy import NPY_MAGIC, read_npy
from .parquet import PARQUET_MAGIC, read_parquet
from .pointset import PointSet
from .tabular import COMMENT, fast_table, line_offset, read_table, slow_table, table_layout  # noqa: F401

__all__ = ["FORMATS", "PointSet", "read_points"]

FORMATS = ("csv", "text", "geojson", "npy", "parquet")
EXTENSIONS = {
    ".csv": "csv",
    ".tsv": "csv",
    ".tab": "csv",
    ".txt": "text",
    ".xy": "text",
    ".dat": "text",
    ".pts": "text",
    ".geojson": "geojson",
    ".json": "geojson",
    ".geojsons": "geojson",  # GeoJSON sequences (RFC 8142), as tvoronoi writes them
    ".geojsonseq": "geojson",
    ".geojsonl": "geojson",
    ".jsonl": "geojson",
    ".ndjson": "geojson",
    ".npy": "npy",
    ".parquet": "parquet",
    ".geoparquet": "parquet",
    ".pq": "parquet",
}
# the separator of a CSV file with this extension (others are found from the first rows)
DELIMITER_OF = {".tsv": "\t", ".tab": "\t"}
_GDAL = "ogr2ogr -f GeoJSON points.geojson {source} (GDAL), or geopandas: read_file(...).to_parquet(...)"
# formats that are not read, by their first bytes and by extension: (name, how to convert)
UNSUPPORTED_MAGIC = (
    (b"SQLite format 3\x00", "GeoPackage (SQLite database)", _GDAL),
    (b"\x00\x00\x27\x0a", "shapefile", _GDAL),
    (b"fgb\x03", "FlatGeobuf", _GDAL),
    (b"\x1f\x8b", "gzip-compressed", "gunzip -k {source}, or pipe it: gunzip -c {source} | tvoronoi batch - -o ..."),
    (
        b"PK\x03\x04",
        "zip archive",
        "unzip it and give the point file inside (a zipped shapefile converts directly: "
        "ogr2ogr -f GeoJSON points.geojson /vsizip/{source})",
    ),
)
UNSUPPORTED_EXTENSIONS = {
    ".gpkg": ("GeoPackage", _GDAL),
    ".shp": ("shapefile", _GDAL),
    ".shx": ("shapefile index", "give the .shp file to " + _GDAL),
    ".dbf": ("shapefile attribute table (dBASE)", "give the .shp file to " + _GDAL),
    ".fgb": ("FlatGeobuf", _GDAL),
    ".kml": ("KML", _GDAL),
    ".kmz": ("KMZ (zipped KML)", _GDAL),
    ".gml": ("GML", _GDAL),
    ".zip": UNSUPPORTED_MAGIC[-1][1:],
    ".gz": UNSUPPORTED_MAGIC[-2][1:],
    ".xlsx": ("Excel workbook", "save the sheet as CSV (File > Save As > CSV)"),
    ".xls": ("Excel workbook", "save the sheet as CSV (File > Save As > CSV)"),
    ".ods": ("OpenDocument spreadsheet", "save the sheet as CSV (File > Save As > CSV)"),
}
STDIN_SOURCE = "<stdin>"
SNIFF_BYTES = 1 << 16


def read_points(
    path: str | os.PathLike,
    *,
    x: str | int | None = None,
    y: str | int | None = None,
    fmt: str | None = None,
    delimiter: str | None = None,
) -> PointSet:
    """Read sites from a CSV, whitespace-text, GeoJSON, .npy or (Geo)Parquet file, or standard input.

    A GeoParquet file gives the points of its primary geometry column and its CRS;
    a plain Parquet file its x/y columns, chosen as a CSV file's are.

    Parameters
    ----------
    path : str or os.PathLike
        The file, or ``"-"`` for standard input.
    x, y : str or int, optional
        The coordinate columns of a table: a name (any case), a 0-based index
        (int or digit string) or ``"colN"`` (1-based). By default the columns
        named x/lon/lng/long/longitude and y/lat/latitude, else the first two
        numeric columns.
    fmt : {None, "csv", "text", "geojson", "npy", "parquet"}
        The format; ``None`` detects it from the extension, else from the content.
    delimiter : str, optional
        The field separator of a CSV file (one character); by default a tab for
        ``.tsv``, else the one of ",", ";", tab and "|" that splits the first rows
        evenly. In a ";"-separated file, coordinates may have a decimal comma.

    Returns
    -------
    PointSet
        The sites, with the other columns (or properties) of each.

    Raises
    ------
    InputFileError
        If the file is missing or unreadable, has no points, or holds a value that
        is not a finite coordinate, or is in a format tvoronoi does not read
        (GeoPackage, shapefile, zip, ...); the message names the file, the line
        (or the feature or row) and the fix.
    TvoronoiError
        If ``fmt`` is unknown, or ``x``/``y`` are given for a GeoJSON file.
    """
    if fmt is not None and fmt not in FORMATS:
        raise TvoronoiError(f"unknown format {fmt!r}; choose one of: {', '.join(FORMATS)}")
    if delimiter is not None and len(delimiter) != 1:
        raise TvoronoiError(f"--delimiter {delimiter!r}: give one character, e.g. ';' or '\\t'")
    source, suffix, data = _read_bytes(path)
    _refuse_unsupported(data, suffix if fmt is None else "", source)
    if fmt is None:
        fmt = EXTENSIONS.get(suffix) or _sniff_format(data)
    if delimiter is not None and fmt not in ("csv", "text"):
        raise TvoronoiError(f"{source}: --delimiter applies to CSV files, and this is read as {fmt}")
    if delimiter is not None or suffix in DELIMITER_OF:
        fmt = "csv"
        delimiter = delimiter or DELIMITER_OF[suffix]
    if fmt == "npy":
        return read_npy(data, source, x, y)
    if fmt == "parquet":
        return read_parquet(data, source, x, y)
    if fmt == "geojson":
        return read_geojson(data, source, x, y, _loads_json)
    text = _decode(data, source)
    # a UTF-8 file's bytes are the text's: the bulk readers take them rather than encode it again
    encoded = _utf8_of(data)
    del data  # other bytes are not needed once decoded (a large file is not held twice)
    return read_table(text, source, fmt, x, y, delimiter, encoded=encoded)


def _refuse_unsupported(data: bytes, suffix: str, source: str) -> None:
    """Name a format that is not read, and how to convert it, rather than fail on its bytes."""
    found = next(((name, how) for magic, name, how in UNSUPPORTED_MAGIC if data.startswith(magic)), None)
    if found is None:
        found = UNSUPPORTED_EXTENSIONS.get(suffix)
    if found is None and _is_binary(data):
        raise InputFileError(
            f"{source}: a binary file, not a point file; tvoronoi reads CSV, text, GeoJSON, .npy and "
            f"(Geo)Parquet: give one of those"
        )
    if found is not None:
        name, how = found
        if suffix in (".shx", ".dbf"):  # the conversion takes the shapefile's .shp, beside this part
            source_of = str(Path(source).with_suffix(".shp"))
        else:
            source_of = source
        raise InputFileError(
            f"{source}: a {name}, which tvoronoi does not read; convert it to GeoJSON, "
            f"GeoParquet or CSV first, e.g. {how.format(source=source_of)}"
        )


# ---------------------------------------------------------------------------
# bytes in, format detected, decoded


def _read_bytes(path) -> tuple[str, str, bytes]:
    """Return (source name, lower-case suffix, content) of a file or of standard input."""
    if isinstance(path, str) and path == STDIO:
        return STDIN_SOURCE, "", sys.stdin.buffer.read()
    try:
        source = os.fsdecode(os.fspath(path))
    except TypeError:
        raise TvoronoiError(f"a point file must be a path or '-', got {path!r}") from None
    p = Path(source)
    try:
        if p.is_dir():
            raise InputFileError(f"{source}: is a directory, not a point file; name a file inside it")
        data = p.read_bytes()
    except FileNotFoundError:
        raise InputFileError(f"{source}: no such file; check the name and the directory") from None
    except IsADirectoryError:
        raise InputFileError(f"{source}: is a directory, not a point file; name a file inside it") from None
    except PermissionError:
        raise InputFileError(f"{source}: permission denied; make the file readable (chmod +r)") from None
    except OSError as e:
        raise InputFileError(f"{source}: cannot read the file: {e.strerror or e}") from None
    return source, p.suffix.lower(), data


def _is_binary(data: bytes) -> bool:
    """Whether the first bytes hold a NUL and are not UTF-8 (nor UTF-16, .npy, Parquet): a binary file.

    A text file with a stray NUL is still text: the reader names the line that holds it.
    """
    head = data[:SNIFF_BYTES]
    if b"\x00" not in head or head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE, NPY_MAGIC, PARQUET_MAGIC)):
        return False
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as e:
        return e.start < len(head) - 4  # not a character cut at the end of the head
    return False


def _sniff_format(data: bytes) -> str:
    """Guess the format from the first bytes: npy magic, a JSON object, a comma or a semicolon (a
    spreadsheet's export, whose delimiter tabular.sniff_delimiter then finds), else text."""
    if data.startswith(NPY_MAGIC):
        return "npy"
    if data.startswith(PARQUET_MAGIC):
        return "parquet"
    head = _decode_lenient(data[:SNIFF_BYTES]).lstrip()
    if head.startswith("{"):
        return "geojson"
    for line in head.splitlines():
        line = line.strip()
        # a "#" line is a comment of a text file, whatever it holds
        if line and not line.startswith(COMMENT):
            return "csv" if "," in line or ";" in line else "text"
    return "text"


def _encoding(data: bytes) -> str:
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return "utf-16"
    return "utf-8-sig"


def _decode_lenient(data: bytes) -> str:
    return data.decode(_encoding(data), errors="replace")


def _decode(data: bytes, source: str) -> str:
    """Decode a text file (UTF-8, with or without BOM; UTF-16 with BOM)."""
    encoding = _encoding(data)
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as e:
        line = _line_of(data, e.start)
        name = "UTF-16" if encoding == "utf-16" else "UTF-8"
        raise InputFileError(
            f"{source}, line {line}: byte 0x{data[e.start]:02x} is not valid {name}; save the file as UTF-8"
        ) from None


def _utf8_of(data: bytes) -> bytes | None:
    """The UTF-8 bytes of the text :func:`_decode` made of ``data``: ``data`` itself without its
    byte order mark (decoding and encoding again gives the same bytes); None for UTF-16."""
    if _encoding(data) != "utf-8-sig":
        return None
    return data[len(codecs.BOM_UTF8) :] if data.startswith(codecs.BOM_UTF8) else data


def _loads_json(data: bytes, source: str):
    """Parse a JSON file (UTF-8, with or without BOM)."""
    if data.startswith(codecs.BOM_UTF8):
        data = data[len(codecs.BOM_UTF8) :]
    if data.lstrip(b" \t\r\n")[:1] == RECORD_SEPARATOR:
        return _loads_json_sequence(data, source)
    try:
        return orjson.loads(data)
    except orjson.JSONDecodeError as e:
        if e.msg == "unexpected content after document" and b"\n" in data[: e.pos]:
            # one document a line: GeoJSONSeq (.geojsonl, as tvoronoi and GDAL write it)
            return _loads_json_sequence(data, source)
        raise InputFileError(
            f"{source}, line {e.lineno}, column {e.colno}: broken JSON: {e.msg}; fix the file there"
        ) from None
    except UnicodeDecodeError as e:
        line = _line_of(data, e.start)
        raise InputFileError(f"{source}, line {line}: the file is not UTF-8; save it as UTF-8") from None


RECORD_SEPARATOR = b"\x1e"


def _loads_json_sequence(data: bytes, source: str) -> dict:
    """A GeoJSON text sequence (RFC 8142: RS before each text, or one text a line) as one
    FeatureCollection of its features; a FeatureCollection in the sequence gives its features."""
    features: list = []
    for number, line in enumerate(data.split(b"\n"), start=1):
        for text in line.split(RECORD_SEPARATOR):
            if not text.strip():
                continue
            try:
                doc = orjson.loads(text)
            except orjson.JSONDecodeError as e:
                raise InputFileError(
                    f"{source}, line {number}: broken JSON in a GeoJSON sequence: {e.msg}; fix the file there"
                ) from None
            except UnicodeDecodeError:
                raise InputFileError(f"{source}, line {number}: the file is not UTF-8; save it as UTF-8") from None
            if type(doc) is dict and doc.get("type") == "FeatureCollection" and type(doc.get("features")) is list:
                features.extend(doc["features"])
            else:
                features.append(doc)
    return {"type": "FeatureCollection", "features": features}


def _line_of(data: bytes, offset: int) -> int:
    """The 1-based line of the byte at ``offset``."""
    return data.count(b"\n", 0, offset) + 1
