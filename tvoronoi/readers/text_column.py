"""A column of text values held as one UTF-8 buffer and offsets, not one Python object per row."""

from __future__ import annotations

from collections.abc import Sequence
from typing import overload

import numpy as np

LF = 0x0A
# bytes that JSON writes escaped inside a string: the quote, the backslash, the control characters
_JSON_ESCAPED = np.zeros(256, bool)
_JSON_ESCAPED[:0x20] = True
_JSON_ESCAPED[[ord('"'), ord("\\")]] = True


class TextColumn(Sequence):
    """Text values of a table column, None where the field was empty or blank.

    A list of a million short strings costs about 60 bytes a value in Python objects;
    this holds the bytes once (about the size of the text) and makes a ``str`` only
    when a value is asked for. It reads like the list it stands for: ``len``,
    indexing, slicing (a list), iteration, ``==`` with a list.

    Parameters
    ----------
    data : numpy.ndarray
        uint8: the UTF-8 bytes of each value followed by a line break, one value after
        the other (so that a block of values splits at its line breaks in one call).
    offsets : numpy.ndarray
        int64, ``n + 1`` offsets: value ``i`` is ``data[offsets[i]:offsets[i + 1] - 1]``.
    valid : numpy.ndarray or None
        bool per value, False where the value is None; None when no value is.
    """

    __slots__ = ("_data", "_offsets", "_packed", "valid", "_plain", "_multiline_flag")

    def __init__(self, data: np.ndarray, offsets: np.ndarray, valid: np.ndarray | None = None):
        self._data: np.ndarray | None = data
        self._offsets: np.ndarray | None = offsets
        # Arrow's layout of the values, when the column came from it (see from_packed)
        self._packed: tuple[np.ndarray, np.ndarray] | None = None
        self.valid = None if valid is None or valid.all() else valid
        self._plain: bool | None = None
        self._multiline_flag: bool | None = None

    @classmethod
    def from_packed(cls, data: np.ndarray, offsets: np.ndarray, valid: np.ndarray | None = None) -> TextColumn:
        """A column of values laid out as Arrow lays out strings, one after the other without a
        separator: value ``i`` is ``data[offsets[i]:offsets[i + 1]]`` (``offsets`` int32 or int64,
        not necessarily from 0). The layout with line breaks is made only when a value is asked
        for; :meth:`to_arrow` hands the buffers back as they are."""
        column = cls.__new__(cls)
        column._data = column._offsets = None
        column._packed = (data, offsets)
        column.valid = None if valid is None or valid.all() else valid
        column._plain = None
        column._multiline_flag = None
        return column

    @property
    def data(self) -> np.ndarray:
        if self._data is None:
            self._unpack()
        assert self._data is not None
        return self._data

    @property
    def offsets(self) -> np.ndarray:
        if self._offsets is None:
            if self._packed is not None and self._data is None:
                self._unpack()
        assert self._offsets is not None
        return self._offsets

    def _unpack(self) -> None:
        """The line-break layout from the packed one: a line break inserted after each value."""
        assert self._packed is not None
        data, offsets = self._packed
        first = int(offsets[0])
        ends = offsets[1:].astype(np.int64) - first
        self._data = np.insert(data[first : int(offsets[-1])], ends, np.uint8(LF))
        self._offsets = np.concatenate([[0], ends + np.arange(1, len(ends) + 1)])

    @property
    def _multiline(self) -> bool:
        """Whether a value holds a line break itself (a quoted CSV field over lines)."""
        if self._multiline_flag is None:
            if self._packed is not None:
                data, offsets = self._packed
                self._multiline_flag = bool((data[int(offsets[0]) : int(offsets[-1])] == LF).any())
            else:
                self._multiline_flag = int(np.count_nonzero(self.data == LF)) != len(self)
        return self._multiline_flag

    @classmethod
    def from_strings(cls, values) -> TextColumn:
        """A column of the given str and None values."""
        valid = np.array([v is not None for v in values], bool)
        parts = [(v or "").encode() + b"\n" for v in values]
        offsets = np.zeros(len(parts) + 1, np.int64)
        np.cumsum([len(p) for p in parts], out=offsets[1:])
        return cls(np.frombuffer(b"".join(parts), np.uint8), offsets, valid)

    def __len__(self) -> int:
        if self._packed is not None:
            return len(self._packed[1]) - 1
        return len(self.offsets) - 1

    @overload
    def __getitem__(self, i: int) -> str | None: ...

    @overload
    def __getitem__(self, i: slice) -> list: ...

    def __getitem__(self, i):
        if isinstance(i, slice):
            a, b, step = i.indices(len(self))
            if step != 1:
                return self.tolist()[i]
            return self.slice_list(a, b)
        n = len(self)
        i = int(i)
        if not -n <= i < n:
            raise IndexError(f"row {i} out of range for {n} values")
        i %= n
        if self.valid is not None and not self.valid[i]:
            return None
        return self.data[self.offsets[i] : self.offsets[i + 1] - 1].tobytes().decode()

    def __iter__(self):
        return iter(self.tolist())

    def __eq__(self, other) -> bool:
        if isinstance(other, TextColumn):
            return self.tolist() == other.tolist()
        if isinstance(other, (list, tuple)):
            return self.tolist() == list(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        head = self.slice_list(0, min(len(self), 3))
        return f"TextColumn({head}{', ...' if len(self) > 3 else ''} ({len(self)} values))"

    def tolist(self) -> list:
        return self.slice_list(0, len(self))

    def slice_list(self, a: int, b: int) -> list:
        """Values a..b-1 as a list of str and None."""
        if b <= a:
            return []
        values: list[str | None]
        if self._multiline:
            values = [part.decode() for part in self.utf8(a, b)]
        else:
            values = list(self.data[self.offsets[a] : self.offsets[b] - 1].tobytes().decode().split("\n"))
        if self.valid is not None:
            for k in np.flatnonzero(~self.valid[a:b]).tolist():
                values[k] = None
        return values

    def utf8(self, a: int, b: int) -> list[bytes]:
        """The UTF-8 bytes of values a..b-1 (those of a None are whatever the field held)."""
        if b <= a:
            return []
        raw = self.data[self.offsets[a] : self.offsets[b] - 1].tobytes()
        if not self._multiline:
            return raw.split(b"\n")
        base = int(self.offsets[a])
        bounds = zip(self.offsets[a:b].tolist(), self.offsets[a + 1 : b + 1].tolist())
        return [raw[s - base : e - 1 - base] for s, e in bounds]

    @property
    def json_plain(self) -> bool:
        """Whether JSON writes every value between quotes as its bytes are (nothing to escape)."""
        if self._plain is None:
            self._plain = not self._multiline and not _JSON_ESCAPED[self.data].sum() - len(self)
        return self._plain

    def to_arrow(self):
        """The column as a pyarrow string array (large_string past 2 GiB), built from its buffers
        (no object per value)."""
        import pyarrow as pa

        if self._packed is not None:
            data, offsets = self._packed
        else:
            # the values without their line breaks, and offsets to match
            keep = np.ones(len(self.data), bool)
            keep[self.offsets[1:] - 1] = False
            data = self.data[keep]
            offsets = self.offsets - np.arange(len(self.offsets), dtype=np.int64)
        validity = None
        if self.valid is not None:
            validity = pa.py_buffer(np.packbits(self.valid, bitorder="little"))
        kind, index = (pa.string(), np.int32) if int(offsets[-1]) < 2**31 else (pa.large_string(), np.int64)
        return pa.Array.from_buffers(
            kind,
            len(self),
            [validity, pa.py_buffer(offsets.astype(index, copy=False)), pa.py_buffer(data)],
            null_count=-1 if validity is not None else 0,
        )
