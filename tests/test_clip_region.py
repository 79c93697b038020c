"""Diagrams clipped to a region: cells tile concave regions, holes, several parts; the batch --clip option."""

from __future__ import annotations

import json

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import tvoronoi
from tvoronoi import cli
from tvoronoi import region as region_module
from tvoronoi.generators import coastline
from tvoronoi.region import ClippedDiagram, local_intersection, region_box
from tvoronoi.shapes import cell_polygons

L_SHAPE = shapely.Polygon([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
WITH_HOLES = shapely.Polygon(
    [(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (2, 1), (2, 2), (1, 2)], [(2.5, 2.5), (3.5, 2.6), (3, 3.5)]]
)
TWO_PARTS = shapely.MultiPolygon([shapely.box(0, 0, 1, 1), shapely.Polygon([(2, 2), (3, 2), (2.5, 4)])])


def star(k: int = 20, inner: float = 0.45, per_edge: int = 1) -> shapely.Polygon:
    t = np.arange(k) * 2 * np.pi / k
    r = np.where(np.arange(k) % 2 == 0, 1.0, inner)
    corners = np.c_[r * np.cos(t), r * np.sin(t)]
    s = np.linspace(0, 1, per_edge, endpoint=False)[:, None]
    return shapely.Polygon(np.concatenate([a + (b - a) * s for a, b in zip(corners, np.roll(corners, -1, 0))]))


def check_tiles(d, region) -> None:
    """The cells of the inside sites tile the region: a valid coverage, union = region, areas sum to its area."""
    cells = d.to_shapely()
    assert isinstance(d, ClippedDiagram)
    present = cells != None  # noqa: E711
    # every site the region covers has a cell holding it, and no other row has one
    distinct = d.site_of == np.arange(d.n_sites)
    assert np.array_equal(present, d.inside & distinct)
    got = cells[present]
    assert shapely.is_valid(got).all()
    assert shapely.coverage_is_valid(got)
    assert shapely.area(got).sum() == pytest.approx(region.area, rel=1e-12)
    assert shapely.union_all(got).symmetric_difference(region).area <= 1e-12 * region.area
    rows = np.flatnonzero(present)
    assert shapely.covers(got, shapely.points(d.sites[rows])).all()
    # exteriors run counter-clockwise, as RFC 7946 wants
    polygons = shapely.get_parts(got)
    assert shapely.is_ccw(shapely.get_exterior_ring(polygons)).all()


@pytest.mark.parametrize(
    "region", [L_SHAPE, WITH_HOLES, TWO_PARTS, star(per_edge=5)], ids=["concave-L", "holes", "multi-part", "star"]
)
@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_cells_tile_the_region(rng, region, engine):
    xmin, ymin, xmax, ymax = region.bounds
    pts = rng.uniform([xmin - 0.5, ymin - 0.5], [xmax + 0.5, ymax + 0.5], (600, 2))
    pts[:5] = pts[5:10]  # repeated points share their first copy's cell
    d = tvoronoi.voronoi(pts, clip=region, engine=engine)
    check_tiles(d, region)
    assert d.n_outside == np.count_nonzero(~shapely.intersects_xy(region, pts[:, 0], pts[:, 1]))
    # untouched cells are the CSR rings as they are
    kept = np.flatnonzero(~d.reshaped)
    for i in kept[:50]:
        assert d.to_shapely()[i].equals_exact(shapely.Polygon(d.cell_polygon(i)), 0)


# a coastline family: detailed, spiky outlines with lakes and islands (tvoronoi.generators.coastline)
COASTS = [coastline(600, spikes=80, lakes=3, islands=4, seed=seed) for seed in (1, 2)] + [
    coastline(1500, spikes=200, seed=3)
]


@pytest.mark.parametrize("region", COASTS, ids=["coast600-1", "coast600-2", "coast1500"])
@pytest.mark.parametrize("grid", [False, True], ids=["tested", "grid"])
def test_spiky_coastlines_are_tiled(rng, region, grid, monkeypatch):
    """Cells cut against local pieces of a spiky outline (and, with the grid, sites and cells placed
    by tiles first) still tile the outline exactly."""
    if grid:
        monkeypatch.setattr(region_module, "GRID_MIN_SITES", 0)
        monkeypatch.setattr(region_module, "GRID_TILES", 16)
    xmin, ymin, xmax, ymax = region.bounds
    pts = rng.uniform([xmin, ymin], [xmax, ymax], (4000, 2))
    d = tvoronoi.voronoi(pts, clip=region)
    check_tiles(d, region)
    assert np.array_equal(d.inside, shapely.intersects_xy(region, pts[:, 0], pts[:, 1]))
    # the cells left whole are those the region contains
    cells = cell_polygons(d)
    whole = np.flatnonzero(~d.reshaped)
    assert shapely.contains_properly(region, cells[whole]).all()
    cut = np.flatnonzero(d.reshaped & (cells != None))  # noqa: E711
    assert not shapely.contains_properly(region, cells[cut]).any()


@pytest.mark.parametrize("spikes", [0, 200])
def test_local_pieces_give_the_whole_intersection(rng, spikes):
    """Each cell cut against its piece of the outline is the cell cut against the whole outline (with its
    long edges split, as for every cell alike): exactly; and against the outline as given, up to rounding
    where long edges (the spikes) were split."""
    region = coastline(1500, spikes=spikes, seed=6)
    xmin, ymin, xmax, ymax = region.bounds
    d = tvoronoi.voronoi(rng.uniform([xmin, ymin], [xmax, ymax], (3000, 2)), bbox=region_box(region))
    cells = cell_polygons(d)
    cells = cells[~shapely.contains_properly(region, cells)]
    local = local_intersection(cells, region)
    split, _ = region_module._short_edged(region)
    assert len(cells) > 100
    assert shapely.equals_exact(
        shapely.normalize(local), shapely.normalize(shapely.intersection(cells, split)), 0
    ).all()
    whole = shapely.intersection(cells, region)
    if spikes:
        same = shapely.equals_exact(shapely.normalize(local), shapely.normalize(whole), 0)
        assert not same.all(), "the long spike edges were split"
    assert (shapely.area(shapely.symmetric_difference(local, whole)) <= 1e-12 * shapely.area(cells)).all()
    assert shapely.coverage_is_valid(local[shapely.area(local) > 0])


def test_grid_places_sites_as_the_region_does(monkeypatch):
    """Sites on tile edges, on the outline's vertices and edges, and in every kind of tile."""
    region = COASTS[0]
    monkeypatch.setattr(region_module, "GRID_TILES", 8)
    grid = region_module._Grid(region)
    xmin, ymin, xmax, ymax = region.bounds
    edges_x = xmin + np.arange(9) * grid.step[0]
    vertices = shapely.get_coordinates(region)
    midpoints = (vertices[:-1] + vertices[1:]) / 2
    rng = np.random.default_rng(8)
    pts = np.concatenate(
        [
            rng.uniform([xmin - 0.1, ymin - 0.1], [xmax + 0.1, ymax + 0.1], (20000, 2)),
            vertices,
            midpoints,
            np.c_[np.repeat(edges_x, 50), rng.uniform(ymin, ymax, 9 * 50)],
        ]
    )
    monkeypatch.setattr(region_module, "GRID_MIN_SITES", 0)
    got = region_module.sites_inside(pts, region, grid)
    assert np.array_equal(got, shapely.intersects_xy(region, pts[:, 0], pts[:, 1]))
    assert grid.inside.any() and grid.outside.any() and not (grid.inside | grid.outside).all()


def test_inner_diagram_is_that_of_the_inside_sites(rng):
    pts = rng.uniform(-1, 3, (300, 2))
    d = tvoronoi.voronoi(pts, clip=L_SHAPE)
    inside = np.flatnonzero(d.inside)
    alone = tvoronoi.voronoi(pts[inside], bbox=d.bbox)
    for k, i in enumerate(inside.tolist()):
        assert np.array_equal(d.cell_polygon(i), alone.cell_polygon(k))
    assert np.array_equal(
        np.sort(d.triangles, axis=1)[np.lexsort(np.sort(d.triangles, axis=1).T)],
        np.sort(inside[alone.triangles], axis=1)[np.lexsort(np.sort(inside[alone.triangles], axis=1).T)],
    )
    # nearest-site queries answer among the inside sites only
    q = rng.uniform(-1, 3, (200, 2))
    got = d.locate(q[:, 0], q[:, 1])
    assert d.inside[got].all()
    assert np.array_equal(got, inside[alone.locate(q[:, 0], q[:, 1])])


def test_region_smaller_than_one_cell():
    region = shapely.Polygon([(0.1, 0.1), (0.3, 0.1), (0.2, 0.25)])
    d = tvoronoi.voronoi([[0.2, 0.15], [5, 5], [-3, 2]], clip=region)
    cells = d.to_shapely()
    assert cells[0].equals(region) and cells[1] is None and cells[2] is None
    assert d.n_outside == 2
    check_tiles(d, region)


def test_site_on_the_boundary_is_inside():
    d = tvoronoi.voronoi([[0, 0], [1, 0.5], [2, 2]], clip=L_SHAPE)
    assert d.inside.tolist() == [True, True, False]
    check_tiles(d, L_SHAPE)


def test_region_missing_every_site_is_an_error():
    with pytest.raises(tvoronoi.TvoronoiError, match="none of the 2 points lies inside the clip region"):
        tvoronoi.voronoi([[5, 5], [6, 6]], clip=L_SHAPE)


@pytest.mark.parametrize(
    "clip, message",
    [
        (shapely.Point(0, 0), "must be a shapely Polygon or MultiPolygon, got Point"),
        (shapely.Polygon(), "empty"),
        (shapely.Polygon([(0, 0), (1, 1), (1, 0), (0, 1)]), "not a valid Polygon .*Self-intersection"),
    ],
)
def test_bad_regions(clip, message):
    with pytest.raises(tvoronoi.TvoronoiError, match=message):
        tvoronoi.voronoi([[0.5, 0.5]], clip=clip)


def test_geopandas_and_writers_carry_the_cut_cells(tmp_path, rng):
    from tvoronoi.writers.geojson_diagram import write_cells

    pts = rng.uniform(-0.5, 4.5, (200, 2))
    d = tvoronoi.voronoi(pts, clip=WITH_HOLES)
    out = tmp_path / "cells.geojson"
    write_cells(d, None, str(out))
    doc = json.loads(out.read_text())
    geoms = [shapely.geometry.shape(f["geometry"]) if f["geometry"] else None for f in doc["features"]]
    assert [g is None for g in geoms] == [g is None for g in d.to_shapely()]
    assert all(g is None or g.equals_exact(h, 0) for g, h in zip(geoms, d.to_shapely()))
    assert doc["bbox"] == list(WITH_HOLES.bounds)
    gdf = d.to_geopandas()
    assert gdf.geometry.isna().sum() == d.n_outside
    assert gdf.area.sum() == pytest.approx(WITH_HOLES.area)


def test_geoparquet_of_cut_cells(tmp_path, rng):
    pq = pytest.importorskip("pyarrow.parquet")
    from tvoronoi.writers.geoparquet import write_cells_parquet

    d = tvoronoi.voronoi(rng.uniform(-0.5, 4.5, (200, 2)), clip=TWO_PARTS)
    out = tmp_path / "cells.parquet"
    write_cells_parquet(d, None, str(out))
    table = pq.read_table(out)
    geo = json.loads(table.schema.metadata[b"geo"])
    assert set(geo["columns"]["geometry"]["geometry_types"]) <= {"Polygon", "MultiPolygon"}
    geoms = shapely.from_wkb(table.column("geometry").to_pylist())
    assert shapely.area(geoms[geoms != None]).sum() == pytest.approx(TWO_PARTS.area)  # noqa: E711


def _repaired(xy) -> shapely.Geometry:
    """shapely's repair of a random ring, or an empty polygon where GEOS itself refuses the ring (its
    overlay raises on some rings with subnormal coordinates: "Overlay input is mixed-dimension")."""
    try:
        return shapely.make_valid(shapely.Polygon(xy))
    except shapely.errors.GEOSException:
        return shapely.Polygon()


polygons = st.lists(st.tuples(st.floats(-10, 10), st.floats(-10, 10)), min_size=3, max_size=12).map(_repaired)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(polygons, st.integers(0, 2**32 - 1))
def test_random_regions_are_tiled(geometry, seed):
    region = shapely.union_all(
        [g for g in shapely.get_parts(geometry) if g.geom_type in ("Polygon", "MultiPolygon")] or [shapely.Polygon()]
    )
    if region.is_empty or region.area < 1e-3 or region.geom_type not in ("Polygon", "MultiPolygon"):
        return
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = region.bounds
    pts = rng.uniform([xmin, ymin], [xmax, ymax], (80, 2))
    pts = np.vstack([pts, region.representative_point().coords])
    try:
        d = tvoronoi.voronoi(pts, clip=region)
    except tvoronoi.TvoronoiError as e:
        # the defined answer when the points or the region spread over more than 2^170 (a subnormal
        # or tiny coordinate next to ordinary ones): refused, naming the value
        assert "exact arithmetic covers a range of 2^170" in str(e)
        for coords in (pts, shapely.get_coordinates(region)):
            magnitude = np.abs(coords[coords != 0])
            if np.log2(magnitude.max()) - np.log2(magnitude.min()) > 169:
                return
        raise AssertionError(f"refused within the range: {e}") from None
    check_tiles(d, region)


def test_region_beyond_the_exact_range_is_refused():
    """A subnormal vertex next to ordinary ones (GEOS's overlays lose area there) is named."""
    region = shapely.Polygon([(1.0, 0.0), (5e-324, 0.0), (5e-324, 1.0)])
    with pytest.raises(tvoronoi.TvoronoiError, match=r"clip: vertex 1: coordinate 5e-324 is over 1e51 times smaller"):
        tvoronoi.voronoi([[0.2, 0.2], [0.5, 0.1]], clip=region)


# --- the batch option


def write_region(path, geometry) -> str:
    path.write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [
                    {"type": "Feature", "properties": {}, "geometry": shapely.geometry.mapping(g)} for g in geometry
                ],
            }
        )
    )
    return str(path)


