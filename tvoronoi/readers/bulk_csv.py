"""A CSV table read in bulk with numpy: fields found by byte masks, numbers parsed by array arithmetic.

The table text is encoded once to UTF-8 and never split into Python strings: the field
boundaries are the separators and line breaks outside quotes, the coordinates are parsed
in bulk (a decimal of up to 16 digits is an exact integer divided by an exact power of ten,
one correctly rounded division, the same double ``float`` gives), and a text column is kept
as its bytes and offsets (:class:`TextColumn`). What this does not handle (blank lines, a
quote inside an unquoted field, a lone carriage return, a field that is not a number where a
number is due) returns None or raises ValueError, and the csv module, then the row walk that
names the line, take over.
"""

from __future__ import annotations

import numpy as np

from .pointset import _is_text, convert_column
from .text_column import TextColumn

QUOTE = ord('"')
LF, CR = 0x0A, 0x0D
# rows converted per step of the number parser (its scratch arrays stay a few megabytes)
PARSE_ROWS = 1 << 16
# a decimal of up to this many digits is an integer below 2**53: exact in a double
MAX_DIGITS = 16
# 10**k is exact in a double up to k = 22
POW10 = 10.0 ** np.arange(23)
_POW10_INT = 10 ** np.arange(MAX_DIGITS + 3, dtype=np.int64)
# the bytes str.strip() removes that are ASCII
_ASCII_SPACE = np.zeros(256, bool)
_ASCII_SPACE[[0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x1C, 0x1D, 0x1E, 0x1F, 0x20]] = True


def bulk_columns(
    text: str, layout, n_cols: int, *, plain: bool, start: int = 0, encoded: bytes | None = None
) -> tuple[np.ndarray, list] | None:
    """The sites and the other columns of the CSV rows in ``text[start:]`` (the text after the header);
    ``encoded``: the UTF-8 bytes of ``text``, when the caller has them.

    Returns (xy, columns): ``columns[j]`` is the JSON-ready column j (a :class:`TextColumn`
    or a list, see :func:`convert_column`), empty for the x and y columns. None when a row
    does not hold ``n_cols`` fields or the text needs the csv module; ValueError at a
    coordinate that is not a number. ``plain`` is as in :func:`convert_column`.
    """
    delimiter = layout.delimiter
    if len(text) <= start or len(delimiter) != 1 or not delimiter.isascii() or delimiter in '"\r\n':
        return None
    if encoded is None:
        encoded = text.encode()
    if b"\0" in encoded:
        return None
    begin = start if len(encoded) == len(text) else len(text[:start].encode())
    raw = np.frombuffer(encoded, np.uint8)[begin:]
    end = len(raw)
    while end and raw[end - 1] in (LF, CR):
        end -= 1  # the line breaks that end the file
    raw = raw[:end]
    if not end:
        return None
    fields = _fields(
        raw, ord(delimiter), n_cols, has_quotes=encoded.find(b'"', begin) >= 0, has_cr=encoded.find(b"\r", begin) >= 0
    )
    del encoded
    if fields is None:
        return None
    starts, stops, unescape = fields
    coordinates = (layout.ix, layout.iy)
    if unescape is not None and unescape[:, coordinates].any():
        return None  # a coordinate with a quote inside: the csv module reads it
    decimal_comma = delimiter == ";"

    def column(j: int):
        if j in coordinates:
            return parse_floats(raw, starts[:, j], stops[:, j], decimal_comma)
        if unescape is not None and unescape[:, j].any():
            values = _unescaped(raw, starts[:, j], stops[:, j])
            return None if values is None else convert_column(values, plain)
        return typed_column(raw, starts[:, j], stops[:, j], plain)

    # one column after the other: read by two threads, a million rows took no less time on two
    # busy cores and left 50 MB more held by the allocator's arena of the second thread
    done = [column(j) for j in range(n_cols)]
    if any(values is None for values in done):
        return None
    xy = np.empty((len(starts), 2), np.float64)
    xy[:, 0], xy[:, 1] = done[layout.ix], done[layout.iy]
    columns = [[] if j in coordinates else values for j, values in enumerate(done)]
    return xy, columns


