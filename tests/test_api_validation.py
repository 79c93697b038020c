"""Bad input to the API: every check happens once, in tvoronoi.api, and its message names the culprit.

voronoi, DynamicVoronoi, lloyd and steps share the checks of points, box and engine; the CLI's
--bbox and --engine use the same ones (their CLI spelling: tests/test_cli.py).
"""

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import exact_checks
import tvoronoi
from tvoronoi.api import as_bbox, check_engine
from tvoronoi.engines import BOX_SCALED_MAX
from tvoronoi.errors import CoordinateRangeError

# -- points ---------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "bad, message",
    [
        ([[0, 0], [np.nan, 1]], "point 1"),
        ([[0, 0], [1, np.inf]], "finite"),
        ([[0, 0, 0]], "shape"),
        ([["a", "b"]], "numbers"),
    ],
)
def test_bad_points_are_named(bad, message):
    with pytest.raises(tvoronoi.TvoronoiError, match=message):
        tvoronoi.voronoi(bad)


def test_dynamic_range_beyond_exact_arithmetic_is_refused():
    with pytest.raises(tvoronoi.TvoronoiError, match="point 2: .* 2\\^170"):
        tvoronoi.voronoi([[0.0, 0.0], [0.0, 1.0], [1e-60, 0.5]])


def test_a_dynamic_box_that_sets_the_scale_is_named_in_the_range_error():
    """A dynamic diagram's scale is its box's and its first sites': when a huge box sets it, the message
    measures the sites against the box (not against the largest site, which is in range of them) and
    advises a smaller box. The batch build takes the same box (its scale is the sites' alone)."""
    pts = np.random.default_rng(1).random((5, 2)) + 0.5
    box = (-1e300, -1e300, 1e300, 1e300)
    with pytest.raises(CoordinateRangeError) as caught:
        tvoronoi.DynamicVoronoi(pts, bbox=box)
    message = str(caught.value)
    assert message.startswith("point 0: coordinate ")
    assert "smaller than the scale of the box (about 1.34e+300)" in message
    assert "choose a box nearer the points' scale" in message
    assert "largest coordinate" not in message
    assert tvoronoi.voronoi(pts, bbox=box).n_sites == 5
    # where the sites themselves set the scale, the message is the batch build's
    with pytest.raises(CoordinateRangeError, match="than the largest coordinate, 1e\\+60 \\(point 0\\)"):
        tvoronoi.DynamicVoronoi([[1e60, 0.0], [1.0, 2.0]], bbox=(-1e61, -1e61, 1e61, 1e61))


# -- the box ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "bbox, message",
    [
        ((0, 0, 0, 1), "bbox (0, 0, 0, 1): the box is empty; it needs xmin < xmax and ymin < ymax"),
        ((0, 2, 1, 1), "bbox (0, 2, 1, 1): the box is empty; it needs xmin < xmax and ymin < ymax"),
        ((0, 0, 1), "bbox (0, 0, 1): expected four numbers xmin, ymin, xmax, ymax, got 3"),
        (5, "bbox 5: expected four numbers xmin, ymin, xmax, ymax"),
        ((0, 0, np.nan, 1), "bbox (0, 0, nan, 1): nan is not a finite number"),
        ((0, 0, "inf", 1), "bbox (0, 0, 'inf', 1): 'inf' is not a finite number"),
        ("abcd", "bbox 'abcd': 'a' is not a number; expected xmin, ymin, xmax, ymax"),
        ((0, None, 1, 1), "bbox (0, None, 1, 1): None is not a number; expected xmin, ymin, xmax, ymax"),
    ],
)
def test_bad_boxes_name_the_value(bbox, message):
    with pytest.raises(tvoronoi.TvoronoiError) as caught:
        tvoronoi.voronoi([[0.5, 0.5]], bbox=bbox)
    assert str(caught.value) == message
    # the same check, the same words, everywhere a box is taken
    for call in (
        lambda: tvoronoi.DynamicVoronoi([[0.5, 0.5]], bbox=bbox),
        lambda: tvoronoi.lloyd([[0.5, 0.5]], 1, bbox=bbox),
        lambda: tvoronoi.steps([[0.5, 0.5]], engine="fortune", bbox=bbox),
        lambda: tvoronoi.steps([[0.5, 0.5]], engine="incremental", bbox=bbox),
    ):
        with pytest.raises(tvoronoi.TvoronoiError) as again:
            call()
        assert str(again.value) == message


