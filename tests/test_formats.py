"""Batch output formats (GeoJSON, GeoJSONSeq, GeoParquet) and Parquet input, read back and checked."""

from __future__ import annotations

import io
import json
import sys

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import DATASETS
from tvoronoi import cli

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

SITES = np.concatenate([DATASETS["uniform"][:50], DATASETS["uniform"][[3]]])  # row 50 repeats row 3


@pytest.fixture
def points_csv(tmp_path):
    lines = ["zip,x,y,name,score"]
    for i, (x, y) in enumerate(SITES.tolist()):
        lines.append(f"{i:05d},{x!r},{y!r},p{i},{i * 0.5 if i % 7 else ''}")
    path = tmp_path / "p.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def run(*args) -> int:
    return cli.main(["batch", *map(str, args), "-q"])


def test_geoparquet_cells_read_back_valid_typed_and_tiling_the_box(tmp_path, points_csv):
    out = tmp_path / "cells.parquet"
    assert run(points_csv, "-o", out, "--bbox", "-1,-1,2,2") == 0
    table = pq.read_table(out)
    assert table.schema.field("site").type == pa.int64()
    assert table.schema.field("zip").type == pa.string() and table.column("zip")[0].as_py() == "00000"
    assert table.schema.field("score").type == pa.float64() and table.column("score")[0].as_py() is None
    assert table.num_rows == 50  # row 50 repeats row 3: no row of its own
    assert table.column("duplicates").to_pylist()[3] == [50]
    cells = shapely.from_wkb(table.column("geometry").to_numpy(zero_copy_only=False))
    assert shapely.is_valid(cells).all()
    assert shapely.area(cells).sum() == pytest.approx(9.0, rel=1e-12)
    bounds = shapely.bounds(cells)
    bbox = table.column("bbox").combine_chunks().flatten()
    np.testing.assert_array_equal(np.column_stack([b.to_numpy() for b in bbox]), bounds)
    geo = json.loads(table.schema.metadata[b"geo"])
    assert geo["version"] == "1.1.0" and geo["primary_column"] == "geometry"
    column = geo["columns"]["geometry"]
    assert column["encoding"] == "WKB" and column["geometry_types"] == ["Polygon"]
    assert column["covering"]["bbox"]["xmin"] == ["bbox", "xmin"]
    assert column["crs"] is None  # x/y of unknown meaning
    assert column["bbox"] == [-1.0, -1.0, 2.0, 2.0]


def test_geoparquet_delaunay_and_crs_option(tmp_path, points_csv):
    assert (
        run(points_csv, "-o", tmp_path / "c.geojson", "--delaunay", tmp_path / "t.parquet", "--crs", "EPSG:3857") == 0
    )
    table = pq.read_table(tmp_path / "t.parquet")
    triangles = shapely.from_wkb(table.column("geometry").to_numpy(zero_copy_only=False))
    assert shapely.is_valid(triangles).all() and len(triangles) > 50
    assert all(len(set(s)) == 3 for s in table.column("sites").to_pylist())
    crs = json.loads(table.schema.metadata[b"geo"])["columns"]["geometry"]["crs"]
    assert crs["id"]["authority"] == "EPSG" and int(crs["id"]["code"]) == 3857


def test_geoparquet_to_stdout(tmp_path, points_csv, capsysbinary):
    assert run(points_csv, "-o", "-", "--to", "parquet") == 0
    assert pq.read_table(io.BytesIO(capsysbinary.readouterr().out)).num_rows == 50


def test_geojson_sequences(tmp_path, points_csv):
    assert run(points_csv, "-o", tmp_path / "c.geojsons", "--delaunay", tmp_path / "t.geojsonl") == 0
    records = (tmp_path / "c.geojsons").read_bytes().split(b"\x1e")
    assert records[0] == b"" and len(records) == 51
    features = [json.loads(r) for r in records[1:]]
    assert all(r.endswith(b"\n") for r in records[1:]) and features[3]["properties"]["duplicates"] == [50]
    lines = (tmp_path / "t.geojsonl").read_text().splitlines()
    assert (
        all(json.loads(line)["type"] == "Feature" for line in lines)
        and b"\x1e" not in (tmp_path / "t.geojsonl").read_bytes()
    )


