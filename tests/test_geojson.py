"""GeoJSON out: valid closed CCW cells tiling the box, exact coordinates, properties, chunks, atomic files."""

from __future__ import annotations

import io
import json
import os
import stat

import numpy as np
import pytest
import scipy.spatial
import shapely

import tvoronoi
from conftest import DATASETS, GENERAL_POSITION
from tvoronoi.errors import TvoronoiError
from tvoronoi.readers import PointSet
from tvoronoi.writers import geojson_diagram
from tvoronoi.writers.geojson_diagram import missing_cells, write_cells, write_delaunay
from tvoronoi.writers.targets import TEMP_SUFFIX

AREA_RTOL = 1e-9


# ---------------------------------------------------------------------------
# helpers shared with test_cli


def load(data: bytes | str | os.PathLike) -> dict:
    """Parse a GeoJSON document given as bytes or as a path."""
    if isinstance(data, (bytes, bytearray)):
        return json.loads(data)
    with open(data, "rb") as f:
        return json.load(f)


def to_bytes(write, *args, **kwargs) -> bytes:
    buf = io.BytesIO()
    write(*args, buf, **kwargs)
    return buf.getvalue()


def ring_of(feature: dict) -> np.ndarray:
    geometry = feature["geometry"]
    assert geometry["type"] == "Polygon"
    assert len(geometry["coordinates"]) == 1, "a cell has one ring and no holes"
    return np.array(geometry["coordinates"][0], dtype=np.float64)


def check_cells_document(doc: dict, sites: np.ndarray, box, *, sites_in_box: bool = True) -> dict:
    """The cells of a FeatureCollection are closed, CCW, valid, hold their sites and tile the box.

    Returns {site row: shapely polygon} of the features with a geometry.
    """
    assert doc["type"] == "FeatureCollection"
    polygons = {}
    for feature in doc["features"]:
        assert feature["type"] == "Feature"
        i = feature["properties"]["site"]
        if feature["geometry"] is None:
            continue
        ring = ring_of(feature)
        assert len(ring) >= 4, f"cell {i}: a ring needs four positions"
        assert np.array_equal(ring[0], ring[-1]), f"cell {i}: ring not closed"
        polygon = shapely.Polygon(ring)
        assert polygon.is_valid, f"cell {i}: {shapely.is_valid_reason(polygon)}"
        assert shapely.is_ccw(polygon.exterior), f"cell {i}: ring is clockwise"
        if sites_in_box:
            assert polygon.covers(shapely.Point(sites[i])), f"site {i} outside its cell"
        polygons[i] = polygon
    xmin, ymin, xmax, ymax = box
    box_area = (xmax - xmin) * (ymax - ymin)
    total = sum(p.area for p in polygons.values())
    assert abs(total - box_area) <= AREA_RTOL * box_area, f"cells cover {total}, the box {box_area}"
    assert shapely.coverage_is_valid(shapely.GeometryCollection(list(polygons.values())))
    return polygons


def grown_box(sites: np.ndarray):
    """The default box: the sites' bounding box grown by 10% of its larger side on each side."""
    lo, hi = sites.min(axis=0), sites.max(axis=0)
    margin = 0.1 * max(hi - lo)
    return (lo[0] - margin, lo[1] - margin, hi[0] + margin, hi[1] + margin)


def hull_size(sites: np.ndarray) -> int:
    return len(scipy.spatial.ConvexHull(sites).vertices)


def temp_files(directory) -> list[str]:
    return [name for name in os.listdir(directory) if name.endswith(TEMP_SUFFIX)]


# ---------------------------------------------------------------------------
# cells


@pytest.mark.parametrize("name", GENERAL_POSITION + ("collinear", "duplicates"))
def test_cells_are_closed_ccw_valid_and_tile_the_box(name):
    sites = DATASETS[name]
    d = tvoronoi.voronoi(sites)
    doc = load(to_bytes(write_cells, d, None))
    polygons = check_cells_document(doc, sites, d.bbox)
    distinct = np.flatnonzero(d.site_of == np.arange(len(sites)))
    assert sorted(polygons) == distinct.tolist()
    assert [f["properties"]["site"] for f in doc["features"]] == distinct.tolist(), "features in input order"