def test_the_box_check_speaks_the_callers_names():
    """The CLI passes its own spelling: the option, and the values as its users type them."""
    with pytest.raises(tvoronoi.TvoronoiError) as caught:
        as_bbox(["1", "0", "0", "1"], what="--bbox '1,0,0,1'", names=("XMIN", "YMIN", "XMAX", "YMAX"), sep=",")
    assert str(caught.value) == "--bbox '1,0,0,1': the box is empty; it needs XMIN < XMAX and YMIN < YMAX"
    assert as_bbox([" -1", "0", "2.5 ", "1e3"]) == (-1.0, 0.0, 2.5, 1000.0)
    assert all(type(v) is float for v in as_bbox(np.array([0, 0, 1, 1], np.int64)))


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("side", [1.5e300, 2.0**1000, 2.0**-701, 1e-250])
def test_a_box_beyond_the_range_rule_is_refused(engine, side):
    """Unit-square sites: box sides past about 1.3e300 (2^997: the exact products split a coordinate by
    multiplying it with 2^27 + 1) or, when nonzero, under 2^-700 are refused with the side and value named."""
    pts = np.random.default_rng(0).random((30, 2))
    with pytest.raises(tvoronoi.TvoronoiError, match=re.escape(f"bbox xmax = {side!r} is beyond the exact range")):
        tvoronoi.voronoi(pts, bbox=(-1.0, -1.0, side, 2.0), engine=engine)
    if side < 1:
        # a dynamic diagram's scale comes from its box too: only a tiny side can be out of range
        with pytest.raises(tvoronoi.TvoronoiError, match="bbox ymin"):
            tvoronoi.DynamicVoronoi(pts, bbox=(-1.0, -side, 2.0, 2.0), engine=engine)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_the_largest_and_smallest_boxes_of_the_range_rule_build(engine):
    pts = np.random.default_rng(0).random((30, 2))
    big = BOX_SCALED_MAX
    d = tvoronoi.voronoi(pts, bbox=(-big, -big, big, big), engine=engine)
    exact_checks.check_cells_valid(d)  # exact at any span (validate's box frame and GEOS are not)
    exact_checks.check_tiling(d)
    small = 2.0**-700
    d = tvoronoi.voronoi(np.vstack([pts, [[0.0, 0.0]]]), bbox=(-small, -small, small, small), engine=engine)
    assert len(d.cell_polygon(30)) == 4  # the box around the site at the origin is its cell


def test_a_tiny_box_around_tiny_sites_is_in_range():
    """The box's range is judged against the sites' scale, never against 1."""
    pts = np.array([[1e-250, 1e-250], [3e-250, 2e-250], [2e-250, 4e-250]])
    d = tvoronoi.voronoi(pts, bbox=(0.0, 0.0, 5e-250, 5e-250))
    assert d.bbox == (0.0, 0.0, 5e-250, 5e-250)
    assert all(len(d.cell_polygon(i)) >= 3 for i in range(3))


# -- engine and options -----------------------------------------------------------------------------


def test_unknown_engine_and_order():
    with pytest.raises(tvoronoi.TvoronoiError, match="unknown engine 'qhull': choose one of incremental, fortune"):
        tvoronoi.voronoi([[0, 0]], engine="qhull")
    with pytest.raises(tvoronoi.TvoronoiError, match="unknown insertion order 'sorted': choose one of brio, random"):
        tvoronoi.voronoi([[0, 0]], insertion="sorted")
    for call in (
        lambda: tvoronoi.DynamicVoronoi([[0, 0]], engine="qhull"),
        lambda: tvoronoi.steps([[0, 0]], engine="qhull"),
        lambda: check_engine("qhull"),
    ):
        with pytest.raises(tvoronoi.TvoronoiError, match="unknown engine 'qhull'"):
            call()


def _reference_bbox(pts: np.ndarray) -> tuple[float, float, float, float]:
    """default_bbox as first written: reductions along axis 0."""
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    side = float(max(hi[0] - lo[0], hi[1] - lo[1]))
    if side > 0:
        margin = 0.1 * side
    else:
        top = float(np.abs(pts).max())
        margin = 0.1 * top if top > 0 else 1.0
    low = np.minimum(lo - margin, np.nextafter(lo, -np.inf))
    high = np.maximum(hi + margin, np.nextafter(hi, np.inf))
    return (float(low[0]), float(low[1]), float(high[0]), float(high[1]))


