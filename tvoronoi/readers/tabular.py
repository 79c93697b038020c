"""CSV and whitespace-text tables: header, x and y columns, a fast bulk read, a line-by-line check."""

from __future__ import annotations

import csv
import io
import json
import math
import sys
import warnings
from dataclasses import dataclass
from typing import Iterator

import numpy as np

from tvoronoi.arrow_arrays import float64_values
from tvoronoi.fileio import gc_paused

from ..errors import InputFileError
from .bulk_csv import bulk_columns, typed_packed_column
from .columns import (
    LAT_NAMES,
    LON_NAMES,
    X_NAMES,
    Y_NAMES,
    as_index,
    check_distinct,
    col_name,
    describe_choice,
    is_id_like,
    resolve_column,
)
from .pointset import PointSet, convert_column
from .text_column import TextColumn

LAYOUT_CHARS = 1 << 16
# a table text up to this size is kept to name the line of a site in a later message
KEEP_TEXT_CHARS = 8 << 20
QUOTE = '"'
COMMENT = "#"
# field separators a CSV file may use, in order of preference when several fit
DELIMITERS = (",", ";", "\t", "|")
# rows the separator is guessed from
SNIFF_ROWS = 20
# a CSV text at least this long is read by pyarrow's reader when pyarrow is loaded
ARROW_MIN_CHARS = 1 << 20


@dataclass(frozen=True)
class _Layout:
    """Where the sites are in a table: its column names and the x and y columns."""

    names: list[str]  # one per column: the header's, or col1, col2, ...
    has_header: bool
    header_lines: int  # physical lines up to the end of the header (0 without one)
    first_line: int  # line of the first data row
    ix: int
    iy: int
    delimiter: str = ","  # of a CSV file
    choice: str | None = None  # which columns became x and y and why, when the caller chose neither
    candidates: tuple[str, ...] = ()  # the numeric columns, when x and y were taken by position among more


def read_table(
    text: str, source: str, kind: str, x, y, delimiter: str | None = None, *, encoded: bytes | None = None
) -> PointSet:
    """The sites and columns of a CSV or text table; ``encoded``: the text's UTF-8 bytes, when the
    caller has them (the bulk readers work on bytes)."""
    # the header and the first data row are near the top: look there first, so that
    # a large file is not scanned for them
    head = text
    if len(text) > LAYOUT_CHARS:
        head = text[: text.find("\n", LAYOUT_CHARS) + 1] or text
    if kind == "csv" and delimiter is None:
        delimiter = sniff_delimiter(head)
    try:
        layout = table_layout(head, source, kind, x, y, delimiter or ",")
    except InputFileError:
        if head is text:
            raise
        head = text
        layout = table_layout(text, source, kind, x, y, delimiter or ",")
    offset = line_offset(head, layout.header_lines)
    try:
        # CSV in bulk, from the text as it is (no copy of the rows); else the other fast paths
        fast = _bulk_table(text, offset, layout, encoded) if kind == "csv" else None
        if fast is None:
            fast = fast_table(text[offset:], kind, layout, bulk=False)
    except (ValueError, csv.Error):
        fast = None
    if fast is None:
        # the fast path met something it does not handle or a bad value: walk the
        # file row by row, which either reads it or names the first bad line
        points = slow_table(text, source, kind, layout)
    else:
        points = PointSet(fast[0], source, fast[1])
        points.where = _fast_lines(text, offset, source, kind, layout, len(points))
    if points.where is not None:
        points.where = _line_label(points.where)
    if layout.delimiter == ";":
        _decimal_comma_columns(points.columns)
    names = [name.strip().lower() for name in (layout.names[layout.ix], layout.names[layout.iy])]
    points.lonlat = layout.has_header and names[0] in LON_NAMES and names[1] in LAT_NAMES
    points.choice = layout.choice
    points.xy_columns = (layout.names[layout.ix], layout.names[layout.iy])
    points.candidates = layout.candidates
    return points


def _fast_lines(text: str, offset: int, source: str, kind: str, layout: _Layout, n_rows: int):
    """The line of each row, as a function of the row, for messages about a site.

    When every row is one line (no blank line, comment or field over lines) it is
    arithmetic; else a walk of the rows, kept only for a text of up to KEEP_TEXT_CHARS
    (a large text is not held for a message: None, and rows are named by index).
    ``offset`` is where the rows start in ``text``.
    """
    breaks = text.count("\n", offset)
    lone_cr = text.find("\r", offset) >= 0 and "\r" in text[offset:].replace("\r\n", "")
    if not lone_cr and breaks - (0 if text.endswith("\n") or len(text) == offset else -1) == n_rows:
        first = layout.first_line
        return lambda i: first + i
    if len(text) > KEEP_TEXT_CHARS:
        return None

    def line_of(i: int) -> int:
        records = _records(text, kind, source, layout.delimiter)
        if layout.has_header:
            next(records, None)
        for k, (line_no, _) in enumerate(records):
            if k == i:
                return line_no
        raise IndexError(i)

    return line_of


