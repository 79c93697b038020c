"""The bulk CSV reader (numpy byte masks, array-parsed decimals, text columns as bytes) against the
row-by-row reader (the csv module and float), on generated files."""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import orjson
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tvoronoi import readers
from tvoronoi.errors import InputFileError
from tvoronoi.readers import bulk_csv
from tvoronoi.readers.bulk_csv import bulk_columns, parse_floats
from tvoronoi.readers.tabular import _decimal_comma_columns
from tvoronoi.readers.text_column import TextColumn

FLOATS = st.floats(allow_nan=False, allow_infinity=False, width=64)
# decimals as people write them: a sign or not, digits, a point anywhere
DECIMALS = st.builds(
    lambda sign, digits, point: sign + (digits[:point] + "." + digits[point:] if point is not None else digits),
    st.sampled_from(["", "-", "+"]),
    st.text(alphabet="0123456789", min_size=1, max_size=20),
    st.one_of(st.none(), st.integers(0, 20)),
).map(lambda s: s if s.strip("+-.") else s + "0")
NUMBER_TEXTS = st.one_of(
    FLOATS.map(repr), DECIMALS, st.sampled_from(["1e5", "-0.0", ".5", "5.", " 7", "1_0", "0x1", "nan", "-inf"])
)
# field values: text with the separators, quotes and line breaks CSV must quote, zip codes, numbers, blanks
VALUES = st.one_of(
    st.text(alphabet='ab ,;|\t"\n\r0é', max_size=6),
    st.sampled_from(["", " ", "01000", "007", "12", "-3", "2.5", "x", "site 1", "\xa0"]),
    st.integers(-(10**6), 10**6).map(str),
)


def _table(rows, names, delimiter, quoting, line_end):
    """CSV text as spreadsheets write it: a field quoted when it holds a separator, a quote or a
    line break (every field with QUOTE_ALL), its quotes doubled."""

    def field(value: str) -> str:
        if quoting == csv.QUOTE_ALL or any(c in value for c in (delimiter, '"', "\r", "\n")):
            return '"' + value.replace('"', '""') + '"'
        return value

    return "".join(delimiter.join(map(field, row)) + line_end for row in [names, *rows])


def _both(text, delimiter):
    """(slow, bulk) reads of a table text: the row walk, and what bulk_columns gives (None if it steps aside)."""
    layout = readers.table_layout(text, "t", "csv", None, None, delimiter)
    slow = readers.slow_table(text, "t", "csv", layout)
    body = text[readers.line_offset(text, layout.header_lines) :]
    bulk = bulk_columns(body, layout, len(layout.names), plain=text.isascii() and "_" not in text)
    return slow, bulk, layout


@settings(max_examples=200, deadline=None)
@given(
    xy=st.lists(st.tuples(FLOATS, FLOATS), min_size=1, max_size=10),
    n_extra=st.integers(0, 3),
    delimiter=st.sampled_from([",", ";", "\t", "|"]),
    quoting=st.sampled_from([csv.QUOTE_MINIMAL, csv.QUOTE_ALL]),
    line_end=st.sampled_from(["\n", "\r\n"]),
    last_line_end=st.booleans(),
    data=st.data(),
)
def test_bulk_reader_agrees_with_the_row_walk(xy, n_extra, delimiter, quoting, line_end, last_line_end, data):
    """Quoted fields with separators, quotes and line breaks inside, empty values, zip codes,
    Windows line ends, a file with or without its last line break: the same sites and the same
    typed columns as the csv module's rows, and the bulk reader does read them."""
    rows = [[repr(a), repr(b), *[data.draw(VALUES) for _ in range(n_extra)]] for a, b in xy]
    names = ["x", "y", *[f"e{j}" for j in range(n_extra)]]
    text = _table(rows, names, delimiter, quoting, line_end)
    if not last_line_end:
        text = text.removesuffix(line_end)
    slow, bulk, layout = _both(text, delimiter)
    if "\r" in "".join(v for row in rows for v in row[2:]) and line_end == "\r\n":
        # a carriage return in a value next to Windows line ends: the bulk reader may step aside
        if bulk is None:
            return
    assert bulk is not None, "the bulk reader stepped aside on a well-formed table"
    got_xy, columns = bulk
    np.testing.assert_array_equal(got_xy, slow.xy)
    typed = {name: columns[j] for j, name in enumerate(layout.names) if j not in (layout.ix, layout.iy)}
    assert typed == slow.columns
    # and through the public entry, with a BOM: the same columns, where a semicolon file's text columns of
    # decimal-comma numbers become numbers (tabular._decimal_comma_columns)
    points = readers.read_table(text, "t", "csv", None, None, delimiter)
    np.testing.assert_array_equal(points.xy, slow.xy)
    want = dict(slow.columns)
    if delimiter == ";":
        _decimal_comma_columns(want)
    assert {k: list(v) for k, v in points.columns.items()} == want


