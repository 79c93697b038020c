"""The triangulation by halves (tvoronoi/halves.py, kernels/seam.pyx): exactly Delaunay, the same cells as
one triangulation of all the sites, and the same Diagram on any thread count.

Builds take that path from SPLIT_MIN_SITES sites on; these tests lower the threshold so that every family
of hard input, small as it is here, is cut in two and joined.
"""

import contextlib
import math
import threading
import time
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from conftest import DATASETS
from tests import adversarial
from tests.exact_checks import CHECKS, cells_of, check_same_cells
from tests.invariants import assert_same_diagram
from tvoronoi import api, engines, halves
from tvoronoi.generators import generate
from tvoronoi.kernels import seam


@contextlib.contextmanager
def split_from_3():
    """Every build of three sites or more goes by halves; yields the list of whether each join held."""
    saved, real = halves.SPLIT_MIN_SITES, halves.joined
    joins: list[bool] = []

    def spy(*args, **kwargs):
        t = real(*args, **kwargs)
        joins.append(t is not None)
        return t

    halves.SPLIT_MIN_SITES, halves.joined = 3, spy
    try:
        yield joins
    finally:
        halves.SPLIT_MIN_SITES, halves.joined = saved, real


@pytest.fixture
def split_always():
    with split_from_3() as joins:
        yield joins


def whole(pts, bbox=None, threads=1, engine="incremental"):
    """The build of one triangulation of all the sites (no halves)."""
    saved = halves.SPLIT_MIN_SITES
    halves.SPLIT_MIN_SITES = 1 << 62
    try:
        return api.voronoi(pts, bbox=bbox, threads=threads, engine=engine)
    finally:
        halves.SPLIT_MIN_SITES = saved


def check_by_halves(pts, bbox=None, joins=None, engine="incremental") -> None:
    """The build by halves: exactly Delaunay, valid cells equal to one triangulation's (of either engine),
    and the same Diagram on 1, 2 and 3 threads."""
    d = api.voronoi(pts, bbox=bbox, threads=2, engine=engine)
    for check in CHECKS.values():  # exactly Delaunay; cells valid, distinct points, a tiling of the box
        check(d)
    check_same_cells(cells_of(whole(pts, bbox)), cells_of(d), names=("whole", "halves"))
    for threads in (1, 3):
        assert_same_diagram(d, api.voronoi(pts, bbox=bbox, threads=threads, engine=engine))
    if joins is not None:
        assert all(joins), "a join reported a defect and the build fell back to one triangulation"


# families whose sites have no two halves to triangulate: too few, or collinear on one side
WHOLE_FAMILIES = {
    "collinear_exact",
    "collinear_dyadic_repeats",
    "collinear_plus_one_ulp",
    "two_sites_1e12_2ulps",
    "two_sites_1e12_1ulp",
    "subnormal_default_box",
    "subnormal_row_default_box",
    "duplicates_of_triangle",
    "duplicates_of_collinear",
}


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("name", sorted(adversarial.FAMILIES))
def test_every_family_by_halves(name, engine, split_always):
    case = adversarial.make(name)
    check_by_halves(case.points, case.bbox, split_always, engine)
    if name not in WHOLE_FAMILIES and not name.startswith("sites_"):
        assert split_always, "the build did not go by halves"


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("name", sorted(DATASETS))
def test_datasets_by_halves(name, engine, split_always):
    check_by_halves(DATASETS[name], joins=split_always, engine=engine)


def lattice_disk(r: int, centre=(0, 0)) -> np.ndarray:
    """Every integer point within distance r of centre: circles of many cocircular sites, cut through."""
    g = np.arange(-r, r + 1)
    x, y = np.meshgrid(g, g)
    keep = x * x + y * y <= r * r
    return np.c_[x[keep] + centre[0], y[keep] + centre[1]].astype(float)


