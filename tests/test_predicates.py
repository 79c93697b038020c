"""Property tests of the exact predicates against rational arithmetic (fractions.Fraction)."""

import itertools
import math
import random
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tvoronoi.kernels.predicates import incircle_many, incircle_sign, orient2d_many, orient2d_sign

# the filter constants of predicates.pxd, to tell which tier of the predicate decides a case
EPSILON = 2.0**-53
CCW_ERRBOUND_A = (3.0 + 16.0 * EPSILON) * EPSILON
ICC_ERRBOUND_A = (10.0 + 96.0 * EPSILON) * EPSILON

# below this magnitude a coordinate becomes 0: the predicates promise exactness only without underflow
TINIEST_COORDINATE = 1e-30


# ---------------------------------------------------------------------------------------------------------
# oracles


def sign(x):
    return (x > 0) - (x < 0)


def orient2d_rational(ax, ay, bx, by, cx, cy):
    ax, ay, bx, by, cx, cy = map(Fraction, (ax, ay, bx, by, cx, cy))
    return sign((ax - cx) * (by - cy) - (ay - cy) * (bx - cx))


def incircle_rational(ax, ay, bx, by, cx, cy, dx, dy):
    ax, ay, bx, by, cx, cy, dx, dy = map(Fraction, (ax, ay, bx, by, cx, cy, dx, dy))
    adx, ady, bdx, bdy, cdx, cdy = ax - dx, ay - dy, bx - dx, by - dy, cx - dx, cy - dy
    a_lift = adx * adx + ady * ady
    b_lift = bdx * bdx + bdy * bdy
    c_lift = cdx * cdx + cdy * cdy
    return sign(a_lift * (bdx * cdy - cdx * bdy) + b_lift * (cdx * ady - adx * cdy) + c_lift * (adx * bdy - bdx * ady))


def orient2d_float(ax, ay, bx, by, cx, cy):
    """The naive determinant in doubles: what the predicate must do better than."""
    return sign((ax - cx) * (by - cy) - (ay - cy) * (bx - cx))


def incircle_float(ax, ay, bx, by, cx, cy, dx, dy):
    adx, ady, bdx, bdy, cdx, cdy = ax - dx, ay - dy, bx - dx, by - dy, cx - dx, cy - dy
    a_lift = adx * adx + ady * ady
    b_lift = bdx * bdx + bdy * bdy
    c_lift = cdx * cdx + cdy * cdy
    return sign(a_lift * (bdx * cdy - cdx * bdy) + b_lift * (cdx * ady - adx * cdy) + c_lift * (adx * bdy - bdx * ady))


def orient2d_filter_decides(ax, ay, bx, by, cx, cy):
    """True when the floating-point filter of orient2d settles the case on its own."""
    det_left = (ax - cx) * (by - cy)
    det_right = (ay - cy) * (bx - cx)
    det = det_left - det_right
    if det_left == 0.0 or (det_left > 0.0) != (det_right > 0.0) or det_right == 0.0:
        return True
    det_sum = abs(det_left) + abs(det_right)
    return abs(det) >= CCW_ERRBOUND_A * det_sum


def incircle_filter_decides(ax, ay, bx, by, cx, cy, dx, dy):
    """True when the floating-point filter of incircle settles the case on its own."""
    adx, ady, bdx, bdy, cdx, cdy = ax - dx, ay - dy, bx - dx, by - dy, cx - dx, cy - dy
    bdxcdy, cdxbdy = bdx * cdy, cdx * bdy
    cdxady, adxcdy = cdx * ady, adx * cdy
    adxbdy, bdxady = adx * bdy, bdx * ady
    a_lift = adx * adx + ady * ady
    b_lift = bdx * bdx + bdy * bdy
    c_lift = cdx * cdx + cdy * cdy
    det = a_lift * (bdxcdy - cdxbdy) + b_lift * (cdxady - adxcdy) + c_lift * (adxbdy - bdxady)
    permanent = (
        (abs(bdxcdy) + abs(cdxbdy)) * a_lift
        + (abs(cdxady) + abs(adxcdy)) * b_lift
        + (abs(adxbdy) + abs(bdxady)) * c_lift
    )
    return abs(det) > ICC_ERRBOUND_A * permanent


def differences_exact(points):
    """True when every coordinate difference against the last point is a double without rounding."""
    *rest, (qx, qy) = points
    return all(
        Fraction(px - qx) == Fraction(px) - Fraction(qx) and Fraction(py - qy) == Fraction(py) - Fraction(qy)
        for px, py in rest
    )


