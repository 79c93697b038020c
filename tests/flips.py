"""Spoiling a triangulation for the tests of its guards: interior edges flipped where the flip is valid."""

import numpy as np

from tvoronoi.kernels import predicates


def nxt(h: int) -> int:
    return h - 2 if h % 3 == 2 else h + 1


def prv(h: int) -> int:
    return h + 2 if h % 3 == 0 else h - 1


def flip_edges(xs: np.ndarray, ys: np.ndarray, tv: np.ndarray, opp: np.ndarray, rng, count: int) -> int:
    """Flip up to ``count`` random edges of triangulation tv, opp in place (vertex len(xs) at infinity):
    edges between two finite triangles whose quadrilateral is strictly convex (exact orientation), so
    that the result is still a triangulation. Returns how many were flipped."""
    n, flipped = len(xs), 0
    for e in rng.permutation(len(tv)):
        o = opp[e]
        t, u = e // 3, o // 3
        if n in tv[3 * t : 3 * t + 3] or n in tv[3 * u : 3 * u + 3]:
            continue
        a, b, c, d = tv[e], tv[nxt(e)], tv[prv(e)], tv[prv(o)]

        def turn(p: int, q: int, r: int) -> int:
            return predicates.orient2d_sign(xs[p], ys[p], xs[q], ys[q], xs[r], ys[r])

        # (a, b, c) and (b, a, d) counter-clockwise: the new diagonal c-d needs c, a, d and d, b, c to turn left
        if turn(c, a, d) <= 0 or turn(d, b, c) <= 0:
            continue
        e2, o2 = prv(e), prv(o)
        A, B = opp[e2], opp[o2]
        tv[e], tv[o] = d, c
        opp[e], opp[B] = B, e
        opp[o], opp[A] = A, o
        opp[e2], opp[o2] = o2, e2
        flipped += 1
        if flipped == count:
            break
    return flipped