SEAM_CASES = {
    # the median line through a column of a grid, through the centre of cocircular rings, along a row
    "grid_column_on_the_line": np.array([(i, j) for i in range(21) for j in range(15)], float),
    "lattice_disk": lattice_disk(12),
    "lattice_disk_offset": lattice_disk(9, (0.5, 0.0)),
    "rotated_square_lattice": np.array([(i - j, i + j) for i in range(16) for j in range(16)], float),
    "two_clusters_apart": np.r_[generate("uniform", 300, seed=5), generate("uniform", 300, seed=6) + 1e6],
    "one_side_collinear": np.r_[
        np.c_[np.linspace(-1, -0.5, 200), np.linspace(0, 1, 200)], generate("uniform", 200, seed=7)
    ],
    "vertical_line_and_cloud": np.r_[np.c_[np.zeros(150), np.arange(150.0)], generate("uniform", 150, seed=8) * 150],
    "half_on_the_median": np.r_[
        np.c_[np.full(300, 0.5), generate("uniform", 300, seed=9)[:, 1]], generate("uniform", 300, seed=10)
    ],
    "circle_points_across": np.c_[
        np.cos(np.linspace(0, 2 * np.pi, 400, endpoint=False)), np.sin(np.linspace(0, 2 * np.pi, 400, endpoint=False))
    ],
    # found by a review: four cocircular sites below the cut, two of their triangles given opposite
    # verdicts by the test in doubles (its radius bound reads the circle from the first corner)
    "cocircular_kept_and_not": np.array([(-1, -3), (0, -5), (3, -1), (4, -3), (2, 5), (2, 3), (1, 0), (1, 6)], float),
    "thin_strip_across": np.c_[generate("uniform", 500, seed=11)[:, 0], 1e-9 * generate("uniform", 500, seed=12)[:, 1]],
}


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("name", sorted(SEAM_CASES))
def test_seam_cases(name, engine, split_always):
    check_by_halves(SEAM_CASES[name], joins=split_always, engine=engine)


def check_split_min_3(pts, engine="incremental") -> None:
    """check_by_halves with the threshold lowered in the test (hypothesis runs many examples in one),
    and no join falling back."""
    with split_from_3() as joins:
        check_by_halves(pts, joins=joins, engine=engine)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(st.integers(-6, 6), st.integers(-6, 6)), min_size=3, max_size=120),
    st.sampled_from([1.0, 0.1, 2.0**-30, 1e9]),
    st.sampled_from(["incremental", "fortune"]),
)
def test_hypothesis_small_integer_sites(coords, unit, engine):
    """Small integer grids (cocircular sites everywhere, many on the median lines) scaled by a unit."""
    check_split_min_3(np.array(coords, float) * unit, engine)


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(8, 400),
    st.sampled_from(["uniform", "gaussian", "clustered"]),
    st.sampled_from(["incremental", "fortune"]),
)
def test_hypothesis_random_sites_rounded(seed, n, dist, engine):
    """Random sites rounded to a few decimals, as instruments give them."""
    check_split_min_3(np.round(generate(dist, n, seed=seed), 2), engine)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_a_large_build_goes_by_halves_and_threads_agree(engine):
    """At the real threshold: the build by halves on 1 and 2 threads is the same Diagram, with the same
    cells as one triangulation."""
    pts = generate("clustered", halves.SPLIT_MIN_SITES + 5000, seed=3)
    e = engines.scale_exponent(pts)
    assert halves.triangulate(pts[:, 0], pts[:, 1], e, engine=engine) is not None
    one, two = api.voronoi(pts, threads=1, engine=engine), api.voronoi(pts, threads=2, engine=engine)
    assert_same_diagram(one, two)
    w = whole(pts)
    assert np.array_equal(w.cell_offsets, two.cell_offsets)
    assert np.array_equal(w.cell_points[w.cell_vertices], two.cell_points[two.cell_vertices])


