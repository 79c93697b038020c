"""Point files in: every format, the column choices, and every bad input named precisely."""

from __future__ import annotations

import csv
import io
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tvoronoi import readers
from tvoronoi.errors import InputFileError, TvoronoiError
from tvoronoi.readers import PointSet, read_points
from tvoronoi.readers.text_column import TextColumn


def write(tmp_path: Path, name: str, content: str | bytes) -> str:
    """Write ``content`` to ``tmp_path / name`` and return the path as a str."""
    path = tmp_path / name
    if isinstance(content, str):
        path.write_text(content, encoding="utf-8", newline="")
    else:
        path.write_bytes(content)
    return str(path)


def read(tmp_path: Path, name: str, content: str | bytes, **kwargs) -> PointSet:
    return read_points(write(tmp_path, name, content), **kwargs)


def error(tmp_path: Path, name: str, content: str | bytes, **kwargs) -> str:
    """The message of the InputFileError that reading ``content`` raises."""
    with pytest.raises(InputFileError) as info:
        read(tmp_path, name, content, **kwargs)
    return str(info.value)


class FakeStdin:
    def __init__(self, data: bytes):
        self.buffer = io.BytesIO(data)


def npy_bytes(array: np.ndarray) -> bytes:
    out = io.BytesIO()
    np.save(out, array, allow_pickle=True)
    return out.getvalue()


def feature(geometry, properties=None) -> dict:
    return {"type": "Feature", "geometry": geometry, "properties": properties}


def collection(*features) -> str:
    return json.dumps({"type": "FeatureCollection", "features": list(features)})


# ---------------------------------------------------------------------------
# CSV


def test_csv_with_header_reads_exact_values(tmp_path):
    points = read(tmp_path, "p.csv", "x,y\n0.1,0.2\n3,-4.5e-3\n1e9,7\n")
    assert points.xy.dtype == np.float64 and points.xy.flags.c_contiguous
    np.testing.assert_array_equal(points.xy, [[0.1, 0.2], [3.0, -4.5e-3], [1e9, 7.0]])
    assert points.source.endswith("p.csv")
    assert points.properties(0) == {} and points.property_names == []
    assert len(points) == 3


def test_csv_source_is_the_name_as_given(tmp_path, monkeypatch):
    write(tmp_path, "p.csv", "x,y\n1,2\n")
    monkeypatch.chdir(tmp_path)
    assert read_points("p.csv").source == "p.csv"
    assert read_points(Path("p.csv")).source == "p.csv"


@pytest.mark.parametrize(
    "header, expected",
    [
        ("X,Y", [[1, 2], [3, 4]]),
        ("Lon,Lat", [[1, 2], [3, 4]]),
        ("LATITUDE,longitude", [[2, 1], [4, 3]]),
        ("lat,lng", [[2, 1], [4, 3]]),
        ("y,x", [[2, 1], [4, 3]]),
        ("Long,Latitude", [[1, 2], [3, 4]]),
    ],
)
def test_csv_columns_found_by_name_in_any_case(tmp_path, header, expected):
    points = read(tmp_path, "p.csv", f"{header}\n1,2\n3,4\n")
    np.testing.assert_array_equal(points.xy, expected)
    assert points.property_names == []


def test_csv_exact_x_y_win_over_lon_lat(tmp_path):
    points = read(tmp_path, "p.csv", "lon,lat,x,y\n10,20,1,2\n")
    np.testing.assert_array_equal(points.xy, [[1, 2]])
    assert points.properties(0) == {"lon": 10, "lat": 20}


def test_csv_header_without_coordinate_names_uses_first_two_numeric_columns(tmp_path):
    points = read(tmp_path, "p.csv", "name,east,north,h\na,1.5,2.5,9\nb,3.5,4.5,8\n")
    np.testing.assert_array_equal(points.xy, [[1.5, 2.5], [3.5, 4.5]])
    assert points.properties(1) == {"name": "b", "h": 8}


def test_csv_without_header(tmp_path):
    points = read(tmp_path, "p.csv", "1,2,7,a\n3,4,8.5,\n")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    assert points.property_names == ["col3", "col4"]
    assert points.properties(0) == {"col3": 7, "col4": "a"}
    assert points.properties(1) == {"col3": 8.5, "col4": None}


def test_csv_without_header_skips_a_leading_text_column(tmp_path):
    points = read(tmp_path, "p.csv", "a,1,2\nb,3,4\n")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    assert [points.properties(i) for i in range(2)] == [{"col1": "a"}, {"col1": "b"}]


@pytest.mark.parametrize(
    "x, y",
    [("East", "NORTH"), (1, 2), ("1", "2"), ("col2", "col3"), ("east", 2)],
)
def test_csv_x_y_chosen_by_name_or_index(tmp_path, x, y):
    points = read(tmp_path, "p.csv", "id,east,north\n1,10,20\n2,30,40\n", x=x, y=y)
    np.testing.assert_array_equal(points.xy, [[10, 20], [30, 40]])
    assert points.properties(1) == {"id": 2}


def test_csv_x_y_chosen_override_names(tmp_path):
    points = read(tmp_path, "p.csv", "x,y,u,v\n1,2,3,4\n", x="v", y="u")
    np.testing.assert_array_equal(points.xy, [[4, 3]])
    assert points.properties(0) == {"x": 1, "y": 2}


def test_csv_x_y_by_index_without_header(tmp_path):
    points = read(tmp_path, "p.csv", "5,1,2\n6,3,4\n", x=2, y=1)
    np.testing.assert_array_equal(points.xy, [[2, 1], [4, 3]])
    assert points.properties(0) == {"col1": 5}


@pytest.mark.parametrize(
    "content, n_sites, names",
    [
        ("1,2,lat\n3,4,lon\n", 2, ["col3"]),  # a coordinate name as a value
        ("a,b\n1,2\n", 1, []),  # names that are not coordinate names
        ("x,y,2019,2020\n1,2,7,8\n", 1, ["2019", "2020"]),  # a header with numeric names
        ("1,2\n3,4\n", 2, []),
        ("lon,lat\n", None, None),  # only a header
    ],
)
def test_header_detection(tmp_path, content, n_sites, names):
    if n_sites is None:
        assert "no points found" in error(tmp_path, "p.csv", content)
        return
    points = read(tmp_path, "p.csv", content)
    assert len(points) == n_sites and points.property_names == names


def test_header_detected_by_a_chosen_column(tmp_path):
    points = read(tmp_path, "p.csv", "1,2,u\n3,4,5\n", y="u")
    np.testing.assert_array_equal(points.xy, [[3, 5]])
    points = read(tmp_path, "q.csv", "1,2,a\n3,4,5\n", x=0, y=2)
    np.testing.assert_array_equal(points.xy, [[3, 5]])


