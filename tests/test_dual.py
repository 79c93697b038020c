"""The dual's layout: vertices numbered in the triangles' order, cells walked in the sites' order.

dual.voronoi_from_delaunay numbers the Voronoi vertices before it walks the cells: the finite triangles
in the order of the triangulation, each vertex its triangle's correctly rounded circumcentre; the
walks then give every half-edge the vertex of the triangle on the right of its Delaunay edge.
Cocircular sites merge vertices (the smallest number kept) and drop the zero-length edges between them.
"""

import numpy as np
import pytest

from tests import adversarial
from tvoronoi import engines
from tvoronoi.generators import generate
from tvoronoi.kernels import dual, predicates


def triangulated(pts: np.ndarray, engine: str):
    e = engines.scale_exponent(pts)
    t = engines.run(pts[:, 0], pts[:, 1], engine=engine, exponent=e)
    return None if t.flat else (t, e)


def finite_rows(t) -> np.ndarray:
    rows = t.tv.reshape(-1, 3)
    return rows[(rows < len(t.sites.xs)).all(axis=1)]


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("name", sorted(adversarial.FAMILIES))
def test_vertices_come_in_the_triangles_order(name, engine):
    got = triangulated(adversarial.make(name).points, engine)
    if got is None:
        return  # collinear sites: strips, no vertex
    t, e = got
    s = t.sites
    out = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e)
    tri = finite_rows(t)
    assert np.array_equal(out["triangles"], tri)
    centres = dual.circumcentres(s.xs, s.ys, np.ascontiguousarray(tri), e)
    m = len(out["vertices"])
    if m == len(tri):
        # no merge: vertex k is row k's circumcentre, bit for bit
        assert np.array_equal(out["vertices"], centres)
    else:
        # merges keep each group's first vertex: the vertices are the centres of some rows, in order
        # (equal centres only where cocircular triangles merged)
        kept = np.unique(out["he_origin"][out["he_origin"] >= 0])
        assert np.array_equal(kept, np.arange(m))
        assert {tuple(v) for v in out["vertices"]} <= {tuple(c) for c in centres}


def origins_checked(out) -> int:
    """Half-edge g of site a's cell lies on the bisector of a and b (its twin's site); its origin is the
    circumcentre of the triangle on the right of the Delaunay edge a->b: the one in which a follows b
    counter-clockwise; -1 where that triangle is infinite. Around a cell, each half-edge starts where
    the one before it ends (its twin's origin). Returns how many origins were finite."""
    # each finite triangle's vertex number, by the directed edges it holds: (p, q) -> the triangle
    # where q follows p counter-clockwise
    by_edge = {}
    for k, (p, q, r) in enumerate(out["triangles"].tolist()):
        by_edge[(p, q)] = by_edge[(q, r)] = by_edge[(r, p)] = k
    face, twin, origin = out["he_face"], out["he_twin"], out["he_origin"]
    checked = 0
    for g in range(len(face)):
        a, b = int(face[g]), int(face[twin[g]])
        assert twin[twin[g]] == g and a != b
        if g + 1 < len(face) and face[g + 1] == a:
            assert origin[g + 1] == origin[twin[g]]
        right = by_edge.get((b, a))
        if right is None:
            assert origin[g] == -1
        else:
            assert origin[g] == right
            checked += 1
    return checked


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_each_origin_is_the_centre_of_the_triangle_on_the_right(engine):
    pts = generate("uniform", 3000, seed=12)
    t, e = triangulated(pts, engine)
    s = t.sites
    out = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e)
    assert origins_checked(out) > 0.9 * len(out["he_face"])


@pytest.mark.parametrize("given", [False, True])
@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_sites_of_hundreds_of_neighbours_have_their_cells_in_order(engine, given):
    """The walks gather a cell's edges in runs (dual.RING at a time): hubs of 150 to 1,500 Delaunay
    neighbours (a centre inside a ring of sites, rounded to a grid, some of it on the hull) give the
    same cells on one thread and on two, each half-edge on the triangle on its right."""
    rng = np.random.default_rng(5)
    parts = []
    for k, (cx, cy, count) in enumerate([(0, 0, 1500), (5000, 0, 150), (0, 5000, 400)]):
        angle = np.sort(rng.uniform(0, 2 * np.pi, count))
        ring = np.column_stack([cx + 1000 * np.cos(angle), cy + 1000 * np.sin(angle)])
        parts += [np.round(ring, 6 - k), [[cx + 0.5, cy - 0.25]]]
    t, e = triangulated(np.vstack(parts), engine)
    s = t.sites
    runs = []
    for threads in (1, 2):
        tv, opp = (t.tv.copy(), t.opp.copy()) if given else (t.tv, t.opp)
        out = dual.voronoi_from_delaunay(
            s.xs, s.ys, tv, opp, e, threads, parallel_min=1, walk_chunk=8, give_triangulation=given
        )
        degree = np.bincount(out["he_face"], minlength=len(s.xs))
        assert degree.max() >= 1500 and (degree > 64).sum() >= 3
        assert origins_checked(out) > 0.9 * len(out["he_face"])
        runs.append(out)
    for key in runs[0]:
        assert np.array_equal(runs[0][key], runs[1][key]), key