@pytest.mark.parametrize(("tall", "sweep_axis", "plain_axis"), [(1.05, 0, 1), (1.9, 0, 1), (2.2, 1, 1), (0.8, 0, 0)])
def test_fortune_cuts_its_halves_narrow(tall, sweep_axis, plain_axis):
    """Fortune's sweep goes up in y and its beach line grows with the width of a half: it cuts at the x
    median unless the box is more than twice as tall as wide; the incremental engine cuts the longer
    side. Either cut gives the whole triangulation's cells."""
    pts = generate("uniform", halves.SPLIT_MIN_SITES + 3000, seed=5) * [1.0, tall]
    assert halves.cut(pts[:, 0], pts[:, 1], sweep=True).axis == sweep_axis
    assert halves.cut(pts[:, 0], pts[:, 1]).axis == plain_axis
    w = whole(pts)
    for engine in ("fortune", "incremental"):
        d = api.voronoi(pts, engine=engine, threads=1)
        assert np.array_equal(w.cell_offsets, d.cell_offsets)
        assert np.array_equal(w.cell_points[w.cell_vertices], d.cell_points[d.cell_vertices])


def test_coordinates_near_the_double_range_cut_without_overflow():
    """Sites from -1e308 to 1e308 in x and -1.7e308 to 1.7e308 in y, above the size that splits: the
    cut measures its spans without overflow (no warning, even as an error), cuts the longer side (y),
    and both thread counts give the same Diagram."""
    import warnings

    rng = np.random.default_rng(12)
    n = halves.SPLIT_MIN_SITES + 4464
    pts = np.c_[1e308 * rng.uniform(-1, 1, n), 1.7e308 * rng.uniform(-1, 1, n)]
    box = (-1.79e308, -1.79e308, 1.79e308, 1.79e308)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        c = halves.cut(pts[:, 0], pts[:, 1])
        assert c is not None and c.axis == 1
        one, two = api.voronoi(pts, bbox=box, threads=1), api.voronoi(pts, bbox=box, threads=2)
    assert_same_diagram(one, two)