def test_csv_only_one_column_named_takes_the_next_numeric_for_the_other(tmp_path):
    points = read(tmp_path, "p.csv", "x,north\n1,2\n")
    np.testing.assert_array_equal(points.xy, [[1, 2]])


def test_csv_quoted_fields_with_commas(tmp_path):
    content = 'x,y,name,note\n1,2,"Smith, J","said ""hi"""\n"3.5","4",plain,"a,b,c"\n'
    points = read(tmp_path, "p.csv", content)
    np.testing.assert_array_equal(points.xy, [[1, 2], [3.5, 4]])
    assert points.properties(0) == {"name": "Smith, J", "note": 'said "hi"'}
    assert points.properties(1) == {"name": "plain", "note": "a,b,c"}


def test_csv_two_quoted_columns(tmp_path):
    points = read(tmp_path, "p.csv", 'x,y\n"1","2"\n"3",4\n')
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])


def test_csv_extra_columns_are_typed_per_column(tmp_path):
    content = (
        "x,y,i,f,mixed,s,e,big,nan\n"
        "0,0,1,1.5,1,abc,,123456789012345678901234567890,nan\n"
        "1,1,-2,2,2.5,x y,,1,inf\n"
        "2,2,+3,-1e3,hello, ,,2,3\n"
    )
    points = read(tmp_path, "p.csv", content)
    # a column with a word is text throughout; a number column with a non-integer is float throughout
    assert points.properties(0) == {
        "i": 1,
        "f": 1.5,
        "mixed": "1",
        "s": "abc",
        "e": None,
        "big": "123456789012345678901234567890",
        "nan": None,
    }
    row1 = points.properties(1)
    assert row1["i"] == -2 and type(row1["i"]) is int
    assert row1["f"] == 2 and type(row1["f"]) is float
    assert row1["mixed"] == "2.5" and row1["s"] == "x y" and row1["nan"] is None
    row2 = points.properties(2)
    # a blank (whitespace-only) field is empty too
    assert row2 == {"i": 3, "f": -1000.0, "mixed": "hello", "s": None, "e": None, "big": "2", "nan": 3.0}
    assert type(row2["f"]) is float and type(row2["nan"]) is float


def test_csv_int_column_stays_int_and_float_column_is_float(tmp_path):
    points = read(tmp_path, "p.csv", "x,y,a,b\n0,0,7,0.5\n1,1,8,2\n2,2,9,1e-3\n")
    a = [points.properties(i)["a"] for i in range(3)]
    b = [points.properties(i)["b"] for i in range(3)]
    assert a == [7, 8, 9] and all(type(v) is int for v in a)
    assert b == [0.5, 2.0, 0.001] and all(type(v) is float for v in b)


def test_csv_properties_are_json_ready(tmp_path):
    points = read(tmp_path, "p.csv", "x,y,a,b,c\n0,0,nan,1e999,\n1,1,2,x,7\n")
    text = json.dumps([points.properties(i) for i in range(2)], allow_nan=False)
    assert json.loads(text) == [{"a": None, "b": "1e999", "c": None}, {"a": 2.0, "b": "x", "c": 7}]


def test_csv_blank_lines_crlf_bom_and_spaces(tmp_path):
    content = "\ufeff\r\n x , y ,label\r\n\r\n1, 2,a\r\n   \r\n3 ,4, b\r\n\r\n"
    points = read(tmp_path, "p.csv", content)
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    assert points.properties(1) == {"label": " b"}


def test_csv_two_columns_with_blank_and_whitespace_lines(tmp_path):
    points = read(tmp_path, "p.csv", "x,y\n\n1,2\n  \n3,4\n\n")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])


def test_csv_duplicate_and_empty_header_names(tmp_path):
    points = read(tmp_path, "p.csv", "x,y,a,a,\n1,2,3,4,5\n")
    assert points.properties(0) == {"a": 3, "a_2": 4, "col5": 5}


def test_csv_old_mac_line_endings(tmp_path):
    points = read(tmp_path, "p.csv", "x,y\r1,2\r3,4\r")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])


def test_csv_utf16_with_bom(tmp_path):
    data = "x,y,name\n1,2,Zürich\n".encode("utf-16")
    points = read(tmp_path, "p.csv", data)
    np.testing.assert_array_equal(points.xy, [[1, 2]])
    assert points.properties(0) == {"name": "Zürich"}


def test_csv_large_table_matches_what_was_written(tmp_path):
    rng = np.random.default_rng(5)
    xy = rng.normal(size=(5000, 2)) * 1e3
    lines = ["id,x,y,tag"] + [f"{i},{a!r},{b!r},t{i % 7}" for i, (a, b) in enumerate(xy.tolist())]
    points = read(tmp_path, "p.csv", "\n".join(lines) + "\n")
    np.testing.assert_array_equal(points.xy, xy)
    assert points.columns["id"] == list(range(5000))
    assert points.properties(4999) == {"id": 4999, "tag": f"t{4999 % 7}"}


def test_csv_data_far_below_the_header(tmp_path):
    # the first data row lies beyond the stretch read to find the header
    gap = "\n" * 70_000
    points = read(tmp_path, "p.csv", "x,y,a\n" + gap + "1,2,3\n4,5,6\n")
    np.testing.assert_array_equal(points.xy, [[1, 2], [4, 5]])
    assert points.columns == {"a": [3, 6]}
    message = error(tmp_path, "q.csv", "x,y\n" + gap + "1,2\n3,abc\n")
    assert 'q.csv, line 70003: "abc" in column "y" is not a number' in message


# ---------------------------------------------------------------------------
# whitespace text


def test_text_rows_comments_and_blank_lines(tmp_path):
    content = "# sites\n1 2\n\n  3\t4   # inline comment\n# 9 9\n5.5 -6e2\n"
    points = read(tmp_path, "p.txt", content)
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4], [5.5, -600]])
    assert points.property_names == []


def test_text_line_endings(tmp_path):
    points = read(tmp_path, "a.txt", "1 2 a\r\n3 4 b\r\n")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    assert points.columns == {"col3": ["a", "b"]}
    points = read(tmp_path, "b.txt", "1 2 a\r3 4 b\r")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    # a lone CR ends a line: the second row has two fields, not four
    assert "c.txt, line 2: 2 fields" in error(tmp_path, "c.txt", "1 2 3 4\n5 6\r7 8\n")


@pytest.mark.parametrize("suffix", [".xy", ".dat", ".pts", ".TXT"])
def test_text_extensions(tmp_path, suffix):
    points = read(tmp_path, "p" + suffix, "1 2\n3 4\n")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])


