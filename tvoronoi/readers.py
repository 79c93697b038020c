"""Point files in: CSV, whitespace text, GeoJSON and .npy, read fast and checked line by line."""

from __future__ import annotations

import codecs
import csv
import gc
import io
import json
import math
import os
import re
import sys
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

import numpy as np

from .errors import InputFileError, TvoronoiError

__all__ = ["FORMATS", "PointSet", "read_points"]

FORMATS = ("csv", "text", "geojson", "npy")
EXTENSIONS = {
    ".csv": "csv",
    ".txt": "text",
    ".xy": "text",
    ".dat": "text",
    ".pts": "text",
    ".geojson": "geojson",
    ".json": "geojson",
    ".npy": "npy",
}
# column names recognised in any case, in order of preference
X_NAMES = ("x", "lon", "lng", "long", "longitude")
Y_NAMES = ("y", "lat", "latitude")
STDIN = "-"
STDIN_SOURCE = "<stdin>"
NPY_MAGIC = b"\x93NUMPY"
SNIFF_BYTES = 1 << 16
LAYOUT_CHARS = 1 << 16
QUOTE = '"'
COMMENT = "#"
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1
GEOMETRY_TYPES = (
    "Point",
    "MultiPoint",
    "LineString",
    "MultiLineString",
    "Polygon",
    "MultiPolygon",
    "GeometryCollection",
)
_INT_LITERAL = re.compile(r"[+-]?[0-9]+")
_FLOAT_LITERAL = re.compile(
    r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|nan|inf|infinity)", re.IGNORECASE
)
_COL_NAME = re.compile(r"col([0-9]+)", re.IGNORECASE)


@dataclass
class PointSet:
    """Sites read from a file, with the other columns (or GeoJSON properties) of each site.

    Attributes
    ----------
    xy : numpy.ndarray
        ``(n, 2)`` float64, C-contiguous; row ``i`` is site ``i``.
    source : str
        The file name as the user gave it, or ``"<stdin>"``.
    columns : dict of str to list
        Extra table columns, one list of ``n`` JSON-ready values per column
        (int, float, str or None), in file order.
    records : list of dict or None
        Per-site properties (GeoJSON); ``None`` when the sites carry them in
        ``columns`` or have none.
    """

    xy: np.ndarray
    source: str
    columns: dict[str, list] = field(default_factory=dict)
    records: list[dict] | None = None

    def __len__(self) -> int:
        return len(self.xy)

    @property
    def property_names(self) -> list[str]:
        """Names of the properties the sites carry, in file order (first seen first)."""
        if self.records is None:
            return list(self.columns)
        return list(dict.fromkeys(key for record in self.records for key in record))

    def properties(self, i: int) -> dict:
        """Properties of site ``i``: its row's other columns or its GeoJSON properties.

        Parameters
        ----------
        i : int
            Site index, ``-n <= i < n``.

        Returns
        -------
        dict
            A new dict of JSON-ready values; empty when the file had nothing but coordinates.

        Raises
        ------
        IndexError
            If ``i`` is out of range.
        """
        n_sites = len(self.xy)
        if not -n_sites <= i < n_sites:
            raise IndexError(f"site {i} out of range for {n_sites} sites")
        if self.records is not None:
            return dict(self.records[i])
        return {name: values[i] for name, values in self.columns.items()}


def read_points(
    path: str | os.PathLike,
    *,
    x: str | int | None = None,
    y: str | int | None = None,
    fmt: str | None = None,
) -> PointSet:
    """Read sites from a CSV, whitespace-text, GeoJSON or .npy file, or standard input.

    Parameters
    ----------
    path : str or os.PathLike
        The file, or ``"-"`` for standard input.
    x, y : str or int, optional
        The coordinate columns of a table: a name (any case), a 0-based index
        (int or digit string) or ``"colN"`` (1-based). By default the columns
        named x/lon/lng/long/longitude and y/lat/latitude, else the first two
        numeric columns.
    fmt : {None, "csv", "text", "geojson", "npy"}
        The format; ``None`` detects it from the extension, else from the content.

    Returns
    -------
    PointSet
        The sites, with the other columns (or properties) of each.

    Raises
    ------
    InputFileError
        If the file is missing or unreadable, has no points, or holds a value that
        is not a finite coordinate; the message names the file, the line (or the
        feature or row) and the fix.
    TvoronoiError
        If ``fmt`` is unknown, or ``x``/``y`` are given for a GeoJSON file.
    """
    if fmt is not None and fmt not in FORMATS:
        raise TvoronoiError(f"unknown format {fmt!r}; choose one of: {', '.join(FORMATS)}")
    source, suffix, data = _read_bytes(path)
    if fmt is None:
        fmt = EXTENSIONS.get(suffix) or _sniff_format(data)
    if fmt == "npy":
        return _read_npy(data, source, x, y)
    if fmt == "geojson":
        return _read_geojson(data, source, x, y)
    return _read_table(_decode(data, source), source, fmt, x, y)


