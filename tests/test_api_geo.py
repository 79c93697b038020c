"""The Python API in the geospatial ecosystem: shapely/geopandas/pandas inputs, shapely and geopandas outputs,
and nearest-site queries (Diagram.locate)."""

import subprocess
import sys

import numpy as np
import pytest
import shapely

import tvoronoi
from conftest import DATASETS, SEED
from tvoronoi import TvoronoiError
from tvoronoi.api import as_points

gpd = pytest.importorskip("geopandas")
pd = pytest.importorskip("pandas")

XY = np.array([[0.0, 0.0], [2.0, 1.0], [1.0, 3.0], [-1.0, 2.5]])


# --- inputs ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make",
    [
        lambda xy: shapely.MultiPoint(xy),
        lambda xy: [shapely.Point(p) for p in xy],
        lambda xy: tuple(shapely.Point(p) for p in xy),
        lambda xy: shapely.points(xy),
        lambda xy: gpd.GeoSeries(shapely.points(xy), index=list("abcd")),
        lambda xy: gpd.GeoDataFrame({"name": list("abcd")}, geometry=shapely.points(xy)),
        lambda xy: pd.Series(list(shapely.points(xy))),
        lambda xy: pd.DataFrame({"id": [7, 8, 9, 10], "x": xy[:, 0], "y": xy[:, 1]}),
        lambda xy: pd.DataFrame({"LAT": xy[:, 1], "name": list("abcd"), "Lon": xy[:, 0]}),
        lambda xy: pd.DataFrame({"Easting": xy[:, 0], "Northing": xy[:, 1]}),
        lambda xy: pd.DataFrame({"a": xy[:, 0], "b": xy[:, 1]}),
        lambda xy: shapely.points(np.c_[xy, np.arange(4.0)]),  # z dropped
    ],
    ids=[
        "multipoint",
        "list",
        "tuple",
        "object_array",
        "geoseries",
        "geodataframe",
        "series",
        "frame_xy",
        "frame_lonlat",
        "frame_easting",
        "frame_two_columns",
        "points_z",
    ],
)
def test_voronoi_takes_geospatial_points(make):
    got = tvoronoi.voronoi(make(XY))
    want = tvoronoi.voronoi(XY)
    np.testing.assert_array_equal(got.sites, XY)
    np.testing.assert_array_equal(got.cell_offsets, want.cell_offsets)
    np.testing.assert_array_equal(got.cell_points, want.cell_points)


def test_shapely_points_round_trip_hypothesis():
    from hypothesis import given, settings
    from hypothesis import strategies as st
    from hypothesis.extra.numpy import arrays

    # within the range rule (2^170 between the largest and the smallest nonzero coordinate)
    finite = st.one_of(st.just(0.0), st.floats(1e-6, 1e6), st.floats(-1e6, -1e-6))

    @settings(max_examples=100, deadline=None)
    @given(arrays(np.float64, st.tuples(st.integers(1, 30), st.just(2)), elements=finite))
    def check(xy):
        for given_points in (
            shapely.MultiPoint(xy),
            list(shapely.points(xy)),
            gpd.GeoSeries(shapely.points(xy)),
            pd.DataFrame({"lon": xy[:, 0], "lat": xy[:, 1]}),
        ):
            got = as_points(given_points)
            assert got.flags.c_contiguous and got.dtype == np.float64
            np.testing.assert_array_equal(got, xy)

    check()


def test_dynamic_and_empty_inputs():
    dv = tvoronoi.DynamicVoronoi(shapely.MultiPoint(XY))
    np.testing.assert_array_equal(dv.diagram().sites, XY)
    assert as_points(shapely.MultiPoint()).shape == (0, 2)
    assert as_points(gpd.GeoSeries([], dtype="geometry")).shape == (0, 2)