def test_text_extra_columns(tmp_path):
    points = read(tmp_path, "p.txt", "1 2 a 7\n3 4 b 8.5  # c\n")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    assert points.properties(0) == {"col3": "a", "col4": 7}
    assert points.properties(1) == {"col3": "b", "col4": 8.5}


def test_text_with_header_and_chosen_columns(tmp_path):
    points = read(tmp_path, "p.txt", "id lat lon\n1 10 20\n2 30 40\n")
    np.testing.assert_array_equal(points.xy, [[20, 10], [40, 30]])
    assert points.properties(0) == {"id": 1}
    points = read(tmp_path, "q.txt", "1 10 20\n2 30 40\n", x="col1", y=2)
    np.testing.assert_array_equal(points.xy, [[1, 20], [2, 40]])
    assert points.properties(1) == {"col2": 30}


def test_text_large_file_with_and_without_extras(tmp_path):
    rng = np.random.default_rng(2)
    xy = rng.random((3000, 2))
    plain = "\n".join(f"{a!r} {b!r}" for a, b in xy.tolist())
    np.testing.assert_array_equal(read(tmp_path, "a.txt", plain).xy, xy)
    extra = "\n".join(f"{a!r} {b!r} {i}" for i, (a, b) in enumerate(xy.tolist()))
    points = read(tmp_path, "b.txt", extra)
    np.testing.assert_array_equal(points.xy, xy)
    assert points.columns["col3"] == list(range(3000))


# ---------------------------------------------------------------------------
# GeoJSON


def test_geojson_points_and_properties(tmp_path):
    content = collection(
        feature({"type": "Point", "coordinates": [1.5, 2.5]}, {"name": "a", "n": 1, "tags": [1, 2]}),
        feature({"type": "Point", "coordinates": [3, 4, 100]}, None),
    )
    points = read(tmp_path, "p.geojson", content)
    np.testing.assert_array_equal(points.xy, [[1.5, 2.5], [3, 4]])
    assert points.properties(0) == {"name": "a", "n": 1, "tags": [1, 2]}
    assert points.properties(1) == {}
    assert points.property_names == ["name", "n", "tags"]


def test_geojson_properties_are_copies(tmp_path):
    content = collection(feature({"type": "Point", "coordinates": [1, 2]}, {"a": 1}))
    points = read(tmp_path, "p.geojson", content)
    points.properties(0)["a"] = 99
    assert points.properties(0) == {"a": 1}


def test_geojson_multipoint_gives_one_site_per_point(tmp_path):
    content = collection(
        feature({"type": "Point", "coordinates": [0, 0]}, {"k": "p"}),
        feature({"type": "MultiPoint", "coordinates": [[1, 1], [2, 2], [3, 3]]}, {"k": "m"}),
        feature({"type": "MultiPoint", "coordinates": []}, {"k": "empty"}),
    )
    points = read(tmp_path, "p.json", content)
    np.testing.assert_array_equal(points.xy, [[0, 0], [1, 1], [2, 2], [3, 3]])
    assert [points.properties(i) for i in range(4)] == [
        {"k": "p"},
        {"k": "m", "part": 0},
        {"k": "m", "part": 1},
        {"k": "m", "part": 2},
    ]


def test_geojson_single_feature_and_bare_geometries(tmp_path):
    one = json.dumps(feature({"type": "Point", "coordinates": [5, 6]}, {"a": 1}))
    points = read(tmp_path, "a.geojson", one)
    np.testing.assert_array_equal(points.xy, [[5, 6]])
    assert points.properties(0) == {"a": 1}
    bare = json.dumps({"type": "Point", "coordinates": [7, 8]})
    np.testing.assert_array_equal(read(tmp_path, "b.geojson", bare).xy, [[7, 8]])
    multi = json.dumps({"type": "MultiPoint", "coordinates": [[1, 2], [3, 4]]})
    points = read(tmp_path, "c.geojson", multi)
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    assert points.properties(1) == {"part": 1}


# ---------------------------------------------------------------------------
# .npy


def test_npy_float_and_int_arrays(tmp_path):
    xy = np.array([[0.5, 1.5], [2.5, 3.5]])
    points = read(tmp_path, "p.npy", npy_bytes(xy))
    np.testing.assert_array_equal(points.xy, xy)
    assert points.property_names == []
    ints = read(tmp_path, "q.npy", npy_bytes(np.array([[1, 2], [3, 4]], dtype=np.int32)))
    assert ints.xy.dtype == np.float64 and ints.xy.flags.c_contiguous
    np.testing.assert_array_equal(ints.xy, [[1, 2], [3, 4]])


def test_npy_fortran_order_is_made_c_contiguous(tmp_path):
    xy = np.asfortranarray(np.arange(10.0).reshape(5, 2))
    points = read(tmp_path, "p.npy", npy_bytes(xy))
    assert points.xy.flags.c_contiguous
    np.testing.assert_array_equal(points.xy, xy)


def test_npy_extra_columns_and_choice(tmp_path):
    array = np.array([[1.0, 2.0, 7.0, np.nan], [3.0, 4.0, 8.0, 0.5]])
    points = read(tmp_path, "p.npy", npy_bytes(array))
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    assert points.properties(0) == {"col3": 7.0, "col4": None}
    assert points.properties(1) == {"col3": 8.0, "col4": 0.5}
    chosen = read(tmp_path, "q.npy", npy_bytes(array), x=2, y="col1")
    np.testing.assert_array_equal(chosen.xy, [[7, 1], [8, 3]])
    assert chosen.property_names == ["col2", "col4"]


def test_npy_structured_array(tmp_path):
    dtype = [("id", "i4"), ("Lat", "f8"), ("Lon", "f4"), ("name", "U8"), ("code", "S3")]
    array = np.array([(1, 10.0, 20.0, "a", b"xy"), (2, 30.0, 40.0, "b", b"z")], dtype=dtype)
    points = read(tmp_path, "p.npy", npy_bytes(array))
    np.testing.assert_array_equal(points.xy, [[20, 10], [40, 30]])
    assert points.properties(0) == {"id": 1, "name": "a", "code": "xy"}
    chosen = read(tmp_path, "q.npy", npy_bytes(array), x="id", y="lon")
    np.testing.assert_array_equal(chosen.xy, [[1, 20], [2, 40]])


def test_npy_structured_without_names_takes_first_numeric_fields(tmp_path):
    array = np.array([("a", 1.0, 2.0)], dtype=[("s", "U2"), ("e", "f8"), ("n", "f8")])
    points = read(tmp_path, "p.npy", npy_bytes(array))
    np.testing.assert_array_equal(points.xy, [[1, 2]])
    assert points.properties(0) == {"s": "a"}