def test_default_box_is_the_grown_bounding_box():
    sites = DATASETS["gaussian"]
    d = tvoronoi.voronoi(sites)
    doc = load(to_bytes(write_cells, d, None))
    assert doc["bbox"] == pytest.approx(grown_box(sites), rel=1e-12)
    union = shapely.union_all([shapely.Polygon(ring_of(f)) for f in doc["features"]])
    assert union.area == pytest.approx(shapely.box(*grown_box(sites)).area, rel=AREA_RTOL)


@pytest.mark.parametrize("name", ["uniform", "tiny", "huge"])
def test_coordinates_read_back_exactly(name):
    d = tvoronoi.voronoi(DATASETS[name])
    doc = load(to_bytes(write_cells, d, None))
    for feature in doc["features"]:
        i = feature["properties"]["site"]
        ring = ring_of(feature)
        np.testing.assert_array_equal(ring[:-1], d.cell_polygon(i))
        np.testing.assert_array_equal(ring[-1], d.cell_polygon(i)[0])


def test_properties_travel_and_clashing_names_are_renamed():
    sites = DATASETS["uniform"][:30]
    n_sites = len(sites)
    points = PointSet(
        sites,
        "t.csv",
        {"name": [f"p{i}" for i in range(n_sites)], "site": list(range(100, 100 + n_sites)), "w": [0.5] * n_sites},
    )
    doc = load(to_bytes(write_cells, tvoronoi.voronoi(sites), points))
    for feature in doc["features"]:
        props = feature["properties"]
        i = props["site"]
        assert list(props) == ["site", "name", "site_2", "w"]
        assert props["name"] == f"p{i}" and props["site_2"] == 100 + i and props["w"] == 0.5


AWKWARD_TEXT = ["plain", "", "a, b", 'say "hi"', "back\\slash", "tab\there", "é ü 中", "%d %b %%", "\u2028", '","']


@pytest.mark.parametrize("chunk", [3, 10_000])
def test_properties_in_bulk_match_each_row(monkeypatch, chunk):
    """Columns serialized a chunk at a time give each row's values as json.dumps writes them:
    ints, floats, nulls, and strings with quotes, commas, backslashes, control characters,
    non-ASCII text and % signs, in chunks with and without a repeated site."""
    rng = np.random.default_rng(5)
    sites = DATASETS["uniform"][:40]
    sites = np.concatenate([sites, sites[[4]]])  # row 40 repeats row 4: its chunk is written row by row
    n_sites = len(sites)
    columns = {
        "int": rng.integers(-(2**62), 2**62, n_sites).tolist(),
        "float": [None if i % 7 == 0 else float(v) for i, v in enumerate(rng.normal(size=n_sites) * 1e300)],
        "text": [AWKWARD_TEXT[i % len(AWKWARD_TEXT)] for i in range(n_sites)],
        "plain": [f"p{i}" for i in range(n_sites)],
        "mixed text": [None if i % 3 == 0 else f"v{i}" for i in range(n_sites)],
        'key "%s"': [[i, "x"] if i % 2 else i for i in range(n_sites)],
    }
    points = PointSet(sites, "t.csv", columns)
    monkeypatch.setattr(geojson_diagram, "CHUNK_FEATURES", chunk)
    text = to_bytes(write_cells, tvoronoi.voronoi(sites), points)
    features = load(text)["features"]
    assert len(features) == n_sites - 1
    for feature in features:
        props = feature["properties"]
        i = props.pop("site")
        props.pop("duplicates", None)
        assert props == {name: values[i] for name, values in columns.items()}
        assert json.dumps(props, ensure_ascii=False) == json.dumps(points.properties(i), ensure_ascii=False)


def test_json_texts_cut_where_json_dumps_does():
    values = [1, None, 2.5, True, *AWKWARD_TEXT, [1, "a,b"], {"k": "v,w"}]
    assert [json.loads(t) for t in geojson_diagram.json_texts(values)] == values
    for part in (values[:4], AWKWARD_TEXT, [[1, 2], [3]]):
        assert [json.loads(t) for t in geojson_diagram.json_texts(part)] == part