def _line_label(line_of):
    return lambda i: f"line {int(line_of(i))}"


def sniff_delimiter(head: str) -> str:
    """The separator of a CSV file from its first rows: the one that splits them all into the
    same number of fields (at least two), the most fields first; "," when none does.

    >>> sniff_delimiter("x;y\n1,5;2,25\n")
    ';'
    """
    lines = [line for line in head.splitlines() if line.strip() and not line.startswith(COMMENT)][:SNIFF_ROWS]
    if len(lines) > 1 and not head.endswith(("\n", "\r")) and len(head) >= LAYOUT_CHARS:
        lines = lines[:-1]  # cut off mid-line
    best, best_fields = ",", 1
    for delimiter in DELIMITERS:
        try:
            counts = {len(row) for row in csv.reader(lines, delimiter=delimiter)}
        except csv.Error:
            continue
        if len(counts) == 1 and (fields := counts.pop()) > best_fields:
            best, best_fields = delimiter, fields
    return best


# ---------------------------------------------------------------------------
# rows with their line numbers; the layout: header, column names, x and y


def _records(text: str, kind: str, source: str, delimiter: str = ",") -> Iterator[tuple[int, list[str]]]:
    """Yield (line number, fields) for each non-blank row of a table; line numbers are 1-based."""
    if kind == "text":
        for line_no, line in enumerate(io.StringIO(text, newline=""), 1):
            fields = line.partition(COMMENT)[0].split()
            if fields:
                yield line_no, fields
        return
    reader = csv.reader(io.StringIO(text, newline=""), delimiter=delimiter)
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


def line_offset(text: str, n_lines: int) -> int:
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


def _is_decimal_comma_number(s: str) -> bool:
    """A number with a decimal point or (spreadsheets' semicolon CSV) a decimal comma."""
    return _is_number(s) or (s.count(",") == 1 and _is_number(s.replace(",", ".")))


def _decimal_comma_columns(columns: dict) -> None:
    """In a semicolon-separated file, a text column all of whose values are numbers, some written with a
    decimal comma ("3,5", "4"), becomes a number column (3.5, 4.0), in place: the coordinates of such a
    file are read so too. (A decimal point stays a decimal point: "1.000" is 1.0, as in any file.)"""
    for name, column in columns.items():
        values = column.tolist() if isinstance(column, TextColumn) else column
        present = [v for v in values if v is not None]
        if not present or not all(isinstance(v, str) for v in present):
            continue
        if not any("," in v for v in present) or not all(_is_decimal_comma_number(v) for v in present):
            continue
        numbers = [None if v is None else float(v.replace(",", ".")) for v in values]
        columns[name] = [v if v is None or math.isfinite(v) else None for v in numbers]


def _decimal_points(values, delimiter: str):
    """Coordinates of a semicolon-separated file may have a decimal comma ("1,5"): read it as a point."""
    if delimiter != ";":
        return values
    return [v.replace(",", ".") for v in values]


