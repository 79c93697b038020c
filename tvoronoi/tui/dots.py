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


def segment_dots(dots: np.ndarray, u0, v0, u1, v1, *, dash: int = 0) -> None:
    """Set the dots along many segments at once.

    Each segment is clipped to the dot array, then sampled once per dot
    along its longer axis (a vectorised DDA), so consecutive samples touch
    and a line has no gaps.

    Parameters
    ----------
    dots : (H, W) bool, changed in place
    u0, v0, u1, v1 : (k,) float
        Segment ends in continuous dot coordinates; they may lie outside.
        Segments with a NaN end are skipped.
    dash : int
        If > 0, draw dashes: ``dash`` dots on, ``dash`` dots off.
    """
    height, width = dots.shape
    u0, v0, u1, v1 = (np.asarray(c, np.float64).ravel() for c in (u0, v0, u1, v1))
    if u0.size == 0 or width == 0 or height == 0:
        return
    # drop the segments wholly beyond one side
    lo_u, hi_u = np.minimum(u0, u1), np.maximum(u0, u1)
    lo_v, hi_v = np.minimum(v0, v1), np.maximum(v0, v1)
    near = (hi_u >= 0) & (lo_u < width) & (hi_v >= 0) & (lo_v < height)
    if not near.all():
        u0, v0, u1, v1 = u0[near], v0[near], u1[near], v1[near]
        lo_u, hi_u, lo_v, hi_v = lo_u[near], hi_u[near], lo_v[near], hi_v[near]
    # clip the segments that cross a side; an end the clip moves is not the segment's own
    crossing = (lo_u < 0) | (hi_u >= width) | (lo_v < 0) | (hi_v >= height)
    own0 = np.ones(u0.shape, bool)
    own1 = np.ones(u0.shape, bool)
    if crossing.any():
        # clip copies: the caller's arrays stay as they were
        u0, v0, u1, v1 = u0.copy(), v0.copy(), u1.copy(), v1.copy()
        keep = np.ones(u0.shape, bool)
        keep[crossing], t0, t1, u0[crossing], v0[crossing], u1[crossing], v1[crossing] = _clip(
            u0[crossing], v0[crossing], u1[crossing], v1[crossing], width, height
        )
        own0[crossing], own1[crossing] = t0 == 0, t1 == 1
        u0, v0, u1, v1, own0, own1 = u0[keep], v0[keep], u1[keep], v1[keep], own0[keep], own1[keep]
    # one sample per dot along the longer axis, at the dot's centre line: the samples
    # depend on the line only, not on where it was cut, so a part of the canvas drawn
    # on its own gets the same dots as the whole
    steep = np.abs(v1 - v0) > np.abs(u1 - u0)
    if dash <= 0:
        # a segment of its own ends within one dot along its longer axis has one sample, in the
        # dot of an end (the same column or row, a height between the ends'): its ends, drawn
        # below, are all its dots. Most edges of a zoomed-out view are such.
        short = own0 & own1 & np.where(steep, np.floor(v0) == np.floor(v1), np.floor(u0) == np.floor(u1))
        if short.any():
            cols_e = np.concatenate([u0[short], u1[short]])
            rows_e = np.concatenate([v0[short], v1[short]])
            long = ~short
            u0, v0, u1, v1, own0, own1, steep = (u0[long], v0[long], u1[long], v1[long], own0[long],
                                                 own1[long], steep[long])
            _set_dots(dots, cols_e, rows_e)
    flat = ~steep
    cols_f, rows_f = _centre_samples(u0[flat], u1[flat], v0[flat], v1[flat], own0[flat], own1[flat], dash)
    rows_s, cols_s = _centre_samples(v0[steep], v1[steep], u0[steep], u1[steep], own0[steep], own1[steep], dash)
    cols, rows = [cols_f, cols_s], [rows_f, rows_s]
    if dash <= 0:
        # the segment's own ends are always drawn
        cols += [u0[own0], u1[own1]]
        rows += [v0[own0], v1[own1]]
    _set_dots(dots, np.concatenate(cols), np.concatenate(rows))


def _set_dots(dots: np.ndarray, cols: np.ndarray, rows: np.ndarray) -> None:
    """Set the dots holding points (cols, rows) in continuous dot coordinates; points beyond the
    canvas (rounding, a cut end between two dot centres) belong to no dot here."""
    height, width = dots.shape
    inside = (cols >= 0) & (cols < width) & (rows >= 0) & (rows < height)
    if not inside.all():
        cols, rows = cols[inside], rows[inside]
    dots.ravel()[rows.astype(np.int64) * width + cols.astype(np.int64)] = True


def _centre_samples(a0, a1, b0, b1, own0, own1, dash: int):
    """Points along segments at every dot centre line of their major axis ``a`` (as floats).

    A centre beyond the segment's own end is pulled back onto it; beyond an
    end the clip made, it lies off the canvas and the caller drops it.
    """
    flip = a1 < a0
    a0, a1 = np.where(flip, a1, a0), np.where(flip, a0, a1)
    b0, b1 = np.where(flip, b1, b0), np.where(flip, b0, b1)
    own_lo, own_hi = np.where(flip, own1, own0), np.where(flip, own0, own1)
    k0 = np.floor(a0)
    counts = (np.floor(a1) - k0).astype(np.int64) + 1
    first = np.cumsum(counts) - counts
    owner = np.repeat(np.arange(counts.size), counts)
    a = np.arange(owner.size, dtype=np.float64) + np.repeat(k0 + 0.5 - first, counts)
    # the first and last sample of each segment, where its own end is nearer than the centre
    last = first + counts - 1
    if counts.size:
        a[first] = np.where(own_lo, np.maximum(a[first], a0), a[first])
        a[last] = np.where(own_hi, np.minimum(a[last], a1), a[last])
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
    return (keep, t0, t1,
            np.where(start, u0, u0 + t0 * du), np.where(start, v0, v0 + t0 * dv),
            np.where(end, u1, u0 + t1 * du), np.where(end, v1, v0 + t1 * dv))


def clip_segments(seg: np.ndarray, bbox) -> np.ndarray:
    """World segments (k, 4) cut to a box (xmin, ymin, xmax, ymax); those wholly outside dropped."""
    seg = np.asarray(seg, np.float64).reshape(-1, 4)
    if not len(seg):
        return seg
    xmin, ymin, xmax, ymax = (float(c) for c in bbox)
    keep, _, _, u0, v0, u1, v1 = _clip(seg[:, 0] - xmin, seg[:, 1] - ymin, seg[:, 2] - xmin, seg[:, 3] - ymin,
                                       xmax - xmin, ymax - ymin)
    out = np.column_stack([u0 + xmin, v0 + ymin, u1 + xmin, v1 + ymin])
    return out[keep & np.isfinite(out).all(axis=1)]


def point_dots(dots: np.ndarray, u, v, *, block: bool = False) -> None:
    """Set the dot under each point that falls on the array.

    With ``block``, set the 2 x 2 dots around it inside its own character,
    so that a lone site reads as a spot.
    """
    height, width = dots.shape
    u = np.asarray(u, np.float64).ravel()
    v = np.asarray(v, np.float64).ravel()
    inside = (u >= 0) & (u < width) & (v >= 0) & (v < height)  # False for NaN too
    col = u[inside].astype(np.int64)
    row = v[inside].astype(np.int64)
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