@pytest.mark.parametrize(
    "pts",
    [
        [[0.0, -0.0], [-0.0, 0.0]],
        [[5e-324, 0.0], [1e-323, -5e-324]],
        [[3.0, 4.0]],
        [[1e300, -1e300], [-1e300, 1e300]],
        [[1.0, 2.0], [1.0 + 2**-52, 2.0]],
    ],
)
def test_default_bbox_by_columns_is_the_reference(pts):
    from tvoronoi.api import BBOX_MARGIN, default_bbox

    assert BBOX_MARGIN == 0.1
    pts = np.asarray(pts, np.float64)
    assert default_bbox(pts) == _reference_bbox(pts)


def test_default_bbox_of_random_sites_is_the_reference():
    from tvoronoi.api import default_bbox

    rng = np.random.default_rng(11)
    for _ in range(200):
        n = int(rng.integers(1, 50))
        pts = rng.normal(size=(n, 2)) * 10.0 ** rng.integers(-300, 300) + rng.choice([0.0, 1e6])
        assert default_bbox(pts) == _reference_bbox(pts)


def test_first_non_finite_point_is_named():
    pts = np.ones((1000, 2))
    pts[[700, 900], [1, 0]] = [np.inf, np.nan]
    with pytest.raises(tvoronoi.TvoronoiError, match=r"point 700 is \(1\.0, inf\).*\(2 such point"):
        tvoronoi.voronoi(pts)


def _reference_range_fault(pts: np.ndarray, e: int):
    """check_range's verdict as first written: every value's magnitude compared (None: no fault)."""
    from tvoronoi.api import RANGE_BITS

    mag = np.abs(pts)
    low = 2.0 ** (e - RANGE_BITS)
    high = 2.0 ** (e + RANGE_BITS) if e + RANGE_BITS < 1024 else np.inf
    bad = (pts != 0) & ((mag < low) | (mag > high))
    return None if not bad.any() else tuple(int(v) for v in np.argwhere(bad)[0])


def test_check_range_fast_path_agrees_with_every_value_compared():
    """Zeros, values just inside and just outside 2^170 of the scale, either sign, any row."""
    from tvoronoi.api import RANGE_BITS, check_range
    from tvoronoi.errors import CoordinateRangeError

    rng = np.random.default_rng(4)
    for trial in range(300):
        e = int(rng.integers(-900, 900))
        pts = rng.random((int(rng.integers(1, 30)), 2)) * 2.0**e * rng.choice([-1, 1], (1, 2))
        for _ in range(int(rng.integers(0, 3))):
            i, j = rng.integers(0, len(pts)), rng.integers(0, 2)
            pts[i, j] = rng.choice(
                [0.0, -0.0, 2.0 ** (e - RANGE_BITS), -(2.0 ** (e - RANGE_BITS - 1)), 2.0 ** (e - RANGE_BITS - 3)]
            )
        if trial % 5 == 0:
            pts[rng.integers(0, len(pts)), rng.integers(0, 2)] = 2.0 ** min(e + RANGE_BITS + 1, 1023)
        expected = _reference_range_fault(pts, e)
        if expected is None:
            check_range(pts, e)
        else:
            with pytest.raises(CoordinateRangeError) as info:
                check_range(pts, e)
            assert info.value.rows[0] == expected[0]


@settings(max_examples=300, deadline=None)
@given(
    values=st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), min_size=1, max_size=12),
    more=st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), max_size=4),
)
def test_scale_exponent_is_that_of_the_largest_magnitude(values, more):
    # the exponent of the largest |v| over every array given, whichever sign it has (two passes, no
    # temporary, against the reference: frexp of the largest absolute value)
    from tvoronoi.engines import scale_exponent

    arrays = [np.array(values), np.array(more)]
    top = max(abs(v) for v in values + more)
    assert scale_exponent(*arrays) == (math.frexp(top)[1] if top > 0 else 0)