def table_layout(text: str, source: str, kind: str, x, y, delimiter: str = ",") -> _Layout:
    """Find the header (if any), the column names and the x and y columns from the first rows."""
    records = _records(text, kind, source, delimiter)
    first = next(records, None)
    if first is None:
        why = "the file is empty" if not text.strip() else "the file has no data rows"
        raise InputFileError(f"{source}: no points found ({why})")
    line_no, fields = first
    number = _is_decimal_comma_number if kind == "csv" and delimiter == ";" else _is_number
    has_header = _is_header(fields, x, y, records, number)
    if has_header:
        names = _unique_names([f.strip() for f in fields])
        header_lines = _header_end(text, kind, source, delimiter)
        records = _records(text, kind, source, delimiter)
        next(records)
        data = next(records, None)
        if data is None:
            raise InputFileError(f"{source}: no points found (the file has only a header, line {line_no})")
        first_line, first_fields = data
    else:
        names = [col_name(j) for j in range(len(fields))]
        header_lines, first_line, first_fields = 0, line_no, fields
    ix = resolve_column(x, "x", names, has_header, source)
    iy = resolve_column(y, "y", names, has_header, source)
    how = "by name" if has_header else "the first two columns"
    skipped: list[str] = []
    candidates: tuple[str, ...] = ()
    if ix is None and iy is None:
        every = [names[j] for j, f in enumerate(first_fields[: len(names)]) if number(f)]
        if len(every) > 2:
            candidates = tuple(every)
    if ix is None or iy is None:
        # the first numeric columns of the first data row that are not taken, and not ids
        numeric = [j for j, f in enumerate(first_fields[: len(names)]) if j not in (ix, iy) and number(f)]
        skipped = [names[j] for j in numeric if has_header and is_id_like(names[j])]
        free = [j for j in numeric if names[j] not in skipped]
        if ix is None and free:
            ix = free.pop(0)
        if iy is None and free:
            iy = free.pop(0)
        how = "the first numeric columns" if has_header or len(names) > 2 else "the two columns"
    if ix is None or iy is None:
        missing = " and ".join(role for role, i in (("x", ix), ("y", iy)) if i is None)
        noun = "columns" if ix is None and iy is None else "column"
        ids = f" (id-like columns are not taken: {', '.join(skipped)})" if skipped else ""
        raise InputFileError(
            f"{source}, line {first_line}: cannot find the {missing} {noun}: no header names it "
            f"and the row has too few numeric columns{ids}; columns: {', '.join(names)}; "
            f"choose them with --x/--y"
        )
    check_distinct(ix, iy, names, source)
    choice = None
    if x is None or y is None:
        choice = describe_choice(names, ix, iy, how if x is None and y is None else "by option and " + how, skipped)
    return _Layout(
        names,
        has_header,
        header_lines,
        first_line,
        ix,
        iy,
        delimiter,
        choice,
        candidates if how == "the first numeric columns" else (),
    )


def _is_header(fields: list[str], x, y, records: Iterator[tuple[int, list[str]]], number=_is_number) -> bool:
    """Whether the first row ``fields`` is a header: a row whose x/y candidates are not numbers.

    The candidates are the columns chosen by index, else the row's first two numeric fields
    (fewer than two: a header), else the fields named like a coordinate column. A data row
    can hold such a name as a value ("1,2,lat"): then the row is a header only if the next
    row has a number where it has the name ("x,y,2019" over "1,2,7").
    """
    numeric = [number(f) for f in fields]
    lowered = [f.strip().lower() for f in fields]
    chosen = [s.strip().lower() for s in (x, y) if isinstance(s, str) and as_index(s) is None]
    if any(name in lowered for name in chosen):
        return True
    explicit = [i for i in (as_index(x), as_index(y)) if i is not None and i < len(fields)]
    if any(not numeric[i] for i in explicit) or sum(numeric) < 2:
        return True
    named = [j for j, name in enumerate(lowered) if name in X_NAMES + Y_NAMES and not numeric[j]]
    if not named:
        return False
    second = next(records, None)
    return second is not None and any(j < len(second[1]) and number(second[1][j]) for j in named)


def _header_end(text: str, kind: str, source: str, delimiter: str = ",") -> int:
    """Number of physical lines up to the end of the first non-blank row (the header)."""
    if kind == "text":
        return next(_records(text, kind, source))[0]
    reader = csv.reader(io.StringIO(text, newline=""), delimiter=delimiter)
    for fields in reader:
        if not _is_blank(fields):
            return reader.line_num
    return 0


def _unique_names(names: list[str]) -> list[str]:
    """Header names made unique and non-empty: an empty name becomes colN, a repeat name_2."""
    out: list[str] = []
    seen: set[str] = set()
    for j, name in enumerate(names):
        name = name or col_name(j)
        base, k = name, 2
        while name in seen:
            name, k = f"{base}_{k}", k + 1
        seen.add(name)
        out.append(name)
    return out


# ---------------------------------------------------------------------------
# the rows: in bulk, else one by one