# ---------------------------------------------------------------------------
# bytes in, format detected


def _read_bytes(path) -> tuple[str, str, bytes]:
    """Return (source name, lower-case suffix, content) of a file or of standard input."""
    if isinstance(path, str) and path == STDIN:
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


def _sniff_format(data: bytes) -> str:
    """Guess the format from the first bytes: npy magic, a JSON object, a comma, else text."""
    if data.startswith(NPY_MAGIC):
        return "npy"
    head = _decode_lenient(data[:SNIFF_BYTES]).lstrip()
    if head.startswith("{"):
        return "geojson"
    for line in head.splitlines():
        line = line.strip()
        # a "#" line is a comment of a text file, whatever it holds
        if line and not line.startswith(COMMENT):
            return "csv" if "," in line else "text"
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
        line = data.count(b"\n", 0, e.start) + 1
        name = "UTF-16" if encoding == "utf-16" else "UTF-8"
        raise InputFileError(
            f"{source}, line {line}: byte 0x{data[e.start]:02x} is not valid {name}; save the file as UTF-8"
        ) from None


# ---------------------------------------------------------------------------
# tables: CSV and whitespace text


@dataclass(frozen=True)
class _Layout:
    """Where the sites are in a table: its column names and the x and y columns."""

    names: list[str]  # one per column: the header's, or col1, col2, ...
    has_header: bool
    header_lines: int  # physical lines up to the end of the header (0 without one)
    first_line: int  # line of the first data row
    ix: int
    iy: int


def _read_table(text: str, source: str, kind: str, x, y) -> PointSet:
    # the header and the first data row are near the top: look there first, so that
    # a large file is not scanned for them
    head = text
    if len(text) > LAYOUT_CHARS:
        head = text[: text.find("\n", LAYOUT_CHARS) + 1] or text
    try:
        layout = _table_layout(head, source, kind, x, y)
    except InputFileError:
        if head is text:
            raise
        head = text
        layout = _table_layout(text, source, kind, x, y)
    body = text[_line_offset(head, layout.header_lines) :]
    try:
        fast = _fast_table(body, kind, layout)
    except (ValueError, csv.Error):
        fast = None
    if fast is None:
        # the fast path met something it does not handle or a bad value: walk the
        # file row by row, which either reads it or names the first bad line
        return _slow_table(text, source, kind, layout)
    xy, columns = fast
    return PointSet(xy, source, columns)


def _records(text: str, kind: str, source: str) -> Iterator[tuple[int, list[str]]]:
    """Yield (line number, fields) for each non-blank row of a table; line numbers are 1-based."""
    if kind == "text":
        for line_no, line in enumerate(io.StringIO(text, newline=""), 1):
            fields = line.partition(COMMENT)[0].split()
            if fields:
                yield line_no, fields
        return
    reader = csv.reader(io.StringIO(text, newline=""))
    start = 1
    try:
        for fields in reader:
            line_no, start = start, reader.line_num + 1
            if len(fields) > 1 or (fields and fields[0].strip()):
                yield line_no, fields
    except csv.Error as e:
        raise InputFileError(f"{source}, line {start}: malformed CSV: {e}") from None


def _is_blank(fields: list[str]) -> bool:
    return not fields or (len(fields) == 1 and not fields[0].strip())