def _fields(raw: np.ndarray, separator: int, n_cols: int, has_quotes: bool, has_cr: bool):
    """(starts, stops, unescape): (rows, n_cols) byte ranges of the fields, their quotes
    taken off, and where a quoted field holds a doubled quote (None when none does); None
    when the rows do not all hold n_cols fields or a quote is not where CSV puts one.
    ``has_quotes``, ``has_cr``: whether the text holds a quote, a carriage return."""
    ends_field = np.zeros(256, bool)
    ends_field[[separator, LF]] = True
    ends = ends_field[raw]
    quote = raw == QUOTE if has_quotes else np.zeros(0, bool)
    if has_quotes:
        # a separator or line break between an odd number of quotes is inside a quoted field;
        # the parity of a uint8 running count is the parity of the count
        inside = np.cumsum(quote, dtype=np.uint8) & 1
        if inside[-1]:
            return None  # a quote opened and not closed
        ends &= inside == 0
        del inside
    cuts = np.flatnonzero(ends)
    del ends
    n_fields = len(cuts) + 1
    if n_fields % n_cols:
        return None
    n_rows = n_fields // n_cols
    flat_starts = np.empty(n_fields, np.int64)
    flat_stops = np.empty(n_fields, np.int64)
    flat_starts[0] = 0
    flat_starts[1:] = cuts + 1
    flat_stops[:-1] = cuts
    flat_stops[-1] = len(raw)
    del cuts
    starts = flat_starts.reshape(n_rows, n_cols)
    stops = flat_stops.reshape(n_rows, n_cols)
    # every row ends at a line break, every other field at a separator
    if n_cols > 1 and not (raw[stops[:, :-1]] == separator).all():
        return None
    if n_rows > 1 and not (raw[stops[:-1, -1]] == LF).all():
        return None
    # Windows line ends: a carriage return before each line break is not part of the last field
    carriage = np.flatnonzero(raw == CR) if has_cr else np.zeros(0, np.int64)
    if len(carriage):
        last = stops[:, -1]
        crlf = (last > starts[:, -1]) & (raw[np.maximum(last - 1, 0)] == CR)
        last -= crlf
        if has_quotes:
            carriage = carriage[~_inside_fields(carriage, starts, stops, quote)]
        if len(carriage) != int(crlf.sum()):
            return None  # a lone carriage return ends a line for the csv module
    unescape = None
    if has_quotes:
        opens = (starts < len(raw)) & (raw[np.minimum(starts, len(raw) - 1)] == QUOTE)
        # a field with a quote must be quoted: "..." with its quotes doubled inside
        at = np.flatnonzero(quote)
        counts = np.searchsorted(at, stops) - np.searchsorted(at, starts)
        quoted = counts > 0
        closes = (stops - starts >= 2) & (raw[np.maximum(stops - 1, 0)] == QUOTE)
        if not np.array_equal(quoted, opens) or not (closes | ~quoted).all() or (counts & 1).any():
            return None
        starts = starts + quoted
        stops = stops - quoted
        if (counts > 2).any():
            unescape = counts > 2
    return starts, stops, unescape


def _inside_fields(positions: np.ndarray, starts: np.ndarray, stops: np.ndarray, quote: np.ndarray) -> np.ndarray:
    """Whether each byte position lies inside a quoted field (between its quotes)."""
    flat_starts, flat_stops = starts.ravel(), stops.ravel()
    k = np.searchsorted(flat_starts, positions, side="right") - 1
    quoted = quote[flat_starts[k]]
    return quoted & (positions > flat_starts[k]) & (positions < flat_stops[k] - 1)