def _bulk_table(text: str, offset: int, layout: _Layout, encoded: bytes | None = None):
    """The rows of a CSV text from ``offset`` on read by :func:`bulk_columns`, as :func:`fast_table`
    gives them; None when they need the csv module, ValueError at a value that is not a number.
    ``encoded``: the text's UTF-8 bytes, if known."""
    names, ix, iy = layout.names, layout.ix, layout.iy
    if len(names) == 2 and layout.delimiter != ";":
        return None  # only coordinates: numpy's loadtxt
    plain = _is_plain(text)
    with gc_paused():
        bulk = None
        if len(text) - offset >= ARROW_MIN_CHARS and "pyarrow" in sys.modules:
            bulk = _arrow_columns(text, layout, len(names), plain, start=offset, encoded=encoded)
        if bulk is None:
            bulk = bulk_columns(text, layout, len(names), plain=plain, start=offset, encoded=encoded)
    if bulk is None:
        return None
    xy, typed = bulk
    if not np.isfinite(xy).all():
        return None
    return xy, {name: typed[j] for j, name in enumerate(names) if j not in (ix, iy)}


def fast_table(body: str, kind: str, layout: _Layout, *, bulk: bool = True):
    """Read the rows after the header in bulk; None (or ValueError) when a row needs a closer look.
    ``bulk=False`` leaves out :func:`bulk_columns` (already tried)."""
    names, ix, iy = layout.names, layout.ix, layout.iy
    n_cols = len(names)
    if n_cols == 2 and layout.delimiter != ";":
        # only coordinates: numpy's C reader, which also checks every row has two fields
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if kind == "csv":
                table = np.loadtxt(
                    io.StringIO(body),
                    dtype=np.float64,
                    delimiter=layout.delimiter,
                    quotechar=QUOTE,
                    comments=None,
                    ndmin=2,
                )
            else:
                table = np.loadtxt(io.StringIO(body), dtype=np.float64, comments=COMMENT, ndmin=2)
        if table.shape[1] != 2 or len(table) == 0:
            return None
        xy = np.ascontiguousarray(table[:, [ix, iy]] if ix else table)
        return (xy, {}) if np.isfinite(xy).all() else None
    split = None
    if kind == "csv" and bulk:
        read = _bulk_table(body, 0, layout)
        if read is not None:
            return read
    if split is not None:
        xy, columns = split
    else:
        rows = _row_columns(body, kind, layout)
        if rows is None:
            return None
        columns = rows
        xy = _coordinates(columns, layout)
        columns[ix] = columns[iy] = []  # the coordinates' text is not needed any more
    if not np.isfinite(xy).all():
        return None
    return xy, _extras(columns, layout, body)


def _coordinates(columns, layout: _Layout) -> np.ndarray:
    """The x and y columns of a table's text as an (n, 2) array; ValueError at a value that is not a number."""
    xy = np.empty((len(columns[layout.ix]), 2), dtype=np.float64)
    for k, j in enumerate((layout.ix, layout.iy)):
        values = _decimal_points(columns[j], layout.delimiter)
        xy[:, k] = np.fromiter(map(float, values), dtype=np.float64, count=len(xy))
    return xy


def _arrow_columns(
    body: str, layout: _Layout, n_cols: int, plain: bool, *, start: int = 0, encoded: bytes | None = None
) -> tuple[np.ndarray, list] | None:
    """What :func:`bulk_columns` gives, read by pyarrow's CSV reader (on every core) when
    pyarrow is already loaded (a GeoParquet output loads it first); None when it is not, or the
    text needs a closer look. Loading pyarrow only to read would cost more memory (its libraries)
    than the time it saves.

    Every field is read as text, and the columns other than x and y are typed from their
    bytes as the bulk reader types them; the coordinates are converted by Arrow, which accepts
    a subset of what ``float`` accepts (no spaces or "_"), with the same correctly rounded
    result: a value it refuses sends the file to the other paths, which read it or name its line.
    The rows are ``body[start:]``; ``encoded``: the UTF-8 bytes of ``body``, if known.
    """
    if "pyarrow" not in sys.modules or not layout.delimiter.isascii():
        return None
    if encoded is None:
        encoded = body.encode()
    begin = start if len(encoded) == len(body) else len(body[:start].encode())
    if any(encoded.find(byte, begin) >= 0 for byte in (b'"', b"\0", b"\r")):
        return None
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.csv as pacsv

    names = [f"c{j}" for j in range(n_cols)]
    # the system allocator hands the table's memory back once it is dropped
    pool = pa.system_memory_pool()
    try:
        table = pacsv.read_csv(
            pa.py_buffer(memoryview(encoded)[begin:]),
            read_options=pacsv.ReadOptions(column_names=names),
            parse_options=pacsv.ParseOptions(
                delimiter=layout.delimiter,
                quote_char=False,
                double_quote=False,
                escape_char=False,
                newlines_in_values=False,
                ignore_empty_lines=False,
            ),
            convert_options=pacsv.ConvertOptions(
                column_types={name: pa.string() for name in names},
                strings_can_be_null=False,
                quoted_strings_can_be_null=False,
            ),
            memory_pool=pool,
        )
    except (pa.ArrowInvalid, pa.ArrowTypeError):
        return None  # a row with another number of fields, a blank line
    xy = np.empty((table.num_rows, 2), np.float64)
    for k, j in enumerate((layout.ix, layout.iy)):
        text = table.column(j)
        if layout.delimiter == ";":
            text = pc.replace_substring(text, ",", ".", memory_pool=pool)  # decimal commas
        try:
            # from the buffers: to_numpy() would import pandas
            xy[:, k] = float64_values(pc.cast(text, pa.float64(), memory_pool=pool))
        except (pa.ArrowInvalid, pa.ArrowTypeError):
            return None
    columns: list = []
    for j in range(n_cols):
        if j in (layout.ix, layout.iy):
            columns.append([])
            continue
        # the column's bytes and offsets, typed as the bulk reader types a column; a text column
        # keeps Arrow's buffers
        values = table.column(j).combine_chunks(memory_pool=pool)
        offsets = np.frombuffer(values.buffers()[1], np.int32)[values.offset : values.offset + len(values) + 1]
        data = values.buffers()[2]
        raw = np.frombuffer(data, np.uint8) if data is not None and data.size else np.zeros(1, np.uint8)
        columns.append(typed_packed_column(raw, offsets, plain))
    return xy, columns