def _line_offset(text: str, n_lines: int) -> int:
    """Character offset of the start of line ``n_lines + 1``."""
    offset = 0
    lines = io.StringIO(text, newline="")
    for _ in range(n_lines):
        offset += len(lines.readline())
    return offset


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _table_layout(text: str, source: str, kind: str, x, y) -> _Layout:
    """Find the header (if any), the column names and the x and y columns from the first rows."""
    records = _records(text, kind, source)
    first = next(records, None)
    if first is None:
        why = "the file is empty" if not text.strip() else "the file has no data rows"
        raise InputFileError(f"{source}: no points found ({why})")
    line_no, fields = first
    has_header = _is_header(fields, x, y, records)
    if has_header:
        names = _unique_names([f.strip() for f in fields])
        header_lines = _header_end(text, kind, source)
        records = _records(text, kind, source)
        next(records)
        data = next(records, None)
        if data is None:
            raise InputFileError(f"{source}: no points found (the file has only a header, line {line_no})")
        first_line, first_fields = data
    else:
        names = [f"col{j + 1}" for j in range(len(fields))]
        header_lines, first_line, first_fields = 0, line_no, fields
    ix = _resolve_column(x, "x", names, has_header, source)
    iy = _resolve_column(y, "y", names, has_header, source)
    if ix is None or iy is None:
        # the first numeric columns of the first data row that are not taken
        free = [
            j
            for j, f in enumerate(first_fields[: len(names)])
            if j not in (ix, iy) and _is_number(f)
        ]
        if ix is None and free:
            ix = free.pop(0)
        if iy is None and free:
            iy = free.pop(0)
    if ix is None or iy is None:
        missing = " and ".join(role for role, i in (("x", ix), ("y", iy)) if i is None)
        noun = "columns" if ix is None and iy is None else "column"
        raise InputFileError(
            f"{source}, line {first_line}: cannot find the {missing} {noun}: no header names it "
            f"and the row has too few numeric columns; columns: {', '.join(names)}; "
            f"choose them with --x/--y"
        )
    if ix == iy:
        raise TvoronoiError(f'{source}: x and y are the same column "{names[ix]}"; choose two columns')
    return _Layout(names, has_header, header_lines, first_line, ix, iy)


def _is_header(fields: list[str], x, y, records: Iterator[tuple[int, list[str]]]) -> bool:
    """Whether the first row ``fields`` is a header: a row whose x/y candidates are not numbers.

    The candidates are the columns chosen by index, else the row's first two numeric fields
    (fewer than two: a header), else the fields named like a coordinate column. A data row
    can hold such a name as a value ("1,2,lat"): then the row is a header only if the next
    row has a number where it has the name ("x,y,2019" over "1,2,7").
    """
    numeric = [_is_number(f) for f in fields]
    lowered = [f.strip().lower() for f in fields]
    chosen = [s.strip().lower() for s in (x, y) if isinstance(s, str) and _as_index(s) is None]
    if any(name in lowered for name in chosen):
        return True
    explicit = [i for i in (_as_index(x), _as_index(y)) if i is not None and i < len(fields)]
    if any(not numeric[i] for i in explicit) or sum(numeric) < 2:
        return True
    named = [j for j, name in enumerate(lowered) if name in X_NAMES + Y_NAMES and not numeric[j]]
    if not named:
        return False
    second = next(records, None)
    return second is not None and any(j < len(second[1]) and _is_number(second[1][j]) for j in named)


def _header_end(text: str, kind: str, source: str) -> int:
    """Number of physical lines up to the end of the first non-blank row (the header)."""
    if kind == "text":
        return next(_records(text, kind, source))[0]
    reader = csv.reader(io.StringIO(text, newline=""))
    for fields in reader:
        if not _is_blank(fields):
            return reader.line_num
    return 0


def _unique_names(names: list[str]) -> list[str]:
    """Header names made unique and non-empty: an empty name becomes colN, a repeat name_2."""
    out: list[str] = []
    seen: set[str] = set()
    for j, name in enumerate(names):
        name = name or f"col{j + 1}"
        base, k = name, 2
        while name in seen:
            name, k = f"{base}_{k}", k + 1
        seen.add(name)
        out.append(name)
    return out


