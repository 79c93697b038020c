"""The dual's check of a triangulation no guard has passed (Fortune's sweep without its closing repair).

dual.voronoi_from_delaunay(check=True) tests every Delaunay edge once as it walks the cells: on the
rounded Voronoi vertices at both ends where they tell (edge_order, with a proven error bound), by the
exact in-circle test where they cannot. Its count of illegal edges must be the exact one, on every
family of hard input and at every scale (the band where the rounded test holds, and outside it), and
a triangulation it passes must give the same DCEL as without the check. engines.Triangulation.voronoi
repairs what it finds and builds again.
"""

import numpy as np
import pytest

import tvoronoi
from tests import adversarial
from tests.exact_checks import ExactPoints
from tests.flips import flip_edges, nxt, prv
from tvoronoi import build, engines, halves
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import generate
from tvoronoi.kernels import dual, fortune

FAMILIES = sorted(adversarial.FAMILIES)
# powers of two: the same geometry, with the vertices inside edge_order's band, below it and above it,
# and subnormal sites (their unit beyond the normal powers of two: the walk's ldexp path)
SCALES = [1.0, 2.0**-1000, 2.0**900, 2.0**-1040]


def triangulation(pts: np.ndarray, engine: str = "fortune", guard: bool = True):
    """The engine's triangulation of pts (None if flat or out of range at this scale)."""
    try:
        e = engines.scale_exponent(pts)
    except TvoronoiError:
        return None
    s = engines.prepare(pts[:, 0], pts[:, 1], engine=engine, exponent=e)
    t = engines.triangulate(s, engine=engine, guard=guard)
    return None if t.flat else t


def illegal_edges(xs: np.ndarray, ys: np.ndarray, tv: np.ndarray, opp: np.ndarray) -> int:
    """Edges between two finite triangles whose far site lies strictly inside the other's circle (exact
    integers)."""
    ex = ExactPoints(np.c_[xs, ys])
    n, count = len(xs), 0
    for e in range(len(tv)):
        o = opp[e]
        if o < e or n in tv[3 * (e // 3) : 3 * (e // 3) + 3] or n in tv[3 * (o // 3) : 3 * (o // 3) + 3]:
            continue
        if ex.incircle(tv[e], tv[nxt(e)], tv[prv(e)], tv[prv(o)]) > 0:
            count += 1
    return count


def dcel(t, check: bool, threads: int = 1) -> dict:
    s = t.sites
    return dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, s.exponent, threads, parallel_min=1, check=check)


@pytest.mark.parametrize("engine", ["fortune", "incremental"])
@pytest.mark.parametrize("name", FAMILIES)
def test_a_delaunay_triangulation_passes_and_gives_the_same_dcel(name, engine):
    t = triangulation(adversarial.make(name).points, engine)
    if t is None:
        return
    plain = dcel(t, False)
    for threads in (1, 2):
        checked = dcel(t, True, threads)
        assert "illegal" not in checked
        assert checked.keys() == plain.keys()
        for key in plain:
            assert np.array_equal(checked[key], plain[key]), key


@pytest.mark.parametrize("scale", SCALES)
@pytest.mark.parametrize("name", FAMILIES)
def test_the_check_counts_exactly_the_illegal_edges(name, scale):
    """Random valid flips spoil the triangulation: on cocircular and nearly cocircular sites most flipped
    edges are illegal by a hair (or not at all), where the rounded vertices nearly coincide."""
    t = triangulation(adversarial.make(name).points * scale)
    if t is None:
        return
    rng = np.random.default_rng(len(name))
    xs, ys = t.sites.xs, t.sites.ys
    for count in (1, 5, 40):
        tv, opp = t.tv.copy(), t.opp.copy()
        if flip_edges(xs, ys, tv, opp, rng, count) == 0:
            return  # no flippable edge (a few sites)
        want = illegal_edges(xs, ys, tv, opp)
        spoiled = engines.Triangulation(t.engine, t.sites, tv, opp, t.dup, checked=False)
        for threads in (1, 2):
            got = dcel(spoiled, True, threads)
            assert got.get("illegal", 0) == want, (count, threads)


@pytest.mark.parametrize("seed", range(6))
def test_near_cocircular_flips_at_random(seed):
    """Sites on a circle rounded to doubles (every quadrilateral nearly cocircular), and a rounded
    lattice turned by a random angle: many flips, counted exactly."""
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, 300))
    radius = rng.uniform(0.5, 2000.0)
    circle = np.c_[radius * np.cos(angles), radius * np.sin(angles)] + rng.uniform(-10, 10, 2)
    g = np.arange(16.0)
    gx, gy = np.meshgrid(g, g)
    turn = rng.uniform(0, np.pi / 2)
    lattice = np.c_[
        gx.ravel() * np.cos(turn) - gy.ravel() * np.sin(turn), gx.ravel() * np.sin(turn) + gy.ravel() * np.cos(turn)
    ]
    for pts in (circle, np.round(lattice, int(rng.integers(2, 9)))):
        t = triangulation(pts)
        assert t is not None
        tv, opp = t.tv.copy(), t.opp.copy()
        assert flip_edges(t.sites.xs, t.sites.ys, tv, opp, rng, 200) > 0
        want = illegal_edges(t.sites.xs, t.sites.ys, tv, opp)
        got = dcel(engines.Triangulation(t.engine, t.sites, tv, opp, t.dup, checked=False), True)
        assert got.get("illegal", 0) == want