@pytest.mark.parametrize(
    "bad, words",
    [
        ([shapely.Point(0, 0), shapely.Point(1, 1), shapely.Point()], ["point 2", "empty"]),
        ([shapely.Point(0, 0), shapely.LineString([(0, 0), (1, 1)])], ["point 1", "LineString"]),
        (shapely.GeometryCollection([shapely.Point(0, 0), shapely.box(0, 0, 1, 1)]), ["point 1", "Polygon"]),
        (gpd.GeoSeries([shapely.Point(0, 0), shapely.box(0, 0, 1, 1)], index=["p", "q"]), ["point 1", "'q'"]),
        (gpd.GeoSeries([shapely.Point(0, 0), None, shapely.Point(1, 1)]), ["point 1", "None"]),
        ([shapely.Point(0, 0), (1.0, 2.0)], ["point 1", "(1.0, 2.0)"]),
        ([(1.0, 2.0), (0.0, 0.0), shapely.Point(0, 0)], ["point 2", "shapely Point"]),
        (shapely.box(0, 0, 1, 1), ["point 0", "Polygon"]),
        (pd.DataFrame({"a": [1.0], "b": [2.0], "c": [3.0]}), ["'a'", "'b'", "'c'"]),
        (pd.DataFrame({"x": ["1", "oops"], "y": [1.0, 2.0]}), ["'x'", "numbers"]),
        (pd.DataFrame({"x": [1.0, np.nan], "y": [1.0, 2.0]}), ["point 1", "finite"]),
    ],
)
def test_bad_geospatial_points_name_the_row(bad, words):
    with pytest.raises(TvoronoiError) as info:
        tvoronoi.voronoi(bad)
    for word in words:
        assert word in str(info.value)


