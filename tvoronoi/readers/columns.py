"""Choosing the x and y columns of a table or an array: by name, by index, or by default."""

from __future__ import annotations

import re

import numpy as np

from ..coordinate_names import LAT_NAMES, LON_NAMES, PAIRED_ONLY, X_NAMES, Y_NAMES, named_column  # noqa: F401
from ..errors import InputFileError, TvoronoiError

# words that make a column an identifier, never a coordinate taken by position
ID_WORDS = frozenset(
    "id fid gid oid uid pk key idx index row rowid rownum no num number objectid code zip zipcode "
    "postcode postal plz fips geoid unnamed".split()
)
_COL_NAME = re.compile(r"col([0-9]+)", re.IGNORECASE)
_WORDS = re.compile(r"[A-Z]?[a-z]+|[A-Z]+(?![a-z])|[0-9]+")


def is_id_like(name: str) -> bool:
    """Whether a column name reads as an identifier: "id", "FID", "row", "station_id", "cityId", "Unnamed: 0".

    >>> [is_id_like(n) for n in ("id", "OBJECTID", "site_no", "zip", "x", "height", "grid")]
    [True, True, True, True, False, False, False]
    """
    lowered = name.strip().lower()
    if lowered in ID_WORDS or lowered.endswith(("_id", "-id", " id", ".id")):
        return True
    words = [w.lower() for w in _WORDS.findall(name)]
    return bool(words) and (words[-1] in ID_WORDS or words[0] in ("unnamed", "index"))


def col_name(j: int) -> str:
    """The name of column ``j`` (0-based) when the file gives none: col1, col2, ..."""
    return f"col{j + 1}"


def as_index(sel) -> int | None:
    """A 0-based column index given as an int or a digit string, else None."""
    if isinstance(sel, (int, np.integer)) and not isinstance(sel, bool):
        return int(sel)
    if isinstance(sel, str) and sel.strip().isdigit() and sel.strip().isascii():
        return int(sel.strip())
    return None


def resolve_column(sel, role: str, names: list[str], by_name: bool, source: str) -> int | None:
    """Index of the column ``sel`` chooses for ``role``; with ``sel=None``, the column named like it."""
    n_cols = len(names)
    listing = ", ".join(f"{j}:{name}" for j, name in enumerate(names))
    if sel is None:
        return named_column(names, role) if by_name else None
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
    index = as_index(sel)
    if index is None and not isinstance(sel, str):
        raise TvoronoiError(f"--{role} must be a column name or a 0-based index, got {sel!r}")
    if index is not None and 0 <= index < n_cols:
        return index
    what = f"column {sel}" if index is not None else f'column "{sel}"'
    raise InputFileError(f"{source}: no {what} for {role}; the file has {n_cols} columns (index:name): {listing}")


def check_distinct(ix: int, iy: int, names: list[str], source: str, noun: str = "column") -> None:
    """Refuse x and y chosen as the same column (or field)."""
    if ix == iy:
        raise TvoronoiError(f'{source}: x and y are the same {noun} "{names[ix]}"; choose two {noun}s')


def describe_choice(names: list[str], ix: int, iy: int, how: str, skipped: list[str] = ()) -> str | None:
    """The line that tells which columns became x and y, e.g. 'x = "lon", y = "lat" (by name)';
    None for columns named x and y, or a file of two columns, which leave nothing to tell."""
    if how == "the two columns" or (how == "by name" and names[ix].lower() == "x" and names[iy].lower() == "y"):
        return None
    text = f'x = "{names[ix]}", y = "{names[iy]}" ({how})'
    if skipped:
        text += f"; skipped the id-like {'column' if len(skipped) == 1 else 'columns'} " + ", ".join(
            f'"{name}"' for name in skipped
        )
    return text + "; choose others with --x/--y"