# ---------------------------------------------------------------------------
# standard input and format detection


@pytest.mark.parametrize(
    "data, expected",
    [
        (b"x,y\n1,2\n3,4\n", [[1, 2], [3, 4]]),
        (b"# comment, with a comma\n1 2\n3 4\n", [[1, 2], [3, 4]]),
        (b"\n\n  1,2\n", [[1, 2]]),
        (b"  " + collection(feature({"type": "Point", "coordinates": [1, 2]})).encode(), [[1, 2]]),
        (npy_bytes(np.array([[1.0, 2.0]])), [[1, 2]]),
    ],
)
def test_stdin_detects_the_format(monkeypatch, data, expected):
    monkeypatch.setattr(sys, "stdin", FakeStdin(data))
    points = read_points("-")
    assert points.source == "<stdin>"
    np.testing.assert_array_equal(points.xy, expected)


def test_stdin_with_explicit_format(monkeypatch):
    monkeypatch.setattr(sys, "stdin", FakeStdin(b"1,2\n3,4\n"))
    # as text, "1,2" is one field that is not a number: line 1 reads as a header
    with pytest.raises(InputFileError, match=r"<stdin>, line 2: cannot find the x and y columns"):
        read_points("-", fmt="text")
    monkeypatch.setattr(sys, "stdin", FakeStdin(b"1,2\n3,4\n"))
    np.testing.assert_array_equal(read_points("-", fmt="csv").xy, [[1, 2], [3, 4]])


@pytest.mark.parametrize(
    "name, content, fmt, expected",
    [
        ("p.in", "1,2\n", None, [[1, 2]]),
        ("p.in", "1 2\n", None, [[1, 2]]),
        ("p", '{"type": "Point", "coordinates": [1, 2]}', None, [[1, 2]]),
        ("p.txt", "x,y\n1,2\n", "csv", [[1, 2]]),
        ("p.csv", "1 2\n", "text", [[1, 2]]),
    ],
)
def test_format_detection_and_override(tmp_path, name, content, fmt, expected):
    np.testing.assert_array_equal(read(tmp_path, name, content, fmt=fmt).xy, expected)


def test_npy_detected_by_content(tmp_path):
    points = read(tmp_path, "points.bin", npy_bytes(np.array([[1.0, 2.0]])))
    np.testing.assert_array_equal(points.xy, [[1, 2]])


def test_properties_index_range(tmp_path):
    points = read(tmp_path, "p.csv", "x,y,a\n1,2,3\n4,5,6\n")
    assert points.properties(-1) == {"a": 6}
    with pytest.raises(IndexError, match="site 2 out of range for 2 sites"):
        points.properties(2)


# ---------------------------------------------------------------------------
# the fast bulk path and the slow line-by-line path agree


CELL_TEXT = st.text(alphabet="abcXY01-.e ", min_size=1, max_size=6).filter(
    # a coordinate name as a value of the first row makes it a header (see test_header_detection)
    lambda s: s.strip() and s.strip().lower() not in readers.X_NAMES + readers.Y_NAMES
)
FLOATS = st.floats(allow_nan=False, allow_infinity=False, width=64)
CELLS = st.one_of(
    st.integers(-(10**20), 10**20).map(str),
    FLOATS.map(repr),
    CELL_TEXT,
    st.sampled_from(["", "nan", "inf", "1_000", "007", "+5", "1e5", ".5", "5."]),
)


@settings(max_examples=150, deadline=None)
@given(
    kind=st.sampled_from(["csv", "text"]),
    header=st.booleans(),
    xy=st.lists(st.tuples(FLOATS, FLOATS), min_size=1, max_size=12),
    n_extra=st.integers(0, 3),
    data=st.data(),
)
def test_fast_and_slow_paths_agree(kind, header, xy, n_extra, data):
    extras = [[data.draw(CELLS) for _ in range(n_extra)] for _ in xy]
    if kind == "text":
        # text fields cannot be empty or hold spaces
        extras = [[c.replace(" ", "_") or "-" for c in row] for row in extras]
    rows = [[repr(a), repr(b), *row] for (a, b), row in zip(xy, extras)]
    names = ["x", "y"] + [f"e{j}" for j in range(n_extra)]
    if kind == "csv":
        out = io.StringIO()
        csv.writer(out, lineterminator="\n").writerows(([names] if header else []) + rows)
        text = out.getvalue()
    else:
        text = "\n".join(" ".join(r) for r in ([names] if header else []) + rows) + "\n"
    layout = readers.table_layout(text, "t", kind, None, None)
    slow = readers.slow_table(text, "t", kind, layout)
    np.testing.assert_array_equal(slow.xy, np.array(xy, dtype=np.float64).reshape(-1, 2))
    body = text[readers.line_offset(text, layout.header_lines) :]
    fast = readers.fast_table(body, kind, layout)
    assert fast is not None
    np.testing.assert_array_equal(fast[0], slow.xy)
    assert fast[1] == slow.columns
    # the public entry gives the same
    points = readers.read_table(text, "t", kind, None, None)
    np.testing.assert_array_equal(points.xy, slow.xy)
    assert points.columns == slow.columns
    for column in slow.columns.values():
        for value in column:
            assert value is None or type(value) in (int, float, str)
            assert not (type(value) is float and not math.isfinite(value))


