"""Arrow arrays made from numpy buffers and read back into numpy, without pyarrow's pandas shim.

``pyarrow.array(...)`` and ``Array.to_numpy()`` import pandas when it is installed (to ask
whether a value is a pandas object): 0.15-0.2 s of a batch run that never uses it. Fixed-width
columns need no such check: these functions hand numpy's buffers to Arrow and Arrow's to
numpy as they are (a copy only to compact a bitmap or join chunks).
"""

from __future__ import annotations

import numpy as np

__all__ = ["fixed_width", "float64_values", "null_count", "validity_bitmap"]

# the numpy type of each Arrow type fixed_width makes
_DTYPES = {"int32": "<i4", "int64": "<i8", "double": "<f8"}


def validity_bitmap(pa, valid: np.ndarray | None):
    """Arrow's validity bitmap (a bit per row, least significant first) of a bool mask; None when
    every row is valid."""
    if valid is None or valid.all():
        return None
    return pa.py_buffer(np.packbits(valid, bitorder="little"))


def fixed_width(pa, values: np.ndarray, kind, valid: np.ndarray | None = None):
    """An Arrow array of ``kind`` (int32, int64 or float64) over the buffer of ``values``, null where
    ``valid`` is False.

    >>> import pyarrow as pa
    >>> fixed_width(pa, np.array([1.5, 2.0, 3.0]), pa.float64(), np.array([True, False, True])).to_pylist()
    [1.5, None, 3.0]
    """
    data = np.ascontiguousarray(values, _DTYPES[str(kind)])
    return pa.Array.from_buffers(
        kind, len(data), [validity_bitmap(pa, valid), pa.py_buffer(data)], null_count=null_count(valid)
    )


def null_count(valid: np.ndarray | None) -> int:
    """The False entries of a validity mask (0 for None)."""
    return 0 if valid is None else int(len(valid) - np.count_nonzero(valid))


def float64_values(values) -> np.ndarray:
    """The values of a float64 Array or ChunkedArray without nulls, as one numpy array
    (a view of the buffer when there is one chunk).

    >>> import pyarrow as pa
    >>> float64_values(pa.chunked_array([fixed_width(pa, np.array([1.0, 2.0]), pa.float64())] * 2))
    array([1., 2., 1., 2.])
    """
    chunks = values.chunks if hasattr(values, "chunks") else [values]
    parts: list[np.ndarray] = []
    for chunk in chunks:
        if chunk.null_count:
            raise ValueError("float64_values: the array holds nulls")
        data = chunk.buffers()[1]
        if len(chunk):
            parts.append(np.frombuffer(data, "<f8")[chunk.offset : chunk.offset + len(chunk)])
    if len(parts) == 1:
        return parts[0]
    return np.concatenate(parts) if parts else np.zeros(0, np.float64)