@settings(max_examples=100, deadline=None)
@given(
    xy=st.lists(st.tuples(NUMBER_TEXTS, NUMBER_TEXTS), min_size=1, max_size=10),
    data=st.data(),
)
def test_bulk_reader_numbers_as_float_reads_them(xy, data):
    """Coordinates written every way float accepts (or refuses): the same doubles, or the row
    walk's error naming the line."""
    rows = [[a, b, data.draw(VALUES.filter(lambda v: "\r" not in v))] for a, b in xy]
    text = _table(rows, ["x", "y", "name"], ",", csv.QUOTE_MINIMAL, "\n")
    try:
        expected = np.array([[float(a), float(b)] for a, b in xy])
    except ValueError:
        expected = None
    if expected is not None and np.isfinite(expected).all():
        points = readers.read_table(text, "t", "csv", None, None)
        np.testing.assert_array_equal(points.xy, expected)
        # signs of zero too
        assert (np.signbit(points.xy) == np.signbit(expected)).all()
    else:
        with pytest.raises(InputFileError, match=r"t, line \d+:"):
            readers.read_table(text, "t", "csv", None, None)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.one_of(FLOATS.map(repr), DECIMALS), min_size=1, max_size=40), st.booleans())
def test_parse_floats_gives_what_float_gives(texts, decimal_comma):
    if decimal_comma:
        texts = [t.replace(".", ",") for t in texts]
    raw = ",".join(texts).encode()
    lengths = np.array([len(t) for t in texts])
    starts = np.concatenate([[0], np.cumsum(lengths + 1)[:-1]])
    got = parse_floats(np.frombuffer(raw, np.uint8), starts, starts + lengths, decimal_comma)
    expected = np.array([float(t.replace(",", ".")) for t in texts])
    assert got.tobytes() == expected.tobytes()  # bit for bit, signs of zero and all


def test_a_bad_value_far_down_is_named_by_its_line(tmp_path):
    lines = ["x,y,name"] + [f"{i}.5,{i % 7}.25,p{i}" for i in range(5000)]
    lines[4001] = "4000.5,12,3.x,p4000"  # a row with a field too many
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputFileError, match=r"bad\.csv, line 4002: 4 fields"):
        readers.read_points(path)
    lines[4001] = "4000.5,1O.5,p4000"  # a letter O for a zero
    path.write_text("\r\n".join(lines) + "\r\n")
    with pytest.raises(InputFileError, match=r'bad\.csv, line 4002: "1O\.5" in column "y" is not a number'):
        readers.read_points(path)


def test_bom_crlf_zip_codes_and_nulls(tmp_path):
    path = tmp_path / "zips.csv"
    rows = ["x,y,zip,name,n"] + [f"{i},{i * 2},0{i:04d},{'' if i % 3 == 0 else f'n{i}'},{i}" for i in range(1, 300)]
    path.write_bytes(b"\xef\xbb\xbf" + "\r\n".join(rows).encode() + b"\r\n")
    points = readers.read_points(path)
    assert points.columns["zip"][:2] == ["00001", "00002"]
    assert points.columns["name"][:4] == ["n1", "n2", None, "n4"]
    assert points.columns["n"][:3] == [1, 2, 3]
    np.testing.assert_array_equal(points.xy[:2], [[1, 2], [2, 4]])


def test_text_column_reads_like_its_list():
    values = ["a", None, 'é, "q"', "", "line\nbreak", "z"]
    column = TextColumn.from_strings(values)
    expected = [v if v else None for v in values]
    expected[3] = ""  # from_strings keeps an empty string as it is
    assert column == expected
    assert column.tolist() == expected
    assert [column[i] for i in range(-len(values), len(values))] == expected + expected
    assert column[1:4] == expected[1:4]
    assert column[::2] == expected[::2]
    with pytest.raises(IndexError):
        column[len(values)]
    assert not column.json_plain
    plain = TextColumn.from_strings(["a", "b c", "d"])
    assert plain.json_plain
    assert plain.utf8(0, 3) == [b"a", b"b c", b"d"]