@pytest.mark.parametrize(
    "values",
    [
        pytest.param(lambda n, rng: rng.random(n), id="uniform"),
        pytest.param(lambda n, rng: np.sort(rng.random(n)), id="sorted"),
        pytest.param(lambda n, rng: np.sort(rng.random(n))[::-1].copy(), id="reversed"),
        # rows alternating between two clusters far apart, and rows in runs of 1000 of one value each
        pytest.param(lambda n, rng: np.where(np.arange(n) % 2 == 0, 0.0, 10.0) + rng.random(n), id="period_2"),
        pytest.param(lambda n, rng: np.repeat(rng.permutation(n // 1000 + 1), 1000)[:n].astype(float), id="runs"),
        pytest.param(lambda n, rng: rng.standard_cauchy(n), id="cauchy"),
    ],
)
@pytest.mark.parametrize("n", [halves.SAMPLE_SITES, 2 * halves.SAMPLE_SITES + 1, 700_001])
def test_the_cut_median_is_a_value_near_the_middle_rank(values, n):
    """halves.median: exact up to 2 SAMPLE_SITES values; above, a sample's median, which must still be a
    value of the column and split it near the middle (within 1% of n here; the sample's error is about
    0.2%), the same value on every call."""
    c = values(n, np.random.default_rng(n))
    m = halves.median(c)
    assert m in c
    below, at_most = np.count_nonzero(c < m), np.count_nonzero(c <= m)
    if n <= 2 * halves.SAMPLE_SITES:
        assert m == np.partition(c, n // 2)[n // 2]
    else:
        assert below <= n // 2 + 0.01 * n and at_most >= n // 2 - 0.01 * n
    assert halves.median(c) == m


def test_no_cut_when_the_median_line_holds_most_sites():
    """Most sites on one vertical and one horizontal line: no balanced cut, the whole triangulation."""
    y = np.arange(100.0)
    pts = np.r_[np.c_[np.zeros(100), y], np.c_[y, np.zeros(100)], [[3.0, 4.0]]]
    assert halves.cut(pts[:, 0], pts[:, 1]) is None


# ---------------------------------------------------------------------------------------------
# what a half keeps: only triangles whose closed circumdisk is strictly on its side, checked exactly


def exact_clear(a, b, c, split, axis, below) -> bool:
    """The closed circumdisk of abc lies strictly below (or above) the line, in rational arithmetic."""
    ax, ay, bx, by, cx, cy = (Fraction(float(v)) for v in (*a, *b, *c))
    d = 2 * ((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))
    if d == 0:
        return False
    b2, c2 = (bx - ax) ** 2 + (by - ay) ** 2, (cx - ax) ** 2 + (cy - ay) ** 2
    ux = ((cy - ay) * b2 - (by - ay) * c2) / d
    uy = ((bx - ax) * c2 - (cx - ax) * b2) / d
    r2 = ux * ux + uy * uy
    centre = ax + ux if axis == 0 else ay + uy
    gap = Fraction(split) - centre if below else centre - Fraction(split)
    return gap > 0 and gap * gap > r2


def kept(tri, split, axis, below):
    xs = np.array([p[0] for p in tri], float)
    ys = np.array([p[1] for p in tri], float)
    keep = np.zeros(1, np.int8)
    marks = np.zeros(3, np.int8)
    seam.kept_triangles(
        xs,
        ys,
        np.array([0, 1, 2], np.int32),
        np.array([0, 1, 2], np.int32),
        0,
        3,
        split,
        axis,
        below,
        0.0,
        0.0,
        0.0,
        0.0,
        keep,
        marks,
    )
    assert marks.tolist() == ([0, 0, 0] if keep[0] else [1, 1, 1])
    return bool(keep[0])


coordinate = st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False)


@settings(max_examples=3000, deadline=None)
@given(
    st.tuples(coordinate, coordinate),
    st.tuples(coordinate, coordinate),
    st.tuples(coordinate, coordinate),
    coordinate,
    st.sampled_from([0, 1]),
    st.booleans(),
    st.integers(0, 1000),
)
# found by this test: sides of 1e-115, whose products of three differences underflowed to zero
@example((0.0, -7.623063129501359e-116), (-7.623063129501359e-116, 0.0), (0.0, 0.0), 0.0, 0, True, 0)
def test_a_kept_triangle_is_clear_of_the_line(a, b, c, split, axis, below, shrink):
    """Whatever the triangle (flat, tiny, huge circle, touching the line, at any scale down to
    subnormal sides), a kept one is clear of it."""
    a, b, c = (tuple(math.ldexp(v, -shrink) for v in p) for p in (a, b, c))
    split = math.ldexp(split, -shrink)
    if orient(a, b, c) <= 0:
        a, b = b, a
    if kept((a, b, c), split, axis, below):
        assert exact_clear(a, b, c, split, axis, below)


def orient(a, b, c):
    return (Fraction(b[0]) - Fraction(a[0])) * (Fraction(c[1]) - Fraction(a[1])) - (Fraction(b[1]) - Fraction(a[1])) * (
        Fraction(c[0]) - Fraction(a[0])
    )


@pytest.mark.parametrize("ulps", [0, 1, 2, 4, 64, 1 << 20])
def test_triangles_whose_circle_touches_the_line_are_left_to_the_seam(ulps):
    """The circle through (-1, 1), (-1, -1) and (0, 0) touches x = 0; lines a few ulps right of it: kept
    only if the exact test agrees, never when the circle touches the line, always when it is far."""
    tri = ((-1.0, 1.0), (-1.0, -1.0), (0.0, 0.0))  # circle centre (-1, 0), radius 1: touches x = 0
    tri = (tri[1], tri[2], tri[0]) if orient(*tri) < 0 else tri
    split = float(np.nextafter(0.0, 1.0) * ulps) if ulps else 0.0
    got = kept(tri, split, 0, True)
    assert not got or exact_clear(*tri, split, 0, True)
    if ulps == 0:
        assert not got
    if ulps == 1 << 20:
        assert not got  # 2^20 subnormal ulps is still far below the filter's margin
    assert kept(tri, 0.5, 0, True)


@pytest.mark.parametrize(("dist", "decimals"), [("uniform", None), ("clustered", None), ("uniform", 2)])
def test_kept_triangles_judged_on_threads_alike(dist, decimals):
    """kept_triangles judges runs of whole blocks of triangles on each thread: the same keep and seam
    marks on 1, 2 and 3 threads, for a half of 60,000 sites (about 120,000 triangles, past the size
    that splits) in a random order of its triangles, cocircular ones among them when rounded."""
    pts = generate(dist, 120_000, seed=4)
    pts = pts if decimals is None else np.round(pts, decimals)
    split = float(np.median(pts[:, 0]))
    left = pts[pts[:, 0] < split]
    left = np.unique(left, axis=0)
    t = engines.run(left[:, 0], left[:, 1], engine="incremental", exponent=0)
    n = len(left)
    rows = np.random.default_rng(1).permutation(len(t.tv) // 3)  # the triangles in a random order
    tv = t.tv.reshape(-1, 3)[rows].reshape(-1)
    new_of = np.empty_like(rows)
    new_of[rows] = np.arange(len(rows))
    old = t.opp.reshape(-1, 3)[rows]
    opp = (3 * new_of[old // 3] + old % 3).astype(np.int32).reshape(-1)
    right = pts[pts[:, 0] >= split]
    box = (right[:, 0].min(), right[:, 1].min(), right[:, 0].max(), right[:, 1].max())
    got = []
    for threads in (1, 2, 3):
        keep, marks = np.zeros(len(rows), np.int8), np.zeros(n, np.int8)
        seam.kept_triangles(t.sites.xs, t.sites.ys, tv, opp, 0, n, split, 0, True, *box, keep, marks, threads)
        got.append((keep, marks))
    assert 0 < np.count_nonzero(got[0][0] == 0) < len(rows) // 4
    for keep, marks in got[1:]:
        assert np.array_equal(keep, got[0][0]) and np.array_equal(marks, got[0][1])


@pytest.mark.parametrize("seed", range(4))
def test_integer_sites_at_the_threshold_join_without_falling_back(seed):
    """Random integer sites (cocircular quadruples everywhere) at the real threshold: the join holds (it
    fell back for 5 of 8 seeds before cocircular neighbours were left to the seam together)."""
    pts = np.random.default_rng(seed).integers(0, 1000, (halves.SPLIT_MIN_SITES + 4000, 2)).astype(float)
    e = engines.scale_exponent(pts)
    t = halves.triangulate(pts[:, 0], pts[:, 1], e, threads=2)
    assert t is not None


def test_an_interrupted_build_stops_its_other_half(monkeypatch):
    """Ctrl-C reaches the main thread's half; the other half's kernels then stop at their next poll
    (tvoronoi.kernels.STOPPING) instead of running to their end, and a build afterwards is whole."""
    from tvoronoi.kernels import STOPPING

    real, outcomes = halves.half_triangles, []

    def half_triangles(engine, xs, ys, rows, out, first, **kw):
        if first == 0:  # the main thread's half: interrupted while the other half works
            time.sleep(0.02)
            raise KeyboardInterrupt
        try:
            outcomes.append(real(engine, xs, ys, rows, out, first, **kw))
        except KeyboardInterrupt as exc:
            outcomes.append(exc)
            raise

    monkeypatch.setattr(halves, "half_triangles", half_triangles)
    pts = generate("uniform", 800_000, seed=9)
    with pytest.raises(KeyboardInterrupt):
        halves.triangulate(pts[:, 0].copy(), pts[:, 1].copy(), 0, threads=2)
    assert len(outcomes) == 1 and isinstance(outcomes[0], KeyboardInterrupt), outcomes
    assert not STOPPING
    monkeypatch.setattr(halves, "half_triangles", real)
    small = generate("uniform", 3000, seed=9)
    with split_from_3() as joins:
        check_by_halves(small, joins=joins)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("late", ["left", "right"])
def test_the_right_half_is_laid_out_by_whichever_thread_is_free(monkeypatch, engine, late):
    """On two threads the right half's triangles are laid out by its own thread when the left half is not
    done yet, else by the main thread on two (halves.on_two_halves): each way the same triangulation
    as on one thread. Each way is forced here by holding one half's triangles back."""
    pts = generate("uniform", 3 * halves.SPLIT_MIN_SITES, seed=5)
    e = engines.scale_exponent(pts)
    one = halves.triangulate(pts[:, 0], pts[:, 1], e, engine=engine, threads=1)
    real_tri, real_lay = halves.half_triangles, halves.lay_out
    laid: list[tuple[int, bool]] = []  # (first site, laid out on the main thread)

    def half_triangles(engine, xs, ys, rows, out, first, **kw):
        t = real_tri(engine, xs, ys, rows, out, first, **kw)
        if (first == 0) == (late == "left"):
            time.sleep(0.3)
        return t

    def lay_out(t, other_box, c, out, first, **kw):
        laid.append((first, threading.current_thread() is threading.main_thread()))
        return real_lay(t, other_box, c, out, first, **kw)

    monkeypatch.setattr(halves, "half_triangles", half_triangles)
    monkeypatch.setattr(halves, "lay_out", lay_out)
    two = halves.triangulate(pts[:, 0], pts[:, 1], e, engine=engine, threads=2)
    right = [on_main for first, on_main in laid if first != 0]
    assert right == [late == "right"], laid
    for name in ("tv", "opp", "dup"):
        assert np.array_equal(getattr(one, name), getattr(two, name)), name
    assert np.array_equal(one.sites.perm, two.sites.perm)
    assert np.array_equal(one.sites.xs, two.sites.xs)


def test_the_waiting_thread_faults_in_the_half_edges_up_to_the_bound_once():
    """HalfEdgeFaults: runs of FAULT_RUN bytes of each of the three arrays, up to 3 (2 d - 2) half-edges
    for the first bound given (a later one changes nothing), then nothing more; contents untouched;
    without he_room (one thread), nothing at all."""
    n = 3 * halves.FAULT_RUN // 4  # the bound below spans several runs
    one = halves.HalfEdgeFaults(halves.Joined.empty(n))
    one.bound(n)
    assert not one.run()
    out = halves.Joined.empty(n, he_room=True)
    assert out.he_room is not None
    for k, a in enumerate(out.he_room):
        a[:] = k - 7
    faults = halves.HalfEdgeFaults(out)
    distinct = n - 1000
    faults.bound(distinct)
    faults.bound(n)  # (ignored: the first bound holds)
    want = 4 * 3 * (2 * distinct - 2)
    assert want < 4 * len(out.he_room[0])
    runs = 0
    while faults.run():
        runs += 1
    assert runs == -(-want // halves.FAULT_RUN) and faults.done == want
    assert not faults.run() and faults.done == want
    for k, a in enumerate(out.he_room):
        assert (a == k - 7).all()


def test_the_second_thread_makes_its_arrays_in_the_pages_of_the_first():
    """on_two_threads: inside pages.small_pages() (a build on two threads) the second thread's arrays are
    made in small pages too; outside it, neither's are."""
    from tvoronoi.kernels import pages

    def flag():
        return pages.small_pages_on()

    assert halves.on_two_threads([flag, flag]) == [False, False]
    with pages.small_pages():
        assert halves.on_two_threads([flag, flag]) == [True, True]
    assert not pages.small_pages_on()
