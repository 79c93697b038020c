"""The spatial renumbering of a triangulation (kernels/renumber.pyx, engines.renumbered): the same
triangulation in new numbers, the same cells, and neighbours near in memory."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import DATASETS
from tests import adversarial
from tvoronoi import build, engines
from tvoronoi.api import as_bbox, default_bbox
from tvoronoi.generators import generate
from tvoronoi.kernels import renumber

ENGINES = ("incremental", "fortune")


def triangulation(pts: np.ndarray, engine: str) -> engines.Triangulation:
    return engines.run(np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1]), engine=engine)


def check_renumbered(t: engines.Triangulation, r: engines.Triangulation) -> None:
    """r is t with its sites and triangles renumbered: a permutation of both, nothing else changed."""
    n = len(t.sites)
    if t.flat:
        assert r is t
        return
    new_to_old = np.empty(n, np.int64)
    for k, row in enumerate(r.sites.perm):  # input rows are one-to-one with sites
        new_to_old[k] = int(np.flatnonzero(t.sites.perm == row)[0])
    assert np.array_equal(np.sort(new_to_old), np.arange(n))
    assert np.array_equal(r.sites.xs, t.sites.xs[new_to_old])
    assert np.array_equal(r.sites.ys, t.sites.ys[new_to_old])
    assert r.sites.exponent == t.sites.exponent
    old_to_new = np.empty(n + 1, np.int64)
    old_to_new[new_to_old] = np.arange(n)
    old_to_new[n] = n

    # the twins: an involution, each half-edge a->b paired with b->a
    tv, opp = r.tv.astype(np.int64), r.opp.astype(np.int64)
    h = np.arange(len(tv))
    assert np.array_equal(opp[opp], h)
    head = tv[3 * (h // 3) + (h % 3 + 1) % 3]
    assert np.array_equal(tv[opp], head) and np.array_equal(head[opp], tv)

    # the same triangles, each in the same rotation
    def rotations(tri):
        tri = tri.reshape(-1, 3)
        k = np.argmin(tri, axis=1)
        return sorted(map(tuple, np.stack([tri[np.arange(len(tri)), (k + j) % 3] for j in range(3)], 1).tolist()))

    assert rotations(old_to_new[t.tv]) == rotations(tv)

    # repeated sites: each names the new number of a site at the same place that is not itself a repeat
    assert np.array_equal(r.dup < 0, (t.dup < 0)[new_to_old])
    rep = np.flatnonzero(r.dup >= 0)
    assert np.all(r.dup[r.dup[rep]] < 0)
    assert np.array_equal(r.sites.xs[r.dup[rep]], r.sites.xs[rep])
    assert np.array_equal(r.sites.ys[r.dup[rep]], r.sites.ys[rep])


def cells(t: engines.Triangulation, pts: np.ndarray, box) -> list:
    s = t.sites
    d = build.assemble(pts, box, s.exponent, s.perm, s.xs, s.ys, t.voronoi(1), engine=t.engine)
    return [d.cell_polygon(i).tolist() for i in range(len(pts))]


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("name", sorted(DATASETS))
def test_the_same_triangulation_and_cells_on_every_data_set(name, engine):
    pts = DATASETS[name]
    t = triangulation(pts, engine)
    r = engines.renumbered(t)
    check_renumbered(t, r)
    box = as_bbox(default_bbox(pts))
    assert cells(r, pts, box) == cells(t, pts, box)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("family", sorted(adversarial.FAMILIES))
def test_the_same_cells_on_the_adversarial_families(family, engine):
    case = adversarial.make(family)
    pts = case.points
    t = triangulation(pts, engine)
    r = engines.renumbered(t)
    if len(pts) <= 3000:
        check_renumbered(t, r)
    box = as_bbox(case.bbox if case.bbox is not None else default_bbox(pts))
    assert cells(r, pts, box) == cells(t, pts, box)


@settings(max_examples=60)
@given(
    st.lists(
        st.tuples(st.integers(-6, 6), st.integers(-6, 6)).map(lambda p: (p[0] * 0.5, p[1] * 0.25)),
        min_size=1,
        max_size=60,
    ),
    st.sampled_from(ENGINES),
)
def test_small_inputs_with_repeats_and_ties(points, engine):
    pts = np.array(points, float)
    t = triangulation(pts, engine)
    r = engines.renumbered(t)
    check_renumbered(t, r)
    box = as_bbox(default_bbox(pts))
    assert cells(r, pts, box) == cells(t, pts, box)


@pytest.mark.parametrize("threads", [2, 3])
def test_the_same_numbering_on_any_thread_count(threads):
    pts = generate("clustered", 60_000, seed=21)  # over 2^16 triangles: the rewrite runs on threads
    t = triangulation(pts, "incremental")
    one = renumber.spatial_order(t.sites.xs, t.sites.ys, t.tv, t.opp, 1)
    many = renumber.spatial_order(t.sites.xs, t.sites.ys, t.tv, t.opp, threads)
    for a, b in zip(one, many, strict=True):
        assert np.array_equal(a, b)


def edge_gap(t: engines.Triangulation) -> float:
    """The median difference of the numbers of two Delaunay neighbours, over the site count."""
    n = len(t.sites)
    tv = t.tv.astype(np.int64)
    h = np.arange(len(tv))
    head = tv[3 * (h // 3) + (h % 3 + 1) % 3]
    finite = (tv != n) & (head != n)
    return float(np.median(np.abs(tv[finite] - head[finite]))) / n


def nested_clusters(rng) -> np.ndarray:
    """Clusters inside clusters beside far sites: one grid over the bounding box puts each in one cell."""
    inner = 0.5 + 1e-12 * rng.random((20_000, 2))
    middle = 0.5 + 1e-6 * rng.random((20_000, 2))
    return np.vstack([inner, middle, [[0.0, 0.0], [1e3, 1e3], [-50.0, 7.0]]])


NEAR = {
    "uniform": lambda rng: generate("uniform", 40_000, seed=22),
    "cluster_beside_far_sites": lambda rng: np.vstack([0.5 + 1e-7 * rng.random((40_000, 2)), [[0, 0], [1e3, 1e3]]]),
    "nested_clusters": nested_clusters,
}


@pytest.mark.parametrize("name", sorted(NEAR))
@pytest.mark.parametrize("engine", ENGINES)
def test_neighbours_are_near_in_memory(rng, name, engine):
    """What the renumbering is for: Delaunay neighbours get near numbers, so the triangles around
    consecutive sites lie together (BRIO numbers neighbours from different rounds: about n/4 apart).
    Clusters beside far sites are ordered inside too (crowded cells are gridded again)."""
    pts = NEAR[name](rng)
    t = triangulation(pts, engine)
    r = engines.renumbered(t)
    assert edge_gap(r) < 1e-3
    if engine == "incremental":
        assert edge_gap(t) > 0.1  # (the insertion order's numbers: what the renumbering improves)


def test_every_site_at_one_place_but_one():
    """Degenerate case: a crowded cell whose sites all repeat one point is left as it is."""
    pts = np.vstack([np.full((500, 2), 0.25), [[1.0, 1.0], [0.0, 1.0]]])
    t = triangulation(pts, "incremental")
    r = engines.renumbered(t)
    check_renumbered(t, r)


def test_grid_bits_give_about_one_site_a_cell():
    assert renumber.grid_bits(0) == 0
    assert renumber.grid_bits(1) == 0
    assert renumber.grid_bits(4) == 1
    assert renumber.grid_bits(5) == 2
    assert renumber.grid_bits(1_000_000) == 10
    assert renumber.grid_bits(10**9) == 11  # capped: the count array stays small


def test_builds_renumber_the_incremental_engine_only():
    pts = generate("uniform", 2_000, seed=23)
    inc, fort = triangulation(pts, "incremental"), triangulation(pts, "fortune")
    assert engines.spatial(fort) is fort
    r = engines.spatial(inc)
    assert r is not inc and np.array_equal(r.sites.perm, engines.renumbered(inc).sites.perm)


def test_a_layout_made_beforehand_gives_the_same_triangulation():
    """build.triangulate_and_lay_out makes the sites' order while the triangulation runs: the same result."""
    pts = generate("clustered", 5_000, seed=24)
    t = triangulation(pts, "incremental")
    layout = engines.spatial_sites(t.sites)
    a, b = engines.renumbered(t), engines.renumbered(t, 2, layout)
    for name in ("tv", "opp", "dup"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    for name in ("perm", "xs", "ys"):
        assert np.array_equal(getattr(a.sites, name), getattr(b.sites, name)), name


def test_the_overlapped_build_gives_the_same_diagram(monkeypatch):
    """On two threads the layout is made beside the triangulation from 2^15 sites on; lowering that bound
    and raising it give the same Diagram."""
    import tvoronoi
    from tvoronoi import build

    pts = generate("gaussian", 3_000, seed=25)
    monkeypatch.setattr(build, "OVERLAP_MIN_SITES", 1)
    overlapped = tvoronoi.voronoi(pts, threads=2)
    monkeypatch.setattr(build, "OVERLAP_MIN_SITES", 10**9)
    plain = tvoronoi.voronoi(pts, threads=2)
    for name in ("he_origin", "he_twin", "he_face", "face_edge", "vertices", "cell_vertices", "cell_offsets"):
        assert np.array_equal(getattr(overlapped, name), getattr(plain, name)), name


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(1, 300),
    data=st.data(),
)
def test_take_sites_is_numpy_indexing_of_both_columns(n, data):
    """take_sites gathers both coordinates at int32 indices, from strided columns as from contiguous ones."""
    pts = np.random.default_rng(n).normal(size=(n, 2))
    idx = np.asarray(data.draw(st.lists(st.integers(0, n - 1), max_size=2 * n)), np.int32)
    x, y = renumber.take_sites(pts[:, 0], pts[:, 1], idx)  # strided columns
    assert x.flags.c_contiguous and y.flags.c_contiguous
    assert np.array_equal(x, pts[idx, 0]) and np.array_equal(y, pts[idx, 1])
    cx, cy = renumber.take_sites(pts[:, 0].copy(), pts[:, 1].copy(), idx)
    assert np.array_equal(cx, x) and np.array_equal(cy, y)