def _as_index(sel) -> int | None:
    """A 0-based column index given as an int or a digit string, else None."""
    if isinstance(sel, (int, np.integer)) and not isinstance(sel, bool):
        return int(sel)
    if isinstance(sel, str) and sel.strip().isdigit() and sel.strip().isascii():
        return int(sel.strip())
    return None


def _resolve_column(sel, role: str, names: list[str], by_name: bool, source: str) -> int | None:
    """Index of the column ``sel`` chooses for ``role``; with ``sel=None``, the column named like it."""
    n_cols = len(names)
    listing = ", ".join(f"{j}:{name}" for j, name in enumerate(names))
    if sel is None:
        if not by_name:
            return None
        for candidate in X_NAMES if role == "x" else Y_NAMES:
            exact = [j for j, name in enumerate(names) if name == candidate]
            loose = [j for j, name in enumerate(names) if name.lower() == candidate]
            if exact or loose:
                return (exact or loose)[0]
        return None
    if isinstance(sel, str):
        key = sel.strip()
        for j, name in enumerate(names):
            if name == key:
                return j
        for j, name in enumerate(names):
            if name.lower() == key.lower():
                return j
        match = _COL_NAME.fullmatch(key)
        if match and 1 <= int(match.group(1)) <= n_cols:
            return int(match.group(1)) - 1
    index = _as_index(sel)
    if index is None and not isinstance(sel, str):
        raise TvoronoiError(f"--{role} must be a column name or a 0-based index, got {sel!r}")
    if index is not None and 0 <= index < n_cols:
        return index
    what = f"column {sel}" if index is not None else f'column "{sel}"'
    raise InputFileError(
        f"{source}: no {what} for {role}; the file has {n_cols} columns (index:name): {listing}"
    )


