"""From checked points to a Diagram: scale exactly, run an engine, clip the cells, map back to input rows."""

from __future__ import annotations

import math

import numpy as np

from tvoronoi.diagram import Diagram
from tvoronoi.errors import TvoronoiError
from tvoronoi.kernels import clip, dcel, delaunay, fortune, order


def power_of_two_scale(pts: np.ndarray) -> int:
    """Exponent e such that the sites' coordinates * 2**-e are at most 1 in magnitude.

    Scaling by a power of two is exact, and keeps the predicates' products
    (degree four in incircle) far from overflow and underflow at any scale.
    Only the sites set it: a box far larger or smaller than the sites costs no
    precision, within the limits of check_box_scale.
    """
    top = float(np.abs(pts).max()) if len(pts) else 0.0
    return math.frexp(top)[1] if top > 0 else 0


# Box sides in the sites' scaled unit. From above, the exact products split a box coordinate into
# halves by multiplying it with 2^27 + 1 (Dekker), which must not overflow: about 2^997, a little
# under (1.3e300 for sites of unit size). From below, a side times a coordinate difference (down to
# 2^-223) must not underflow. Ring tests between points of the box and the sites, whose magnitudes
# may then span 2^1700, are exact at any span (clipper.turn).
BOX_SCALED_MIN = 2.0 ** -700
BOX_SCALED_MAX = math.ldexp(1.0 - 2.0 ** -20, 997)


def check_box_scale(box, e: int) -> None:
    """Refuse a box whose sides the exact tests could not handle in the sites' scaled unit."""
    for name, v in zip(("xmin", "ymin", "xmax", "ymax"), box):
        if v == 0.0:
            continue
        # |v| * 2^-e without overflow or underflow, whatever e: compare the exponents first
        k = math.frexp(v)[1] - e
        s = abs(math.ldexp(math.frexp(v)[0], k)) if -1000 < k < 1000 else math.inf if k > 0 else 0.0
        if not (BOX_SCALED_MIN <= s <= BOX_SCALED_MAX):
            raise TvoronoiError(
                f"bbox {name} = {v!r} is beyond the exact range for these sites (their largest "
                f"coordinate is about 2^{e}): a nonzero box side must lie between 2^-700 and about "
                f"2^997 (1.3e300) times that; choose a box nearer the sites' scale"
            )