def _gather(raw: np.ndarray, starts: np.ndarray, stops: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The bytes of the fields, each followed by a line break, and their n + 1 offsets (as a
    :class:`TextColumn` holds them): each field is gathered with the byte after it, which
    becomes the line break."""
    lengths = stops - starts + 1
    offsets = np.zeros(len(lengths) + 1, np.int64)
    np.cumsum(lengths, out=offsets[1:])
    # the index of each byte: one more than the last, but where a field starts
    kind = np.int32 if len(raw) < 2**31 else np.int64
    step = np.ones(int(offsets[-1]), kind)
    step[0] = starts[0]
    step[offsets[1:-1]] = starts[1:] - stops[:-1]
    index = np.cumsum(step, out=step)
    np.minimum(index, len(raw) - 1, out=index)  # the last field of the text has no byte after it
    data = raw[index]
    data[offsets[1:] - 1] = LF
    return data, offsets


def typed_column(raw: np.ndarray, starts: np.ndarray, stops: np.ndarray, plain: bool):
    """A column other than x and y: a TextColumn when its first non-blank value is text, else
    the values typed by :func:`convert_column`."""
    data, offsets = _gather(raw, starts, stops)
    column = TextColumn(data, offsets)
    blank = _blank(data, offsets)
    first = np.flatnonzero(~blank)[:1]
    if len(first) and _is_text((column[int(first[0])],)):
        return TextColumn(data, offsets, ~blank)
    return convert_column(column.tolist(), plain)


def typed_packed_column(data: np.ndarray, offsets: np.ndarray, plain: bool):
    """:func:`typed_column` of values laid out as Arrow lays out strings (see
    :meth:`TextColumn.from_packed`): a text column keeps that layout, with no copy."""
    blank = _blank(data, offsets, separator=0)
    first = np.flatnonzero(~blank)[:1]
    if len(first):
        i = int(first[0])
        if _is_text((data[offsets[i] : offsets[i + 1]].tobytes().decode(),)):
            return TextColumn.from_packed(data, offsets, ~blank)
    return convert_column(TextColumn.from_packed(data, offsets).tolist(), plain)


def _blank(data: np.ndarray, offsets: np.ndarray, separator: int = 1) -> np.ndarray:
    """Whether each field is empty or white space only (what ``str.strip`` empties): fields
    laid out as :func:`_gather` gives them, each followed by its line break, or with
    ``separator=0`` one after the other (Arrow's layout)."""
    lengths = np.diff(offsets) - separator
    if not len(data):
        return lengths == 0
    # a field that opens with a printable ASCII byte is not blank: look closer only at the others
    starts = offsets[:-1]
    # an empty field's first byte is its line break, or the next field's (any byte will do)
    first = data[np.minimum(starts, len(data) - 1)]
    maybe = np.flatnonzero((lengths == 0) | _ASCII_SPACE[first] | (first >= 0x80))
    blank = np.zeros(len(lengths), bool)
    if not len(maybe):
        return blank
    ends = offsets[1:][maybe] - separator
    starts = starts[maybe]
    # among those, a field with a printable ASCII byte is not blank either
    # (reduceat over start, end pairs sums each field; its every other sum is a gap; a byte
    # past the data stands for an end at its end)
    pairs = np.stack([starts, ends], axis=1).ravel()
    solid = np.zeros(len(data) + 1, bool)
    solid[:-1] = ~_ASCII_SPACE[data] & (data < 0x80)
    counts = np.add.reduceat(solid, pairs, dtype=np.int64)[::2]
    blank[maybe] = (ends == starts) | (counts == 0)
    wide = np.zeros(len(data) + 1, bool)
    wide[:-1] = data >= 0x80
    non_ascii = np.add.reduceat(wide, pairs, dtype=np.int64)[::2] > 0
    for i in maybe[non_ascii & (ends > starts) & blank[maybe]].tolist():
        blank[i] = not data[offsets[i] : offsets[i + 1] - separator].tobytes().decode().strip()
    return blank


def _unescaped(raw: np.ndarray, starts: np.ndarray, stops: np.ndarray) -> list[str] | None:
    """A column some of whose quoted fields hold doubled quotes, as str values; None when a
    quote inside a field is not doubled (the csv module reads that its own way)."""
    text = raw.tobytes()
    fields = [text[a:b] for a, b in zip(starts.tolist(), stops.tolist())]
    if any(b'"' in field.replace(b'""', b"") for field in fields):
        return None
    return [field.replace(b'""', b'"').decode() for field in fields]


def parse_floats(raw: np.ndarray, starts: np.ndarray, stops: np.ndarray, decimal_comma: bool = False) -> np.ndarray:
    """The numbers in ``raw[starts[i]:stops[i]]``, each as ``float`` reads it.

    A plain decimal (an optional sign, up to 16 digits, at most one point) is parsed by
    array arithmetic: its digits as an integer below 2**53 divided by a power of ten up to
    10**22, both exact in a double, so the one division rounds correctly, as ``float`` does.
    Any other field (an exponent, more digits, spaces, "nan") is given to ``float``; a
    field ``float`` refuses raises ValueError. ``decimal_comma`` reads "1,5" as 1.5.
    """
    n = len(starts)
    out = np.empty(n, np.float64)
    lengths = stops - starts
    width = int(min(lengths.max(initial=0), MAX_DIGITS + 2))
    done = np.zeros(n, bool)
    if width:
        columns = np.arange(width, dtype=np.int64)
        for a in range(0, n, PARSE_ROWS):
            b = min(n, a + PARSE_ROWS)
            out[a:b], done[a:b] = _parse_block(raw, starts[a:b], lengths[a:b], columns, decimal_comma)
    text = None
    for i in np.flatnonzero(~done).tolist():
        if text is None:
            text = raw.tobytes()
        field = text[starts[i] : stops[i]].decode()
        if decimal_comma:
            field = field.replace(",", ".")
        out[i] = float(field)
    return out


def _parse_block(raw, starts, lengths, columns, decimal_comma):
    """(values, parsed) of one block of fields: parsed is False where a field is not a plain decimal.

    The fields are laid out right-aligned, one row per character position from the end: a
    digit's weight is ten to the number of digits to its right, and the number of decimals
    is the number of digits right of the point.
    """
    width = len(columns)
    # row k holds each field's character k places before its end (NUL before its start)
    back = columns[::-1, None]
    inside = back < lengths
    chars = raw[np.maximum(starts + lengths - 1 - back, 0)]
    chars[~inside] = 0
    digit = chars - ord("0")
    is_digit = digit < 10
    is_point = chars == ord(".")
    if decimal_comma:
        is_point |= chars == ord(",")
    # digits at or right of each position; a digit's own weight counts those right of it
    right = is_digit.astype(np.int8)
    for k in range(width - 2, -1, -1):
        right[k] += right[k + 1]
    n_digits = right[0].astype(np.int64)
    digit[~is_digit] = 0
    mantissa = (digit * _POW10_INT[np.maximum(right - 1, 0)]).sum(axis=0)
    decimals = (right * is_point).sum(axis=0)
    first = chars[width - lengths.clip(1, width), np.arange(len(starts))]
    sign = (first == ord("-")) | (first == ord("+"))
    # every character a digit or the point, but a sign first; at most one point
    stray = inside & ~is_digit & ~is_point
    ok = (lengths > 0) & (lengths <= width) & (n_digits >= 1) & (n_digits <= MAX_DIGITS)
    ok &= stray.sum(axis=0) == sign
    ok &= is_point.sum(axis=0) <= 1
    ok &= mantissa <= (1 << 53)
    values = mantissa.astype(np.float64) / POW10[np.minimum(decimals, 22)]
    values[first == ord("-")] *= -1.0
    return values, ok