@settings(max_examples=100, deadline=None)
@given(
    xy=st.lists(st.tuples(FLOATS, FLOATS), min_size=1, max_size=12),
    n_extra=st.integers(0, 3),
    delimiter=st.sampled_from([",", ";", "\t"]),
    blank_line=st.booleans(),
    data=st.data(),
)
def test_arrow_reader_agrees_with_the_others(xy, n_extra, delimiter, blank_line, data):
    """pyarrow's CSV reader (used when pyarrow is loaded) gives the sites and typed columns the
    bulk reader and the row walk give, or steps aside; ";" files with decimal commas included."""
    pytest.importorskip("pyarrow")
    from tvoronoi.readers import tabular

    cells = st.one_of(CELL_TEXT.filter(lambda c: delimiter not in c), CELLS.filter(lambda c: delimiter not in c))
    rows = [[repr(a), repr(b), *[data.draw(cells) for _ in range(n_extra)]] for a, b in xy]
    if delimiter == ";":
        rows = [[r[0].replace(".", ","), *r[1:]] for r in rows]
    lines = [delimiter.join(["x", "y", *[f"e{j}" for j in range(n_extra)]])] + [delimiter.join(r) for r in rows]
    if blank_line:
        lines.insert(2, "")
    text = "\n".join(lines) + "\n"
    layout = readers.table_layout(text, "t", "csv", None, None, delimiter)
    body = text[readers.line_offset(text, layout.header_lines) :]
    plain = text.isascii() and "_" not in text
    arrow = tabular._arrow_columns(body, layout, len(layout.names), plain)
    if arrow is None:
        return
    try:
        other = tabular.bulk_columns(body, layout, len(layout.names), plain=plain)
    except ValueError:
        other = None
    assert other is not None, "Arrow read a table the bulk reader refuses"
    np.testing.assert_array_equal(arrow[0], other[0])
    assert arrow[1] == other[1]
    # a text column that keeps Arrow's layout reads, writes and converts as the bulk reader's
    for ours, theirs in zip(arrow[1], other[1]):
        if isinstance(theirs, TextColumn):
            assert isinstance(ours, TextColumn) and len(ours) == len(theirs)
            assert ours.to_arrow().equals(theirs.to_arrow())
            assert ours.json_plain == theirs.json_plain
            assert ours.utf8(0, len(ours)) == theirs.utf8(0, len(theirs))
            assert ours[1:] == theirs[1:]
    # and both as the row walk reads the table
    slow = readers.slow_table(text, "t", "csv", layout)
    np.testing.assert_array_equal(arrow[0], slow.xy)
    typed = {name: arrow[1][j] for j, name in enumerate(layout.names) if j not in (layout.ix, layout.iy)}
    assert typed == slow.columns


# ---------------------------------------------------------------------------
# errors: each names the file, the place and the fix


def test_missing_file(tmp_path):
    path = tmp_path / "nope.csv"
    with pytest.raises(InputFileError, match=r"nope\.csv: no such file"):
        read_points(path)


def test_directory(tmp_path):
    with pytest.raises(InputFileError, match=r"is a directory, not a point file"):
        read_points(tmp_path)


def test_unreadable_file(tmp_path, monkeypatch):
    path = write(tmp_path, "locked.csv", "x,y\n1,2\n")

    def refuse(self):
        raise PermissionError(13, "Permission denied", str(self))

    monkeypatch.setattr(Path, "read_bytes", refuse)
    with pytest.raises(InputFileError, match=r"locked\.csv: permission denied"):
        read_points(path)


@pytest.mark.parametrize(
    "name, content, expected",
    [
        ("empty.csv", "", r"empty\.csv: no points found \(the file is empty\)"),
        ("blank.csv", "\n  \n\n", r"blank\.csv: no points found"),
        ("header.csv", "x,y\n\n", r"header\.csv: no points found \(the file has only a header, line 1\)"),
        ("comments.txt", "# nothing\n\n# here\n", r"comments\.txt: no points found"),
        ("empty.geojson", "", r"empty\.geojson: no points found"),
        ("empty.npy", b"", r"empty\.npy: no points found"),
    ],
)
def test_no_points(tmp_path, name, content, expected):
    with pytest.raises(InputFileError, match=expected):
        read(tmp_path, name, content)


def test_geojson_without_point_features(tmp_path):
    message = error(tmp_path, "p.geojson", collection())
    assert "p.geojson: no points found" in message


def test_npy_with_zero_rows(tmp_path):
    assert "no points found" in error(tmp_path, "p.npy", npy_bytes(np.zeros((0, 2))))


@pytest.mark.parametrize(
    "content, expected",
    [
        ("x,y\n1,2\n3,4\n5,nan\n", "points.csv, line 4: y is nan; tvoronoi needs finite coordinates"),
        ("x,y\n1,2\n-inf,4\n", "points.csv, line 3: x is -inf; tvoronoi needs finite coordinates"),
        ("x,y,a\n1,2,3\n1e999,4,5\n", "points.csv, line 3: x is 1e999 (it overflows to infinity)"),
        ("lat,lon\n1,2\nNaN,4\n", 'points.csv, line 3: y (column "lat") is NaN'),
    ],
)
def test_non_finite_coordinates(tmp_path, content, expected):
    assert expected in error(tmp_path, "points.csv", content)


def test_non_finite_in_text_npy_and_geojson(tmp_path):
    assert "p.txt, line 2: y is inf" in error(tmp_path, "p.txt", "# c\n1 inf\n")
    array = np.array([[1.0, 2.0], [3.0, 4.0], [np.nan, 5.0]])
    assert "p.npy, row 2 (0-based): x is nan" in error(tmp_path, "p.npy", npy_bytes(array))
    nan_json = (
        '{"type": "FeatureCollection", "features": [\n'
        + json.dumps(feature({"type": "Point", "coordinates": [1, 2]}))
        + ',\n{"type": "Feature", "geometry": {"type": "Point", "coordinates": [NaN, 1]}}]}'
    )
    message = error(tmp_path, "p.geojson", nan_json)
    # orjson refuses NaN while parsing, on line 3
    assert "p.geojson, line 3" in message


def test_non_finite_geojson_coordinates_are_named(monkeypatch):
    """The reader's own finiteness check names the feature and the point."""
    doc = {
        "type": "FeatureCollection",
        "features": [
            feature({"type": "Point", "coordinates": [1, 2]}),
            feature({"type": "MultiPoint", "coordinates": [[1, 2], [3, float("inf")]]}),
        ],
    }
    monkeypatch.setattr(readers, "_loads_json", lambda data, source: doc)
    monkeypatch.setattr(sys, "stdin", FakeStdin(b"{}"))
    with pytest.raises(InputFileError, match=r"<stdin>, features\[1\], point 1: y is inf; tvoronoi needs finite"):
        read_points("-")


@pytest.mark.parametrize(
    "name, content, expected",
    [
        ("r.csv", "x,y,z\n1,2,3\n4,5\n", "r.csv, line 3: 2 fields, but the header has 3 (x, y, z)"),
        ("r.csv", "x,y\n1,2\n4,5,6\n", "r.csv, line 3: 3 fields, but the header has 2 (x, y)"),
        ("r.csv", "1,2,3\n\n4,5\n", "r.csv, line 3: 2 fields, but the first row (line 1) has 3"),
        ("r.txt", "1 2\n# c\n3\n", "r.txt, line 3: 1 field, but the first row (line 1) has 2"),
        ("r.txt", "1 2 a\n3 4 b c\n", "r.txt, line 2: 4 fields, but the first row (line 1) has 3"),
    ],
)
def test_ragged_rows(tmp_path, name, content, expected):
    assert expected in error(tmp_path, name, content)


