"""Constructed coordinates are the doubles nearest to the exact values (checked with Fractions)."""

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tvoronoi.kernels import clip, dual


def exact_circumcentre(a, b, c):
    ax, ay, bx, by, cx, cy = (Fraction(v) for v in (*a, *b, *c))
    d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    aa, bb, cc = ax * ax + ay * ay, bx * bx + by * by, cx * cx + cy * cy
    ux = (aa * (by - cy) + bb * (cy - ay) + cc * (ay - by)) / d
    uy = (aa * (cx - bx) + bb * (ax - cx) + cc * (bx - ax)) / d
    return ux, uy


def rounded(q: Fraction, e: int = 0) -> float:
    # int / int true division is correctly rounded, ties to even
    q = q * Fraction(2) ** e
    return q.numerator / q.denominator


def kernel_circumcentres(tris, e=0):
    tris = np.asarray(tris, np.float64).reshape(-1, 3, 2)
    xs = np.ascontiguousarray(tris[:, :, 0].ravel())
    ys = np.ascontiguousarray(tris[:, :, 1].ravel())
    idx = np.arange(3 * len(tris), dtype=np.int32).reshape(-1, 3)
    return dual.circumcentres(xs, ys, idx, e)


def collinear(a, b, c):
    ax, ay, bx, by, cx, cy = (Fraction(v) for v in (*a, *b, *c))
    return (bx - ax) * (cy - ay) == (by - ay) * (cx - ax)


def check_triangles(tris, e=0):
    got = kernel_circumcentres(tris, e)
    for k, (a, b, c) in enumerate(np.asarray(tris, np.float64).reshape(-1, 3, 2)):
        if collinear(a, b, c):
            continue
        ux, uy = exact_circumcentre(a, b, c)
        assert got[k, 0] == rounded(ux, e) and got[k, 1] == rounded(uy, e), (a.tolist(), b.tolist(), c.tolist())


def test_random_triangles_are_correctly_rounded():
    rng = np.random.default_rng(7)
    check_triangles(rng.random((3000, 3, 2)))


@pytest.mark.parametrize("offset, scale", [(0.0, 1.0), (0.5, 1e-7), (4.5e5, 1e3), (-3.0, 1e-3)])
def test_delaunay_triangles_are_correctly_rounded(offset, scale):
    """A build's triangles: the doubles settle about 5 centres in 6 by their bound (rounds_alike), the
    others go on to long double; either way each coordinate is the nearest double (a sample against
    Fractions, at offsets where a centre's offset from its site is small against an ulp and where not)."""
    from tvoronoi import engines

    rng = np.random.default_rng(13)
    pts = offset + scale * rng.random((20000, 2))
    e = engines.scale_exponent(pts)
    s = engines.prepare(pts[:, 0], pts[:, 1], engine="incremental", exponent=e)
    t = engines.triangulate(s, engine="incremental")
    tri = t.voronoi()["triangles"]
    pick = tri[rng.choice(len(tri), 1500, replace=False)]
    got = dual.circumcentres(s.xs, s.ys, np.ascontiguousarray(pick), e)
    for k, (a, b, c) in enumerate(pick):
        ux, uy = exact_circumcentre(*((s.xs[v], s.ys[v]) for v in (a, b, c)))
        assert got[k, 0] == rounded(ux, e) and got[k, 1] == rounded(uy, e), (a, b, c)


