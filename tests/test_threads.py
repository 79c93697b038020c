"""Builds on several threads give the same Diagram, bit for bit, as on one.

The split phases are the dual's vertices (circumcentres, by blocks of triangles) and walks, which mark
the zero-length edges (dual.voronoi_from_delaunay), and the clipping of the cells (clip.clip_cells). The API tests use enough sites for the clipper to split; the
kernel tests force the split on every adversarial family, small as they are.
"""

import numpy as np
import pytest

import tvoronoi
from tests import adversarial
from tests.invariants import assert_same_diagram as assert_same
from tvoronoi import engines
from tvoronoi.api import as_bbox, default_bbox
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import generate
from tvoronoi.kernels import clip, dual


def grid(side: int) -> np.ndarray:
    g = np.arange(float(side))
    x, y = np.meshgrid(g, g)
    return np.c_[x.ravel(), y.ravel()]


LARGE = {
    "uniform": lambda: generate("uniform", 40_000, seed=3),
    "clustered": lambda: generate("clustered", 40_000, seed=4),
    # every square cocircular: the merged vertices and dropped zero-length edges
    "grid": lambda: grid(200),
    "rounded": lambda: np.round(generate("uniform", 40_000, seed=5), 2),  # repeats and cocircular ties
}


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("name", sorted(LARGE))
def test_api_threads_give_the_same_diagram(name, engine):
    pts = LARGE[name]()
    one = tvoronoi.voronoi(pts, engine=engine, threads=1)
    for threads in (2, 3):
        assert_same(one, tvoronoi.voronoi(pts, engine=engine, threads=threads))


def test_api_threads_with_a_box_that_cuts():
    pts = generate("uniform", 40_000, seed=6)
    box = (0.2, 0.1, 0.7, 0.95)
    assert_same(tvoronoi.voronoi(pts, bbox=box, threads=1), tvoronoi.voronoi(pts, bbox=box, threads=2))


def test_default_threads_match_one_thread():
    pts = generate("gaussian", 40_000, seed=7)
    assert_same(tvoronoi.voronoi(pts, threads=1), tvoronoi.voronoi(pts))


@pytest.mark.parametrize("bad", [0, -1, 1.5, "2", True])
def test_bad_thread_counts_are_refused(bad):
    with pytest.raises(TvoronoiError, match="threads"):
        tvoronoi.voronoi([[0, 0], [1, 0], [0, 1]], threads=bad)


@pytest.mark.parametrize("order", ["shuffled", "reversed", "halves_swapped"])
@pytest.mark.parametrize("n", [3_000, 40_000])
def test_dual_first_pass_on_threads_with_triangles_in_any_order(order, n):
    """The dual's first pass on several threads: each thread writes the sites of its run of triangles
    and lists the others, merged after (the least half-edge wins); a run that meets too many of them
    falls back to one thread. Triangles in an order far from their sites' (shuffled: 40,000 sites
    overflow the lists; reversed; the two halves swapped) give the same DCEL on 1, 2, 3 and 5 threads."""
    rng = np.random.default_rng(n)
    pts = rng.random((n, 2))
    e = engines.scale_exponent(pts)
    t = engines.run(pts[:, 0], pts[:, 1], engine="incremental", exponent=e)
    s, n_tri = t.sites, len(t.tv) // 3
    if order == "shuffled":
        new_of_old = rng.permutation(n_tri)
    elif order == "reversed":
        new_of_old = np.arange(n_tri)[::-1].copy()
    else:
        new_of_old = np.roll(np.arange(n_tri), n_tri // 2)
    old_of_new = np.argsort(new_of_old)
    tv = t.tv.reshape(-1, 3)[old_of_new].ravel()
    twin = t.opp.reshape(-1, 3)[old_of_new].ravel()
    opp = (3 * new_of_old[twin // 3] + twin % 3).astype(np.int32)
    outs = [dual.voronoi_from_delaunay(s.xs, s.ys, tv, opp, e, k, parallel_min=1) for k in (1, 2, 3, 5)]
    assert len(outs[0]["he_origin"]) > 0
    for out in outs[1:]:
        for key in outs[0]:
            assert np.array_equal(outs[0][key], out[key]), key


@pytest.mark.parametrize("name", sorted(adversarial.FAMILIES))
def test_kernels_split_on_every_family(name):
    case = adversarial.make(name)
    pts = case.points
    assert_same(tvoronoi.voronoi(pts, bbox=case.bbox, threads=1), tvoronoi.voronoi(pts, bbox=case.bbox, threads=2))
    box = default_bbox(pts) if case.bbox is None else as_bbox(case.bbox)
    e = engines.scale_exponent(pts)
    t = engines.run(pts[:, 0], pts[:, 1], engine="incremental", exponent=e)
    if t.flat:
        return  # collinear sites: parallel strips, no triangles and nothing split
    s = t.sites
    outs = [dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1) for threads in (1, 2, 3)]
    # the walks in runs of 1 to 5 sites: a run's lookups into the runs before it wait for the pass after
    outs += [
        dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, walk_chunk=chunk)
        for threads, chunk in ((2, 1), (2, 3), (3, 2), (2, 5))
    ]
    for out in outs[1:]:
        for key in outs[0]:
            assert np.array_equal(outs[0][key], out[key]), key
    out = outs[0]
    active = (t.dup < 0).astype(np.int8)
    cells = [
        clip.clip_cells(
            s.xs,
            s.ys,
            out["vertices"],
            out["he_origin"],
            out["he_twin"],
            out["he_face"],
            out["face_edge"],
            active,
            box,
            e,
            threads,
            parallel_min=1,
        )
        for threads in (1, 2, 3)
    ]
    for got in cells[1:]:
        assert got[3] == cells[0][3] == 0
        for x, y in zip(got[:3], cells[0][:3]):
            assert np.array_equal(x, y)
    # the new points written into the dual's room after the vertices: the same points and rings
    roomy = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, 2, parallel_min=1, clip_room=True)
    room = roomy["vertex_room"]

    def clip_into(buffer):
        keys = ("vertices", "he_origin", "he_twin", "he_face", "face_edge")
        return clip.clip_cells(s.xs, s.ys, *(roomy[k] for k in keys), active, box, e, 2, parallel_min=1, room=buffer)

    got = clip_into(room)
    assert np.shares_memory(got[0], room)
    for x, y in zip(got[:3], cells[0][:3]):
        assert np.array_equal(x, y)
    # room that does not start with the vertices, or is too small: a copy, the same result
    for other in (room.copy(), room[: len(roomy["vertices"]) + 3]):
        got = clip_into(other)
        assert not np.shares_memory(got[0], other)
        for x, y in zip(got[:3], cells[0][:3]):
            assert np.array_equal(x, y)


