"""Fortune's sweep on near-degenerate families: an exact event order gives a Delaunay triangulation every time."""

import math
import subprocess
import sys
import textwrap
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tvoronoi
from test_fortune import assert_same_diagram  # noqa: F401 (used on the fixtures)
from tvoronoi.engines import sweep_order
from tvoronoi.kernels import fortune, incremental

FIXTURES = Path(__file__).parent / "fixtures"
SEED = 20261123


# ---------------------------------------------------------------------------------------------------------
# exact checks (fractions.Fraction on the input doubles)


def _orient(p, q, r):
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])


def _incircle(a, b, c, d):
    """> 0: d strictly inside the circle through a, b, c (counter-clockwise)."""
    rows = [(p[0] - d[0], p[1] - d[1]) for p in (a, b, c)]
    (ax, ay), (bx, by), (cx, cy) = rows
    return (
        (ax * ax + ay * ay) * (bx * cy - by * cx)
        - (bx * bx + by * by) * (ax * cy - ay * cx)
        + (cx * cx + cy * cy) * (ax * by - ay * bx)
    )


def exact_hull_count(points):
    """Number of distinct points on the convex hull's boundary (collinear ones on an edge included)."""
    pts = sorted(set(points))
    if len(pts) < 3:
        return len(pts)
    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and _orient(lower[-2], lower[-1], p) < 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and _orient(upper[-2], upper[-1], p) < 0:
            upper.pop()
        upper.append(p)
    return len(set(lower[:-1] + upper[:-1]))


def sweep_points(pts):
    """Fortune's sweep over pts (any order): (xs, ys in event order, the kernel's result)."""
    pts = np.asarray(pts, float).reshape(-1, 2)
    order = sweep_order(pts[:, 0], pts[:, 1])
    xs, ys = np.ascontiguousarray(pts[order, 0]), np.ascontiguousarray(pts[order, 1])
    return xs, ys, fortune.sweep(xs, ys)


