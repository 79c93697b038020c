""".npy point files: an (n, k) number array, or a structured array with named fields."""

from __future__ import annotations

import io

import numpy as np

from ..errors import InputFileError
from .columns import LAT_NAMES, LON_NAMES, check_distinct, col_name, describe_choice, is_id_like, resolve_column
from .pointset import PointSet, json_column

NPY_MAGIC = b"\x93NUMPY"


def read_npy(data: bytes, source: str, x, y) -> PointSet:
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
    names = [col_name(j) for j in range(array.shape[1])]
    ix = resolve_column(x, "x", names, False, source)
    iy = resolve_column(y, "y", names, False, source)
    free = [j for j in range(len(names)) if j not in (ix, iy)]
    ix = free.pop(0) if ix is None else ix
    iy = free.pop(0) if iy is None else iy
    check_distinct(ix, iy, names, source)
    xy = np.ascontiguousarray(array[:, [ix, iy]], dtype=np.float64)
    _check_finite_rows(xy, source)
    columns = {names[j]: json_column(array[:, j]) for j in range(array.shape[1]) if j not in (ix, iy)}
    return PointSet(xy, source, columns)


def _structured_npy(array: np.ndarray, source: str, x, y) -> PointSet:
    if array.ndim != 1:
        raise InputFileError(f"{source}: a structured array of shape {array.shape}; tvoronoi needs shape (n,)")
    names = list(array.dtype.names)
    ix = resolve_column(x, "x", names, True, source)
    iy = resolve_column(y, "y", names, True, source)
    how, skipped = "by name", []
    if ix is None or iy is None:
        numeric = [j for j, name in enumerate(names) if j not in (ix, iy) and array.dtype[name].kind in "iuf"]
        skipped = [names[j] for j in numeric if is_id_like(names[j])]
        free = [j for j in numeric if names[j] not in skipped]
        ix = free.pop(0) if ix is None and free else ix
        iy = free.pop(0) if iy is None and free else iy
        how = "the first numeric fields"
    if ix is None or iy is None:
        ids = f" (id-like fields are not taken: {', '.join(skipped)})" if skipped else ""
        raise InputFileError(
            f"{source}: cannot find the x and y fields among {', '.join(names)}{ids}; choose them with --x/--y"
        )
    check_distinct(ix, iy, names, source, noun="field")
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
    columns = {names[j]: json_column(array[names[j]]) for j in range(len(names)) if j not in (ix, iy)}
    lonlat = names[ix].lower() in LON_NAMES and names[iy].lower() in LAT_NAMES
    choice = describe_choice(names, ix, iy, how, skipped) if x is None or y is None else None
    every = tuple(name for name in names if array.dtype[name].kind in "iuf" and not array.dtype[name].shape)
    ambiguous = x is None and y is None and how != "by name" and len(every) > 2
    return PointSet(
        xy,
        source,
        columns,
        lonlat=lonlat,
        choice=choice,
        xy_columns=(names[ix], names[iy]),
        candidates=every if ambiguous else (),
        where=lambda i: f"row {i} (0-based)",
    )


def _check_finite_rows(xy: np.ndarray, source: str) -> None:
    finite = np.isfinite(xy)
    if finite.all():
        return
    i, k = np.argwhere(~finite)[0]
    raise InputFileError(f"{source}, row {i} (0-based): {'xy'[k]} is {xy[i, k]}; tvoronoi needs finite coordinates")