@pytest.mark.parametrize("check", [False, True])
@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("name", sorted(adversarial.FAMILIES))
def test_a_triangulation_given_up_gives_the_same_dcel_with_its_triangles_in_place(name, engine, check):
    """give_triangulation: the finite triangles are moved to the front of tv itself (no copy) and the
    walks write in opp; everything else is what a dual that keeps both makes, on one thread and on two
    (Fortune's check reads tv's rows too)."""
    got = triangulated(adversarial.make(name).points, engine)
    if got is None:
        return
    t, e = got
    s = t.sites
    for threads in (1, 2):
        want = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, check=check)
        tv, opp = t.tv.copy(), t.opp.copy()
        given = dual.voronoi_from_delaunay(
            s.xs, s.ys, tv, opp, e, threads, parallel_min=1, check=check, give_triangulation=True
        )
        assert set(given) == set(want)
        for key in want:
            assert np.array_equal(given[key], want[key]), key
        assert np.array_equal(given["triangles"], finite_rows(t))
        if len(given["triangles"]):
            assert np.shares_memory(given["triangles"], tv) and given["triangles"].flags.writeable
            assert not np.array_equal(opp, t.opp)  # (written: no array of its own)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize(
    "name", ["concentric_exact", "circle_lattice_5525", "grid_with_holes_23deg_2dec", "heavy_duplicates"]
)
def test_half_edges_written_in_arrays_given_with_room(name, engine):
    """he_room: arrays long enough (holding old values: every place is written) take the half-edges and
    the result's are views of them, equal to those of a dual that makes its own; a room too short is
    not used. Cocircular sites too (the merge moves the half-edges within them)."""
    got = triangulated(adversarial.make(name).points, engine)
    if got is None:
        return
    t, e = got
    s = t.sites
    for threads in (1, 2):
        want = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, check=True)
        room = tuple(np.full(len(t.tv) + 7, -5, np.int32) for _ in range(3))
        given = dual.voronoi_from_delaunay(
            s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, check=True, he_room=room
        )
        for key in want:
            assert np.array_equal(given[key], want[key]), key
        for key, a in zip(("he_origin", "he_twin", "he_face"), room, strict=True):
            assert len(given[key]) == 0 or np.shares_memory(given[key], a), key
        short = tuple(np.full(len(t.tv) - 1, -5, np.int32) for _ in range(3))
        other = dual.voronoi_from_delaunay(
            s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, check=True, he_room=short
        )
        assert (short[0] == -5).all()
        for key in want:
            assert np.array_equal(other[key], want[key]), key


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize(("on_circle", "inside"), [(0, 20_000), (600, 12_000), (3_000, 12_000), (5_000, 2_000)])
def test_triangles_given_up_move_to_the_front_alike_on_threads(engine, on_circle, inside):
    """The finite triangles are moved to the front of tv by runs of blocks on two threads (those that
    land where the run before still reads wait in a buffer), or on one when that buffer would be large:
    the same rows as finite_rows either way, with infinite triangles spread through tv (a hull of up to
    5,000 sites around up to 20,000, every triangle count above a few blocks)."""
    rng = np.random.default_rng(on_circle + inside)
    angle = rng.uniform(0, 2 * np.pi, on_circle)
    pts = np.r_[np.c_[np.cos(angle), np.sin(angle)], 0.7 * (rng.random((inside, 2)) - 0.5)]
    t, e = triangulated(pts, engine)
    s = t.sites
    rows = finite_rows(t)
    assert len(t.tv) // 3 > 3 * dual.TRI_BLOCK_SIZE and len(rows) < len(t.tv) // 3
    for threads in (1, 2):
        tv = t.tv.copy()
        out = dual.voronoi_from_delaunay(
            s.xs, s.ys, tv, t.opp.copy(), e, threads, parallel_min=1, give_triangulation=True
        )
        assert np.shares_memory(out["triangles"], tv)
        assert np.array_equal(out["triangles"], rows), threads


