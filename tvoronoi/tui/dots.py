"""Braille dots with numpy: segments and points set on a dot array, packed into braille characters.

A character cell holds 2 x 4 braille dots, so a canvas of ``cols x rows``
characters is a boolean dot array of shape ``(rows * 4, cols * 2)``. Dot
coordinates ``(u, v)`` are continuous: dot column ``floor(u)``, dot row
``floor(v)``, with ``v`` growing downwards.
"""

from __future__ import annotations

import numpy as np

DOT_COLS, DOT_ROWS = 2, 4
BRAILLE_BLANK = 0x2800
# DOT_BITS[row, col]: the bit of the dot at (col, row) inside a character
DOT_BITS = np.array([[0x01, 0x08], [0x02, 0x10], [0x04, 0x20], [0x40, 0x80]], np.uint8)
SPACE = 0x20


def segment_dots(
    dots: np.ndarray, u0, v0, u1, v1, *, dash: int = 0, origin: tuple[int, int] = (0, 0), ends: bool = True
) -> None:
    """Set the dots along many segments at once.

    Each segment is sampled once per dot along its longer axis (a vectorised
    DDA), so consecutive samples touch and a line has no gaps. The samples
    depend on the segment only, never on the array: the array is a window on
    an unbounded plane of dots, from dot ``origin`` on, and it gets exactly
    the dots of that plane inside it. So two windows that overlap agree dot
    for dot where they overlap (a layer drawn before can be shifted and only
    the strip it lacks drawn).

    Parameters
    ----------
    dots : (H, W) bool, changed in place
    u0, v0, u1, v1 : (k,) float
        Segment ends in continuous dot coordinates of the plane; they may lie
        outside the window. Segments with a NaN end are skipped.
    dash : int
        If > 0, draw dashes: ``dash`` dots on, ``dash`` dots off (counted on the plane).
    origin : (int, int)
        The plane's dot (column, row) at the window's top left.
    ends : bool
        False: leave out the dots of the segments' ends (solid lines only), for a caller that
        sets them itself (``point_dots`` on each end once, where many segments share ends).
    """
    height, width = dots.shape
    ou, ov = (int(o) for o in origin)
    u0, v0, u1, v1 = (np.asarray(c, np.float64).ravel() for c in (u0, v0, u1, v1))
    if u0.size == 0 or width == 0 or height == 0:
        return
    # drop the segments wholly beyond one side (and those with a NaN end)
    lo_u, hi_u = np.minimum(u0, u1), np.maximum(u0, u1)
    lo_v, hi_v = np.minimum(v0, v1), np.maximum(v0, v1)
    near = (hi_u >= ou) & (lo_u < ou + width) & (hi_v >= ov) & (lo_v < ov + height)
    if not near.all():
        u0, v0, u1, v1 = u0[near], v0[near], u1[near], v1[near]
    steep = np.abs(v1 - v0) > np.abs(u1 - u0)
    # the ends are always drawn (those beyond the window are dropped there)
    cols, rows = ([u0, u1], [v0, v1]) if ends else ([], [])
    if dash <= 0:
        # a segment whose ends lie within one dot along its longer axis has one sample, in the
        # dot of an end (the same column or row, a height between the ends'): its ends are all
        # its dots. Most edges of a zoomed-out view are such.
        short = np.where(steep, np.floor(v0) == np.floor(v1), np.floor(u0) == np.floor(u1))
        if short.any():
            long = ~short
            u0, v0, u1, v1, steep = u0[long], v0[long], u1[long], v1[long], steep[long]
    else:
        cols, rows = [], []
    flat = ~steep
    cols_f, rows_f = _centre_samples(u0[flat], u1[flat], v0[flat], v1[flat], ou, ou + width, dash)
    rows_s, cols_s = _centre_samples(v0[steep], v1[steep], u0[steep], u1[steep], ov, ov + height, dash)
    _set_dots(dots, np.concatenate(cols + [cols_f, cols_s]), np.concatenate(rows + [rows_f, rows_s]), (ou, ov))


def _set_dots(dots: np.ndarray, cols: np.ndarray, rows: np.ndarray, origin: tuple[int, int] = (0, 0)) -> None:
    """Set the dots holding points (cols, rows) in continuous dot coordinates of the plane whose dot
    ``origin`` is the window's top left; points beyond the window belong to no dot here."""
    height, width = dots.shape
    ou, ov = origin
    col = np.floor(cols)
    row = np.floor(rows)
    inside = (col >= ou) & (col < ou + width) & (row >= ov) & (row < ov + height)  # False for NaN
    if not inside.all():
        col, row = col[inside], row[inside]
    dots.ravel()[(row.astype(np.int64) - ov) * width + (col.astype(np.int64) - ou)] = True