def test_text_column_to_arrow_matches_pyarrow():
    pa = pytest.importorskip("pyarrow")
    values = ["a", None, 'é, "q"', "", "line\nbreak", "z", None]
    assert TextColumn.from_strings(values).to_arrow().equals(pa.array(values, pa.string()))


@pytest.mark.parametrize(
    "values",
    [
        ["a", "", " ", "\u3000", "é", " b ", "\x1c", "x y", "\u00a0z\u2003", ""],
        ["", "", " "],
        ["", "12", " 3"],
        ["007", "1"],
        ["1.5", "", "2"],
        ["line\nbreak", 'q"uote'],
    ],
)
def test_packed_text_column_types_and_reads_as_the_gathered_one(values):
    """A column in Arrow's layout (values one after the other, offsets not from 0) is typed,
    blanked and read as the same column gathered with line breaks."""
    encoded = [v.encode() for v in values]
    joined = b"pad" + b"".join(encoded)
    offsets = np.concatenate([[3], 3 + np.cumsum([len(v) for v in encoded])]).astype(np.int32)
    packed = bulk_csv.typed_packed_column(np.frombuffer(joined, np.uint8), offsets, plain=True)
    raw = np.frombuffer(b"\n".join(encoded), np.uint8)
    starts = np.concatenate([[0], np.cumsum([len(v) + 1 for v in encoded])[:-1]]).astype(np.int64)
    gathered = bulk_csv.typed_column(raw, starts, starts + [len(v) for v in encoded], plain=True)
    assert type(packed) is type(gathered)
    assert packed == gathered
    if isinstance(gathered, TextColumn):
        assert packed.utf8(0, len(values)) == gathered.utf8(0, len(values))
        assert packed.json_plain == gathered.json_plain
        pa = pytest.importorskip("pyarrow")
        assert packed.to_arrow().equals(gathered.to_arrow())
        assert packed.to_arrow().equals(pa.array([v if v.strip() else None for v in values], pa.string()))


@pytest.mark.parametrize("layout", ["collection", "seq", "lines"])
def test_geojson_from_text_columns_matches_lists(layout):
    """Cells written with TextColumn properties (plain, escaped, with None) are the bytes the
    same properties as lists give."""
    from tvoronoi import voronoi
    from tvoronoi.readers import PointSet
    from tvoronoi.writers.geojson_diagram import write_cells

    rng = np.random.default_rng(3)
    xy = rng.random((300, 2))
    names = [f"p{i}" for i in range(300)]
    odd = [None if i % 5 == 0 else f'q"{i}\\' for i in range(300)]
    diagram = voronoi(xy)
    outs = []
    for wrap in (list, TextColumn.from_strings):
        points = PointSet(xy, "t", {"name": wrap(names), "odd": wrap(odd)})
        out = io.BytesIO()
        write_cells(diagram, points, out, layout=layout)
        outs.append(out.getvalue())
    assert outs[0] == outs[1]
    if layout == "collection":
        features = orjson.loads(outs[0])["features"]
        assert [f["properties"]["odd"] for f in features] == odd
        assert all(not math.isnan(f["geometry"]["coordinates"][0][0][0]) for f in features)


def test_a_failing_stream_fails_the_write():
    from tvoronoi import voronoi
    from tvoronoi.writers.geojson_diagram import write_cells

    class Full(io.RawIOBase):
        def writable(self):
            return True

        def write(self, data):
            raise OSError(28, "No space left on device")

    diagram = voronoi(np.random.default_rng(1).random((30000, 2)))
    with pytest.raises(OSError, match="No space left"):
        write_cells(diagram, None, Full())