@pytest.mark.parametrize("read_only", ["tv", "opp", "both"])
def test_a_read_only_triangulation_is_not_written_when_given_up(read_only):
    t, e = triangulated(generate("uniform", 500, seed=3), "incremental")
    s = t.sites
    want = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e)
    tv, opp = t.tv.copy(), t.opp.copy()
    for name, a in (("tv", tv), ("opp", opp)):
        a.flags.writeable = read_only not in (name, "both")
    out = dual.voronoi_from_delaunay(s.xs, s.ys, tv, opp, e, give_triangulation=True)
    for key in want:
        assert np.array_equal(out[key], want[key]), key
    if read_only != "opp":
        assert np.array_equal(tv, t.tv) and not np.shares_memory(out["triangles"], tv)
    if read_only != "tv":
        assert np.array_equal(opp, t.opp)


def zero_length_edges(t) -> int:
    """Delaunay edges between two finite triangles whose four sites are cocircular (exact): each is an
    edge of length zero between two triangles with one circumcentre."""
    n = len(t.sites.xs)
    rows = t.tv.reshape(-1, 3)
    count = 0
    for d in range(len(t.tv)):
        e = int(t.opp[d])
        if e < d or (rows[d // 3] >= n).any() or (rows[e // 3] >= n).any():
            continue
        p, q = int(t.tv[d]), int(t.tv[3 * (d // 3) + (d + 1) % 3])
        r = int(t.tv[3 * (d // 3) + (d + 2) % 3])
        s = int(t.tv[3 * (e // 3) + (e + 2) % 3])
        xs, ys = t.sites.xs, t.sites.ys
        count += predicates.incircle_sign(xs[p], ys[p], xs[q], ys[q], xs[r], ys[r], xs[s], ys[s]) == 0
    return count


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize(
    "name",
    [
        "grid10_noise1e-17",
        "pythagorean_grid",
        "overlaid_grids_3_5",
        "refined_cells",
        "grid_with_holes",
        "offset_grid_1e15",
    ],
)
def test_cocircular_merges_are_the_same_on_any_count_of_threads(name, engine):
    """Cocircular sites: the walks mark one half-edge of each zero-length edge (that of the site that
    comes first), and drop_zero_edges marks its twin, then merges, renumbers and moves a run on each
    thread. Every count of threads and every run length of the walks gives the arrays of one thread,
    whose vertices number the finite triangles less the zero-length edges (exact in-circle tests: they
    form a forest)."""
    got = triangulated(adversarial.make(name).points, engine)
    assert got is not None
    t, e = got
    s = t.sites
    want = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e)
    zero = zero_length_edges(t)
    assert zero > 0
    assert len(want["vertices"]) == len(finite_rows(t)) - zero
    for threads in (2, 3, 5, 8):
        for walk_chunk in (1, 7, 4096):
            for given in (False, True):
                tv, opp = (t.tv.copy(), t.opp.copy()) if given else (t.tv, t.opp)
                out = dual.voronoi_from_delaunay(
                    s.xs, s.ys, tv, opp, e, threads, parallel_min=1, walk_chunk=walk_chunk, give_triangulation=given
                )
                for key in want:
                    assert np.array_equal(out[key], want[key]), (threads, walk_chunk, given, key)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("side", [2, 3, 5])
def test_cocircular_merges_on_more_threads_than_half_edges(side, engine):
    """A side x side grid (from four cocircular sites on): up to 64 threads and more, most of their runs
    of half-edges and of vertices empty or shorter than a word of marks, give the arrays of one thread."""
    g = np.array([(i, j) for i in range(side) for j in range(side)], np.float64)
    t, e = triangulated(g[np.random.default_rng(side).permutation(len(g))], engine)
    s = t.sites
    want = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e)
    assert len(want["vertices"]) == (side - 1) ** 2
    for threads in (2, 7, 16, 31, 64, 100):
        for walk_chunk in (1, 3):
            out = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, walk_chunk=walk_chunk)
            for key in want:
                assert np.array_equal(out[key], want[key]), (threads, walk_chunk, key)