@pytest.mark.parametrize("offset, scale, e", [(0.0, 1.0, 0), (1.0, 1.0, 0), (4.5e5, 1e3, 3), (-3.0, 1e-3, -1060)])
def test_blocks_give_the_centres_one_by_one_gives(offset, scale, e):
    """The dual's blocks (a vectorized first tier, then circumcentre for what it leaves open) and
    circumcentre called on each triangle give the same doubles, on a build's triangles and on hard ones
    (nearly collinear, near ties of a noisy lattice, far from the origin, results out of range), in
    counts that leave partial blocks."""
    from tvoronoi import engines

    rng = np.random.default_rng(21)
    pts = offset + scale * rng.random((30011, 2))
    s = engines.prepare(pts[:, 0], pts[:, 1], engine="incremental", exponent=engines.scale_exponent(pts))
    tri = engines.triangulate(s, engine="incremental").voronoi()["triangles"]
    sets = [(s.xs, s.ys, np.ascontiguousarray(tri))]
    t = np.linspace(0, 1, 301)
    line = offset + scale * np.column_stack((t, 1 + 2 * t))
    k = 40
    g = np.stack(np.meshgrid(np.arange(k), np.arange(k)), -1).reshape(-1, 2) * 2.0**-6
    g = offset + scale * (g + 1e-15 * rng.standard_normal(g.shape))
    for p, m in ((line, 299), (g, 997)):
        i = rng.integers(0, len(p) - 2, m)
        idx = np.column_stack((i, i + 1, i + 2)) if p is line else rng.integers(0, len(p), (m, 3))
        keep = [not collinear(p[a], p[b], p[c]) for a, b, c in idx]
        sets.append((np.ascontiguousarray(p[:, 0]), np.ascontiguousarray(p[:, 1]), idx[keep].astype(np.int32)))
    for xs, ys, idx in sets:
        blocks = dual.circumcentres(xs, ys, idx, e)
        single = dual.circumcentres(xs, ys, idx, e, by_blocks=False)
        assert len(idx) % 64 != 0
        np.testing.assert_array_equal(blocks.view(np.int64), single.view(np.int64))


def test_nearly_collinear_triangles():
    # sites on y = 1 + 2x rounded to doubles: the determinant is a few ulps, the vertex far away
    t = np.linspace(0, 1, 60)
    pts = np.column_stack((t, 1 + 2 * t))
    tris = [(pts[i], pts[i + 1], pts[i + 2]) for i in range(58)]
    check_triangles(tris)


def test_perturbed_lattice_and_decimals():
    rng = np.random.default_rng(8)
    g = np.array([(i, j) for i in range(8) for j in range(8)], float) + rng.normal(0, 1e-17, (64, 2))
    idx = rng.integers(0, 64, (800, 3))
    check_triangles(g[idx])
    dec = np.round(rng.random((900, 3, 2)), 2)
    check_triangles(dec)


def test_near_ties_of_noisy_lattices():
    """Centres of a lattice with tiny noise sit within 1e-6 ulp of a rounding tie (about 40% of them):
    the exact stage decides them, in coordinates relative to a site where the differences are exact."""
    rng = np.random.default_rng(11)
    for noise in (1e-12, 1e-15, 1e-17):
        k = 30
        g = np.stack(np.meshgrid(np.arange(k), np.arange(k)), -1).reshape(-1, 2) * 2.0**-6
        g = g + noise * rng.standard_normal(g.shape)
        i = rng.integers(0, k - 1, 600)
        j = rng.integers(0, k - 1, 600)
        at = lambda di, dj: g[(i + di) * k + j + dj]  # noqa: E731, B023 (used in this iteration)
        check_triangles(np.stack([at(0, 0), at(1, 0), at(0, 1)], 1))
        check_triangles(np.stack([at(1, 1), at(0, 1), at(1, 0)], 1))


def test_relative_differences_not_exact_fall_back():
    """Sites whose differences are not doubles (a site at 0 beside ones near 1, magnitudes far apart)."""
    rng = np.random.default_rng(12)
    a = np.zeros((300, 2)) + rng.normal(0, 1e-30, (300, 2))
    b = 1 + rng.random((300, 2)) * 1e-3
    c = np.column_stack((1 + rng.random(300) * 1e-3, 2 + rng.random(300)))
    check_triangles(np.stack([a, b, c], 1))


def test_scaled_output_is_rounded_once():
    # the kernel folds the scale 2^e into the rounding: a subnormal result is still the nearest double
    rng = np.random.default_rng(9)
    tris = rng.random((300, 3, 2))
    check_triangles(tris, e=-1060)
    check_triangles(tris, e=40)