def _centre_samples(a0, a1, b0, b1, lo: int, hi: int, dash: int):
    """Points along segments at every dot centre line of their major axis ``a`` (as floats) from
    dot ``lo`` up to (not including) dot ``hi`` of that axis, the window's.

    A centre beyond the segment's end is pulled back onto it. Each sample is
    computed from the segment's own ends, so it is the same whatever the window.
    """
    flip = a1 < a0
    a0, a1 = np.where(flip, a1, a0), np.where(flip, a0, a1)
    b0, b1 = np.where(flip, b1, b0), np.where(flip, b0, b1)
    k0 = np.maximum(np.floor(a0), lo)
    k1 = np.minimum(np.floor(a1), hi - 1)
    counts = np.maximum(k1 - k0 + 1, 0).astype(np.int64)
    first = np.cumsum(counts) - counts
    owner = np.repeat(np.arange(counts.size), counts)
    a = np.arange(owner.size, dtype=np.float64) + np.repeat(k0 + 0.5 - first, counts)
    a = np.minimum(np.maximum(a, a0[owner]), a1[owner])
    span = a1 - a0
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(span > 0, (b1 - b0) / span, 0.0)
        b = b0[owner] + (a - a0[owner]) * slope[owner]
    if dash > 0:
        on = (np.floor(a).astype(np.int64) // dash) % 2 == 0
        a, b = a[on], b[on]
    return a, b


def _clip(u0, v0, u1, v1, width: float, height: float):
    """Clip segments to [0, W) x [0, H) (Liang-Barsky, all at once); returns keep, t0, t1, u0, v0, u1, v1."""
    du, dv = u1 - u0, v1 - v0
    t0 = np.zeros_like(u0)
    t1 = np.ones_like(u0)
    keep = np.ones(u0.shape, bool)
    top_u, top_v = np.nextafter(width, 0), np.nextafter(height, 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for p, q in ((-du, u0), (du, top_u - u0), (-dv, v0), (dv, top_v - v0)):
            # this side keeps the points with p * t <= q
            keep &= ~((p == 0) & (q < 0))
            r = q / p
            t0 = np.where(p < 0, np.maximum(t0, r), t0)
            t1 = np.where(p > 0, np.minimum(t1, r), t1)
    keep &= t0 <= t1
    # an end the clip did not move is returned as given (u0 + 1 * du can differ from u1 by an ulp)
    start, end = t0 == 0, t1 == 1
    return (
        keep,
        t0,
        t1,
        np.where(start, u0, u0 + t0 * du),
        np.where(start, v0, v0 + t0 * dv),
        np.where(end, u1, u0 + t1 * du),
        np.where(end, v1, v0 + t1 * dv),
    )


def clip_segments(seg: np.ndarray, bbox) -> np.ndarray:
    """World segments (k, 4) cut to a box (xmin, ymin, xmax, ymax); those wholly outside dropped."""
    seg = np.asarray(seg, np.float64).reshape(-1, 4)
    if not len(seg):
        return seg
    xmin, ymin, xmax, ymax = (float(c) for c in bbox)
    keep, _, _, u0, v0, u1, v1 = _clip(
        seg[:, 0] - xmin, seg[:, 1] - ymin, seg[:, 2] - xmin, seg[:, 3] - ymin, xmax - xmin, ymax - ymin
    )
    out = np.column_stack([u0 + xmin, v0 + ymin, u1 + xmin, v1 + ymin])
    return out[keep & np.isfinite(out).all(axis=1)]


def point_dots(dots: np.ndarray, u, v, *, block: bool = False, origin: tuple[int, int] = (0, 0)) -> None:
    """Set the dot under each point that falls on the array, a window from dot ``origin`` on (see
    ``segment_dots``; a whole number of characters, so that blocks stay inside their character).

    With ``block``, set the 2 x 2 dots around it inside its own character,
    so that a lone site reads as a spot.
    """
    height, width = dots.shape
    ou, ov = (int(o) for o in origin)
    u = np.floor(np.asarray(u, np.float64).ravel())
    v = np.floor(np.asarray(v, np.float64).ravel())
    inside = (u >= ou) & (u < ou + width) & (v >= ov) & (v < ov + height)  # False for NaN too
    col = u[inside].astype(np.int64) - ou
    row = v[inside].astype(np.int64) - ov
    dots[row, col] = True
    if block:
        # the other column of the character, and the neighbouring row inside it
        other_col = col ^ 1
        other_row = np.where(row % DOT_ROWS == DOT_ROWS - 1, row - 1, row + 1)
        dots[row, other_col] = True
        dots[other_row, col] = True
        dots[other_row, other_col] = True


def pack_braille(dots: np.ndarray) -> np.ndarray:
    """Pack a (rows * 4, cols * 2) dot array into (rows, cols) braille bit patterns."""
    height, width = dots.shape
    rows, cols = height // DOT_ROWS, width // DOT_COLS
    cells = dots[: rows * DOT_ROWS, : cols * DOT_COLS].reshape(rows, DOT_ROWS, cols, DOT_COLS)
    codes = np.zeros((rows, cols), np.uint8)
    for r in range(DOT_ROWS):
        for c in range(DOT_COLS):
            codes |= cells[:, r, :, c].view(np.uint8) * DOT_BITS[r, c]
    return codes


def braille_text(codes: np.ndarray) -> str:
    """One row of bit patterns as text: braille glyphs, a plain space where no dot is set."""
    chars = np.where(codes == 0, SPACE, BRAILLE_BLANK + codes.astype(np.uint32)).astype("<u4")
    return chars.tobytes().decode("utf-32-le")