def parity(permutation):
    """+1 for an even permutation of range(n), -1 for an odd one."""
    inversions = sum(
        1 for i, j in itertools.combinations(range(len(permutation)), 2) if permutation[i] > permutation[j]
    )
    return -1 if inversions % 2 else 1


# ---------------------------------------------------------------------------------------------------------
# coordinate strategies: each example draws all its coordinates from one of them


def _no_underflow(x):
    return 0.0 if abs(x) < TINIEST_COORDINATE else x


ULP_OF_1E9 = 2.0**-23

COORDINATES = {
    # every triple collinear-prone, every quadruple cocircular-prone: the filter fails often
    "integer_grid": st.integers(-3, 3).map(float),
    "half_grid": st.integers(-6, 6).map(lambda k: k / 2),
    # 1e9 plus a few units in the last place, or plus a decimal fraction
    "huge_ulps": st.integers(-8, 8).map(lambda k: 1e9 + k * ULP_OF_1E9),
    "huge_offsets": st.floats(-4.0, 4.0).map(lambda t: 1e9 + t),
    # 1e-9 scale
    "tiny_grid": st.integers(-4, 4).map(lambda k: k * 1e-9),
    "tiny_floats": st.floats(-1e-9, 1e-9).map(_no_underflow),
    # mantissas at exponents far apart, so that differences round
    "mixed_exponents": st.builds(math.ldexp, st.integers(-(2**20), 2**20), st.integers(-80, 40)),
    "decimal_grid": st.integers(-5, 5).map(lambda k: k / 10),
    "any_double": st.floats(-1e12, 1e12, allow_nan=False, allow_infinity=False).map(_no_underflow),
}


@st.composite
def point_tuples(draw, n_points):
    coordinate = draw(st.sampled_from(sorted(COORDINATES)).map(COORDINATES.__getitem__))
    return [(draw(coordinate), draw(coordinate)) for _ in range(n_points)]


def flat(points):
    return [value for point in points for value in point]


# ---------------------------------------------------------------------------------------------------------
# agreement with the rational oracle


@settings(max_examples=1500, deadline=None)
@given(point_tuples(3))
def test_orient2d_matches_rational(points):
    coords = flat(points)
    assert orient2d_sign(*coords) == orient2d_rational(*coords)


@settings(max_examples=1500, deadline=None)
@given(point_tuples(4))
def test_incircle_matches_rational(points):
    coords = flat(points)
    assert incircle_sign(*coords) == incircle_rational(*coords)


@settings(max_examples=300, deadline=None)
@given(point_tuples(3))
def test_orient2d_permutations(points):
    """Cyclic shifts keep the sign, a swap of two points flips it."""
    base = orient2d_rational(*flat(points))
    for permutation in itertools.permutations(range(3)):
        permuted = [points[i] for i in permutation]
        assert orient2d_sign(*flat(permuted)) == parity(permutation) * base


@settings(max_examples=300, deadline=None)
@given(point_tuples(4))
def test_incircle_permutations(points):
    """The lifted determinant is antisymmetric in all four points, d included."""
    base = incircle_rational(*flat(points))
    for permutation in itertools.permutations(range(4)):
        permuted = [points[i] for i in permutation]
        assert incircle_sign(*flat(permuted)) == parity(permutation) * base


# ---------------------------------------------------------------------------------------------------------
# classic hard cases


def test_near_collinear_grid():
    """Shewchuk's grid: points 0.5 + i*2^-53 against the line through (12, 12) and (24, 24)."""
    ulp = 2.0**-53
    grid = [(0.5 + i * ulp, 0.5 + j * ulp) for i in range(64) for j in range(64)]
    expected = [orient2d_rational(px, py, 12.0, 12.0, 24.0, 24.0) for px, py in grid]
    got = [orient2d_sign(px, py, 12.0, 12.0, 24.0, 24.0) for px, py in grid]
    assert got == expected
    # the grid is hard: plain doubles get some of it wrong, and all three answers occur
    naive = [orient2d_float(px, py, 12.0, 12.0, 24.0, 24.0) for px, py in grid]
    assert naive != expected
    assert set(expected) == {-1, 0, 1}
    # the vectorized form agrees, row by row
    a = np.array(grid)
    b = np.tile([12.0, 12.0], (len(grid), 1))
    c = np.tile([24.0, 24.0], (len(grid), 1))
    assert orient2d_many(a, b, c).tolist() == expected