def test_arrays_do_not_import_pandas_or_geopandas():
    code = (
        "import sys, numpy as np, shapely, tvoronoi; tvoronoi.voronoi(np.random.rand(20, 2)); "
        "tvoronoi.voronoi(shapely.MultiPoint(np.random.rand(20, 2))).to_shapely(); "
        "print('pandas' in sys.modules or 'geopandas' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


# --- shapely and geopandas outputs -------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_to_shapely_matches_cell_polygon(name):
    d = tvoronoi.voronoi(DATASETS[name])
    polys = d.to_shapely()
    assert polys.shape == (d.n_sites,)
    for i in range(d.n_sites):
        ring = d.cell_polygon(i)
        if len(ring) == 0:
            assert polys[i] is None
            continue
        one = shapely.Polygon(ring)
        assert shapely.equals_exact(polys[i], one, tolerance=0.0)
        np.testing.assert_array_equal(shapely.get_coordinates(polys[i])[:-1], ring)
        assert polys[i].is_valid and polys[i].exterior.is_ccw
    cells = polys[polys != None]  # noqa: E711
    box = shapely.box(*d.bbox)
    assert shapely.union_all(cells).equals(box)
    assert np.isclose(shapely.area(cells).sum(), box.area)


def test_to_shapely_rows_without_cells():
    # row 1 repeats row 0; the box misses the cell of row 2
    d = tvoronoi.voronoi([[0, 0], [0, 0], [10, 0]], bbox=(-1, -1, 1, 1))
    polys = d.to_shapely()
    assert polys[0] is not None and polys[1] is None and polys[2] is None


def test_to_geopandas():
    rng = np.random.default_rng(SEED)
    xy = rng.random((300, 2))
    xy[7] = xy[3]
    props = pd.DataFrame(
        {"name": [f"p{i}" for i in range(300)], "v": np.arange(300) * 0.5}, index=np.arange(300) + 1000
    )
    d = tvoronoi.voronoi(xy)
    g = d.to_geopandas(props, crs="EPSG:3857")
    assert isinstance(g, gpd.GeoDataFrame)
    assert list(g.columns) == ["site", "name", "v", "geometry"]
    assert g["site"].tolist() == list(range(300))
    assert g["name"].tolist() == props["name"].tolist()
    assert g.crs.to_epsg() == 3857
    assert g.geometry.isna().tolist() == [i == 7 for i in range(300)]
    assert g.geometry.is_valid[~g.geometry.isna()].all()
    assert g.geometry.contains(gpd.GeoSeries(shapely.points(xy), crs="EPSG:3857")).drop(7).all()
    assert d.to_geopandas().columns.tolist() == ["site", "geometry"]


@pytest.mark.parametrize("props", [{"v": [1, 2]}, {"site": [1, 2, 3, 4]}])
def test_to_geopandas_bad_properties(props):
    with pytest.raises(TvoronoiError):
        tvoronoi.voronoi(XY).to_geopandas(props)


def test_to_geopandas_without_geopandas(monkeypatch):
    monkeypatch.setitem(sys.modules, "geopandas", None)
    with pytest.raises(TvoronoiError, match="pip install geopandas"):
        tvoronoi.voronoi(XY).to_geopandas()


# --- nearest-site queries ----------------------------------------------------------------------------------


def nearest_reference(sites, qx, qy):
    """The lowest row among the sites nearest to each query, exactly: doubles shortlist, Fractions decide."""
    from fractions import Fraction

    sites = np.asarray(sites, float)
    out = []
    for x, y in zip(np.ravel(qx), np.ravel(qy)):
        d2 = (sites[:, 0] - x) ** 2 + (sites[:, 1] - y) ** 2
        near = np.flatnonzero(d2 <= d2.min() * (1 + 1e-6) + 1e-300)
        fx, fy = Fraction(float(x)), Fraction(float(y))
        exact = [(Fraction(float(sites[i, 0])) - fx) ** 2 + (Fraction(float(sites[i, 1])) - fy) ** 2 for i in near]
        best = min(exact)
        out.append(min(int(i) for i, v in zip(near, exact) if v == best))
    return np.asarray(out)


@pytest.mark.parametrize("n", [1, 2, 3, 50, 3000])
def test_locate_matches_ckdtree(n):
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(SEED + n)
    sites = rng.random((n, 2))
    d = tvoronoi.voronoi(sites)
    q = np.concatenate([rng.random((4000, 2)) * 1.6 - 0.3, rng.normal(0, 1e3, (500, 2))])
    got = d.locate(q[:, 0], q[:, 1])
    assert got.dtype == np.int32
    np.testing.assert_array_equal(got, cKDTree(sites).query(q)[1])
    # Voronoi vertices: three sites nearly (or exactly) as near, which cKDTree may pick any of
    v = d.vertices[:200]
    np.testing.assert_array_equal(d.locate(v[:, 0], v[:, 1]), nearest_reference(sites, v[:, 0], v[:, 1]))


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_locate_matches_exact_reference(name):
    rng = np.random.default_rng(SEED)
    sites = DATASETS[name]
    d = tvoronoi.voronoi(sites)
    lo, hi = sites.min(axis=0), sites.max(axis=0)
    span = np.maximum(hi - lo, np.abs(hi) * 1e-3 + 1e-300)
    # random queries, the sites themselves, midpoints of Delaunay edges (exact ties on grid data), vertices
    edges = np.c_[d.he_face, d.he_face[d.he_twin]] if d.n_edges else np.empty((0, 2), int)
    mids = (sites[edges[:, 0]] + sites[edges[:, 1]]) / 2
    q = np.concatenate([lo + rng.random((300, 2)) * span * 1.4 - span * 0.2, sites, mids[:300], d.vertices[:100]])
    np.testing.assert_array_equal(d.locate(q[:, 0], q[:, 1]), nearest_reference(sites, q[:, 0], q[:, 1]))


def test_locate_lattice_ties_go_to_the_lowest_row():
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(SEED)
    grid = np.array([(i, j) for i in range(40) for j in range(30)], float)[rng.permutation(1200)]
    grid = np.concatenate([grid, grid[:100]])  # repeated points: their first row answers
    d = tvoronoi.voronoi(grid)
    q = rng.integers(-6, 90, (20000, 2)) / 2.0  # on sites, on bisectors, on Voronoi vertices
    got = d.locate(q[:, 0], q[:, 1])
    # every answer is at the nearest distance (cKDTree), and the lowest row at it
    dist = np.hypot(*(grid[got] - q).T)
    np.testing.assert_array_equal(dist, cKDTree(grid).query(q)[0])
    d2 = ((q[:, None, :] - grid[None, :, :]) ** 2).sum(-1)
    np.testing.assert_array_equal(got, np.argmax(d2 == d2.min(axis=1, keepdims=True), axis=1))


def test_locate_decides_ties_beyond_double_precision():
    d = tvoronoi.voronoi([[0.0, 0.0], [1.0, 0.0]])
    # far above the bisector x = 0.5: doubles see one distance, the exact test sees which side
    x = [0.5 + 2.0**-53, 0.5, 0.5 - 2.0**-54]
    assert d.locate(x, [1e15] * 3).tolist() == [1, 0, 0]
    # sites mirrored in y = x (coordinates that are not dyadic): every query on y = x is an exact tie
    t = np.array([1e12 + 0.1, -3.7, 0.2, 12345.678])
    for sites in ([[0.1, 0.3], [0.3, 0.1]], [[0.3, 0.1], [0.1, 0.3]]):
        assert tvoronoi.voronoi(sites).locate(t, t).tolist() == [0, 0, 0, 0]


def test_locate_shapes_and_errors():
    d = tvoronoi.voronoi(XY)
    assert d.locate(np.zeros((2, 3)), 2.0).shape == (2, 3)
    assert d.locate(0.0, 0.0).shape == ()
    assert d.locate([], []).shape == (0,)
    with pytest.raises(TvoronoiError, match="query point 1"):
        d.locate([0.0, np.nan], [0.0, 1.0])
    with pytest.raises(TvoronoiError, match="query point 0"):
        d.locate([1e300], [0.0])
    with pytest.raises(TvoronoiError, match="no sites"):
        tvoronoi.voronoi(np.empty((0, 2))).locate([0.0], [0.0])


def test_locate_hypothesis():
    from hypothesis import given, settings
    from hypothesis import strategies as st

    coords = st.integers(-6, 6)

    @settings(max_examples=200, deadline=None)
    @given(
        st.lists(st.tuples(coords, coords), min_size=1, max_size=25),
        st.lists(st.tuples(coords, coords), min_size=1, max_size=20),
    )
    def check(sites, queries):
        sites = np.asarray(sites, float)
        q = np.asarray(queries, float) / 2.0
        got = tvoronoi.voronoi(sites).locate(q[:, 0], q[:, 1])
        np.testing.assert_array_equal(got, nearest_reference(sites, q[:, 0], q[:, 1]))

    check()


def test_locate_on_a_dynamic_diagram_skips_removed_sites():
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(SEED)
    xy = rng.random((800, 2))
    dv = tvoronoi.DynamicVoronoi(xy[:500])
    for p in xy[500:]:
        dv.insert(*p)
    for i in range(0, 800, 3):
        dv.remove(i)
    d = dv.diagram().to_diagram()
    alive = np.setdiff1d(np.arange(800), np.arange(0, 800, 3))
    q = rng.random((5000, 2)) * 1.4 - 0.2
    np.testing.assert_array_equal(d.locate(q[:, 0], q[:, 1]), alive[cKDTree(xy[alive]).query(q)[1]])
    dv = tvoronoi.DynamicVoronoi([[0.0, 0.0], [1.0, 1.0], [2.0, 0.0]])
    dv.remove(0)
    dv.remove(2)
    assert dv.diagram().to_diagram().locate([0.0, 5.0], [0.0, -3.0]).tolist() == [1, 1]


def _frame_with_points(xy, extra=None):
    import pandas as pd

    frame = pd.DataFrame({"name": [f"p{i}" for i in range(len(xy))], "geometry": shapely.points(xy)})
    for key, values in (extra or {}).items():
        frame[key] = values
    return frame


def test_dataframe_with_a_column_of_points():
    xy = np.random.default_rng(SEED).random((300, 2))
    want = tvoronoi.voronoi(xy)
    got = tvoronoi.voronoi(_frame_with_points(xy))
    assert np.array_equal(got.cell_points, want.cell_points)
    assert np.array_equal(got.cell_vertices, want.cell_vertices)
    # a points column under another name is found too
    frame = _frame_with_points(xy).rename(columns={"geometry": "where"})
    assert np.array_equal(as_points(frame), xy)


def test_dataframe_named_coordinates_come_before_a_points_column():
    xy = np.random.default_rng(SEED + 1).random((50, 2))
    other = xy[::-1].copy()
    frame = _frame_with_points(other, {"x": xy[:, 0], "y": xy[:, 1]})
    assert np.array_equal(as_points(frame), xy)


@pytest.mark.parametrize(
    "bad, words",
    [
        (shapely.LineString([(0, 0), (1, 1)]), ["column 'geometry'", "point 3", "LineString"]),
        (None, ["column 'geometry'", "point 3", "None"]),
        (shapely.Point(), ["column 'geometry'", "point 3", "empty"]),
    ],
)
def test_dataframe_points_column_errors_name_column_and_row(bad, words):
    frame = _frame_with_points(np.random.default_rng(SEED).random((6, 2)))
    values = frame["geometry"].to_numpy().copy()
    values[3] = bad
    frame["geometry"] = values
    with pytest.raises(TvoronoiError) as info:
        tvoronoi.voronoi(frame)
    for word in words:
        assert word in str(info.value)


def test_a_geoseries_crs_reaches_the_cells():
    geopandas = pytest.importorskip("geopandas")
    rng = np.random.default_rng(31)
    xy = rng.random((200, 2)) * 1000
    series = geopandas.GeoSeries(shapely.points(xy), crs="EPSG:3035")
    d = tvoronoi.voronoi(series)
    assert d.crs == series.crs
    assert d.to_geopandas().crs == series.crs
    assert d.to_geopandas(crs="EPSG:3857").crs == "EPSG:3857"  # given: it wins
    frame = geopandas.GeoDataFrame({"v": np.arange(200)}, geometry=series)
    clipped = tvoronoi.voronoi(frame, clip=shapely.box(100, 100, 900, 900))
    assert clipped.to_geopandas().crs == series.crs
    assert tvoronoi.voronoi(xy).crs is None and tvoronoi.voronoi(xy).to_geopandas().crs is None
    # the same cells either way
    assert np.array_equal(d.cell_vertices, tvoronoi.voronoi(xy).cell_vertices)