@pytest.mark.skipif(not __import__("tvoronoi.writers.forked").writers.forked.can_fork(), reason="fork is used on Linux")
@pytest.mark.parametrize("layout", ["collection", "seq", "lines"])
@pytest.mark.parametrize("case", ["plain", "repeats_and_box", "clip"])
def test_output_made_in_two_processes_is_the_same(monkeypatch, tmp_path, layout, case):
    """The second half of the features made by a forked process: the same bytes, to a file and to a stream."""
    import shapely

    from tvoronoi import voronoi
    from tvoronoi.readers import PointSet
    from tvoronoi.writers import forked
    from tvoronoi.writers.geojson_diagram import CHUNK_FEATURES, write_cells

    rng = np.random.default_rng(5)
    n = 3 * CHUNK_FEATURES + 17
    xy = rng.random((n, 2)) * 100
    options = {}
    if case == "repeats_and_box":
        xy[n - 40 :] = xy[:40]  # repeated sites in the second half
        options["bbox"] = (10, 10, 90, 90)  # cells of sites outside miss the box
    if case == "clip":
        options["clip"] = shapely.Polygon([(0, 0), (100, 0), (50, 80)]).buffer(-5)
    diagram = voronoi(xy, **options)
    points = PointSet(
        xy, "t", {"name": TextColumn.from_strings([f"n{i}" for i in range(n)]), "k": [i % 7 for i in range(n)]}
    )
    outs = []
    for minimum in (10**12, 1):
        monkeypatch.setattr(forked, "MIN_FEATURES", minimum)
        path = tmp_path / f"{minimum}.geojson"
        seen: list = []
        count = write_cells(
            diagram,
            points,
            str(path),
            layout=layout,
            precision=6 if case == "clip" else None,
            progress=lambda done, total, seen=seen: seen.append((done, total)),
        )
        stream = io.BytesIO()
        assert write_cells(diagram, points, stream, layout=layout) == count
        outs.append((path.read_bytes(), count, stream.getvalue()))
        assert seen[-1] == (count, count)
        assert all(done <= total for done, total in seen)
        assert all(a[0] < b[0] for a, b in zip(seen, seen[1:])), "progress only moves forward"
    assert outs[0] == outs[1]
    if layout == "collection":
        assert len(orjson.loads(outs[1][0])["features"]) == outs[1][1]


@pytest.mark.skipif(not __import__("tvoronoi.writers.forked").writers.forked.can_fork(), reason="fork is used on Linux")
def test_an_error_in_the_forked_half_is_raised(monkeypatch, tmp_path):
    from tvoronoi import voronoi
    from tvoronoi.errors import TvoronoiError
    from tvoronoi.readers import PointSet
    from tvoronoi.writers import forked
    from tvoronoi.writers.geojson_diagram import CHUNK_FEATURES, write_cells

    monkeypatch.setattr(forked, "MIN_FEATURES", 1)
    n = 2 * CHUNK_FEATURES + 5
    xy = np.random.default_rng(2).random((n, 2))
    values: list = list(range(n))
    values[n - 3] = object()  # not JSON, in the second half
    path = tmp_path / "out.geojson"
    with pytest.raises(TvoronoiError, match=f"site {n - 3}"):
        write_cells(voronoi(xy), PointSet(xy, "t", {"v": values}), str(path))
    assert not path.exists()
    assert not list(tmp_path.iterdir())  # no temporary file left


def test_without_a_second_process_one_writes_it_all(monkeypatch):
    """No temporary file or no process to be had for the second half: the same output from one process."""
    from tvoronoi import voronoi
    from tvoronoi.writers import forked
    from tvoronoi.writers.geojson_diagram import CHUNK_FEATURES, write_cells

    xy = np.random.default_rng(4).random((2 * CHUNK_FEATURES + 9, 2))
    diagram = voronoi(xy)
    monkeypatch.setattr(forked, "MIN_FEATURES", 10**12)
    alone = io.BytesIO()
    write_cells(diagram, None, alone)

    def refuse(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(forked, "MIN_FEATURES", 1)
    monkeypatch.setattr(forked, "can_fork", lambda: True)
    monkeypatch.setattr(forked.tempfile, "TemporaryFile", refuse)
    out = io.BytesIO()
    assert write_cells(diagram, None, out) == len(xy)
    assert out.getvalue() == alone.getvalue()


def test_a_worker_thread_writes_in_one_process(monkeypatch):
    """Saving from a worker thread (the terminal UI does) never forks."""
    import threading

    from tvoronoi.writers import forked

    seen = []
    worker = threading.Thread(target=lambda: seen.append(forked.can_fork()))
    worker.start()
    worker.join()
    assert seen == [False]