def check_sweep(pts, *, against_all=None):
    """The sweep of pts is a Delaunay triangulation, checked exactly. Returns (xs, ys, out, cocircular).

    Checks: status OK, twin links consistent, 2n - 2 - h finite triangles over
    the n distinct sites (h on the hull), every one counter-clockwise, every
    distinct site in some triangle, no repair flip, and the empty circle: of
    every site for small n (or against_all=True), else across every edge
    (locally Delaunay everywhere is Delaunay). cocircular: some interior edge
    has its opposite site exactly on the circle (the triangulation is then
    one of several).
    """
    xs, ys, out = sweep_points(pts)
    assert out["status"] == fortune.STATUS_OK
    exact = [(Fraction(float(x)), Fraction(float(y))) for x, y in zip(xs, ys)]
    distinct = set(exact)
    n = len(xs)
    h = exact_hull_count(list(distinct))
    if len(distinct) < 3 or h == len(distinct) and all(_orient(*sorted(distinct)[:2], p) == 0 for p in distinct):
        assert "tv" not in out  # collinear: no triangle
        return xs, ys, out, False
    tv, opp = out["tv"], out["opp"]
    n_he = len(tv)
    e = np.arange(n_he)
    nxt = np.where(e % 3 == 2, e - 2, e + 1)
    prv = np.where(e % 3 == 0, e + 2, e - 1)
    assert np.all((opp >= 0) & (opp < n_he)), "a half-edge without twin"
    assert np.all(opp[opp] == e) and np.all(tv[opp] == tv[nxt]), "twin links"
    tri = tv.reshape(-1, 3)
    finite = ~np.any(tri == n, axis=1)
    assert finite.sum() == 2 * len(distinct) - 2 - h, "not a triangulation of all sites"
    used = {exact[i] for i in np.unique(tri[finite])}
    assert used == distinct, "a site outside every triangle"
    assert out["flips"] == 0, "the guard repair had to flip: the sweep's order was wrong"
    for t in tri[finite]:
        assert _orient(exact[t[0]], exact[t[1]], exact[t[2]]) > 0
    cocircular = False
    if against_all if against_all is not None else len(distinct) <= 40:
        for t in tri[finite]:
            a, b, c = (exact[k] for k in t)
            for d in distinct:
                s = _incircle(a, b, c, d)
                assert s <= 0, "a site inside a triangle's circle"
                cocircular |= s == 0 and d not in (a, b, c)
    for k in np.flatnonzero(np.repeat(finite, 3)):
        if not finite[opp[k] // 3]:
            continue
        a, b, c, d = exact[tv[k]], exact[tv[nxt[k]]], exact[tv[prv[k]]], exact[tv[prv[opp[k]]]]
        s = _incircle(a, b, c, d)
        assert s <= 0, "an edge that is not locally Delaunay"
        cocircular |= s == 0
    return xs, ys, out, cocircular


def _ring(poly, atol):
    """A cell's ring without consecutive vertices closer than atol (cocircular sites: rounded copies of
    one Voronoi vertex, which each engine may emit a different number of times)."""
    keep = []
    for p in poly:
        if not keep or np.hypot(*(p - keep[-1])) > atol:
            keep.append(p)
    while len(keep) > 1 and np.hypot(*(keep[0] - keep[-1])) <= atol:
        keep.pop()
    return np.array(keep).reshape(-1, 2)


def assert_same_cells(a, b):
    """The two diagrams give every site the same cell, up to rounding of the vertices."""
    assert np.array_equal(a.site_of, b.site_of)
    scale = max(a.bbox[2] - a.bbox[0], a.bbox[3] - a.bbox[1])
    atol = max(1e-9 * scale, 16 * np.spacing(max(abs(v) for v in a.bbox)))  # far from 0: a few ulps
    for i in range(a.n_sites):
        ra, rb = _ring(a.cell_polygon(i), atol), _ring(b.cell_polygon(i), atol)
        assert len(ra) == len(rb), f"cell {i}: {len(ra)} vs {len(rb)} vertices"
        if len(ra):
            k = int(np.argmin(np.hypot(*(rb - ra[0]).T)))
            np.testing.assert_allclose(np.roll(rb, -k, axis=0), ra, rtol=0, atol=atol)


def check_against_incremental(pts):
    """check_sweep, then the same triangles as the incremental engine (general position) or the same cells."""
    xs, ys, out, cocircular = check_sweep(pts)
    if "tv" not in out:
        return
    if cocircular:
        assert_same_cells(tvoronoi.voronoi(pts, engine="fortune"), tvoronoi.voronoi(pts, engine="incremental"))
        return
    status, tv, _, _ = incremental.triangulate(xs, ys)
    assert status == incremental.STATUS_OK
    n = len(xs)

    def triangles(t):
        # by coordinates: of repeated points, the engines may keep different copies
        t = t.reshape(-1, 3)
        return {tuple(sorted((xs[k], ys[k]) for k in r)) for r in t[~np.any(t == n, axis=1)].tolist()}

    assert triangles(out["tv"]) == triangles(tv)


# ---------------------------------------------------------------------------------------------------------
# generators of hard families


def near_line(n, slope, offset, seed, spread=1.0):
    """Points (t, slope * t + offset) rounded to doubles, t random."""
    t = np.random.default_rng(seed).random(n) * spread
    return np.column_stack([t, slope * t + offset])


def collinear_with_off_line(n_line, n_off, seed):
    rng = np.random.default_rng(seed)
    t = rng.permutation(n_line).astype(float)
    line = np.column_stack([t, 2 * t + 1])
    off = np.column_stack([rng.integers(0, n_line, n_off), rng.integers(-3, 2 * n_line + 4, n_off)]).astype(float)
    return np.concatenate([line, off])


def parallel_lines(m, gap, eps, seed):
    """2 m sites within eps of the lines y = 0 and y = gap."""
    rng = np.random.default_rng(seed)
    x = rng.random(2 * m)
    y = np.concatenate([np.zeros(m), np.full(m, gap)]) + rng.uniform(-eps, eps, 2 * m)
    return np.column_stack([x, y])


def lattice(k, kind, angle, noise, seed):
    """A k x k square or triangular lattice, rotated by angle, each coordinate moved by up to noise."""
    i, j = np.meshgrid(np.arange(k, dtype=float), np.arange(k, dtype=float))
    i, j = i.ravel(), j.ravel()
    if kind == "triangular":
        x, y = i + 0.5 * (j % 2), j * math.sqrt(3) / 2
    else:
        x, y = i, j
    c, s = math.cos(angle), math.sin(angle)
    pts = np.column_stack([c * x - s * y, s * x + c * y])
    if noise:
        pts = pts + np.random.default_rng(seed).uniform(-noise, noise, pts.shape)
    return pts


def lattice_circle(r):
    """The integer points on x^2 + y^2 = r^2 (exactly cocircular) and the centre."""
    pts = {(x, y) for x in range(-r, r + 1) for y in range(-r, r + 1) if x * x + y * y == r * r}
    return np.array(sorted(pts) + [(0, 0)], float)


def concentric(radii, m, shift):
    pts = [(0.0, 0.0)]
    for k, r in enumerate(radii):
        for a in range(m):
            t = 2 * math.pi * a / m + shift * k
            pts.append((r * math.cos(t), r * math.sin(t)))
    return np.array(pts)


def rounded_uniform(n, decimals, seed):
    return np.round(np.random.default_rng(seed).random((n, 2)), decimals)


def offset_cloud(n, offset, spread, seed):
    return offset + np.random.default_rng(seed).random((n, 2)) * spread


# ---------------------------------------------------------------------------------------------------------
# regression inputs, one file per bug


def test_fixture_near_line_4_sites():
    """Four sites within 1e-16 of y = 0: one inside the triangle of the others. The rounded top of a
    circle event (centre ~1e17 below) put a site out of order: one triangle instead of three."""
    pts = np.load(FIXTURES / "fortune_near_line_4_sites.npy")
    xs, ys, out, _ = check_sweep(pts, against_all=True)
    assert (out["tv"].reshape(-1, 3) < len(pts)).all(axis=1).sum() == 3


def test_fixture_parallel_lines_8_sites():
    """Eight sites on two lines within 1e-16 of y = 0 and y = 1: the rounded order left half-edges
    without twins (not a triangulation); at scale this hung the clipper and crashed close_hull."""
    pts = np.load(FIXTURES / "fortune_parallel_lines_8_sites.npy")
    check_against_incremental(pts)


def test_fixture_voronoi_diagrams():
    for name in ("fortune_near_line_4_sites.npy", "fortune_parallel_lines_8_sites.npy"):
        pts = np.load(FIXTURES / name)
        assert_same_diagram(tvoronoi.voronoi(pts, engine="fortune"), tvoronoi.voronoi(pts, engine="incremental"))


# ---------------------------------------------------------------------------------------------------------
# the filter and the exact event order


def _exact_top(tri):
    """Top of the circle through a, b, c, to 60 digits (decimal)."""
    from decimal import Decimal, getcontext

    getcontext().prec = 80
    ax, ay, bx, by, cx, cy = (Fraction(v) for v in tri)
    bx, by, cx, cy = bx - ax, by - ay, cx - ax, cy - ay
    d = bx * cy - by * cx
    ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / (2 * d)
    uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / (2 * d)
    r2 = ux * ux + uy * uy
    r = Decimal(r2.numerator) / Decimal(r2.denominator)
    return Decimal(ay.numerator) / Decimal(ay.denominator) + Decimal(uy.numerator) / Decimal(uy.denominator) + r.sqrt()


def _ccw_triples(rng, count, scale_y):
    out = []
    while len(out) < count:
        p = rng.random((3, 2))
        p[:, 1] *= scale_y
        if rng.random() < 0.3:
            p[:, 1] += 1.0
        t = tuple(float(v) for v in p.ravel())
        o = _orient(*[(Fraction(t[2 * k]), Fraction(t[2 * k + 1])) for k in range(3)])
        if o == 0:
            continue
        if o < 0:
            t = t[2:4] + t[0:2] + t[4:6]
        out.append(t)
    return out


@pytest.mark.parametrize("scale_y", [1.0, 1e-6, 1e-12, 1e-18])
def test_filter_interval_holds_the_exact_top(scale_y):
    rng = np.random.default_rng(SEED)
    from decimal import Decimal

    for tri in _ccw_triples(rng, 200, scale_y):
        top, lo, hi, base, rise, rise_err, _, _ = fortune.circle_event_top(*tri)
        exact = _exact_top(tri)
        if math.isfinite(lo):
            assert Decimal(lo) <= exact <= Decimal(hi)
            assert lo <= top <= hi
        if math.isfinite(rise_err):
            assert abs(Decimal(base) + Decimal(rise) - exact) <= Decimal(rise_err)


def _family_triples():
    """Counter-clockwise triples of neighbouring sites from the hard families."""
    rng = np.random.default_rng(SEED + 2)
    sets = [
        parallel_lines(200, 1.0, 1e-16, SEED),
        parallel_lines(200, 1.0, 1e-12, SEED),
        near_line(200, 1 / 3, 0.7, SEED),
        near_line(200, 2.0, 0.0, SEED),
        near_line(200, 1e6, 3.0, SEED),
        near_line(200, 0.0, 1e-18, SEED),
        lattice(12, "square", 0.1, 1e-12, SEED),
        offset_cloud(200, 1e12, 1.0, SEED),
        lattice(12, "triangular", 0.0, 0.0, SEED),
    ]
    out = []
    for pts in sets:
        pts = np.unique(pts, axis=0)
        for _ in range(150):
            i = rng.integers(len(pts))
            near = np.argsort(np.hypot(*(pts - pts[i]).T))[1:8]
            j, k = rng.choice(near, 2, replace=False)
            t = tuple(float(v) for v in (*pts[i], *pts[j], *pts[k]))
            o = _orient(*[(Fraction(t[2 * m]), Fraction(t[2 * m + 1])) for m in range(3)])
            if o != 0:
                out.append(t if o > 0 else t[2:4] + t[0:2] + t[4:6])
    return out


def test_filters_hold_the_exact_top_on_hard_families():
    from decimal import Decimal

    decided = 0
    for tri in _family_triples():
        exact = _exact_top(tri)
        top, lo, hi, base, rise, rise_err, _, _ = fortune.circle_event_top(*tri)
        if math.isfinite(lo):
            assert Decimal(lo) <= exact <= Decimal(hi)
        if math.isfinite(rise_err):
            assert abs(Decimal(base) + Decimal(rise) - exact) <= Decimal(rise_err)
        fine = fortune.circle_event_top_fine(*tri)
        if fine is not None:
            head, tail, err = fine
            assert abs(Decimal(head) + Decimal(tail) - exact) <= Decimal(err)
            decided += 1
    assert decided > 100


@pytest.mark.parametrize("scale_y", [1.0, 1e-9, 1e-18])
def test_exact_orders_agree_with_high_precision(scale_y):
    from decimal import Decimal

    rng = np.random.default_rng(SEED + 1)
    tris = _ccw_triples(rng, 60, scale_y)
    tops = [_exact_top(t) for t in tris]
    for k in range(len(tris) - 1):
        a, b = tris[k], tris[k + 1]
        want = (tops[k] > tops[k + 1]) - (tops[k] < tops[k + 1])
        assert fortune.event_top_order(a, b) == want
        assert fortune.event_top_order(b, a) == -want
        assert fortune.event_top_order(a, a) == 0
        y = float(tops[k])  # the rounded top: just above or just below the exact one
        assert fortune.site_before_event(y, *a) == (Decimal(y) <= tops[k])
        assert fortune.site_before_event(float(a[1]), *a)


def test_exact_order_of_equal_tops():
    """Translated copies of one circle have equal tops; a site exactly at a top comes first."""
    a = (0.0, 0.0, 1.0, 0.0, 0.0, 1.0)  # circle centre (0.5, 0.5)
    b = (5.0, 0.0, 6.0, 0.0, 5.0, 1.0)
    c = (0.0, 0.0, 2.0, 0.0, 1.0, 1.0)  # centre (1, 0), radius 1: top y = 1 exactly
    assert fortune.event_top_order(a, b) == 0
    assert fortune.site_before_event(1.0, *c)
    assert not fortune.site_before_event(1.0 + 2.0**-52, *c)
    assert fortune.site_before_event(1.0 - 2.0**-53, *c)


def test_exact_order_of_far_apart_magnitudes():
    """Coordinates 1 and 1e-300 in one test: beyond any expansion's exponent range, exact in integers."""
    a = (0.0, 0.0, 1.0, 1e-300, 0.5, 1e-290)
    b = (0.0, 0.0, 1.0, 1e-300, 0.5, 2e-290)
    assert fortune.event_top_order(a, b) == -fortune.event_top_order(b, a) != 0
    assert fortune.site_before_event(1e-300, *a)


# ---------------------------------------------------------------------------------------------------------
# the families


@pytest.mark.parametrize("slope", [0.0, 1e-12, 1.0, 1 / 3, 2.0, 1e6])
@pytest.mark.parametrize("offset", [0.0, 1e-18, 0.7])
def test_near_collinear_on_slopes(slope, offset):
    pts = near_line(60, slope, offset, SEED)
    pts[::7, 1] += 1e-9  # a few clearly off the line
    check_against_incremental(pts)
    check_against_incremental(near_line(30, slope, offset, SEED + 1))


def test_exactly_collinear_with_a_few_off_line():
    for k in range(4):
        check_against_incremental(collinear_with_off_line(40, 1 + k, SEED + k))


@pytest.mark.parametrize("eps", [1e-16, 1e-12, 1e-9, 1e-6])
def test_near_parallel_lines(eps):
    for seed in range(3):
        check_against_incremental(parallel_lines(6, 1.0, eps, SEED + seed))
        check_sweep(parallel_lines(300, 1.0, eps, SEED + seed))


@pytest.mark.parametrize("kind", ["square", "triangular"])
@pytest.mark.parametrize("angle", [0.0, 0.1, math.pi / 6, 1.0])
@pytest.mark.parametrize("noise", [0.0, 1e-17, 1e-12, 1e-6])
def test_lattices(kind, angle, noise):
    check_against_incremental(lattice(5, kind, angle, noise, SEED))
    check_sweep(lattice(14, kind, angle, noise, SEED))


@pytest.mark.parametrize("r", [5, 25, 65])
def test_integer_points_on_a_circle_and_centre(r):
    check_against_incremental(lattice_circle(r))


@pytest.mark.parametrize("m", [8, 12, 30])
def test_concentric_circles(m):
    check_against_incremental(concentric([1.0, 2.0, 3.0], m, 0.0))
    check_against_incremental(concentric([1.0, 2.0, 3.0], m, 0.5))


@pytest.mark.parametrize("decimals", [1, 2, 3])
def test_rounded_points(decimals):
    check_against_incremental(rounded_uniform(40, decimals, SEED))
    check_sweep(rounded_uniform(400, decimals, SEED + 1))


@pytest.mark.parametrize("offset", [1e6, 1e9, 1e12, 1e15])
@pytest.mark.parametrize("spread", [1e-3, 1.0, 100.0])
def test_large_offsets_small_spreads(offset, spread):
    check_against_incremental(offset_cloud(40, offset, spread, SEED))


# ---------------------------------------------------------------------------------------------------------
# property tests

coarse = st.integers(-20, 20).map(lambda k: k / 10)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(coarse, coarse), min_size=3, max_size=12))
def test_property_coarse_decimals(points):
    check_against_incremental(np.array(points, float))