def test_batch_clip(tmp_path, capsys):
    src = tmp_path / "pts.csv"
    src.write_text("x,y,name\n0.5,0.5,a\n1.5,0.5,b\n0.5,1.5,c\n2.5,2.5,d\n1.5,1.5,e\n0.6,0.4,f\n")
    region = write_region(tmp_path / "region.geojson", [L_SHAPE, shapely.box(2, 2, 3, 3)])
    out = tmp_path / "cells.geojson"
    status = cli.main(["batch", str(src), "-o", str(out), "--clip", region])
    err = capsys.readouterr().err
    assert status == 0
    assert "warning: 1 site lies outside the --clip region" in err and "region.geojson" in err
    features = json.loads(out.read_text())["features"]
    assert [f["properties"]["name"] for f in features if f["geometry"] is None] == ["e"]
    cells = [shapely.geometry.shape(f["geometry"]) for f in features if f["geometry"]]
    assert sum(c.area for c in cells) == pytest.approx(L_SHAPE.area + 1)
    assert cli.main(["batch", str(src), "-o", str(out), "--force", "-q", "--clip", region]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize(
    "text, message",
    [
        ('{"type": "Point", "coordinates": [0, 0]}', "expected a GeoJSON FeatureCollection, Feature, Polygon"),
        (
            '{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, '
            '"geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]}}]}',
            "feature 0 is a LineString; --clip takes Polygons and MultiPolygons only",
        ),
        ('{"type": "Feature", "geometry": null, "properties": {}}', "feature 0 has a null geometry"),
        ('{"type": "Polygon", "coordinates": [[[0, 0], [1, 1], [1, 0], [0, 1], [0, 0]]]}', "not a valid Polygon"),
        ("not json", "not JSON"),
        ('{"type": "FeatureCollection", "features": []}', "holds no Polygon"),
    ],
)
def test_batch_clip_errors_name_the_file(tmp_path, capsys, text, message):
    src = tmp_path / "pts.csv"
    src.write_text("x,y\n0.5,0.5\n1.5,0.5\n")
    region = tmp_path / "bad.geojson"
    region.write_text(text)
    status = cli.main(["batch", str(src), "-o", str(tmp_path / "o.geojson"), "--clip", str(region)])
    err = capsys.readouterr().err
    assert status == 2
    assert err.startswith(f"tvoronoi: error: --clip {region}: ") and message in err
    assert not (tmp_path / "o.geojson").exists()


def test_batch_clip_missing_file(tmp_path, capsys):
    src = tmp_path / "pts.csv"
    src.write_text("x,y\n0.5,0.5\n")
    status = cli.main(["batch", str(src), "-o", "-", "--clip", str(tmp_path / "nope.geojson")])
    assert status == 2 and "--clip" in capsys.readouterr().err


@pytest.mark.parametrize("spikes", [0, 200])
def test_a_cells_cut_depends_on_it_and_the_region_alone(rng, spikes):
    """The cut of a crossing cell is the same, to the bit, whether it is cut among all the cells or among
    any subset (as the tiles of a distributed build cut theirs): the outline's long edges are split by a
    length of its own, and the pieces only choose where each cut runs."""
    from tvoronoi.region import cut_polygons

    region = coastline(1500, spikes=spikes, seed=7)
    xmin, ymin, xmax, ymax = region.bounds
    d = tvoronoi.voronoi(rng.uniform([xmin, ymin], [xmax, ymax], (4000, 2)), bbox=region_box(region))
    cells = cell_polygons(d)
    whole, reshaped = cut_polygons(cells, region)
    assert reshaped.sum() > 100
    areas = shapely.area(cells)
    for part in (
        np.flatnonzero(rng.random(len(cells)) < 0.3),
        np.arange(len(cells) // 2),
        np.flatnonzero(reshaped)[:9],
        np.flatnonzero(areas < np.nanmedian(areas)),
    ):
        sub, _ = cut_polygons(cells[part], region)
        assert (shapely.to_wkb(sub) == shapely.to_wkb(whole[part])).all()


def test_a_geoseries_or_geodataframe_clips_as_the_union_of_its_geometries(rng):
    geopandas = pytest.importorskip("geopandas")
    parts = [shapely.box(0, 0, 1, 1), shapely.box(1, 0, 2, 1), shapely.box(3, 3, 4, 4)]
    pts = rng.random((300, 2)) * 4
    union = shapely.union_all(parts)
    want = tvoronoi.voronoi(pts, clip=union).to_shapely()
    for clip in (geopandas.GeoSeries(parts), geopandas.GeoDataFrame(geometry=parts)):
        got = tvoronoi.voronoi(pts, clip=clip).to_shapely()
        assert [None if g is None else g.wkb for g in got] == [None if g is None else g.wkb for g in want]