coord = st.one_of(
    st.integers(-50, 50).map(float),
    st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False).filter(lambda v: v == 0 or abs(v) > 1e-100),
    st.decimals(-10, 10, places=2).map(float),
)


@settings(max_examples=400, deadline=None)
@given(st.lists(coord, min_size=6, max_size=6))
def test_hypothesis_circumcentres(values):
    a, b, c = np.array(values).reshape(3, 2)
    check_triangles([(a, b, c)])


def exact_bisector_at(a, b, t, along_y):
    ax, ay, bx, by, t = (Fraction(v) for v in (*a, *b, t))
    num = bx * bx + by * by - ax * ax - ay * ay
    if along_y:  # y = t: returns x
        return (num - 2 * t * (by - ay)) / (2 * (bx - ax))
    return (num - 2 * t * (bx - ax)) / (2 * (by - ay))


@pytest.mark.parametrize("along_y", [False, True])
def test_bisector_crossings_are_correctly_rounded(along_y):
    rng = np.random.default_rng(10)
    for _ in range(400):
        a, b = rng.random((2, 2)) * rng.choice([1e-3, 1.0, 1e3])
        t = float(rng.normal() * rng.choice([1.0, 1e10, 1e-5]))
        if (a[0] == b[0]) if along_y else (a[1] == b[1]):
            continue
        got = clip.bisector_crossing(a[0], a[1], b[0], b[1], t, along_y, 0)
        assert got == rounded(exact_bisector_at(a, b, t, along_y))


def test_ties_round_to_even():
    # circumcentres exactly halfway between two doubles (x = 2^52 + k + 1/2, where the ulp is 1)
    big = 2.0**52
    tris = [((big + k, 0.0), (big + k + 1, 0.0), (big + k, 2.0)) for k in range(0, 12, 2)]
    tris += [((big + k, 1.0), (big + k + 1, 1.0), (big + k + 1, -3.0)) for k in range(1, 12, 2)]
    check_triangles(tris)
    got = kernel_circumcentres(tris[:1])
    assert got[0, 0] == big  # 2^52 + 1/2 -> the even neighbour, 2^52


def exact_orientation(a, b, c) -> int:
    ax, ay, bx, by, cx, cy = (Fraction(v) for v in (*a, *b, *c))
    o = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return (o > 0) - (o < 0)


# doubles of every magnitude the clipper's rings can hold: box sides up to 1.3e300, sites down to 2^-900
wide = st.one_of(
    st.floats(min_value=-1.3e300, max_value=1.3e300, allow_nan=False, allow_infinity=False),
    st.floats(min_value=-1.0, max_value=1.0, allow_nan=False, allow_infinity=False, allow_subnormal=False),
    st.sampled_from([0.0, 1.0, -1.0, 1e300, -1e300, 2.0**-900, 1.0 + 2.0**-52, 1e-300]),
)


@settings(max_examples=400, deadline=None)
@given(st.tuples(wide, wide), st.tuples(wide, wide), st.tuples(wide, wide))
def test_ring_turns_are_exact_at_any_span(a, b, c):
    """Points of a ring on a box of 1e300 around unit sites: products of box-sized differences overflow
    and those of tiny ones underflow in plain expansions; the clipper's turn is exact anyway."""
    assert clip.ring_turn(*a, *b, *c) == exact_orientation(a, b, c)


@pytest.mark.parametrize("scale", [2.0**-1000, 2.0**-300, 1.0, 2.0**300, 2.0**996])
def test_ring_turns_see_one_ulp_beside_a_huge_segment(scale):
    """A point one ulp off the line through the origin and a far point: the spans of the largest ring."""
    far = (1e300, 1e300)
    on = (scale, scale)
    off = (scale, float(np.nextafter(scale, np.inf)))
    assert clip.ring_turn(0.0, 0.0, *far, *on) == 0
    assert clip.ring_turn(0.0, 0.0, *far, *off) == 1
    assert clip.ring_turn(*far, 0.0, 0.0, *off) == -1