def test_walks_in_any_runs_find_the_same_zero_length_edges():
    """Hypothesis hunts over small integer and rounded point sets (cocircular quadruples everywhere,
    repeats, collinear runs): the dual on 2 or 3 threads with walks in runs of any length, where a
    twin made by another run waits for the pass after the walks, equals the one-thread dual, and its
    zero-length edges are exactly the Delaunay edges between cocircular triangles."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    @st.composite
    def sites(draw):
        side = draw(st.integers(2, 12))
        k = draw(st.integers(3, 160))
        pts = draw(st.lists(st.tuples(st.integers(0, side), st.integers(0, side)), min_size=k, max_size=k))
        pts = np.array(pts, float)
        angle = draw(st.sampled_from([0.0, 0.5, 1.0]))
        if angle:  # a lattice turned and rounded: cocircular ties that only the exact tests see
            c, s = np.cos(angle), np.sin(angle)
            pts = np.round(pts @ np.array([[c, -s], [s, c]]), draw(st.integers(0, 3)))
        return pts

    @settings(max_examples=150, deadline=None)
    @given(sites(), st.integers(1, 9), st.integers(2, 3))
    def check(pts, chunk, threads):
        e = engines.scale_exponent(pts)
        t = engines.run(pts[:, 0], pts[:, 1], engine="incremental", exponent=e)
        if t.flat:
            return
        s = t.sites
        one = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, 1)
        many = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, walk_chunk=chunk)
        for key in one:
            assert np.array_equal(one[key], many[key]), key
        # every Voronoi edge left has two distinct ends (the zero-length ones are all gone) ...
        h, nxt_origin = one["he_origin"], np.empty_like(one["he_origin"])
        face, first = one["he_face"], one["face_edge"]
        last = np.r_[face[1:] != face[:-1], True]
        nxt_origin[~last] = h[1:][~last[:-1]]
        nxt_origin[last] = h[first[face[last]]]
        both = (h >= 0) & (nxt_origin >= 0)
        assert np.all(h[both] != nxt_origin[both])
        # ... and as many vertices as the triangles have distinct circumcircles (exactly, in rationals)
        assert len(one["vertices"]) == distinct_circles(s.xs, s.ys, t.tv)

    check()


def distinct_circles(xs, ys, tv) -> int:
    """The number of distinct circumcircles of the finite triangles, in exact rational arithmetic:
    a merged vertex per group of cocircular triangles that share edges (groups of a Delaunay
    triangulation with one circle are connected), so distinct circles and merged vertices agree."""
    from fractions import Fraction

    n = len(xs)
    circles = set()
    for t in np.asarray(tv).reshape(-1, 3):
        if n in t:
            continue
        (ax, ay), (bx, by), (cx, cy) = ((Fraction(xs[i]), Fraction(ys[i])) for i in t)
        d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
        ux = ((ax * ax + ay * ay) * (by - cy) + (bx * bx + by * by) * (cy - ay) + (cx * cx + cy * cy) * (ay - by)) / d
        uy = ((ax * ax + ay * ay) * (cx - bx) + (bx * bx + by * by) * (ax - cx) + (cx * cx + cy * cy) * (bx - ax)) / d
        circles.add((ux, uy))
    return len(circles)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_repeated_rows_past_the_sampled_cut_on_threads(engine):
    """150,000 rows, 45,000 of them repeating earlier places (some several times), past the size from
    which the halves are cut at a sampled median: the same Diagram on 1 and 2 threads, each row's cell
    held by the first row at its place (site_of is built as the identity and only those rows written),
    every cell valid."""
    from tests.invariants import validate
    from tvoronoi import halves

    rng = np.random.default_rng(5)
    base = np.round(rng.random((105_000, 2)) * 1000, 2)
    pts = np.vstack([base, base[rng.integers(0, len(base), 45_000)]])
    pts = pts[rng.permutation(len(pts))]
    assert len(pts) > 2 * halves.SAMPLE_SITES
    _, first_row, inverse = np.unique(pts, axis=0, return_index=True, return_inverse=True)
    one, two = (tvoronoi.voronoi(pts, engine=engine, threads=t) for t in (1, 2))
    assert_same(one, two)
    assert np.array_equal(one.site_of, first_row[inverse.ravel()])
    validate(one)