@contextmanager
def _gc_paused():
    """Pause the cyclic garbage collector: building a million small row lists otherwise
    triggers it over and over, for nothing (rows hold no cycles)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _fast_table(body: str, kind: str, layout: _Layout):
    """Read the rows after the header in bulk; None (or ValueError) when a row needs a closer look."""
    names, ix, iy = layout.names, layout.ix, layout.iy
    n_cols = len(names)
    if n_cols == 2:
        # only coordinates: numpy's C reader, which also checks every row has two fields
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if kind == "csv":
                table = np.loadtxt(
                    io.StringIO(body), dtype=np.float64, delimiter=",", quotechar=QUOTE,
                    comments=None, ndmin=2,
                )
            else:
                table = np.loadtxt(io.StringIO(body), dtype=np.float64, comments=COMMENT, ndmin=2)
        if table.shape[1] != 2 or len(table) == 0:
            return None
        xy = np.ascontiguousarray(table[:, [ix, iy]] if ix else table)
        return (xy, {}) if np.isfinite(xy).all() else None
    with _gc_paused():
        if kind == "csv":
            rows = list(csv.reader(io.StringIO(body, newline="")))
        else:
            if "\r" in body and "\r" in body.replace("\r\n", ""):
                return None  # a line ending in a lone CR (old Mac): the row walk splits there
            lines = body.split("\n")
            if COMMENT in body:
                lines = [line.partition(COMMENT)[0] for line in lines]
            rows = list(map(str.split, lines))
        if set(map(len, rows)) != {n_cols}:
            # blank lines (csv gives [] or a lone blank field, text gives [])
            rows = [r for r in rows if not _is_blank(r)]
            if not rows or set(map(len, rows)) != {n_cols}:
                return None
        columns = list(zip(*rows))
        del rows
    xy = np.empty((len(columns[0]), 2), dtype=np.float64)
    xy[:, 0] = np.fromiter(map(float, columns[ix]), dtype=np.float64, count=len(xy))
    xy[:, 1] = np.fromiter(map(float, columns[iy]), dtype=np.float64, count=len(xy))
    if not np.isfinite(xy).all():
        return None
    plain = body.isascii() and "_" not in body
    extras = {names[j]: _convert_column(columns[j], plain) for j in range(n_cols) if j not in (ix, iy)}
    return xy, extras


def _slow_table(text: str, source: str, kind: str, layout: _Layout) -> PointSet:
    """Read a table row by row, keeping line numbers, and raise on the first row that is not a site."""
    names, ix, iy = layout.names, layout.ix, layout.iy
    n_cols = len(names)
    records = _records(text, kind, source)
    if layout.has_header:
        next(records)
    line_nos: list[int] = []
    rows: list[list[str]] = []
    with _gc_paused():
        for line_no, fields in records:
            if len(fields) != n_cols:
                # a field spanning lines is quoted: an unclosed quote swallows the lines after it
                unclosed = any("\n" in f or "\r" in f for f in fields)
                hint = " (a quote opened here is not closed)" if unclosed else ""
                raise InputFileError(
                    f"{source}, line {line_no}: {_plural(len(fields), 'field')}{hint}, "
                    f"but {_row_shape(layout)}; give every row the same {n_cols} columns"
                )
            line_nos.append(line_no)
            rows.append(fields)
        columns = list(zip(*rows))
        del rows
    xy = np.empty((len(line_nos), 2), dtype=np.float64)
    xy[:, 0] = _floats_or_nan(columns[ix])
    xy[:, 1] = _floats_or_nan(columns[iy])
    bad = np.flatnonzero(~np.isfinite(xy).all(axis=1))
    if len(bad):
        # the first bad row: x is checked before y, as it reads
        r = bad[0]
        for j, role in ((ix, "x"), (iy, "y")):
            _coordinate(columns[j][r], role, names[j], line_nos[r], source, layout.has_header)
    plain = text.isascii() and "_" not in text
    extras = {names[j]: _convert_column(columns[j], plain) for j in range(n_cols) if j not in (ix, iy)}
    return PointSet(xy, source, extras)


def _floats_or_nan(values) -> np.ndarray:
    """``float`` over a column, NaN where a value is not a number."""
    try:
        return np.fromiter(map(float, values), dtype=np.float64, count=len(values))
    except ValueError:
        return np.array([_float_or_nan(v) for v in values], dtype=np.float64)


def _float_or_nan(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def _quoted(text: str) -> str:
    """A field as it reads in a message: in double quotes, control characters escaped."""
    return json.dumps(text, ensure_ascii=False)


def _plural(count: int, noun: str) -> str:
    return f"{count} {noun}" if count == 1 else f"{count} {noun}s"


def _row_shape(layout: _Layout) -> str:
    n_cols = len(layout.names)
    if layout.has_header:
        return f"the header has {n_cols} ({', '.join(layout.names)})"
    return f"the first row (line {layout.first_line}) has {n_cols}"


def _coordinate(text: str, role: str, name: str, line_no: int, source: str, named: bool) -> float:
    column = f'column "{name}"' if name == role else f'column "{name}" ({role})'
    try:
        value = float(text)
    except ValueError:
        raise InputFileError(
            f"{source}, line {line_no}: {_quoted(text)} in {column} is not a number; "
            f"fix the value, or choose other columns with --x/--y"
        ) from None
    if not math.isfinite(value):
        who = role if name == role or not named else f'{role} (column "{name}")'
        shown = text.strip()
        if shown.lower().lstrip("+-") not in ("nan", "inf", "infinity"):
            shown += " (it overflows to infinity)"
        raise InputFileError(
            f"{source}, line {line_no}: {who} is {shown}; tvoronoi needs finite coordinates"
        )
    return value


def _convert_value(s: str):
    """A property value: int for an int literal, float for a float literal, None for "" or a
    non-finite number (JSON has none), else the string as written."""
    t = s.strip()
    if not t:
        return None
    if _INT_LITERAL.fullmatch(t):
        value = int(t)
        # beyond 64 bits most JSON writers fail: keep the digits as text
        return value if INT64_MIN <= value <= INT64_MAX else s
    if _FLOAT_LITERAL.fullmatch(t):
        value = float(t)
        return value if math.isfinite(value) else None
    return s


def _convert_column(values, plain: bool) -> list:
    """``_convert_value`` over a column; ``plain`` (ASCII, no "_") lets int() and float() decide in bulk,
    since on such text they accept exactly the literals the regexes describe."""
    if plain:
        try:
            ints = list(map(int, values))
        except ValueError:
            pass
        else:
            if not ints or (INT64_MIN <= min(ints) and max(ints) <= INT64_MAX):
                return ints
        try:
            floats = np.fromiter(map(float, values), dtype=np.float64, count=len(values))
        except ValueError:
            pass
        else:
            if np.isfinite(floats).all():
                # float literals keep the parsed float, int literals go back through _convert_value
                return [
                    f if ("." in v or "e" in v or "E" in v) else _convert_value(v)
                    for v, f in zip(values, floats.tolist())
                ]
    # mixed or text: convert each distinct value once
    memo = {v: _convert_value(v) for v in set(values)}
    return list(map(memo.__getitem__, values))


# ---------------------------------------------------------------------------
# GeoJSON


def _loads_json(data: bytes, source: str):
    if data.startswith(codecs.BOM_UTF8):
        data = data[len(codecs.BOM_UTF8) :]
    try:
        import orjson
    except ImportError:  # orjson is a dependency; json is the stand-in
        loads = json.loads
    else:
        loads = orjson.loads
    try:
        return loads(data)
    except json.JSONDecodeError as e:  # orjson's error derives from it
        raise InputFileError(
            f"{source}, line {e.lineno}, column {e.colno}: broken JSON: {e.msg}; fix the file there"
        ) from None
    except UnicodeDecodeError as e:
        line = data.count(b"\n", 0, e.start) + 1
        raise InputFileError(f"{source}, line {line}: the file is not UTF-8; save it as UTF-8") from None


def _describe(value) -> str:
    if isinstance(value, dict):
        return f'an object of type "{value["type"]}"' if "type" in value else "an object without a type"
    return {list: "a list", str: "a string", bool: "a boolean", type(None): "null"}.get(
        type(value), "a number"
    )


def _geojson_sites(doc, source: str):
    """Yield (where, part, position, properties) for each site of a GeoJSON document.

    ``where`` names the feature ("features[3]"), ``part`` is the index within a MultiPoint
    (None for a Point); the position is checked to be a list of at least two numbers.
    """
    kind = doc.get("type") if isinstance(doc, dict) else None
    if kind == "FeatureCollection":
        features = doc.get("features")
        if not isinstance(features, list):
            raise InputFileError(f'{source}: the FeatureCollection has no "features" list')
        labelled = ((f"features[{k}]", feature) for k, feature in enumerate(features))
    elif kind == "Feature":
        labelled = iter([("the feature", doc)])
    elif kind in ("Point", "MultiPoint"):
        labelled = iter([("the geometry", {"type": "Feature", "geometry": doc, "properties": None})])
    elif kind in GEOMETRY_TYPES:
        raise InputFileError(
            f'{source}: the file is a single {kind} geometry; tvoronoi reads Point and MultiPoint geometries'
        )
    else:
        raise InputFileError(
            f"{source}: not GeoJSON: expected a FeatureCollection, a Feature or a Point/MultiPoint "
            f"geometry, found {_describe(doc)}"
        )
    for where, feature in labelled:
        if not isinstance(feature, dict):
            raise InputFileError(f"{source}, {where}: not a Feature object but {_describe(feature)}")
        properties = feature.get("properties")
        if properties is None:
            properties = {}
        elif not isinstance(properties, dict):
            raise InputFileError(
                f'{source}, {where}: "properties" is {_describe(properties)}; it must be an object or null'
            )
        geometry = feature.get("geometry")
        if geometry is None:
            raise InputFileError(
                f"{source}, {where}: the geometry is null; tvoronoi reads Point and MultiPoint "
                f"features: give the feature a point or remove it"
            )
        kind = geometry.get("type") if isinstance(geometry, dict) else _describe(geometry)
        coordinates = geometry.get("coordinates") if isinstance(geometry, dict) else None
        if kind == "Point":
            yield where, None, _position(coordinates, source, where), properties
        elif kind == "MultiPoint":
            if not isinstance(coordinates, list):
                raise InputFileError(
                    f"{source}, {where}: MultiPoint coordinates are {_describe(coordinates)}, not a list of positions"
                )
            for part, position in enumerate(coordinates):
                yield where, part, _position(position, source, f"{where}, point {part}"), properties
        else:
            raise InputFileError(
                f'{source}, {where}: geometry type "{kind}" is not a point; tvoronoi reads Point and '
                f"MultiPoint features: convert it (e.g. to its centroid) or remove it"
            )


_NUMBER_TYPES = (int, float)


def _position(position, source: str, where: str):
    if (
        type(position) is list
        and len(position) >= 2
        and type(position[0]) in _NUMBER_TYPES
        and type(position[1]) in _NUMBER_TYPES
    ):
        return position
    raise InputFileError(
        f"{source}, {where}: coordinates {position!r} are not a position; a point needs [x, y] numbers"
    )


def _point_features(features: list):
    """(xs, ys, properties) of a list of well-formed Point features, or None at the first
    feature that is anything else (the checked walk then reads or names it)."""
    xs: list = []
    ys: list = []
    records: list[dict] = []
    try:
        for feature in features:
            geometry = feature["geometry"]
            properties = feature["properties"]
            if geometry["type"] != "Point":
                return None
            position = geometry["coordinates"]
            x, y = position[0], position[1]
            if type(position) is not list or type(x) not in _NUMBER_TYPES or type(y) not in _NUMBER_TYPES:
                return None
            if properties is None:
                properties = {}
            elif type(properties) is not dict:
                return None
            xs.append(x)
            ys.append(y)
            records.append(properties)
    except (KeyError, TypeError, IndexError):
        return None
    return xs, ys, records


def _checked_sites(doc, source: str):
    """(xs, ys, properties) of any GeoJSON document, each feature checked."""
    xs: list = []
    ys: list = []
    records: list[dict] = []
    for _, part, position, properties in _geojson_sites(doc, source):
        xs.append(position[0])
        ys.append(position[1])
        records.append(properties if part is None else {**properties, "part": part})
    return xs, ys, records


def _read_geojson(data: bytes, source: str, x, y) -> PointSet:
    if x is not None or y is not None:
        raise TvoronoiError(
            f"{source}: --x/--y choose table columns; a GeoJSON file keeps its coordinates "
            f"in its geometries: drop --x/--y"
        )
    if not data.strip():
        raise InputFileError(f"{source}: no points found (the file is empty)")
    # a million features are a million dicts: the collector would walk them again and again
    with _gc_paused():
        doc = _loads_json(data, source)
        sites = None
        if type(doc) is dict and doc.get("type") == "FeatureCollection" and type(doc.get("features")) is list:
            sites = _point_features(doc["features"])
        if sites is None:
            sites = _checked_sites(doc, source)
    xs, ys, records = sites
    if not xs:
        raise InputFileError(f"{source}: no points found (no Point or MultiPoint features)")
    xy = np.empty((len(xs), 2), dtype=np.float64)
    try:
        xy[:, 0] = xs
        xy[:, 1] = ys
    except OverflowError:  # an integer beyond float range
        xy[:, 0] = [float(v) if abs(v) < 1e308 else math.inf for v in xs]
        xy[:, 1] = [float(v) if abs(v) < 1e308 else math.inf for v in ys]
    bad = np.flatnonzero(~np.isfinite(xy).all(axis=1))
    if len(bad):
        for i, (where, part, position, _) in enumerate(_geojson_sites(doc, source)):
            if i == bad[0]:
                break
        if part is not None:
            where = f"{where}, point {part}"
        role = "x" if not math.isfinite(xy[bad[0], 0]) else "y"
        raise InputFileError(
            f"{source}, {where}: {role} is {position[0 if role == 'x' else 1]}; tvoronoi needs finite coordinates"
        )
    return PointSet(xy, source, {}, records if any(records) else None)


# ---------------------------------------------------------------------------
# .npy


def _read_npy(data: bytes, source: str, x, y) -> PointSet:
    if not data:
        raise InputFileError(f"{source}: no points found (the file is empty)")
    if not data.startswith(NPY_MAGIC):
        raise InputFileError(
            f"{source}: not a .npy file (it does not start with the .npy magic bytes); "
            f"save the array with numpy.save, or give the right format"
        )
    try:
        array = np.load(io.BytesIO(data), allow_pickle=False)
    except ValueError as e:
        if "allow_pickle" in str(e) or "Object arrays" in str(e):
            raise InputFileError(
                f"{source}: the array holds Python objects (dtype object), which tvoronoi does not load; "
                f"save a float array of shape (n, 2)"
            ) from None
        raise InputFileError(f"{source}: broken .npy file: {e}") from None
    except (OSError, EOFError) as e:
        raise InputFileError(f"{source}: broken .npy file: {e}") from None
    if array.dtype.names is not None:
        return _structured_npy(array, source, x, y)
    if array.dtype.kind not in "iuf":
        raise InputFileError(
            f"{source}: dtype {array.dtype} is not a number type; save a float or int array of shape (n, 2)"
        )
    if array.ndim != 2 or array.shape[1] < 2:
        raise InputFileError(
            f"{source}: shape {array.shape}; tvoronoi needs (n, 2) (or (n, k) with k >= 2, x and y first)"
        )
    if len(array) == 0:
        raise InputFileError(f"{source}: no points found (the array has 0 rows)")
    names = [f"col{j + 1}" for j in range(array.shape[1])]
    ix = _resolve_column(x, "x", names, False, source)
    iy = _resolve_column(y, "y", names, False, source)
    free = [j for j in range(len(names)) if j not in (ix, iy)]
    ix = free.pop(0) if ix is None else ix
    iy = free.pop(0) if iy is None else iy
    if ix == iy:
        raise TvoronoiError(f'{source}: x and y are the same column "{names[ix]}"; choose two columns')
    xy = np.ascontiguousarray(array[:, [ix, iy]], dtype=np.float64)
    _check_finite_rows(xy, source)
    columns = {names[j]: _json_column(array[:, j]) for j in range(array.shape[1]) if j not in (ix, iy)}
    return PointSet(xy, source, columns)


def _structured_npy(array: np.ndarray, source: str, x, y) -> PointSet:
    if array.ndim != 1:
        raise InputFileError(f"{source}: a structured array of shape {array.shape}; tvoronoi needs shape (n,)")
    names = list(array.dtype.names)
    ix = _resolve_column(x, "x", names, True, source)
    iy = _resolve_column(y, "y", names, True, source)
    if ix is None or iy is None:
        free = [j for j, name in enumerate(names) if j not in (ix, iy) and array.dtype[name].kind in "iuf"]
        ix = free.pop(0) if ix is None and free else ix
        iy = free.pop(0) if iy is None and free else iy
    if ix is None or iy is None:
        raise InputFileError(
            f"{source}: cannot find the x and y fields among {', '.join(names)}; choose them with --x/--y"
        )
    if ix == iy:
        raise TvoronoiError(f'{source}: x and y are the same field "{names[ix]}"; choose two fields')
    for j in (ix, iy):
        if array.dtype[names[j]].kind not in "iuf" or array.dtype[names[j]].shape:
            raise InputFileError(
                f'{source}: field "{names[j]}" has dtype {array.dtype[names[j]]}, not a number; '
                f"choose numeric fields with --x/--y"
            )
    if len(array) == 0:
        raise InputFileError(f"{source}: no points found (the array has 0 rows)")
    xy = np.empty((len(array), 2), dtype=np.float64)
    xy[:, 0] = array[names[ix]]
    xy[:, 1] = array[names[iy]]
    _check_finite_rows(xy, source)
    columns = {names[j]: _json_column(array[names[j]]) for j in range(len(names)) if j not in (ix, iy)}
    return PointSet(xy, source, columns)


def _check_finite_rows(xy: np.ndarray, source: str) -> None:
    finite = np.isfinite(xy)
    if finite.all():
        return
    i, k = np.argwhere(~finite)[0]
    raise InputFileError(
        f"{source}, row {i} (0-based): {'xy'[k]} is {xy[i, k]}; tvoronoi needs finite coordinates"
    )


def _json_column(values: np.ndarray) -> list:
    """A numpy column as JSON-ready Python values: NaN/inf become None, bytes are decoded."""
    kind = values.dtype.kind
    if values.ndim == 1 and kind in "iubU":
        return values.tolist()
    if values.ndim == 1 and kind == "f":
        out = values.tolist()
        for i in np.flatnonzero(~np.isfinite(values)):
            out[i] = None
        return out
    return [_json_value(v) for v in values.tolist()]


def _json_value(value):
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, bytes):
        return value.decode("utf-8", errors="replace")
    if isinstance(value, (list, tuple)):
        return [_json_value(v) for v in value]
    return str(value)