def first_copies(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """For each point, the first earlier index with identical coordinates, or -1."""
    n = len(xs)
    dup = np.full(n, -1, np.int32)
    if n < 2:
        return dup
    order = np.lexsort((ys, xs))            # stable: earlier indices first within a tie
    same = (xs[order][1:] == xs[order][:-1]) & (ys[order][1:] == ys[order][:-1])
    if not same.any():
        return dup
    # the start of each run of equal points, carried along the run
    start = np.maximum.accumulate(np.where(np.concatenate(([True], ~same)), np.arange(n), 0))
    first = order[start]
    dup[order] = np.where(first != order, first, -1)
    return dup


def collinear_dcel(xs: np.ndarray, ys: np.ndarray) -> dict:
    """Voronoi DCEL of 0, 1, 2 or more collinear sites (parallel strips), repeats included."""
    dup = first_copies(xs, ys)
    distinct = np.flatnonzero(dup < 0)
    line = distinct[np.lexsort((ys[distinct], xs[distinct]))]   # sorted by x then y: line order
    out = dcel.voronoi_collinear(np.ascontiguousarray(xs[line]), np.ascontiguousarray(ys[line]))
    out["he_face"] = line[out["he_face"]].astype(np.int32)
    face_edge = np.full(len(xs), -1, np.int32)
    face_edge[line] = out["face_edge"]
    out["face_edge"] = face_edge
    out["dup"] = dup
    return out


def incremental_dcel(xs: np.ndarray, ys: np.ndarray, *, insertion: str, seed: int, exponent: int = 0):
    """Run the randomized incremental engine on sites in input order.

    Returns (perm, out): the engine numbers site k = input site perm[k]
    (insertion order), and out holds its Voronoi DCEL and repeats in that
    numbering; its vertices are in the unit 2^exponent times that of xs, ys.
    """
    if insertion == "brio":
        perm = order.brio_order(xs, ys, seed)
    else:
        perm = np.random.default_rng(seed).permutation(len(xs)).astype(np.int32)
    xs = np.ascontiguousarray(xs[perm])
    ys = np.ascontiguousarray(ys[perm])
    status, tv, opp, dup = delaunay.triangulate(xs, ys, conflict_lists=(insertion == "random"))
    if status != delaunay.STATUS_OK:
        return perm, xs, ys, collinear_dcel(xs, ys)
    out = dcel.voronoi_from_delaunay(xs, ys, tv, opp, exponent)
    out["dup"] = dup
    return perm, xs, ys, out


def sweep_order(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Event order of Fortune's sweep: by y, then x (int32)."""
    perm = np.argsort(ys)
    sy = ys[perm]
    if len(sy) > 1 and np.any(sy[1:] == sy[:-1]):
        # rows of equal y: order them by x (a complex sort compares real, then imaginary parts)
        perm = np.argsort(ys + 1j * xs, kind="stable")
    return perm.astype(np.int32)


def sweep_checked(xs: np.ndarray, ys: np.ndarray) -> dict:
    """fortune.sweep on sites in sweep order; a state the sweep could not complete is an error, never a result."""
    result = fortune.sweep(xs, ys)
    if result["status"] != fortune.STATUS_OK:
        raise TvoronoiError(
            f"{fortune.STATUS_MESSAGES[result['status']]} on {len(xs)} points; "
            "build with engine='incremental' instead, and please report the input"
        )
    return result


def fortune_dcel(xs: np.ndarray, ys: np.ndarray, exponent: int = 0):
    """Run Fortune's sweep on sites in input order; returns (perm, xs, ys, out) as incremental_dcel."""
    perm = sweep_order(xs, ys)
    xs = np.ascontiguousarray(xs[perm])
    ys = np.ascontiguousarray(ys[perm])
    result = sweep_checked(xs, ys)
    if "tv" not in result:
        return perm, xs, ys, collinear_dcel(xs, ys)
    out = dcel.voronoi_from_delaunay(xs, ys, result["tv"], result["opp"], exponent)
    out["dup"] = result["dup"]
    return perm, xs, ys, out


def build_diagram(pts: np.ndarray, box, *, engine: str, insertion: str, seed: int) -> Diagram:
    """Build the Diagram of checked points (n, 2) in the checked box."""
    e = power_of_two_scale(pts)
    check_box_scale(box, e)
    xs = np.ldexp(pts[:, 0], -e)
    ys = np.ldexp(pts[:, 1], -e)
    if engine == "incremental":
        perm, exs, eys, out = incremental_dcel(xs, ys, insertion=insertion, seed=seed, exponent=e)
    else:
        perm, exs, eys, out = fortune_dcel(xs, ys, exponent=e)
    return assemble(pts, box, e, perm, exs, eys, out, engine=engine)


def assemble(pts, box, e, perm, exs, eys, out, *, engine, present=None, first_row_holds=True) -> Diagram:
    """Clip an engine's DCEL and map it back to input rows.

    Parameters
    ----------
    pts : (n, 2) the input points; box : the box, unscaled; e : the scale exponent
        (the vertices in ``out`` are already in the user's unit)
    perm : (n,) engine site k is input row perm[k]; exs, eys : scaled sites in engine order
    out : the engine's DCEL dict (with ``dup``)
    present : (n,) bool in engine order, optional -- sites already in the
        diagram (the step trace shows diagrams of the first sites only)
    first_row_holds : bool
        A place shared by repeated points gets its cell under the first input
        row there (batch); False keeps it with the site the engine holds it by
        (dynamic diagrams, where the oldest copy at a place holds it).
    """
    n = len(pts)
    dup = out["dup"]
    first = dup < 0 if present is None else (dup < 0) & present
    points, offsets, ring, status = clip.clip_cells(
        exs, eys, out["vertices"], out["he_origin"], out["he_twin"], out["he_next"], out["he_prev"],
        out["he_face"], out["face_edge"], first.astype(np.int8), box, e,
    )
    if status != 0:
        from tvoronoi.errors import EngineError

        raise EngineError("the clipper found a cell whose edges do not chain: please report this input")

    # the cell of a repeated point belongs to the first input row at that place
    root = np.where(dup >= 0, dup, np.arange(n, dtype=np.int32))
    owner = perm.copy()                              # engine site -> input row owning its cell
    if first_row_holds and (dup >= 0).any():
        np.minimum.at(owner, root, perm)
    site_of = np.empty(n, np.int32)
    site_of[perm] = owner[root]

    # cells to input rows (CSR gather)
    lengths = np.diff(offsets)
    cell_of_row = np.full(n, -1, np.int64)           # engine site whose cell row r shows
    firsts = np.flatnonzero(first)
    cell_of_row[owner[firsts]] = firsts
    row_len = np.where(cell_of_row >= 0, lengths[np.maximum(cell_of_row, 0)], 0)
    cell_offsets = np.zeros(n + 1, np.int64)
    np.cumsum(row_len, out=cell_offsets[1:])
    src_start = np.where(cell_of_row >= 0, offsets[:-1][np.maximum(cell_of_row, 0)], 0)
    gather = np.repeat(src_start - cell_offsets[:-1], row_len) + np.arange(cell_offsets[-1])
    cell_vertices = ring[gather]

    face_edge = np.full(n, -1, np.int32)
    face_edge[owner[firsts]] = out["face_edge"][firsts]
    return Diagram(
        sites=pts,
        site_of=site_of,
        vertices=out["vertices"],
        he_origin=out["he_origin"],
        he_twin=out["he_twin"],
        he_next=out["he_next"],
        he_prev=out["he_prev"],
        he_face=owner[out["he_face"]],
        face_edge=face_edge,
        triangles=owner[out["triangles"]].astype(np.int32).reshape(-1, 3),
        bbox=tuple(float(v) for v in box),
        cell_points=points,
        cell_offsets=cell_offsets,
        cell_vertices=cell_vertices,
        engine=engine,
    )