def _row_columns(body: str, kind: str, layout: _Layout) -> list | None:
    """The columns of a table read row by row in bulk (the csv module, or whitespace splits);
    None when the rows do not all hold the header's number of fields."""
    n_cols = len(layout.names)
    with gc_paused():
        if kind == "csv":
            rows = list(csv.reader(io.StringIO(body, newline=""), delimiter=layout.delimiter))
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
    return columns


def slow_table(text: str, source: str, kind: str, layout: _Layout) -> PointSet:
    """Read a table row by row, keeping line numbers, and raise on the first row that is not a site.

    The sites' ``where`` gives the line number of each row (not yet a label)."""
    names, ix, iy = layout.names, layout.ix, layout.iy
    n_cols = len(names)
    records = _records(text, kind, source, layout.delimiter)
    if layout.has_header:
        next(records)
    line_nos: list[int] = []
    rows: list[list[str]] = []
    with gc_paused():
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
    xy[:, 0] = _floats_or_nan(_decimal_points(columns[ix], layout.delimiter))
    xy[:, 1] = _floats_or_nan(_decimal_points(columns[iy], layout.delimiter))
    bad = np.flatnonzero(~np.isfinite(xy).all(axis=1))
    if len(bad):
        # the first bad row: x is checked before y, as it reads
        r = bad[0]
        for j, role in ((ix, "x"), (iy, "y")):
            text = columns[j][r]
            _coordinate(
                _decimal_points([text], layout.delimiter)[0],
                role,
                names[j],
                line_nos[r],
                source,
                layout.has_header,
                text,
            )
    points = PointSet(xy, source, _extras(columns, layout, text))
    points.where = np.asarray(line_nos, np.int64).__getitem__
    return points


def _extras(columns: list, layout: _Layout, text: str) -> dict[str, list]:
    """The columns other than x and y, as JSON-ready values; ``text`` holds the rows they come from."""
    plain = _is_plain(text)
    return {
        name: convert_column(columns[j], plain)
        for j, name in enumerate(layout.names)
        if j not in (layout.ix, layout.iy)
    }


def _is_plain(text: str) -> bool:
    """Whether int() and float() read the numbers of a table text exactly as its literals (see convert_column)."""
    return text.isascii() and "_" not in text


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


def _coordinate(
    text: str, role: str, name: str, line_no: int, source: str, named: bool, written: str | None = None
) -> float:
    column = f'column "{name}"' if name == role else f'column "{name}" ({role})'
    try:
        value = float(text)
    except ValueError:
        raise InputFileError(
            f"{source}, line {line_no}: {_quoted(text if written is None else written)} in {column} is not a number; "
            f"fix the value, or choose other columns with --x/--y"
        ) from None
    if not math.isfinite(value):
        who = role if name == role or not named else f'{role} (column "{name}")'
        shown = text.strip()
        if shown.lower().lstrip("+-") not in ("nan", "inf", "infinity"):
            shown += " (it overflows to infinity)"
        raise InputFileError(f"{source}, line {line_no}: {who} is {shown}; tvoronoi needs finite coordinates")
    return value