@settings(max_examples=300, deadline=None)
@given(
    rows=st.lists(
        st.tuples(
            st.floats(width=64) | st.sampled_from([0.0, -0.0, 5e-324, -1e308]),
            st.floats(width=64) | st.sampled_from([0.0, -0.0, 5e-324, -1e308]),
        ),
        max_size=40,
    )
)
def test_point_bounds_is_numpys_reductions_in_one_pass(rows):
    """The one-pass kernel: the count of non-finite values; else the box as numpy's reductions give it
    (the first row's value among equal extremes, a zero's sign included) and the least nonzero
    magnitude."""
    from tvoronoi.kernels.bounds import point_bounds

    pts = np.array(rows, np.float64).reshape(-1, 2)
    n_bad, *box, smallest = point_bounds(pts)
    assert n_bad == int((~np.isfinite(pts)).sum())
    if n_bad or len(pts) == 0:
        return
    want = [math.inf, math.inf, -math.inf, -math.inf]
    for x, y in pts.tolist():
        want = [min(want[0], x), min(want[1], y), max(want[2], x), max(want[3], y)]  # (first of equals)
    assert np.array_equal(np.array(box).view(np.int64), np.array(want).view(np.int64))
    assert box == [pts[:, 0].min(), pts[:, 1].min(), pts[:, 0].max(), pts[:, 1].max()]
    mags = np.abs(pts[pts != 0])
    assert smallest == (mags.min() if mags.size else math.inf)


@pytest.mark.parametrize("threads", [2, 3, 7])
@pytest.mark.parametrize("seed", range(4))
def test_point_bounds_on_threads_is_the_one_thread_pass(threads, seed):
    """On several threads (a run of rows each, from 2^16 rows on) the same figures as on one, bit for bit:
    equal extremes of either sign (0.0 and -0.0) in different runs keep the first row's, the least
    magnitude and the count of non-finite values merge across runs."""
    from tvoronoi.kernels.bounds import point_bounds

    rng = np.random.default_rng(seed)
    n = 200_000
    pts = rng.uniform(0.5, 1.0, (n, 2)) * rng.choice([-1.0, 1.0], (n, 2))
    pts[rng.integers(0, n, 5)] = 0.0  # +0.0 and -0.0 at random rows: tied lows, highs and no magnitude
    pts[rng.integers(0, n, 5)] = -0.0
    pts[:, 0] = np.abs(pts[:, 0])  # x >= 0: its low is a zero, whose sign comes from its first row
    pts[:, 1] = -np.abs(pts[:, 1])  # y <= 0: its high is a zero
    pts[rng.integers(0, n), 0] = 1e-300  # the least magnitude, in a random run
    one = point_bounds(pts)
    assert np.array_equal(np.array(point_bounds(pts, threads)).view(np.int64), np.array(one).view(np.int64))
    first_x_zero = pts[np.flatnonzero(pts[:, 0] == 0)[0], 0]
    assert math.copysign(1, one[1]) == math.copysign(1, first_x_zero)
    assert one[5] == 1e-300
    bad = pts.copy()
    bad[rng.integers(0, n, 3), 1] = np.nan
    bad[rng.integers(0, n), 0] = np.inf
    assert point_bounds(bad, threads)[0] == point_bounds(bad)[0] == int((~np.isfinite(bad)).sum())


def test_checked_points_range_verdict_is_check_ranges():
    """checked_points reads the range rule off the one pass (the least nonzero magnitude against the
    scale): it refuses exactly what check_range, comparing every value, refuses, and names the same row;
    its bounds are the box, and default_bbox from them is default_bbox from the points."""
    from tvoronoi.api import RANGE_BITS, checked_points, default_bbox
    from tvoronoi.engines import scale_exponent
    from tvoronoi.errors import CoordinateRangeError

    rng = np.random.default_rng(27)
    for _ in range(400):
        e = int(rng.integers(-900, 900))
        pts = rng.random((int(rng.integers(1, 30)), 2)) * 2.0**e * rng.choice([-1, 1], (1, 2))
        for _ in range(int(rng.integers(0, 3))):
            i, j = rng.integers(0, len(pts)), rng.integers(0, 2)
            top = scale_exponent(pts)
            pts[i, j] = rng.choice(
                [0.0, -0.0, 2.0 ** (top - RANGE_BITS), -(2.0 ** (top - RANGE_BITS - 1)), 2.0 ** (top - RANGE_BITS - 3)]
            )
        expected = _reference_range_fault(pts, scale_exponent(pts))
        if expected is None:
            out, bounds = checked_points(pts)
            assert np.array_equal(out, pts) and out.flags.c_contiguous
            assert bounds == (pts[:, 0].min(), pts[:, 1].min(), pts[:, 0].max(), pts[:, 1].max())
            assert default_bbox(out, bounds) == default_bbox(out) == _reference_bbox(pts)
        else:
            with pytest.raises(CoordinateRangeError) as info:
                checked_points(pts)
            assert info.value.rows[0] == expected[0]