def test_precision_rounds_coordinates(tmp_path, points_csv):
    assert run(points_csv, "-o", tmp_path / "c.geojson", "--precision", "3") == 0
    doc = json.loads((tmp_path / "c.geojson").read_text())
    coords = np.array([p for f in doc["features"] for p in f["geometry"]["coordinates"][0]])
    np.testing.assert_array_equal(coords, np.round(coords, 3))
    assert len(doc["features"]) == 50


def test_parquet_inputs_plain_and_geo(tmp_path):
    plain = tmp_path / "plain.parquet"
    pq.write_table(
        pa.table(
            {
                "id": [1, 2, 3, 4],
                "Easting": [0.0, 10, 0, 7],
                "Northing": [0.0, 0, 10, 7],
                "zip": ["01000", "02000", None, "04000"],
            }
        ),
        plain,
    )
    assert run(plain, "-o", tmp_path / "a.parquet", "--crs", "EPSG:27700") == 0
    table = pq.read_table(tmp_path / "a.parquet")
    assert table.column("zip").to_pylist() == ["01000", "02000", None, "04000"]
    assert table.column("id").type == pa.int64()
    points = shapely.points([[5e5, 0], [5e5 + 10, 0], [5e5, 10], [5e5 + 7, 7]])
    geo = pa.table({"name": list("abcd"), "geometry": pa.array(shapely.to_wkb(points), pa.binary())})
    crs = {"id": {"authority": "EPSG", "code": 32631}}
    meta = {
        "version": "1.1.0",
        "primary_column": "geometry",
        "columns": {"geometry": {"encoding": "WKB", "geometry_types": ["Point"], "crs": crs}},
    }
    pq.write_table(geo.replace_schema_metadata({b"geo": json.dumps(meta)}), tmp_path / "geo.parquet")
    assert run(tmp_path / "geo.parquet", "-o", tmp_path / "b.parquet") == 0
    out = pq.read_table(tmp_path / "b.parquet")
    assert out.column("name").to_pylist() == list("abcd")
    assert json.loads(out.schema.metadata[b"geo"])["columns"]["geometry"]["crs"] == crs


def test_lonlat_default_box_stays_on_the_globe(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("lon,lat\n170,80\n179.5,85\n175,60\n-179,-89\n")
    assert run(path, "-o", tmp_path / "c.parquet") == 0
    table = pq.read_table(tmp_path / "c.parquet")
    geo = json.loads(table.schema.metadata[b"geo"])["columns"]["geometry"]
    xmin, ymin, xmax, ymax = geo["bbox"]
    assert (xmin, ymin, xmax, ymax) == (-180.0, -90.0, 180.0, 90.0)
    assert geo["crs"]["id"] == {"authority": "OGC", "code": "CRS84"}


@pytest.mark.parametrize(
    ("rows", "culprit", "count"),
    [
        ("-170,10\n170,20\n0,95\n10,-80\n", "line 4: latitude 95 lies beyond", 1),
        ("500,10\n170,20\n0,-95\n10,-80\n", "line 2: longitude 500 lies beyond", 2),
        ("-180,90\n180,-90\n0,0\n", None, 0),  # the edges of the range are on the globe
    ],
)
def test_lonlat_beyond_the_globe_warns_with_the_line(tmp_path, capsys, rows, culprit, count):
    path = tmp_path / "p.csv"
    path.write_text("lon,lat\n" + rows)
    assert cli.main(["batch", str(path), "-o", str(tmp_path / "c.geojson")]) == 0
    err = capsys.readouterr().err
    if culprit is None:
        assert "warning" not in err
    else:
        assert f"p.csv, {culprit} [-180, 180] x [-90, 90]" in err
        assert ("more sites" in err) == (count > 1)
    assert cli.main(["batch", str(path), "-o", str(tmp_path / "q.geojson"), "-q"]) == 0
    assert capsys.readouterr().err == ""


def test_non_wgs84_geojson_input_warns_for_geojson_output(tmp_path, capsys):
    doc = {
        "type": "FeatureCollection",
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::3857"}},
        "features": [
            {"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": c}}
            for c in ([0, 0], [10, 0], [0, 10])
        ],
    }
    path = tmp_path / "p.geojson"
    path.write_text(json.dumps(doc))
    assert cli.main(["batch", str(path), "-o", str(tmp_path / "c.geojson")]) == 0
    assert "EPSG:3857" in capsys.readouterr().err
    assert cli.main(["batch", str(path), "-o", str(tmp_path / "c.parquet")]) == 0
    assert capsys.readouterr().err == ""
    crs = json.loads(pq.read_table(tmp_path / "c.parquet").schema.metadata[b"geo"])["columns"]["geometry"]["crs"]
    assert crs["id"]["code"] in (3857, "3857")