@pytest.mark.parametrize("name", ["circle_rounded", "grid30_noise1e-12", "pythagorean_grid", "spiral"])
def test_an_unchecked_triangulation_is_repaired_and_gives_the_guarded_diagram(name, rng):
    """What the check finds, Triangulation.voronoi repairs (exact flips) before building again: the
    Voronoi vertices of the guarded sweep, and the same number of half-edges."""
    pts = adversarial.make(name).points
    guarded = triangulation(pts, guard=True)
    unguarded = triangulation(pts, guard=False)
    assert guarded is not None and unguarded is not None and not unguarded.checked
    assert np.array_equal(guarded.tv, unguarded.tv)  # (the sweep itself is the same)
    assert flip_edges(unguarded.sites.xs, unguarded.sites.ys, unguarded.tv, unguarded.opp, rng, 30) > 0
    assert illegal_edges(unguarded.sites.xs, unguarded.sites.ys, unguarded.tv, unguarded.opp) > 0
    want, got = guarded.voronoi(), unguarded.voronoi()
    assert "illegal" not in got
    assert len(got["he_origin"]) == len(want["he_origin"])
    assert np.array_equal(np.unique(got["vertices"], axis=0), np.unique(want["vertices"], axis=0))


def test_a_build_by_halves_is_checked_in_its_dual():
    """Fortune by halves (from 65,536 sites) sweeps without its guard; the build's dual checks it, and
    the diagram is the incremental engine's."""
    pts = generate("uniform", halves.SPLIT_MIN_SITES + 1000, seed=3)
    e = engines.scale_exponent(pts)
    with build.build_arrays():
        t = build.triangulation(pts, e, engine="fortune", insertion="brio", seed=0, threads=1)
    assert not t.checked
    a = tvoronoi.voronoi(pts, engine="fortune")
    b = tvoronoi.voronoi(pts, engine="incremental")
    assert np.array_equal(a.cell_offsets, b.cell_offsets)
    for k in range(0, len(pts), 997):
        ra = a.cell_points[a.cell_vertices[a.cell_offsets[k] : a.cell_offsets[k + 1]]]
        rb = b.cell_points[b.cell_vertices[b.cell_offsets[k] : b.cell_offsets[k + 1]]]
        assert np.array_equal(ra, rb)


def test_a_repair_that_does_not_converge_is_an_error(monkeypatch, rng):
    """Were the triangulation so broken that the bounded repair gave up (as the sweep's own guard would
    have, with STATUS_NO_REPAIR), the build stops with an error naming the way out, not a diagram."""
    t = triangulation(adversarial.make("circle_rounded").points, guard=False)
    assert t is not None
    assert flip_edges(t.sites.xs, t.sites.ys, t.tv, t.opp, rng, 10) > 0
    monkeypatch.setattr(fortune, "legalize", lambda *args, **kw: -1)
    with pytest.raises(TvoronoiError, match="engine='incremental'"):
        t.voronoi()


def test_renumbering_keeps_an_unchecked_triangulation_unchecked():
    t = triangulation(adversarial.make("spiral").points, guard=False)
    assert t is not None and not t.checked
    assert not engines.renumbered(t).checked
    assert engines.renumbered(triangulation(adversarial.make("spiral").points, guard=True)).checked


@pytest.mark.parametrize("threads", [1, 2])
def test_a_triangulation_given_up_is_left_as_it_was_when_an_edge_is_illegal(rng, threads):
    """give_triangulation moves the triangles only once the walks found every edge legal, and the walks
    that wrote in opp restore it: an illegal edge leaves tv and opp as they were for the repair
    (Triangulation.voronoi then repairs it and builds again, still giving it up)."""
    pts = adversarial.make("circle_rounded").points
    guarded = triangulation(pts, guard=True)
    unguarded = triangulation(pts, guard=False)
    assert flip_edges(unguarded.sites.xs, unguarded.sites.ys, unguarded.tv, unguarded.opp, rng, 30) > 0
    s = unguarded.sites
    before = unguarded.tv.copy(), unguarded.opp.copy()
    got = dual.voronoi_from_delaunay(
        s.xs,
        s.ys,
        unguarded.tv,
        unguarded.opp,
        s.exponent,
        threads,
        parallel_min=1,
        walk_chunk=16,
        check=True,
        give_triangulation=True,
    )
    assert got.get("illegal", 0) > 0
    assert np.array_equal(unguarded.tv, before[0]) and np.array_equal(unguarded.opp, before[1])
    want, repaired = guarded.voronoi(), unguarded.voronoi(threads, give_triangulation=True)
    assert np.shares_memory(repaired["triangles"], unguarded.tv)
    assert len(repaired["he_origin"]) == len(want["he_origin"])
    assert np.array_equal(np.unique(repaired["vertices"], axis=0), np.unique(want["vertices"], axis=0))