@pytest.mark.parametrize(
    "name, content, expected",
    [
        (
            "points.csv",
            "x,y\n1,2\n3,4\n5,6\n7,8\n9,10\n11,abc\n",
            'points.csv, line 7: "abc" in column "y" is not a number',
        ),
        (
            "points.csv",
            "id,lon,lat,name\n1,2,3,a\n2,,3,b\n",
            'points.csv, line 3: "" in column "lon" (x) is not a number',
        ),
        ("points.txt", "1 2\n3 4\n\n5 six\n", 'points.txt, line 4: "six" in column "col2" (y) is not a number'),
        ("points.csv", 'x,y\n"1,5",2\n', 'points.csv, line 2: "1,5" in column "x" is not a number'),
    ],
)
def test_text_where_a_number_belongs(tmp_path, name, content, expected):
    message = error(tmp_path, name, content)
    assert expected in message
    assert "--x/--y" in message


def test_chosen_column_that_does_not_exist(tmp_path):
    message = error(tmp_path, "p.csv", "id,east,north\n1,2,3\n", x="lon", y="north")
    assert 'p.csv: no column "lon" for x' in message
    assert "0:id, 1:east, 2:north" in message
    message = error(tmp_path, "p.csv", "1,2,3\n", y=5)
    assert "p.csv: no column 5 for y; the file has 3 columns" in message
    assert "0:col1, 1:col2, 2:col3" in message
    message = error(tmp_path, "p.npy", npy_bytes(np.zeros((2, 2))), x="x")
    assert 'p.npy: no column "x" for x' in message


def test_same_column_for_x_and_y(tmp_path):
    with pytest.raises(TvoronoiError, match=r'x and y are the same column "b"'):
        read(tmp_path, "p.csv", "a,b\n1,2\n", x="b", y=1)


def test_too_few_numeric_columns(tmp_path):
    message = error(tmp_path, "p.csv", "name,value\na,1\n")
    assert "p.csv, line 2: cannot find the y column" in message
    assert "choose them with --x/--y" in message


def test_not_utf8(tmp_path):
    message = error(tmp_path, "p.csv", b"x,y,name\n1,2,a\n3,4,Z\xfcrich\n")
    assert "p.csv, line 3: byte 0xfc is not valid UTF-8; save the file as UTF-8" in message


def test_broken_json_names_line_and_column(tmp_path):
    message = error(tmp_path, "p.geojson", '{"type": "FeatureCollection",\n  "features": [,]}')
    assert "p.geojson, line 2, column 16: broken JSON" in message


@pytest.mark.parametrize(
    "content, expected",
    [
        (
            collection(
                feature({"type": "Point", "coordinates": [0, 0]}),
                feature({"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [0, 1], [0, 0]]]}),
            ),
            'p.geojson, features[1]: geometry type "Polygon" is not a point',
        ),
        (collection(feature(None)), "p.geojson, features[0]: the geometry is null"),
        (
            collection(feature({"type": "Point", "coordinates": [1]})),
            "p.geojson, features[0]: coordinates [1] are not a position",
        ),
        (
            collection(feature({"type": "Point", "coordinates": ["1", 2]})),
            "p.geojson, features[0]: coordinates ['1', 2] are not a position",
        ),
        (
            collection(feature({"type": "MultiPoint", "coordinates": [[1, 2], [True, 3]]})),
            "p.geojson, features[0], point 1: coordinates [True, 3] are not a position",
        ),
        (
            collection(feature({"type": "Point", "coordinates": [1, 2]}, [1])),
            'p.geojson, features[0]: "properties" is a list',
        ),
        (collection(5), "p.geojson, features[0]: not a Feature object but a number"),
        ('{"type": "FeatureCollection"}', 'p.geojson: the FeatureCollection has no "features" list'),
        ("[[1, 2]]", "p.geojson: not GeoJSON: expected a FeatureCollection"),
        (
            '{"type": "LineString", "coordinates": [[0, 0], [1, 1]]}',
            "p.geojson: the file is a single LineString geometry",
        ),
        (
            json.dumps(feature({"type": "GeometryCollection", "geometries": []})),
            'p.geojson, the feature: geometry type "GeometryCollection" is not a point',
        ),
    ],
)
def test_geojson_errors(tmp_path, content, expected):
    assert expected in error(tmp_path, "p.geojson", content)


def test_geojson_rejects_column_choice(tmp_path):
    path = write(tmp_path, "p.geojson", json.dumps({"type": "Point", "coordinates": [1, 2]}))
    with pytest.raises(TvoronoiError, match=r"--x/--y choose table columns"):
        read_points(path, x="lon")


@pytest.mark.parametrize(
    "array, expected",
    [
        (np.zeros(4), r"shape \(4,\); tvoronoi needs \(n, 2\)"),
        (np.zeros((3, 1)), r"shape \(3, 1\)"),
        (np.zeros((2, 2, 2)), r"shape \(2, 2, 2\)"),
        (np.zeros((3, 2), dtype=complex), r"dtype complex128 is not a number type"),
        (np.zeros((3, 2), dtype=bool), r"dtype bool is not a number type"),
        (np.array([["a", "b"]]), r"dtype <U1 is not a number type"),
        (np.array([[1, None]], dtype=object), r"holds Python objects \(dtype object\)"),
        (np.zeros(2, dtype=[("s", "U2"), ("t", "U2")]), r"cannot find the x and y fields among s, t"),
        (np.zeros((2, 2), dtype=[("x", "f8"), ("y", "f8")]), r"a structured array of shape \(2, 2\)"),
    ],
)
def test_npy_wrong_shape_or_dtype(tmp_path, array, expected):
    with pytest.raises(InputFileError, match=r"p\.npy: .*" + expected):
        read(tmp_path, "p.npy", npy_bytes(array))


def test_npy_structured_text_field_chosen(tmp_path):
    array = np.zeros(2, dtype=[("x", "f8"), ("y", "U3")])
    assert 'field "y" has dtype <U3, not a number' in error(tmp_path, "p.npy", npy_bytes(array))


def test_npy_that_is_not_npy(tmp_path):
    assert "p.npy: not a .npy file" in error(tmp_path, "p.npy", b"x,y\n1,2\n")
    truncated = npy_bytes(np.zeros((100, 2)))[:-40]
    assert "p.npy: broken .npy file" in error(tmp_path, "p.npy", truncated)


def test_unknown_format():
    with pytest.raises(TvoronoiError, match=r"unknown format 'xlsx'; choose one of: csv, text, geojson, npy"):
        read_points("p.xlsx", fmt="xlsx")


def test_unterminated_quote(tmp_path):
    # the quote swallows the rest of the file into one field of the row on line 3
    message = error(tmp_path, "q.csv", 'x,y\n1,2\n"3,4\n5,6\n')
    assert "q.csv, line 3: 1 field (a quote opened here is not closed), but the header has 2" in message


def test_control_characters_are_shown_escaped(tmp_path):
    message = error(tmp_path, "p.csv", "x,y\n1,2\n3,4\x00\n")
    assert 'p.csv, line 3: "4\\u0000" in column "y" is not a number' in message


# ---------------------------------------------------------------------------
# columns typed per column


def test_zip_codes_keep_their_leading_zeros(tmp_path):
    points = read(tmp_path, "p.csv", "zip,x,y\n01000,0,0\n02134,1,0\n90210,0,1\n")
    assert [points.properties(i)["zip"] for i in range(3)] == ["01000", "02134", "90210"]


def test_a_column_is_integer_only_if_every_value_is(tmp_path):
    points = read(tmp_path, "p.csv", "x,y,n,m,t\n0,0,1,1,7\n1,0,,2.5,7a\n0,1,3,,8\n")
    assert [points.properties(i)["n"] for i in range(3)] == [1, None, 3]
    assert [type(points.properties(i)["m"]) for i in range(3)] == [float, float, type(None)]
    assert [points.properties(i)["t"] for i in range(3)] == ["7", "7a", "8"]


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.one_of(
            st.integers(-(10**20), 10**20).map(str),
            st.from_regex(r"0[0-9]{1,5}", fullmatch=True),
            st.floats(allow_nan=False, allow_infinity=False).map(repr),
            st.just(""),
            st.text("abc ", min_size=1, max_size=4),
        ),
        min_size=1,
        max_size=12,
    )
)
def test_every_column_has_one_type(values):
    from tvoronoi.readers.pointset import convert_column

    for plain in (True, False):
        out = convert_column(values, plain)
        assert [v is None for v in out] == [not v.strip() for v in values]
        kinds = {type(v) for v in out} - {type(None)}
        assert len(kinds) <= 1
        if kinds == {str}:
            assert all(o == v for o, v in zip(out, values) if o is not None)
        if any(v.strip().startswith("0") and v.strip()[1:2].isdigit() for v in values):
            assert kinds <= {str}


