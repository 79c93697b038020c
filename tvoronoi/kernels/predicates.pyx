"""Exact orientation and in-circle signs of double coordinates, callable from Python for tests and benchmarks."""
# The predicates themselves are the inline functions of predicates.pxd: Cython reads a module's own
# .pxd automatically, so orient2d and incircle are in scope here without a cimport. Other kernels
# write `from tvoronoi.kernels.predicates cimport orient2d, incircle` and get them compiled inline.
# The Python wrappers carry a _sign suffix so that they do not clash with those cdef names.

import numpy as np


def orient2d_sign(double ax, double ay, double bx, double by, double cx, double cy) -> int:
    """Turn of the points a, b, c, exactly.

    Parameters
    ----------
    ax, ay, bx, by, cx, cy : float
        Finite coordinates of the three points.

    Returns
    -------
    int
        +1 if a, b, c are counter-clockwise, -1 if clockwise, 0 if collinear.

    Examples
    --------
    >>> orient2d_sign(0.0, 0.0, 1.0, 0.0, 0.0, 1.0)
    1
    >>> orient2d_sign(0.5000000000000001, 0.5, 12.0, 12.0, 24.0, 24.0)  # plain doubles would say 0
    -1
    """
    return orient2d(ax, ay, bx, by, cx, cy)


def incircle_sign(double ax, double ay, double bx, double by, double cx, double cy,
                  double dx, double dy) -> int:
    """Position of d against the circle through a, b, c, exactly.

    Parameters
    ----------
    ax, ay, bx, by, cx, cy, dx, dy : float
        Finite coordinates of the four points.

    Returns
    -------
    int
        With a, b, c counter-clockwise: +1 if d lies strictly inside their circle, -1 outside,
        0 on it (the sign flips when a, b, c are clockwise).

    Examples
    --------
    >>> incircle_sign(5.0, 0.0, 0.0, 5.0, -5.0, 0.0, 3.0, -4.0)
    0
    >>> incircle_sign(5.0, 0.0, 0.0, 5.0, -5.0, 0.0, 3.0, -3.9999999999999996)
    1
    """
    return incircle(ax, ay, bx, by, cx, cy, dx, dy)


def _check_rows(name_shapes):
    n_rows = name_shapes[0][1][0]
    for name, shape in name_shapes:
        if shape[0] != n_rows or shape[1] != 2:
            raise ValueError(
                f"{name} has shape ({shape[0]}, {shape[1]}); every argument must have shape ({n_rows}, 2)"
            )
    return n_rows


def orient2d_many(const double[:, ::1] a, const double[:, ::1] b, const double[:, ::1] c) -> np.ndarray:
    """Row-wise orient2d of three point arrays.

    Parameters
    ----------
    a, b, c : ndarray of float64, shape (n, 2), C-contiguous
        Row i holds the points a_i, b_i, c_i.

    Returns
    -------
    ndarray of int8, shape (n,)
        The sign of each row as in `orient2d_sign`.

    Raises
    ------
    ValueError
        If the arrays do not share one shape (n, 2).
    """
    cdef Py_ssize_t n_rows = _check_rows([("a", a.shape), ("b", b.shape), ("c", c.shape)])
    out = np.empty(n_rows, dtype=np.int8)
    cdef signed char[::1] signs = out
    cdef Py_ssize_t i
    with nogil:
        for i in range(n_rows):
            signs[i] = <signed char>orient2d(a[i, 0], a[i, 1], b[i, 0], b[i, 1], c[i, 0], c[i, 1])
    return out


def incircle_many(const double[:, ::1] a, const double[:, ::1] b, const double[:, ::1] c,
                  const double[:, ::1] d) -> np.ndarray:
    """Row-wise incircle of four point arrays.

    Parameters
    ----------
    a, b, c, d : ndarray of float64, shape (n, 2), C-contiguous
        Row i holds the points a_i, b_i, c_i, d_i.

    Returns
    -------
    ndarray of int8, shape (n,)
        The sign of each row as in `incircle_sign`.

    Raises
    ------
    ValueError
        If the arrays do not share one shape (n, 2).
    """
    cdef Py_ssize_t n_rows = _check_rows(
        [("a", a.shape), ("b", b.shape), ("c", c.shape), ("d", d.shape)]
    )
    out = np.empty(n_rows, dtype=np.int8)
    cdef signed char[::1] signs = out
    cdef Py_ssize_t i
    with nogil:
        for i in range(n_rows):
            signs[i] = <signed char>incircle(a[i, 0], a[i, 1], b[i, 0], b[i, 1],
                                             c[i, 0], c[i, 1], d[i, 0], d[i, 1])
    return out