@settings(max_examples=80, deadline=None)
@given(
    n=st.integers(1, 200),
    exponent=st.sampled_from([-1100, -1074, -1023, -1022, -60, -1, 1, 7, 900, 1022, 1023, 1074, 1100]),
    mantissa_bits=st.sampled_from([1, 20, 53]),
    magnitude=st.integers(-1074, 1023),
    seed=st.integers(0, 2**16),
)
def test_take_sites_scales_as_numpy_ldexp_does(n, exponent, mantissa_bits, magnitude, seed):
    """take_sites(..., exponent) is xs[idx] * 2^-exponent rounded as np.ldexp rounds it, bit for bit:
    exact for normal results, and the same rounding where the result is subnormal, overflows or
    underflows to zero, with the factor a normal double or not."""
    rng = np.random.default_rng(seed)
    m = rng.integers(1, 2**mantissa_bits, size=(n, 2)).astype(np.float64) * rng.choice([-1.0, 1.0], size=(n, 2))
    pts = np.ldexp(
        m, np.clip(magnitude - mantissa_bits + rng.integers(-40, 40, size=(n, 2)), -1074, 1023 - mantissa_bits)
    )
    pts[rng.random((n, 2)) < 0.1] = 0.0
    idx = rng.integers(0, n, size=2 * n).astype(np.int32)
    with np.errstate(over="ignore", under="ignore"):
        want_x, want_y = np.ldexp(pts[idx, 0], -exponent), np.ldexp(pts[idx, 1], -exponent)
    x, y = renumber.take_sites(pts[:, 0], pts[:, 1], idx, exponent)
    assert np.array_equal(x.view(np.int64), want_x.view(np.int64))
    assert np.array_equal(y.view(np.int64), want_y.view(np.int64))