def test_missing_pyarrow_names_the_extra(tmp_path, points_csv, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    monkeypatch.setitem(sys.modules, "pyarrow.parquet", None)
    assert cli.main(["batch", str(points_csv), "-o", str(tmp_path / "c.parquet")]) == 2
    err = capsys.readouterr().err
    assert "tvoronoi[parquet]" in err and err.count("\n") == 1
    assert not (tmp_path / "c.parquet").exists()


def test_unknown_crs_fails_before_the_build(tmp_path, points_csv, capsys):
    pytest.importorskip("pyproj")
    assert cli.main(["batch", str(points_csv), "-o", str(tmp_path / "c.parquet"), "--crs", "EPSG:999999"]) == 2
    assert "EPSG:999999" in capsys.readouterr().err and not (tmp_path / "c.parquet").exists()


def test_crs_code_without_pyproj_names_the_extra(tmp_path, points_csv, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyproj", None)
    assert cli.main(["batch", str(points_csv), "-o", str(tmp_path / "c.parquet"), "--crs", "EPSG:3857"]) == 2
    assert "tvoronoi[parquet]" in capsys.readouterr().err


def test_geopandas_reads_cells_with_crs_types_and_covering(tmp_path):
    gpd = pytest.importorskip("geopandas")
    path = tmp_path / "p.csv"
    path.write_text(
        "name,Easting,Northing,zip\na,500000,100,01000\nb,500100,120,02000\nc,500050,190,\nd,500020,40,04000\n"
    )
    assert run(path, "-o", tmp_path / "c.parquet", "--crs", "EPSG:27700") == 0
    frame = gpd.read_parquet(tmp_path / "c.parquet")
    assert frame.crs.to_epsg() == 27700
    assert frame.geometry.is_valid.all() and len(frame) == 4
    assert frame["zip"].tolist()[:2] == ["01000", "02000"] and frame["zip"].isna().tolist()[2]
    # the default box: 10% of the larger side (150) on every side
    assert frame.total_bounds.tolist() == pytest.approx([500000 - 15, 40 - 15, 500100 + 15, 190 + 15])


@pytest.mark.parametrize("suffix", [".geojsons", ".geojsonl", ".geojson"])
def test_gdal_reads_every_geojson_layout(tmp_path, points_csv, suffix):
    pyogrio = pytest.importorskip("pyogrio")
    out = tmp_path / f"cells{suffix}"
    assert run(points_csv, "-o", out) == 0
    info = pyogrio.read_info(out)
    assert info["driver"] == ("GeoJSON" if suffix == ".geojson" else "GeoJSONSeq")
    assert info["features"] == 50
    frame = pyogrio.read_dataframe(out)
    assert frame["zip"].tolist()[:3] == ["00000", "00001", "00002"]


@settings(max_examples=30, deadline=None)
@given(st.lists(st.integers(3, 9), min_size=1, max_size=30), st.integers(0, 2**32 - 1))
def test_bulk_wkb_is_shapely_wkb(ring_sizes, seed):
    from tvoronoi.writers.geoparquet import _wkb_polygons

    rng = np.random.default_rng(seed)
    rings = [np.vstack([pts, pts[:1]]) for pts in (rng.normal(size=(k, 2)) * 1e3 for k in ring_sizes)]
    offsets = np.concatenate([[0], np.cumsum([len(r) for r in rings])]).astype(np.int64)
    xy = np.vstack(rings)
    ours = _wkb_polygons(pa, xy, offsets).to_pylist()
    polygons = shapely.from_ragged_array(
        shapely.GeometryType.POLYGON, xy, (offsets, np.arange(len(rings) + 1, dtype=np.int64))
    )
    assert ours == list(shapely.to_wkb(polygons, byte_order=1))


def test_parquet_input_binary_and_decimal_columns(tmp_path):
    import decimal

    table = pa.table(
        {
            "x": [0.0, 1, 0],
            "y": [0.0, 0, 1],
            "raw": [b"\x00", b"\x01", b"\x02"],
            "price": pa.array([decimal.Decimal("1.25"), None, decimal.Decimal("3")], pa.decimal128(5, 2)),
        }
    )
    pq.write_table(table, tmp_path / "p.parquet")
    assert run(tmp_path / "p.parquet", "-o", tmp_path / "c.geojson") == 0
    doc = json.loads((tmp_path / "c.geojson").read_text())
    assert [f["properties"] for f in doc["features"]] == [
        {"site": 0, "price": 1.25},
        {"site": 1, "price": None},
        {"site": 2, "price": 3.0},
    ]


def test_geoparquet_row_groups_hold_the_same_rows(tmp_path, monkeypatch):
    """Written a row group at a time (seams with repeated sites and a cell that misses the box),
    the file reads back as the one-group file does, and its geometries are the cells'."""
    pq = pytest.importorskip("pyarrow.parquet")
    import tvoronoi
    from tvoronoi.readers import PointSet
    from tvoronoi.writers import geoparquet

    base = DATASETS["clustered"][:40]
    sites = np.concatenate([base, base[[5, 6, 7]], [[1e6, 1e6]]])
    box = (base.min() - 1, base.min() - 1, base.max() + 1, base.max() + 1)
    d = tvoronoi.voronoi(sites, bbox=box)
    points = PointSet(sites, "t.csv", {"name": [f"s{i}" for i in range(len(sites))]})
    geoparquet.write_cells_parquet(d, points, str(tmp_path / "one.parquet"))
    monkeypatch.setattr(geoparquet, "ROW_GROUP", 6)
    geoparquet.write_cells_parquet(d, points, str(tmp_path / "many.parquet"))
    one, many = pq.read_table(tmp_path / "one.parquet"), pq.read_table(tmp_path / "many.parquet")
    assert pq.ParquetFile(tmp_path / "many.parquet").num_row_groups == -(-len(one) // 6) > 1
    assert many.equals(one) and many.schema.metadata == one.schema.metadata
    polygons = shapely.from_wkb(many["geometry"].to_numpy(zero_copy_only=False))
    sites_kept = many["site"].to_pylist()
    assert sites_kept == list(range(40)) + [len(sites) - 1]
    assert polygons[-1] is None
    expected = d.to_shapely()[sites_kept[:-1]]
    assert all(shapely.equals_exact(p, q, 0.0) for p, q in zip(polygons[:-1], expected))
    assert many["duplicates"].to_pylist()[5:8] == [[40], [41], [42]]
    geo = json.loads(many.schema.metadata[b"geo"])
    assert geo["columns"]["geometry"]["bbox"] == list(shapely.total_bounds(polygons))


def test_a_part_written_from_its_diagram_equals_the_part_of_its_shapely_cells(tmp_path, monkeypatch):
    """A distributed task's part written straight from its diagram, a row group at a time (some rows
    only, repeated sites and a cell that misses the box among them), reads back as the part of the
    same rows' shapely cells: the same WKB bytes, bbox, properties and geo metadata."""
    pq = pytest.importorskip("pyarrow.parquet")
    import pandas as pd

    import tvoronoi
    from tvoronoi.writers import geoparquet
    from tvoronoi.writers.parts import write_cells_part, write_part

    base = DATASETS["clustered"][:60]
    sites = np.concatenate([base, base[[5, 6, 7]], [[1e6, 1e6]]])
    box = (base.min() - 1, base.min() - 1, base.max() + 1, base.max() + 1)
    d = tvoronoi.voronoi(sites, bbox=box)
    rows = np.concatenate([np.arange(0, 60, 3), np.arange(60, len(sites))])
    frame = pd.DataFrame({"site": rows + 1000, "name": [f"s{i}" for i in rows]})
    monkeypatch.setattr(geoparquet, "ROW_GROUP", 5)
    direct = write_cells_part(frame, d, rows, tmp_path, "part-direct", "EPSG:3857")
    shapes = write_part(frame, d.to_shapely()[rows], tmp_path, "part-shapes", "parquet", "EPSG:3857")
    got, want = pq.read_table(tmp_path / direct), pq.read_table(tmp_path / shapes)
    assert pq.ParquetFile(tmp_path / direct).num_row_groups == -(-len(rows) // 5)
    assert got.equals(want) and got.schema.metadata == want.schema.metadata
    wkb = got["geometry"].to_pylist()
    assert wkb[-4:] == [None] * 4  # the repeats and the cell outside the box
    assert wkb[:-4] == list(shapely.to_wkb(d.to_shapely()[rows[:-4]]))
    assert write_cells_part(frame[:0], d, rows[:0], tmp_path, "part-empty") == ""


@pytest.mark.parametrize("name", ["cells.gpkg", "cells.shp", "cells.csv", "CELLS.KML"])
def test_an_output_named_for_a_format_not_written_is_refused(tmp_path, points_csv, capsys, name):
    assert run(points_csv, "-o", tmp_path / name) == 2
    err = capsys.readouterr().err
    assert name in err and "does not write" in err and "--to" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == [points_csv.name]  # nothing written


@pytest.mark.parametrize(
    ("cells", "triangles", "to", "refused"),
    [
        ("c.geojson", "t.parquet", "geojsonl", "t.parquet"),  # text into a .parquet file
        ("c.geojson", None, "parquet", "c.geojson"),  # Parquet into a GeoJSON name
        ("c.json", None, "geojsonl", None),  # within the GeoJSON family, --to decides
        ("c.dat", "t.parquet", "parquet", None),
        ("c.csv", None, "geojson", None),  # --to says what a foreign name holds
    ],
)
def test_to_against_the_extension(tmp_path, points_csv, capsys, cells, triangles, to, refused):
    args = [points_csv, "-o", tmp_path / cells, "--to", to]
    if triangles:
        args += ["--delaunay", tmp_path / triangles]
    status = run(*args)
    err = capsys.readouterr().err
    if refused:
        assert status == 2 and f"{refused}: --to {to}" in err
        assert sorted(p.name for p in tmp_path.iterdir()) == [points_csv.name]
    else:
        assert status == 0, err
        head = (tmp_path / cells).read_bytes()[:4]
        assert (head == b"PAR1") == (to == "parquet")


def _features(path) -> list[dict]:
    return [f["properties"] for f in json.loads(path.read_text())["features"]]


def test_geoparquet_keeps_null_list_and_struct_columns(tmp_path):
    """Property columns Arrow cannot count the distinct values of (all null, lists, structs, maps)
    are written with their own types, and read back as the GeoJSON output writes them."""
    (tmp_path / "empty.csv").write_text("x,y,note\n0,0,\n1,0,\n0,1,\n1,1,\n")
    features = [
        {"tags": ["a", "b"], "meta": {"k": 1, "ok": True}},
        {"tags": ["a"], "meta": {"k": 2, "ok": False}},
        {"tags": None, "meta": None},
        {"tags": [], "meta": {"k": 3, "ok": None}},
    ]
    doc = {
        "type": "FeatureCollection",
        "features": [
            {"type": "Feature", "geometry": {"type": "Point", "coordinates": xy}, "properties": p}
            for xy, p in zip([[0, 0], [1, 0], [0, 1], [1, 1]], features)
        ],
    }
    (tmp_path / "nested.geojson").write_text(json.dumps(doc))
    table = pa.table(
        {
            "x": [0.0, 1, 0, 1],
            "y": [0.0, 0, 1, 1],
            "ids": pa.array([[1, 2], [3], None, []], pa.list_(pa.int64())),
            "none": pa.nulls(4),
        }
    )
    pq.write_table(table, tmp_path / "lists.parquet")
    expected_types = {
        "empty.csv": {"note": pa.null()},
        "nested.geojson": {
            "tags": pa.list_(pa.string()),
            "meta": pa.struct([("k", pa.int64()), ("ok", pa.bool_())]),
        },
        "lists.parquet": {"ids": pa.list_(pa.int64()), "none": pa.null()},
    }
    for name, types in expected_types.items():
        stem = name.split(".")[0]
        assert run(tmp_path / name, "-o", tmp_path / f"{stem}.out.parquet") == 0, name
        assert run(tmp_path / name, "-o", tmp_path / f"{stem}.out.geojson") == 0, name
        got = pq.read_table(tmp_path / f"{stem}.out.parquet")
        for column, kind in types.items():
            assert got.schema.field(column).type.equals(kind, check_metadata=False), (name, column)
        rows = got.drop_columns(["geometry", "bbox", "duplicates"]).to_pylist()
        assert rows == _features(tmp_path / f"{stem}.out.geojson"), name


def test_parts_keep_null_list_struct_and_dictionary_columns(tmp_path):
    """A distributed task's GeoParquet parts (from its diagram, or from shapely cells) take the
    columns pandas hands to Arrow as null, list, struct and dictionary arrays."""
    pd = pytest.importorskip("pandas")
    import tvoronoi
    from tvoronoi.writers.parts import write_cells_part, write_part

    d = tvoronoi.voronoi(np.array([[0.0, 0], [1, 0], [0, 1], [1, 1]]), bbox=(-1, -1, 2, 2))
    rows = np.arange(4)
    frame = pd.DataFrame(
        {
            "site": rows,
            "none": [None] * 4,
            "ids": [[1, 2], [3], None, []],
            "meta": [{"k": 1}, {"k": 2}, None, {"k": 3}],
            "kind": pd.Categorical(["a", "b", "a", None]),
        }
    )
    direct = write_cells_part(frame, d, rows, tmp_path, "part-direct")
    shapes = write_part(frame, d.to_shapely(), tmp_path, "part-shapes", "parquet")
    for name in (direct, shapes):
        got = pq.read_table(tmp_path / name).drop_columns(["geometry", "bbox"])
        assert got.schema.field("none").type == pa.null()
        assert got.to_pydict() == {
            "site": [0, 1, 2, 3],
            "none": [None] * 4,
            "ids": [[1, 2], [3], None, []],
            "meta": [{"k": 1}, {"k": 2}, None, {"k": 3}],
            "kind": ["a", "b", "a", None],
        }


def test_a_property_of_mixed_types_is_text_that_agrees_with_geojson(tmp_path):
    """A GeoJSON property whose values mix types is a GeoParquet string column: each string as it
    is ("01" stays "01", not '"01"'), each other value the JSON text the GeoJSON output holds."""
    import orjson

    values = [1, "01", 2.5, None, [1, "x"], {"k": 'say "hi"'}, True, 'a "quoted", word']
    doc = {
        "type": "FeatureCollection",
        "features": [
            {"type": "Feature", "geometry": {"type": "Point", "coordinates": [i % 3, i // 3]}, "properties": {"a": v}}
            for i, v in enumerate(values)
        ],
    }
    (tmp_path / "mixed.geojson").write_text(json.dumps(doc))
    assert run(tmp_path / "mixed.geojson", "-o", tmp_path / "c.parquet") == 0
    assert run(tmp_path / "mixed.geojson", "-o", tmp_path / "c.geojson") == 0
    column = pq.read_table(tmp_path / "c.parquet")["a"]
    assert column.type == pa.string()
    assert column.to_pylist()[:4] == ["1", "01", "2.5", None]
    written = [p["a"] for p in _features(tmp_path / "c.geojson")]
    assert written == values
    assert column.to_pylist() == [v if v is None or isinstance(v, str) else orjson.dumps(v).decode() for v in written]


def test_crs_option_over_the_file_s_own_crs_warns(tmp_path, capsys):
    doc = {
        "type": "FeatureCollection",
        "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::3035"}},
        "features": [
            {"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": c}}
            for c in ([0, 0], [10, 0], [0, 10])
        ],
    }
    path = tmp_path / "p.geojson"
    path.write_text(json.dumps(doc))
    out = tmp_path / "c.parquet"
    assert cli.main(["batch", str(path), "-o", str(out), "--crs", "EPSG:3857"]) == 0
    err = capsys.readouterr().err
    assert "--crs EPSG:3857 replaces" in err and "EPSG:3035" in err and "not transformed" in err
    crs = json.loads(pq.read_table(out).schema.metadata[b"geo"])["columns"]["geometry"]["crs"]
    assert crs["id"]["code"] in (3857, "3857")
    # the same CRS given again: nothing to say
    assert cli.main(["batch", str(path), "-o", str(tmp_path / "d.parquet"), "--crs", "EPSG:3035"]) == 0
    assert "replaces" not in capsys.readouterr().err


@pytest.mark.parametrize(("suffix", "separator"), [(".geojsonl", b""), (".geojsons", b"\x1e"), (".json", b"")])
def test_geojson_sequences_are_read(tmp_path, capsys, suffix, separator):
    """Point features one a line (GDAL's GeoJSONSeq, jq's output) or after RS (RFC 8142), by extension
    or found in a .json file: the same sites and properties as the FeatureCollection."""
    sites = DATASETS["uniform"][:40]
    features = [
        {"type": "Feature", "properties": {"k": i}, "geometry": {"type": "Point", "coordinates": [x, y]}}
        for i, (x, y) in enumerate(sites.tolist())
    ]
    path = tmp_path / f"p{suffix}"
    path.write_bytes(b"".join(separator + json.dumps(f).encode() + b"\n" for f in features))
    whole = tmp_path / "whole.geojson"
    whole.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    assert cli.main(["batch", str(path), "-o", str(tmp_path / "a.geojson"), "-q"]) == 0
    assert cli.main(["batch", str(whole), "-o", str(tmp_path / "b.geojson"), "-q"]) == 0
    assert (tmp_path / "a.geojson").read_bytes() == (tmp_path / "b.geojson").read_bytes()


def test_a_broken_line_of_a_geojson_sequence_is_named(tmp_path, capsys):
    path = tmp_path / "p.geojsonl"
    good = json.dumps({"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [0, 1]}})
    path.write_text(f"{good}\n{good}\n{{broken\n")
    assert cli.main(["batch", str(path), "-o", str(tmp_path / "c.geojson")]) == 2
    assert "p.geojsonl, line 3: broken JSON" in capsys.readouterr().err