@settings(max_examples=150, deadline=None)
@given(
    st.lists(st.floats(0, 1).filter(lambda v: v == 0 or v > 1e-40), min_size=3, max_size=12),
    st.sampled_from([0.0, 1e-9, 1 / 3, 1.0, 3.0]),
    st.lists(st.sampled_from([0.0, 1e-18, -1e-17, 1e-16, 2.5e-16]), min_size=12, max_size=12),
)
def test_property_near_one_line(ts, slope, bumps):
    # (subnormal coordinates are left out, as in test_fortune: orient2d and incircle underflow there)
    pts = np.array([(t, slope * t + bumps[k]) for k, t in enumerate(ts)], float)
    check_against_incremental(pts)


@settings(max_examples=150, deadline=None)
@given(
    st.lists(st.tuples(st.sampled_from([1.0, 2.0, 5.0]), st.integers(0, 23)), min_size=3, max_size=12), st.booleans()
)
def test_property_on_a_few_circles(polar, centre):
    pts = [(r * math.cos(math.pi * k / 12), r * math.sin(math.pi * k / 12)) for r, k in polar]
    if centre:
        pts.append((0.0, 0.0))
    check_against_incremental(np.array(pts, float))


# ---------------------------------------------------------------------------------------------------------
# the families that stalled finish (in a subprocess: a stall fails the test instead of hanging it)