def expected_split(pts, axis, split, exponent):
    """split_sites by numpy: each side's rows, its sites scaled by ldexp, and its box by a loop of strict
    comparisons (the first site's value among equal extremes, bit for bit: a zero keeps its sign)."""
    below = pts[:, axis] < split
    sides = []
    for part in (below, ~below):
        rows = np.flatnonzero(part)
        want = [math.inf, math.inf, -math.inf, -math.inf]
        for x, y in pts[part].tolist():
            want = [x if x < want[0] else want[0], y if y < want[1] else want[1],
                    x if x > want[2] else want[2], y if y > want[3] else want[3]]  # fmt: skip
        sides.append((rows, np.ldexp(pts[rows, 0], -exponent), np.ldexp(pts[rows, 1], -exponent), want))
    return sides


def assert_split_is(got, sides):
    (rows_l, xl, yl), (rows_r, xr, yr), box_l, box_r = got
    for (rows, xs, ys), box, (w_rows, w_xs, w_ys, w_box) in zip(
        ((rows_l, xl, yl), (rows_r, xr, yr)), (box_l, box_r), sides, strict=True
    ):
        assert rows.dtype == np.int32 and np.array_equal(rows, w_rows)
        assert np.array_equal(xs.view(np.int64), w_xs.view(np.int64))
        assert np.array_equal(ys.view(np.int64), w_ys.view(np.int64))
        assert np.array_equal(np.array(box).view(np.int64), np.array(w_box).view(np.int64))