# ---------------------------------------------------------------------------
# column choice: names, id-like columns, separators


@pytest.mark.parametrize(
    "header, expect",
    [
        ("name,Easting,Northing", ("Easting", "Northing")),
        ("name,E,N", ("E", "N")),
        ("name,X,Y", ("X", "Y")),
        ("name,Longitude,Latitude", ("Longitude", "Latitude")),
        ("name,lng,lat", ("lng", "lat")),
    ],
)
def test_coordinate_columns_recognised_by_name(tmp_path, header, expect):
    points = read(tmp_path, "p.csv", f"{header}\na,5,7\nb,6,8\n")
    np.testing.assert_array_equal(points.xy, [[5, 7], [6, 8]])
    assert points.property_names == ["name"]
    assert points.choice is None or f'x = "{expect[0]}", y = "{expect[1]}" (by name)' in points.choice


def test_n_alone_is_not_a_northing(tmp_path):
    points = read(tmp_path, "p.csv", "a,n,x\n5,1,7\n6,2,8\n")
    # "n" (a count) has no "e" beside it: y is the first free numeric column
    np.testing.assert_array_equal(points.xy, [[7, 5], [8, 6]])
    assert points.property_names == ["n"]


@pytest.mark.parametrize("id_name", ["id", "FID", "index", "row", "OBJECTID", "station_id", "Unnamed: 0"])
def test_id_like_columns_are_never_taken_by_position(tmp_path, id_name):
    points = read(tmp_path, "p.csv", f"{id_name},a,b\n1,5,7\n2,6,8\n3,1,1\n")
    np.testing.assert_array_equal(points.xy, [[5, 7], [6, 8], [1, 1]])
    assert points.choice.startswith('x = "a", y = "b" (the first numeric columns); skipped the id-like column')
    assert f'"{id_name}"' in points.choice


def test_readers_report_the_columns_taken_and_the_candidates_when_ambiguous(tmp_path):
    # three numeric columns, none named: x and y by position, all three offered
    points = read(tmp_path, "p.csv", "a,b,c,name\n1,2,3,u\n4,5,6,v\n")
    assert points.xy_columns == ("a", "b") and points.candidates == ("a", "b", "c")
    # named, given or only two: nothing to choose
    assert read(tmp_path, "q.csv", "lon,lat,pop\n1,2,3\n4,5,6\n").candidates == ()
    given = read(tmp_path, "r.csv", "a,b,c\n1,2,3\n4,5,6\n", x="c", y="a")
    assert given.xy_columns == ("c", "a") and given.candidates == ()
    np.testing.assert_array_equal(given.xy, [[3, 1], [6, 4]])
    assert read(tmp_path, "s.csv", "a,b,name\n1,2,u\n").candidates == ()
    # a header-less table: the columns by their colN names, which the readers take back
    bare = read(tmp_path, "t.csv", "1,2,3\n4,5,6\n")
    assert bare.candidates == ("col1", "col2", "col3")
    np.testing.assert_array_equal(read(tmp_path, "t.csv", "1,2,3\n4,5,6\n", x="col3", y="col2").xy, [[3, 2], [6, 5]])
    # a structured .npy array of three unnamed numeric fields
    array = np.array([(1.0, 2.0, 3.0)], dtype=[("p", "f8"), ("q", "f8"), ("r", "i4")])
    npy = read(tmp_path, "p.npy", npy_bytes(array))
    assert npy.xy_columns == ("p", "q") and npy.candidates == ("p", "q", "r")


def test_only_id_columns_left_is_an_error_naming_them(tmp_path):
    message = error(tmp_path, "p.csv", "id,value,name\n1,5,a\n2,6,b\n")
    assert "id-like columns are not taken: id" in message and "--x/--y" in message


def test_semicolon_csv_with_decimal_commas(tmp_path):
    points = read(tmp_path, "p.csv", "Name;X;Y;Pop\nA;1,5;2,25;1000\nB;3;4,75;2000\n")
    np.testing.assert_array_equal(points.xy, [[1.5, 2.25], [3.0, 4.75]])
    assert points.properties(1) == {"Name": "B", "Pop": 2000}


