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
from tvoronoi.kernels import dual


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


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_each_origin_is_the_centre_of_the_triangle_on_the_right(engine):
    """Half-edge g of site a's cell lies on the bisector of a and b (its twin's site); its origin is the
    circumcentre of the triangle on the right of the Delaunay edge a->b: the one in which a follows b
    counter-clockwise; -1 where that triangle is infinite."""
    pts = generate("uniform", 3000, seed=12)
    t, e = triangulated(pts, engine)
    s = t.sites
    out = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e)
    tri = out["triangles"]
    # each finite triangle's vertex number, by the directed edges it holds: (p, q) -> the triangle
    # where q follows p counter-clockwise
    by_edge = {}
    for k, (p, q, r) in enumerate(tri.tolist()):
        by_edge[(p, q)] = by_edge[(q, r)] = by_edge[(r, p)] = k
    face, twin, origin = out["he_face"], out["he_twin"], out["he_origin"]
    checked = 0
    for g in range(len(face)):
        a, b = int(face[g]), int(face[twin[g]])
        right = by_edge.get((b, a))
        if right is None:
            assert origin[g] == -1
        else:
            assert origin[g] == right
            checked += 1
    assert checked > 0.9 * len(face)


@pytest.mark.parametrize("check", [False, True])
@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("name", sorted(adversarial.FAMILIES))
def test_a_triangulation_given_up_gives_the_same_dcel_with_its_triangles_in_place(name, engine, check):
    """give_tv: the finite triangles are moved to the front of tv itself (no copy); everything else is
    what a dual that keeps tv makes, on one thread and on two (Fortune's check reads tv's rows too)."""
    got = triangulated(adversarial.make(name).points, engine)
    if got is None:
        return
    t, e = got
    s = t.sites
    for threads in (1, 2):
        want = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, check=check)
        tv = t.tv.copy()
        given = dual.voronoi_from_delaunay(s.xs, s.ys, tv, t.opp, e, threads, parallel_min=1, check=check, give_tv=True)
        assert set(given) == set(want)
        for key in want:
            assert np.array_equal(given[key], want[key]), key
        assert np.array_equal(given["triangles"], finite_rows(t))
        if len(given["triangles"]):
            assert np.shares_memory(given["triangles"], tv) and given["triangles"].flags.writeable


def test_a_read_only_triangulation_is_not_written_when_given_up():
    t, e = triangulated(generate("uniform", 500, seed=3), "incremental")
    s = t.sites
    tv = t.tv.copy()
    tv.flags.writeable = False
    out = dual.voronoi_from_delaunay(s.xs, s.ys, tv, t.opp, e, give_tv=True)
    assert np.array_equal(tv, t.tv)
    assert not np.shares_memory(out["triangles"], tv)
    assert np.array_equal(out["triangles"], finite_rows(t))