def lattice_circle(radius):
    """All integer points on x^2 + y^2 = radius^2, counter-clockwise from the positive x axis."""
    points = [
        (x, y)
        for x in range(-radius, radius + 1)
        for y in range(-radius, radius + 1)
        if x * x + y * y == radius * radius
    ]
    return sorted(points, key=lambda p: math.atan2(p[1], p[0]) % (2 * math.pi))


# scale, x shift, y shift: each keeps the points exactly representable, hence exactly cocircular
EXACT_PLACEMENTS = [(1.0, 0.0, 0.0), (1.0, 1000.0, -7.0), (2.0**-30, 0.0, 0.0), (16.0, 2.0**30, -(2.0**30))]


@pytest.mark.parametrize("scale, shift_x, shift_y", EXACT_PLACEMENTS)
def test_cocircular_radius_5(scale, shift_x, shift_y):
    circle = [(x * scale + shift_x, y * scale + shift_y) for x, y in lattice_circle(5)]
    assert len(circle) == 12
    for quadruple in itertools.permutations(circle, 4):
        assert incircle_sign(*flat(quadruple)) == 0


@pytest.mark.parametrize("scale, shift_x, shift_y", EXACT_PLACEMENTS)
def test_cocircular_radius_65(scale, shift_x, shift_y):
    circle = np.array(lattice_circle(65), dtype=float) * scale + [shift_x, shift_y]
    assert len(circle) == 36
    rows = np.array(list(itertools.combinations(range(len(circle)), 4)))
    a, b, c, d = (np.ascontiguousarray(circle[rows[:, k]]) for k in range(4))
    signs = incircle_many(a, b, c, d)
    assert signs.shape == (len(rows),)
    assert not signs.any()


def test_lattice_points_near_radius_65():
    """Points just inside (+1) and just outside (-1) the circle through three of its lattice points."""
    a, b, c = (65.0, 0.0), (0.0, 65.0), (-65.0, 0.0)  # counter-clockwise
    near = [(x, y) for x in range(-66, 67) for y in range(-66, 67) if 0 < abs(x * x + y * y - 65 * 65) <= 130]
    assert len(near) > 100
    for x, y in near:
        expected = 1 if x * x + y * y < 65 * 65 else -1
        assert incircle_sign(*a, *b, *c, float(x), float(y)) == expected
        # the same points, moved to 1e9 where a lift of 1e18 swamps their differences
        moved = [(px + 1e9, py + 1e9) for px, py in (a, b, c, (x, y))]
        assert incircle_sign(*flat(moved)) == expected


# ---------------------------------------------------------------------------------------------------------
# the exact tiers, not only the filter


def _one_ulp_away(rng, x):
    return math.nextafter(x, math.inf if rng.random() < 0.5 else -math.inf)


def test_orient2d_exact_tiers():
    """Near-collinear cases that the filter cannot settle, with exact and with rounded differences."""
    rng = random.Random(20240601)
    undecided_exact = undecided_rounded = naive_wrong = 0
    for _ in range(3000):
        if rng.random() < 0.5:
            # on the diagonal, at random magnitudes: differences usually round
            ts = [rng.uniform(-1.0, 1.0) * 2.0 ** rng.randint(-30, 30) for _ in range(3)]
            points = [(t, t) for t in ts]
        else:
            # on a line through integer points: differences are exact
            step = (rng.randint(-5, 5), rng.randint(1, 5))
            base = (rng.randint(-(2**40), 2**40), rng.randint(-(2**40), 2**40))
            points = [
                (float(base[0] + k * step[0]), float(base[1] + k * step[1])) for k in rng.sample(range(-50, 50), 3)
            ]
        if rng.random() < 0.7:
            i, axis = rng.randrange(3), rng.randrange(2)
            moved = list(points[i])
            moved[axis] = _one_ulp_away(rng, moved[axis])
            points[i] = tuple(moved)
        coords = flat(points)
        expected = orient2d_rational(*coords)
        assert orient2d_sign(*coords) == expected, coords
        if not orient2d_filter_decides(*coords):
            if differences_exact(points):
                undecided_exact += 1
            else:
                undecided_rounded += 1
        naive_wrong += orient2d_float(*coords) != expected
    assert undecided_exact > 100
    assert undecided_rounded > 100
    assert naive_wrong > 100