def test_geojson_records_travel():
    sites = np.array([[0.0, 0.0], [1.0, 0.2], [0.3, 1.0], [0.9, 0.8]])
    records = [{"id": "a", "tags": [1, 2]}, {}, {"id": "c", "duplicates": "x"}, {"nested": {"k": None}}]
    points = PointSet(sites, "t.geojson", {}, records)
    doc = load(to_bytes(write_cells, tvoronoi.voronoi(sites), points))
    props = [f["properties"] for f in doc["features"]]
    assert props == [
        {"site": 0, "id": "a", "tags": [1, 2]},
        {"site": 1},
        {"site": 2, "id": "c", "duplicates_2": "x"},
        {"site": 3, "nested": {"k": None}},
    ]


def test_duplicates_are_listed_on_the_first_row():
    base = DATASETS["uniform"][:20]
    sites = np.concatenate([base, base[[3, 7, 3]], base[:1]])  # rows 20, 22 repeat 3; 21 repeats 7; 23 repeats 0
    d = tvoronoi.voronoi(sites)
    doc = load(to_bytes(write_cells, d, None))
    check_cells_document(doc, sites, d.bbox)
    by_site = {f["properties"]["site"]: f["properties"] for f in doc["features"]}
    assert sorted(by_site) == list(range(20)), "no feature for a repeated row"
    assert by_site[3]["duplicates"] == [20, 22]
    assert by_site[7]["duplicates"] == [21]
    assert by_site[0]["duplicates"] == [23]
    assert all("duplicates" not in p for i, p in by_site.items() if i not in (0, 3, 7))


def test_cell_that_misses_the_box_is_null():
    sites = np.array([[0.2, 0.2], [0.8, 0.3], [0.5, 0.9], [50.0, 50.0]])
    box = (0.0, 0.0, 1.0, 1.0)
    d = tvoronoi.voronoi(sites, bbox=box)
    doc = load(to_bytes(write_cells, d, None))
    assert len(doc["features"]) == 4
    assert doc["features"][3] == {"type": "Feature", "geometry": None, "properties": {"site": 3}}
    assert missing_cells(d).tolist() == [3]
    check_cells_document(doc, sites, box)


def test_small_chunks_give_the_same_document(monkeypatch):
    """Chunk seams (with duplicates and a null cell next to them) change nothing."""
    base = DATASETS["clustered"][:40]
    sites = np.concatenate([base, base[[5, 6, 7]], [[1e6, 1e6]]])
    d = tvoronoi.voronoi(sites, bbox=(base.min() - 1, base.min() - 1, base.max() + 1, base.max() + 1))
    whole = to_bytes(write_cells, d, None)
    seen = []
    monkeypatch.setattr(geojson_diagram, "CHUNK_FEATURES", 7)
    chunked = to_bytes(write_cells, d, None, progress=lambda done, total: seen.append((done, total)))
    assert chunked == whole
    assert load(chunked)["features"][-1]["geometry"] is None
    total = len(load(whole)["features"])
    assert seen[0] == (0, total) and seen[-1] == (total, total)
    assert all(a[0] < b[0] for a, b in zip(seen, seen[1:])), "progress only moves forward"


def test_one_feature_per_line():
    d = tvoronoi.voronoi(DATASETS["uniform"])
    lines = to_bytes(write_cells, d, None).splitlines()
    assert len(lines) == 2 + d.n_sites
    assert json.loads(lines[1].rstrip(b","))["properties"]["site"] == 0


def test_points_must_match_the_diagram():
    d = tvoronoi.voronoi(DATASETS["uniform"])
    with pytest.raises(TvoronoiError, match="rows"):
        to_bytes(write_cells, d, PointSet(DATASETS["uniform"][:10], "t.csv"))


# ---------------------------------------------------------------------------
# Delaunay