@settings(max_examples=80, deadline=None)
@given(
    n=st.integers(1, 300),
    axis=st.sampled_from([0, 1]),
    kind=st.sampled_from(["normal", "grid", "signed zeros"]),
    exponent=st.sampled_from([0, 3, -7, 1030, -1040]),
    seed=st.integers(0, 2**16),
)
def test_split_sites_is_the_two_masks_their_sites_and_boxes(n, axis, kind, exponent, seed):
    """split_sites gives the rows below the split and the others, each in row order with its sites
    scaled as np.ldexp scales them, and each part's box (unscaled), from strided columns; ties with the
    split go right. A box's bounds are the first site's value among equal extremes, bit for bit."""
    rng = np.random.default_rng(seed)
    if kind == "normal":
        pts = rng.normal(size=(n, 2))
    elif kind == "grid":
        pts = rng.integers(0, 6, size=(n, 2)).astype(np.float64)
    else:
        pts = rng.choice(np.array([-0.0, 0.0, -1.0, 1.0, 5e-324, -1e300]), size=(n, 2))
    split = float(pts[rng.integers(0, n), axis]) if rng.random() < 0.8 else float(rng.normal() * 3)
    with np.errstate(over="ignore"):
        sides = expected_split(pts, axis, split, exponent)
        assert_split_is(renumber.split_sites(pts[:, 0], pts[:, 1], axis, split, exponent), sides)
    n_left = len(sides[0][0])
    least = min(n_left, n - n_left)
    assert renumber.split_sites(pts[:, 0], pts[:, 1], axis, split, exponent, least) is not None
    assert renumber.split_sites(pts[:, 0], pts[:, 1], axis, split, exponent, least + 1) is None


