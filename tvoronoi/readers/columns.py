"""Choosing the x and y columns of a table or an array: by name, by index, or by default."""

from __future__ import annotations

import re

import numpy as np

from ..errors import InputFileError, TvoronoiError

# column names recognised in any case, in order of preference
X_NAMES = ("x", "lon", "lng", "long", "longitude")
Y_NAMES = ("y", "lat", "latitude")
_COL_NAME = re.compile(r"col([0-9]+)", re.IGNORECASE)


def _col_name(j: int) -> str:
    """The name of column ``j`` (0-based) when the file gives none: col1, col2, ..."""
    return f"col{j + 1}"


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


def _check_distinct(ix: int, iy: int, names: list[str], source: str, noun: str = "column") -> None:
    """Refuse x and y chosen as the same column (or field)."""
    if ix == iy:
        raise TvoronoiError(f'{source}: x and y are the same {noun} "{names[ix]}"; choose two {noun}s')