@pytest.mark.parametrize("rows", [50, 5000])  # the row walk, and the bulk readers
def test_semicolon_csv_properties_with_decimal_commas_are_numbers(tmp_path, rows):
    body = "".join(f"P{i};{i},5;2,25;{i % 7},{i % 10};{i};{i},{i}x;0{i % 3}\n" for i in range(rows))
    points = read(tmp_path, "p.csv", "Name;X;Y;Area;Pop;Code;Zip\n" + body + "Q;1;2;;7;a;\n")
    area = [points.properties(i)["Area"] for i in range(rows + 1)]
    assert area[:rows] == [float(f"{i % 7}.{i % 10}") for i in range(rows)] and area[rows] is None
    assert [points.properties(i)["Pop"] for i in range(3)] == [0, 1, 2]  # integers stay integers
    assert points.properties(1)["Code"] == "1,1x"  # not a number: text as written
    assert points.properties(1)["Zip"] == "01"  # leading zeros: text as written


def test_comma_csv_keeps_a_quoted_decimal_comma_as_text(tmp_path):
    points = read(tmp_path, "p.csv", 'x,y,area\n1,2,"3,5"\n3,4,"4,5"\n')
    assert points.properties(0)["area"] == "3,5"


def test_semicolon_csv_bad_value_is_named_as_written(tmp_path):
    message = error(tmp_path, "p.csv", "x;y\n1,5;2\n1,5,3;4\n")
    assert 'line 3: "1,5,3" in column "x" is not a number' in message


def test_tsv_and_explicit_delimiter(tmp_path):
    points = read(tmp_path, "p.tsv", "x\ty\tname\n1\t2\ta b\n3\t4\t\n")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])
    assert points.properties(0) == {"name": "a b"} and points.properties(1) == {"name": None}
    points = read(tmp_path, "p.txt", "x|y|name\n1|2|a\n3|4|b\n", delimiter="|")
    np.testing.assert_array_equal(points.xy, [[1, 2], [3, 4]])


@pytest.mark.parametrize(
    "name, content, what",
    [
        ("p.gpkg", b"SQLite format 3\x00" + bytes(100), "GeoPackage"),
        ("p.dat", b"SQLite format 3\x00" + bytes(100), "GeoPackage"),
        ("p.shp", b"\x00\x00\x27\x0a" + bytes(96), "shapefile"),
        ("p.zip", b"PK\x03\x04" + bytes(40), "zip archive"),
        ("p.csv", b"PK\x03\x04" + bytes(40), "zip archive"),
        ("p.xlsx", b"PK\x03\x04" + bytes(40), "zip archive"),
        ("p.kml", b"<?xml version='1.0'?><kml/>", "KML"),
        ("p.csv.gz", b"\x1f\x8b\x08" + bytes(20), "gzip"),
    ],
)
def test_unsupported_formats_are_named_with_a_conversion(tmp_path, name, content, what):
    message = error(tmp_path, name, content)
    assert what in message and "does not read" in message
    assert "ogr2ogr" in message or "gunzip" in message or "unzip" in message
    assert "UTF-8" not in message


def test_a_binary_file_is_named_as_such(tmp_path):
    message = error(tmp_path, "points", b"\x7fELF\x02\x01\x01\x00" + bytes(64) + b"\xd0\x8f\xff" + bytes(64))
    assert "a binary file" in message and "UTF-8" not in message


@settings(max_examples=40, deadline=None)
@given(
    st.sampled_from([",", ";", "\t", "|"]),
    st.lists(
        st.tuples(st.integers(-(10**6), 10**6), st.integers(-(10**6), 10**6), st.text("ab ,;|", max_size=5)),
        min_size=1,
        max_size=20,
    ),
)
def test_any_separator_is_found_from_the_rows(tmp_path_factory, delimiter, rows):
    out = io.StringIO()
    writer = csv.writer(out, delimiter=delimiter, lineterminator="\n")
    writer.writerow(["x", "y", "label"])
    writer.writerows(rows)
    path = write(tmp_path_factory.mktemp("sep"), "p.csv", out.getvalue())
    points = read_points(path)
    np.testing.assert_array_equal(points.xy, [[x, y] for x, y, _ in rows])
    assert [points.properties(i)["label"] for i in range(len(rows))] == [
        label if label.strip() else None for _, _, label in rows
    ]


@pytest.mark.parametrize(
    "content, rows_lines",
    [
        ("x,y\n1,2\n3,4\n5,6\n", [(0, 2), (2, 4)]),  # fast path, one line per row
        ("\nx,y\n\n1,2\n\n3,4\n5,6", [(0, 4), (1, 6), (2, 7)]),  # blank lines
        ('x,y,n\n1,2,"a\nb"\n3,4,c\n', [(0, 2), (1, 4)]),  # a field over two lines
        ("x,y\n1,2\n3,abc\n", None),  # the slow path names the line itself
    ],
)
def test_each_site_knows_its_line(tmp_path, content, rows_lines):
    if rows_lines is None:
        assert "line 3" in error(tmp_path, "p.csv", content)
        return
    points = read(tmp_path, "p.csv", content)
    for row, line in rows_lines:
        assert points.place(row) == f"line {line}"


@pytest.mark.parametrize("bom", [b"", b"\xef\xbb\xbf"])
@pytest.mark.parametrize("arrow", [True, False])
def test_file_bytes_given_to_the_bulk_readers_read_as_the_text(tmp_path, monkeypatch, bom, arrow):
    """read_points hands a UTF-8 file's own bytes (without its BOM) to the bulk readers instead of
    encoding the decoded text again: the same sites and columns, with non-ASCII text in the header
    (the rows start at another byte than character) and in the rows."""
    from tvoronoi.readers import tabular

    if arrow:
        pytest.importorskip("pyarrow")
    else:
        monkeypatch.setattr(tabular, "ARROW_MIN_CHARS", 1 << 62)
    rng = np.random.default_rng(6)
    xy = rng.random((30_000, 2)) * 100
    lines = ["x,y,nöm,n"] + [f"{a!r},{b!r},café {i} ünïcode,{i}" for i, (a, b) in enumerate(xy.tolist())]
    path = tmp_path / "p.csv"
    path.write_bytes(bom + ("\n".join(lines) + "\n").encode())
    read_by_arrow: list[bool] = []
    arrow_columns = tabular._arrow_columns

    def spy(*args, **kwargs):
        result = arrow_columns(*args, **kwargs)
        read_by_arrow.append(result is not None)
        return result

    monkeypatch.setattr(tabular, "_arrow_columns", spy)
    points = read_points(path)
    assert read_by_arrow == ([True] if arrow else [])
    text = path.read_bytes().decode("utf-8-sig")
    reference = readers.read_table(text, str(path), "csv", None, None)  # encodes the text itself
    np.testing.assert_array_equal(points.xy, xy)
    np.testing.assert_array_equal(points.xy, reference.xy)
    assert points.columns == reference.columns
    assert points.columns["nöm"][29_999] == "café 29999 ünïcode"
    assert points.columns["n"][:3] == [0, 1, 2]
