"""The sites read from a point file, and the JSON-ready values their properties hold."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1
_INT_LITERAL = re.compile(r"[+-]?[0-9]+")
_FLOAT_LITERAL = re.compile(
    r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|nan|inf|infinity)", re.IGNORECASE
)


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
    crs : str or dict or None
        The coordinate reference system the file declares ("EPSG:3857", a
        PROJJSON dict), None when it declares none.
    lonlat : bool
        Whether the sites are longitude/latitude degrees: columns named so,
        GeoJSON without a ``crs`` member (RFC 7946), or a geographic CRS.
    choice : str or None
        Which columns became x and y and why, for tables whose columns were not
        all given by the caller; None otherwise.
    xy_columns : (str, str) or None
        The names of the table columns (or fields) that became x and y; None
        for files without columns (GeoJSON, geometry columns, plain arrays).
    candidates : tuple of str
        When x and y were taken by position (the first numeric columns, neither
        named x/y or lon/lat nor given by the caller) and more than two columns
        could have been: every numeric column, in file order, for a user to
        choose from. Empty when the choice was not ambiguous.
    where : callable(int) -> str, optional
        Where site ``i`` is in the file ("line 7", "features[3]", "row 3").
    """

    xy: np.ndarray
    source: str
    columns: dict[str, list] = field(default_factory=dict)
    records: list[dict] | None = None
    crs: str | dict | None = None
    lonlat: bool = False
    choice: str | None = None
    xy_columns: tuple[str, str] | None = None
    candidates: tuple[str, ...] = ()
    where: Callable[[int], str] | None = field(default=None, repr=False, compare=False)

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

    def place(self, i: int) -> str:
        """Where site ``i`` is in its file, for a message: "line 7", "features[3]", "row 3 (0-based)"."""
        return self.where(i) if self.where is not None else f"row {i} (0-based)"

    def locate(self, i: int) -> str:
        """Where site ``i`` is, with the file: "data.csv, line 7"."""
        return f"{self.source}, {self.place(i)}"


# ---------------------------------------------------------------------------
# JSON-ready values: from the text of a table field, from a numpy column


# rows from which a text column is judged to be a category (few values, each repeated)
CATEGORY_SAMPLE = 1000
_LEADING_ZERO = re.compile(r"^\s*[+-]?0[0-9]", re.MULTILINE)


def _convert_value(s: str):
    """A property value: int for an int literal, float for a float literal, None for "" or a
    non-finite number (JSON has none), else the string as written.

    A number written with a leading zero ("01000", a zip code) stays a string."""
    t = s.strip()
    if not t:
        return None
    if _LEADING_ZERO.match(t):
        return s
    if _INT_LITERAL.fullmatch(t):
        value = int(t)
        # beyond 64 bits most JSON writers fail: keep the digits as text
        return value if INT64_MIN <= value <= INT64_MAX else s
    if _FLOAT_LITERAL.fullmatch(t):
        value = float(t)
        return value if math.isfinite(value) else None
    return s


def convert_column(values, plain: bool) -> list:
    """A table column as JSON-ready values of one type: the column is typed, not each value.

    Empty values are None. The rest are ints if every one is an int literal (within 64 bits),
    else floats if every one is a number (a non-finite one is None), else strings as written:
    "01000" in a zip column stays "01000", and so does "7" in a column that also holds "7a".
    ``plain`` (ASCII, no "_") lets int() and float() decide in bulk, since on such text they
    accept exactly the literals the regexes describe.
    """
    if not values:
        return []
    first = next((v for v in values if v.strip()), None)
    if first is not None and _is_text((first,)):
        # the first value already makes it a text column
        return _text_column(values)
    if plain and not _LEADING_ZERO.search("\n".join(values)):
        try:
            ints = list(map(int, values))
        except ValueError:
            ints = None
        if ints is not None and INT64_MIN <= min(ints) and max(ints) <= INT64_MAX:
            return ints
        try:
            if ints is not None:
                raise ValueError("integers beyond 64 bits are kept as text")
            floats = np.fromiter(map(float, values), dtype=np.float64, count=len(values))
        except ValueError:
            pass
        else:
            out = floats.tolist()
            for i in np.flatnonzero(~np.isfinite(floats)):
                out[i] = None
            return out
    distinct = set(values)
    if _is_text(distinct):
        return _text_column(values)
    # numbers and empty values: convert each distinct value once, then settle the column's type
    memo = {v: _convert_value(v) for v in distinct}
    kinds = {type(value) for value in memo.values()} - {type(None)}
    if kinds <= {int}:
        pass
    elif kinds <= {int, float}:
        memo = {v: None if value is None else float(value) for v, value in memo.items()}
    else:
        memo = {v: None if not v.strip() else v for v in memo}
    return list(map(memo.__getitem__, values))


def _text_column(values) -> list:
    """A text column as written, empty values None; a value that repeats (a category, judged
    from the first rows) is held once, not once per row."""
    head = len(set(values[:CATEGORY_SAMPLE]))
    if head * 2 <= min(len(values), CATEGORY_SAMPLE):
        memo = {v: None if not v.strip() else v for v in set(values)}
        return list(map(memo.__getitem__, values))
    if "" in values or any(map(str.isspace, values)):
        return [None if not v.strip() else v for v in values]
    return list(values)


def _is_text(distinct) -> bool:
    """Whether a column holds a value that is not a number, or a number with a leading zero
    (stops at the first: a text column is told from its first values)."""
    for v in distinct:
        t = v.strip()
        if t and (_LEADING_ZERO.match(t) or not _FLOAT_LITERAL.fullmatch(t)):
            return True
    return False


def json_column(values: np.ndarray) -> list:
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
