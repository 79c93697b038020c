"""The Python API in the geospatial ecosystem: shapely/geopandas/pandas inputs, shapely and geopandas outputs,
and nearest-site queries (Diagram.locate)."""

import subprocess
import sys

import numpy as np
import pytest
import shapely

import tvoronoi
from tvoronoi import TvoronoiError
from tvoronoi.api import as_points

from conftest import DATASETS, SEED

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
    ids=["multipoint", "list", "tuple", "object_array", "geoseries", "geodataframe", "series", "frame_xy",
         "frame_lonlat", "frame_easting", "frame_two_columns", "points_z"],
)
def test_voronoi_takes_geospatial_points(make):
    got = tvoronoi.voronoi(make(XY))
    want = tvoronoi.voronoi(XY)
    np.testing.assert_array_equal(got.sites, XY)
    np.testing.assert_array_equal(got.cell_offsets, want.cell_offsets)
    np.testing.assert_array_equal(got.cell_points, want.cell_points)


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
    code = ("import sys, numpy as np, shapely, tvoronoi; tvoronoi.voronoi(np.random.rand(20, 2)); "
            "tvoronoi.voronoi(shapely.MultiPoint(np.random.rand(20, 2))).to_shapely(); "
            "print('pandas' in sys.modules or 'geopandas' in sys.modules)")
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
    props = pd.DataFrame({"name": [f"p{i}" for i in range(300)], "v": np.arange(300) * 0.5},
                         index=np.arange(300) + 1000)
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