_FINISH = textwrap.dedent("""
    import sys, numpy as np, tvoronoi
    from tvoronoi.engines import sweep_order
    from tvoronoi.kernels import fortune
    kind = sys.argv[1]
    rng = np.random.default_rng(7)
    if kind == "lines":
        m = 20000
        x = rng.random(2 * m)
        y = np.concatenate([np.zeros(m), np.ones(m)]) + rng.uniform(-1e-16, 1e-16, 2 * m)
        pts = np.column_stack([x, y])
    else:
        g = np.array([(i, j) for i in range(100) for j in range(100)], float)
        pts = g + rng.normal(0, 1e-12, g.shape)
    order = sweep_order(pts[:, 0], pts[:, 1])
    xs, ys = np.ascontiguousarray(pts[order, 0]), np.ascontiguousarray(pts[order, 1])
    out = fortune.sweep(xs, ys)
    tv, opp = out["tv"], out["opp"]
    e = np.arange(len(tv))
    twins = bool(np.all(opp[opp] == e) and np.all(tv[opp] == tv[np.where(e % 3 == 2, e - 2, e + 1)]))
    n_finite = int((tv.reshape(-1, 3) < len(pts)).all(axis=1).sum())
    print(out["status"], out["flips"], int(twins), n_finite)
    d = tvoronoi.voronoi(pts, engine="fortune")
    print(d.n_sites)
    np.save(sys.argv[2], pts)
""")