def test_incircle_exact_tiers():
    """Near-cocircular cases that the filter cannot settle, with exact and with rounded differences."""
    rng = random.Random(20240602)
    undecided_exact = undecided_rounded = naive_wrong = 0
    radius_5 = lattice_circle(5)
    for _ in range(3000):
        if rng.random() < 0.5:
            # (+-p, +-q) and (+-q, +-p) lie on one circle for any doubles p, q; their differences round
            p = rng.uniform(-1.0, 1.0) * 2.0 ** rng.randint(-20, 20)
            q = rng.uniform(-1.0, 1.0) * 2.0 ** rng.randint(-20, 20)
            circle = [(sx * u, sy * v) for u, v in ((p, q), (q, p)) for sx in (1, -1) for sy in (1, -1)]
        else:
            # lattice points at 1e9: integers, so differences are exact
            shift = float(rng.randint(10**8, 10**9))
            circle = [(x + shift, y - shift) for x, y in radius_5]
        points = rng.sample(circle, 4)
        if rng.random() < 0.7:
            moved = list(points[3])
            axis = rng.randrange(2)
            moved[axis] = _one_ulp_away(rng, moved[axis])
            points[3] = tuple(moved)
        coords = flat(points)
        expected = incircle_rational(*coords)
        assert incircle_sign(*coords) == expected, coords
        if not incircle_filter_decides(*coords):
            if differences_exact(points):
                undecided_exact += 1
            else:
                undecided_rounded += 1
        naive_wrong += incircle_float(*coords) != expected
    assert undecided_exact > 100
    assert undecided_rounded > 100
    assert naive_wrong > 100


# ---------------------------------------------------------------------------------------------------------
# vectorized wrappers


@settings(max_examples=100, deadline=None)
@given(st.lists(point_tuples(4), min_size=0, max_size=20))
def test_many_match_scalar(rows):
    arrays = [np.array([row[k] for row in rows], dtype=float).reshape(len(rows), 2) for k in range(4)]
    got_orient = orient2d_many(*arrays[:3])
    got_incircle = incircle_many(*arrays)
    assert got_orient.dtype == np.int8 and got_incircle.dtype == np.int8
    assert got_orient.tolist() == [orient2d_sign(*flat(row[:3])) for row in rows]
    assert got_incircle.tolist() == [incircle_sign(*flat(row)) for row in rows]


def test_many_reject_mismatched_shapes():
    a = np.zeros((3, 2))
    with pytest.raises(ValueError, match="c has shape"):
        orient2d_many(a, a, np.zeros((4, 2)))
    with pytest.raises(ValueError, match="d has shape"):
        incircle_many(a, a, a, np.zeros((3, 3)))


def integer_span(values) -> int:
    """Bits from the lowest set bit of any nonzero value to above the largest: the span the in-circle
    test's integer tier (tvoronoi_incircle_small) takes up to 30."""
    nonzero = [Fraction(v) for v in values if v != 0]
    if not nonzero:
        return 0
    low = min(
        (f.numerator & -f.numerator).bit_length() - 1 - (f.denominator.bit_length() - 1) for f in map(abs, nonzero)
    )
    high = max(math.frexp(float(f))[1] for f in map(abs, nonzero))
    return high - low


def test_incircle_integer_tier_on_dyadic_points_near_and_on_circles():
    """Points whose differences are integers times one power of two, spanning 6 to 38 bits (both sides
    of the integer tier's 30, where its 64-bit lifts would overflow at 32): on circles through lattice
    points stretched by an odd factor (cocircular), and moved off them by the last bit, at scales from
    2^-60 to 2^40. Every sign against rational arithmetic."""
    rng = random.Random(20261126)
    circles = [lattice_circle(r) for r in (5, 25, 65)]
    tier = 0
    spans = set()
    for _ in range(4000):
        bits = rng.randint(0, 32)
        k = 2 * rng.randint(2 ** max(bits - 2, 0), 2**bits) + 1  # odd: the lowest bit stays set
        scale = 2.0 ** rng.randint(-60, 40)
        ox, oy = rng.randint(-(2**bits), 2**bits), rng.randint(-(2**bits), 2**bits)
        points = [((k * x + ox) * scale, (k * y + oy) * scale) for x, y in rng.sample(rng.choice(circles), 4)]
        if rng.random() < 0.5:
            j = rng.randrange(4)
            points[j] = (points[j][0] + rng.choice([-1, 1]) * scale, points[j][1])
        coords = flat(points)
        assert incircle_sign(*coords) == incircle_rational(*coords), coords
        d = points[3]
        diffs = [c - d[i % 2] for i, c in enumerate(coords[:6])]
        if differences_exact(points) and not incircle_filter_decides(*coords):
            spans.add(integer_span(diffs))
            tier += integer_span(diffs) <= 30
    assert tier > 500, f"only {tier} cases reached the integer tier"
    assert min(spans) < 10 and {29, 30, 31, 32} <= spans, sorted(spans)