@pytest.mark.parametrize("name", ["uniform", "gaussian", "clustered"])
def test_delaunay_triangles(name):
    sites = DATASETS[name]
    d = tvoronoi.voronoi(sites)
    doc = load(to_bytes(write_delaunay, d))
    features = doc["features"]
    assert len(features) == 2 * len(sites) - 2 - hull_size(sites)
    ours = set()
    for feature in features:
        i, j, k = feature["properties"]["sites"]
        ring = ring_of(feature)
        np.testing.assert_array_equal(ring, sites[[i, j, k, i]])
        assert shapely.is_ccw(shapely.Polygon(ring).exterior)
        ours.add(tuple(sorted((i, j, k))))
    qhull = {tuple(sorted(t)) for t in scipy.spatial.Delaunay(sites).simplices.tolist()}
    assert ours == qhull
    area = sum(shapely.Polygon(ring_of(f)).area for f in features)
    assert area == pytest.approx(scipy.spatial.ConvexHull(sites).volume, rel=AREA_RTOL)


def test_delaunay_of_collinear_points_is_empty():
    d = tvoronoi.voronoi(DATASETS["collinear"])
    assert load(to_bytes(write_delaunay, d)) == {"type": "FeatureCollection", "features": []}


# ---------------------------------------------------------------------------
# files: atomic, never half written


def test_write_to_a_path_and_stdout(tmp_path, capsysbinary):
    d = tvoronoi.voronoi(DATASETS["uniform"])
    path = tmp_path / "cells.geojson"
    assert write_cells(d, None, str(path)) == d.n_sites
    write_cells(d, None, "-")
    assert capsysbinary.readouterr().out == path.read_bytes()
    assert temp_files(tmp_path) == []


def test_failure_leaves_the_existing_file_and_no_temporary(tmp_path, monkeypatch):
    """A property orjson cannot write fails the run after chunks were written."""
    sites = DATASETS["uniform"]
    path = tmp_path / "cells.geojson"
    path.write_bytes(b"old content")
    before = path.stat()
    points = PointSet(sites, "t.csv", {"bad": [0] * (len(sites) - 1) + [{1, 2}]})  # a set is not JSON
    monkeypatch.setattr(geojson_diagram, "CHUNK_FEATURES", 16)
    with pytest.raises(TvoronoiError, match="site 199"):
        write_cells(tvoronoi.voronoi(sites), points, path)
    assert path.read_bytes() == b"old content"
    assert path.stat().st_mtime_ns == before.st_mtime_ns
    assert temp_files(tmp_path) == []


def test_overwrite_false_refuses_an_existing_file(tmp_path):
    path = tmp_path / "cells.geojson"
    path.write_bytes(b"keep me")
    with pytest.raises(FileExistsError):
        write_cells(tvoronoi.voronoi(DATASETS["uniform"]), None, path, overwrite=False)
    assert path.read_bytes() == b"keep me"
    assert temp_files(tmp_path) == []


def test_new_file_mode_follows_umask_and_replacing_keeps_the_mode(tmp_path):
    d = tvoronoi.voronoi(DATASETS["uniform"])
    old = os.umask(0o022)
    try:
        new = tmp_path / "new.geojson"
        write_cells(d, None, new)
        assert stat.S_IMODE(new.stat().st_mode) == 0o644
        kept = tmp_path / "kept.geojson"
        kept.write_bytes(b"old")
        kept.chmod(0o600)
        write_cells(d, None, kept)
        assert stat.S_IMODE(kept.stat().st_mode) == 0o600
        assert load(kept)["type"] == "FeatureCollection"
    finally:
        os.umask(old)


def test_a_symbolic_link_is_followed(tmp_path):
    target = tmp_path / "real.geojson"
    target.write_bytes(b"old")
    link = tmp_path / "link.geojson"
    link.symlink_to(target)
    write_delaunay(tvoronoi.voronoi(DATASETS["uniform"]), link)
    assert link.is_symlink()
    assert load(target)["type"] == "FeatureCollection"


def test_a_directory_is_not_an_output(tmp_path):
    with pytest.raises(IsADirectoryError):
        write_cells(tvoronoi.voronoi(DATASETS["uniform"]), None, tmp_path)
    assert temp_files(tmp_path) == []