@pytest.mark.parametrize("kind", ["lines", "grid"])
def test_hard_families_finish(kind, tmp_path):
    """2 x 20,000 sites within 1e-16 of two parallel lines; a 100 x 100 grid with 1e-12 noise."""
    saved = tmp_path / "points.npy"
    run = subprocess.run([sys.executable, "-c", _FINISH, kind, str(saved)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr[-2000:]
    status, flips, twins, n_finite = map(int, run.stdout.split("\n")[0].split())
    assert status == fortune.STATUS_OK and flips == 0 and twins == 1
    pts = np.load(saved)
    assert int(run.stdout.split("\n")[1]) == len(pts)
    exact = [(Fraction(float(x)), Fraction(float(y))) for x, y in pts]
    assert len(set(exact)) == len(pts)
    assert n_finite == 2 * len(pts) - 2 - exact_hull_count(exact)


# ---------------------------------------------------------------------------------------------------------
# the stages of the event order are all exercised, and trouble is an error, not a crash


def two_circles_with_one_top():
    """The integer points of two circles whose tops are at one height but whose radii differ (5 about
    (0, 0), 10 about (40, -5)), the top points left out: equal tops that no shift along x relates."""
    pts = []
    for (cx, cy), r in (((0, 0), 5), ((40, -5), 10)):
        pts += [
            (cx + x, cy + y)
            for x in range(-r, r + 1)
            for y in range(-r, r + 1)
            if x * x + y * y == r * r and (x, y) != (0, r)
        ]
    return np.array(pts, float)


def test_every_stage_of_the_event_order_runs():
    """Equal tops of circles of different sizes: exact integers decide; sites within 1e-16 of two lines
    have near ties that the rises settle; every sweep stays exact."""
    _, _, out, _ = check_sweep(two_circles_with_one_top(), against_all=True)
    assert out["exact_tests"][1] > 0
    _, _, out, _ = check_sweep(parallel_lines(300, 1.0, 1e-16, SEED))
    assert out["near_ties"][0] > 0


@pytest.mark.parametrize("kind", ["square", "triangular"])
@pytest.mark.parametrize("scale", [1.0, 0.125, 3.0])
def test_lattice_rows_are_settled_without_the_integer_fallback(kind, scale):
    """A lattice row parallel to the sweep line puts many events at one exact height (congruent circles side
    by side, several triples of one cocircular square); an exact shift along x proves those ties
    (a 1000 x 1000 grid took 54 s when each went to the integer fallback, 5 s now). The sweep stays exact."""
    pts = lattice(12, kind, 0.0, 0.0, SEED)
    if kind == "triangular":
        pts = np.round(pts * 8) / 8  # rows at exact heights, coordinates exact in binary
    pts = pts * scale + 1000.0  # exact: a power of two or a small integer, and an offset
    _, _, out, _ = check_sweep(pts)
    assert out["near_ties"][0] > 0
    assert out["exact_tests"][1] == 0


@pytest.mark.parametrize("kind", ["square", "triangular"])
def test_a_large_lattice_proves_each_tie_about_once(kind):
    """Hundreds of events of one lattice row wait in the queue at one height, and a heap compares them with
    each other again and again: events proven equal share a class, so the near ties stay a few per site
    (a 400 x 400 grid had 52 per site, 1000 x 1000 took 6.5 s to sweep, 4x uniform)."""
    side = 400
    if kind == "square":
        g = np.arange(float(side))
        x, y = np.meshgrid(g, g)
        pts = np.c_[x.ravel(), y.ravel()]
    else:
        pts = np.round(lattice(side // 2, kind, 0.0, 0.0, SEED) * 8) / 8
    order = sweep_order(pts[:, 0], pts[:, 1])
    out = fortune.sweep(np.ascontiguousarray(pts[order, 0]), np.ascontiguousarray(pts[order, 1]))
    assert out["status"] == fortune.STATUS_OK
    assert out["near_ties"][0] < 8 * len(pts)  # 20 to 50 per site when each pair was proven anew
    assert out["exact_tests"][1] == 0
    if kind == "square":
        # every tie of a square lattice is exact: the shift proves it before any double-double top
        # is computed (which took half the sweep of a 1000 x 1000 grid)
        assert out["near_ties"][1] == 0


def test_an_inconsistent_sweep_is_a_tvoronoi_error(monkeypatch):
    real = fortune.sweep
    monkeypatch.setattr(fortune, "sweep", lambda xs, ys, **kw: {**real(xs, ys, **kw), "status": fortune.STATUS_BROKEN})
    with pytest.raises(tvoronoi.TvoronoiError, match="inconsistent state"):
        tvoronoi.voronoi(np.random.default_rng(SEED).random((20, 2)), engine="fortune")


def test_an_inconsistent_sweep_stops_a_dynamic_diagram_too(monkeypatch):
    """DynamicVoronoi's start with the Fortune engine goes through the same check as a batch build."""
    real = fortune.sweep
    monkeypatch.setattr(fortune, "sweep", lambda xs, ys, **kw: {**real(xs, ys, **kw), "status": fortune.STATUS_BROKEN})
    with pytest.raises(tvoronoi.TvoronoiError, match="inconsistent state"):
        tvoronoi.DynamicVoronoi(np.random.default_rng(SEED).random((20, 2)), engine="fortune")


@pytest.mark.parametrize("noise", [1e-17, 1e-13, 1e-9])
@pytest.mark.parametrize("scale", [1.0, 2.0**-60, 2.0**-150])
def test_fine_filter_holds_and_decides_on_noisy_squares(noise, scale):
    """The double-double stage's bound holds on the triangles of noisy lattice squares (the near-cocircular
    pairs that reach it), at several scales, and it decides them: exact integers stay the exception."""
    from decimal import Decimal

    rng = np.random.default_rng(SEED + 3)
    decided = 0
    for _ in range(120):
        i, j = rng.integers(0, 50, 2)
        sq = (
            np.array([(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)], float) / 64 + noise * rng.standard_normal((4, 2))
        ) * scale
        for a, b, c in ((0, 1, 2), (0, 2, 3), (0, 1, 3), (1, 2, 3)):
            tri = tuple(float(v) for v in (*sq[a], *sq[b], *sq[c]))
            if _orient(*[(Fraction(tri[2 * k]), Fraction(tri[2 * k + 1])) for k in range(3)]) <= 0:
                continue
            fine = fortune.circle_event_top_fine(*tri)
            if fine is None:
                continue
            head, tail, err = fine
            assert abs(Decimal(head) + Decimal(tail) - _exact_top(tri)) <= Decimal(err)
            assert err <= 1e-28 * max(abs(head), 1e-300)
            decided += 1
    assert decided > 300