@pytest.mark.parametrize("kind", ["uniform", "sorted", "all left", "runs of ties"])
def test_split_sites_gives_the_same_arrays_on_any_thread_count(kind):
    """Above the size split on threads, each thread counts and writes a run of rows: the arrays are those
    of one pass for any count, the boxes too (a later run's bound only where strictly beyond: a tie
    keeps the earlier site's signed zero)."""
    n = 70_001
    rng = np.random.default_rng(len(kind))
    pts = rng.random((n, 2))
    split = 0.5
    if kind == "sorted":
        pts = pts[np.argsort(pts[:, 0])]
    elif kind == "all left":
        split = 2.0
    elif kind == "runs of ties":
        pts = np.repeat(np.array([[-0.0, 0.0], [0.0, -0.0], [0.5, 1.0], [1.0, 0.5]]), n // 4 + 1, axis=0)[:n]
    sides = expected_split(pts, 0, split, 2)
    for threads in (1, 2, 3, 7):
        assert_split_is(renumber.split_sites(pts[:, 0], pts[:, 1], 0, split, 2, 0, threads), sides)


@pytest.mark.parametrize("bad", [-1, 5, 2**31 - 1])
def test_take_sites_refuses_an_index_out_of_range(bad):
    xs = np.arange(5.0)
    with pytest.raises(IndexError, match="out of range"):
        renumber.take_sites(xs, xs, np.array([0, bad, 1], np.int32))


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 200), n_rows=st.integers(1, 400), seed=st.integers(0, 2**16))
def test_sites_into_is_the_three_gathers_it_replaces(n, n_rows, seed):
    """sites_into writes xs[new_to_old], ys[new_to_old] and rows[perm][new_to_old] into slices of larger
    arrays, leaving the rest of them alone."""
    rng = np.random.default_rng(seed)
    xs, ys = rng.random(n), rng.random(n)
    rows = rng.integers(0, 10**6, n_rows).astype(np.int32)
    perm = rng.integers(0, n_rows, n).astype(np.int32)
    new_to_old = rng.permutation(n).astype(np.int32)
    ox, oy, orows = np.full(n + 7, -1.0), np.full(n + 7, -1.0), np.full(n + 7, -1, np.int32)
    renumber.sites_into(xs, ys, rows, perm, new_to_old, ox[3 : 3 + n], oy[3 : 3 + n], orows[3 : 3 + n])
    assert np.array_equal(ox[3 : 3 + n], xs[new_to_old]) and np.array_equal(oy[3 : 3 + n], ys[new_to_old])
    assert np.array_equal(orows[3 : 3 + n], rows[perm][new_to_old])
    assert (ox[:3] == -1).all() and (ox[3 + n :] == -1).all() and (orows[3 + n :] == -1).all()


def test_sites_into_refuses_an_index_out_of_range():
    xs = np.arange(4.0)
    out = np.empty(4), np.empty(4), np.empty(4, np.int32)
    ok = np.arange(4, dtype=np.int32)
    with pytest.raises(IndexError):
        renumber.sites_into(xs, xs, ok, ok, np.array([0, 1, 2, 4], np.int32), *out)
    with pytest.raises(IndexError):
        renumber.sites_into(xs, xs, ok[:3], ok, ok, *out)  # perm names row 3 of 3
    with pytest.raises(ValueError):
        renumber.sites_into(xs, xs, ok, ok, ok, np.empty(3), out[1], out[2])


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 200), seed=st.integers(0, 2**16))
def test_sites_into_without_perm_takes_rows_in_the_new_order(n, seed):
    """perm None: out_rows[k] = rows[new_to_old[k]] (a half's sites gathered along their curve)."""
    rng = np.random.default_rng(seed)
    xs, ys = rng.random(n), rng.random(n)
    rows = rng.permutation(10 * n)[:n].astype(np.int32)
    new_to_old = rng.permutation(n).astype(np.int32)
    ox, oy, orows = np.empty(n), np.empty(n), np.empty(n, np.int32)
    renumber.sites_into(xs, ys, rows, None, new_to_old, ox, oy, orows)
    assert np.array_equal(ox, xs[new_to_old]) and np.array_equal(oy, ys[new_to_old])
    assert np.array_equal(orows, rows[new_to_old])


@pytest.mark.parametrize("name", ["uniform", "grid", "circle", "duplicates", "clustered"])
def test_triangle_order_without_renumbering_is_the_identity_renumbering(name):
    """triangle_order_into with old_to_new None (sites numbered along a curve already) sorts the
    triangles exactly as with the identity renumbering, and writes the sites as they are."""
    t = triangulation(DATASETS[name], "incremental")
    assert not t.flat
    n = len(t.sites)
    a, b = np.empty_like(t.tv), np.empty_like(t.opp)
    c, d = np.empty_like(t.tv), np.empty_like(t.opp)
    renumber.triangle_order_into(t.tv, t.opp, np.arange(n, dtype=np.int32), a, b, 0, 0, n)
    renumber.triangle_order_into(t.tv, t.opp, None, c, d, 0, 0, n, n_sites=n)
    assert np.array_equal(a, c) and np.array_equal(b, d)
    assert sorted(map(tuple, np.sort(c.reshape(-1, 3), axis=1))) == sorted(
        map(tuple, np.sort(t.tv.reshape(-1, 3), axis=1))
    )
    with pytest.raises(ValueError):
        renumber.triangle_order_into(t.tv, t.opp, None, c, d, 0, 0, n)
