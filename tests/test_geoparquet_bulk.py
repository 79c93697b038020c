"""The GeoParquet writer's bulk paths held to the straightforward ones: padded WKB against
shapely.to_wkb, the box as the cells' extent against their points, Arrow arrays from numpy
buffers against pyarrow.array, and a batch run to GeoParquet that never imports pandas."""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

import tvoronoi
from conftest import DATASETS
from tvoronoi.arrow_arrays import fixed_width, float64_values
from tvoronoi.readers.tabular import ARROW_MIN_CHARS
from tvoronoi.writers import geoparquet
from tvoronoi.writers.geojson_diagram import MIN_RING_POINTS

pa = pytest.importorskip("pyarrow")
pytest.importorskip("pyarrow.compute")


def _sites(seed: int, n: int, repeats: int, spokes: int) -> np.ndarray:
    """Random sites, some rows repeated, and a ring of ``spokes`` sites around one (a cell
    with ``spokes`` vertices)."""
    rng = np.random.default_rng(seed)
    xy = rng.random((n, 2)) * 100.0
    angles = np.arange(spokes) * (2 * math.pi / max(spokes, 1))
    ring = 150.0 + 5.0 * np.column_stack([np.cos(angles), np.sin(angles)])
    xy = np.concatenate([xy, [[150.0, 150.0]], ring])
    if repeats:
        xy = np.concatenate([xy, xy[rng.integers(0, len(xy), repeats)]])
    return xy[rng.permutation(len(xy))]


def _cell_rows(d):
    rows = np.arange(d.n_sites)
    distinct = d.site_of == rows
    has_ring = distinct & (np.diff(d.cell_offsets) >= MIN_RING_POINTS)
    return distinct, has_ring


@settings(max_examples=25, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(1, 60),
    st.integers(0, 8),
    st.sampled_from([0, 3, 40, 200]),
    st.booleans(),
    st.integers(1, 70),
)
def test_padded_cells_are_shapely_wkb_and_bounds(seed, n, repeats, spokes, small_box, group):
    """Cells with few and many vertices, repeated points (null rows) and, with a small box,
    cells that miss it (null rows too), written a group of rows at a time."""
    xy = _sites(seed, n, repeats, spokes)
    box = (20.0, 20.0, 80.0, 80.0) if small_box else None
    d = tvoronoi.voronoi(xy, bbox=box)
    distinct, has_ring = _cell_rows(d)
    kept = np.flatnonzero(distinct)
    present = has_ring[distinct]
    polygons = d.to_shapely()[kept]
    expected_wkb = list(shapely.to_wkb(polygons, byte_order=1))
    expected_bounds = shapely.bounds(polygons)
    ours_wkb: list = []
    ours_bounds = []
    for a in range(0, len(kept), group):
        b = min(a + group, len(kept))
        ra, rb = int(kept[a]), int(kept[b - 1]) + 1
        padded, mins, maxs = geoparquet._padded_cells(pa, d, ra, rb, has_ring[ra:rb], present[a:b])
        ours_wkb += geoparquet.unpadded(padded).to_pylist()
        ours_bounds.append(np.column_stack([mins, maxs]))
    assert ours_wkb == expected_wkb
    assert np.array_equal(np.concatenate(ours_bounds), expected_bounds, equal_nan=True)


def test_padded_cells_of_a_group_without_a_ring():
    """A group whose rows all miss the box: every row null, no bytes."""
    d = tvoronoi.voronoi([[0.0, 0.0], [1.0, 0.0], [50.0, 50.0], [51.0, 50.0]], bbox=(-1, -1, 2, 1))
    distinct, has_ring = _cell_rows(d)
    padded, mins, maxs = geoparquet._padded_cells(pa, d, 2, 4, has_ring[2:4], has_ring[2:4])
    assert geoparquet.unpadded(padded).to_pylist() == [None, None]
    assert np.isnan(mins).all() and np.isnan(maxs).all()


@pytest.mark.parametrize("name", sorted(DATASETS))
@pytest.mark.parametrize("box", [None, "inside", "wide"])
def test_extent_is_the_box_when_every_cell_is_written(name, box):
    """The shortcut (the box) against the extent of the rings' own points."""
    xy = DATASETS[name]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    span = float(max(hi - lo)) or 1.0
    # an axis without extent (collinear sites) gets one around the sites
    inner_lo = np.where(hi > lo, lo + 0.3 * (hi - lo), lo - 0.5 * span)
    inner_hi = np.where(hi > lo, hi - 0.3 * (hi - lo), hi + 0.5 * span)
    bbox = {
        None: None,
        "inside": (*inner_lo, *inner_hi),
        "wide": (lo[0] - 3.7 * span, lo[1] - 0.01 * span, hi[0] + 0.1 * span, hi[1] + 11.0 * span),
    }[box]
    d = tvoronoi.voronoi(xy, bbox=bbox)
    distinct, has_ring = _cell_rows(d)
    assert geoparquet._rings_extent(d, has_ring) == geoparquet._points_extent(d, has_ring)


def test_extent_of_cells_some_of_which_miss_the_box():
    d = tvoronoi.voronoi([[0.0, 0.0], [1.0, 0.2], [50.0, 50.0], [51.0, 50.0]], bbox=(-1, -1, 2, 1))
    distinct, has_ring = _cell_rows(d)
    assert has_ring.tolist() == [True, True, False, False]
    extent = geoparquet._rings_extent(d, has_ring)
    assert extent == list(shapely.total_bounds(d.to_shapely()[:2])) == [-1.0, -1.0, 2.0, 1.0]


@pytest.mark.parametrize(
    "values",
    [
        [1, 2, -(2**63), 2**63 - 1],
        [1, None, 3],
        [None, None],
        [0.5, float("nan"), None, -0.0, float("inf")],
        [1, 2.5],  # mixed: pyarrow's own inference
        [True, False, None],
        ["a", 1],  # mixed types: text, a string as it is, a number its JSON text
        ["01", None, 2.5, [1, "x"], {"k": "v"}, True, 'say "hi"'],
        [],
    ],
)
def test_number_columns_as_pyarrow_makes_them(values):
    ours = geoparquet._typed_column(pa, values)
    try:
        theirs = pa.array(values)
    except (pa.ArrowInvalid, pa.ArrowTypeError, OverflowError):
        theirs = pa.array([v if v is None or isinstance(v, str) else json_text(v) for v in values], pa.string())
    assert ours.type == theirs.type
    assert ours.null_count == theirs.null_count
    assert ours.to_pylist() == theirs.to_pylist() or _same_with_nan(ours.to_pylist(), theirs.to_pylist())


def json_text(value) -> str:
    import orjson

    return orjson.dumps(value).decode()


def _same_with_nan(a: list, b: list) -> bool:
    return len(a) == len(b) and all(x == y or (x != x and y != y) for x, y in zip(a, b))


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(allow_nan=False), max_size=40), st.lists(st.booleans(), max_size=40), st.data())
def test_fixed_width_and_float64_values_round_trip(values, valid_bits, data):
    xs = np.array(values, np.float64)
    valid = np.array((valid_bits + [True] * len(xs))[: len(xs)], bool)
    ours = fixed_width(pa, xs, pa.float64(), valid)
    theirs = pa.array(xs, pa.float64(), mask=~valid)
    assert ours.equals(theirs) and ours.null_count == theirs.null_count
    ints = fixed_width(pa, np.arange(len(xs)) - 3, pa.int64())
    assert ints.to_pylist() == list(range(-3, len(xs) - 3))
    # float64_values: chunks that are slices of larger buffers, read without a copy of each
    cut = data.draw(st.integers(0, len(xs)))
    whole = pa.array(np.concatenate([[7.0], xs, [8.0]]), pa.float64())
    chunked = pa.chunked_array([whole.slice(1, cut), whole.slice(1 + cut, len(xs) - cut)], pa.float64())
    assert np.array_equal(float64_values(chunked), xs)
    with pytest.raises(ValueError):
        float64_values(theirs if not valid.all() else pa.array([None], pa.float64()))


def test_batch_to_geoparquet_does_not_import_pandas(tmp_path):
    """pyarrow.array and to_numpy import pandas (0.15-0.2 s); the batch run to GeoParquet,
    reading a CSV large enough for pyarrow's reader, never calls them."""
    pytest.importorskip("pandas")
    rng = np.random.default_rng(5)
    xy = rng.random((40_000, 2))
    lines = ["x,y,name,count,share"] + [f"{x!r},{y!r},s{i},{i},{i / 7!r}" for i, (x, y) in enumerate(xy.tolist())]
    (tmp_path / "p.csv").write_text("\n".join(lines) + "\n")
    assert sum(map(len, lines)) > ARROW_MIN_CHARS  # pyarrow's CSV reader
    script = textwrap.dedent(
        f"""
        import sys
        from tvoronoi import cli
        status = cli.main(["batch", "-q", {str(tmp_path / "p.csv")!r}, "-o", {str(tmp_path / "c.parquet")!r}])
        print(status, "pandas" in sys.modules)
        """
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["0", "False"]
    import pyarrow.parquet as pq

    table = pq.read_table(tmp_path / "c.parquet")
    assert table["count"].type == pa.int64() and table["share"].type == pa.float64()
    assert table["count"].to_pylist() == list(range(40_000))


def test_column_options_reach_every_column(tmp_path):
    """Per-column options name Parquet's column paths (an option under another name is silently
    ignored): the geometry and the nested duplicates compressed, the cells' bbox not, a
    dictionary for the property that repeats and none for the one that does not."""
    import pyarrow.parquet as pq

    from tvoronoi.readers import PointSet

    xy = _sites(3, 3000, 5, 0)
    d = tvoronoi.voronoi(xy)
    kinds = ["shop", "park", "school"]
    columns = {"name": [f"site {i}" for i in range(len(xy))], "kind": [kinds[i % 3] for i in range(len(xy))]}
    geoparquet.write_cells_parquet(d, PointSet(xy, "t.csv", columns), str(tmp_path / "c.parquet"))
    meta = pq.read_metadata(tmp_path / "c.parquet")
    group = meta.row_group(0)
    chunks = {group.column(k).path_in_schema: group.column(k) for k in range(group.num_columns)}
    assert list(chunks) == geoparquet._leaf_paths(pq.read_schema(tmp_path / "c.parquet"))
    assert "duplicates.list.element" in chunks
    for path, chunk in chunks.items():
        assert chunk.compression == ("UNCOMPRESSED" if path.startswith("bbox.") else "ZSTD"), path
    assert "DELTA_BINARY_PACKED" in chunks["site"].encodings
    assert "RLE_DICTIONARY" in chunks["kind"].encodings
    assert "RLE_DICTIONARY" not in chunks["name"].encodings
    assert pq.read_table(tmp_path / "c.parquet")["name"].to_pylist()[:2] == ["site 0", "site 1"]


def test_column_options_reach_the_leaves_of_nested_properties(tmp_path):
    """A property of lists, structs or maps is stored as Parquet columns of its leaves: the
    dictionary goes to each leaf whose values repeat, statistics to every leaf; an all-null
    property and a dictionary array are written too (Arrow counts neither's distinct values)."""
    import pyarrow.parquet as pq

    n = 64
    columns = {
        "site": pa.array(range(n), pa.int64()),
        "tags": pa.array([["a", "b"][: i % 3] for i in range(n)]),
        "meta": pa.array([{"k": i % 2, "name": f"n{i}"} for i in range(n)]),
        "pairs": pa.array([[("k", i)] for i in range(n)], pa.map_(pa.string(), pa.int64())),
        "none": pa.nulls(n),
        "kind": pa.array(["x", "y"] * (n // 2)).dictionary_encode(),
        "duplicates": pa.nulls(n, pa.list_(pa.int64())),
    }
    table = pa.table(columns)
    geoparquet.write_table(pa, table, str(tmp_path / "t.parquet"), overwrite=False)
    group = pq.read_metadata(tmp_path / "t.parquet").row_group(0)
    chunks = {group.column(k).path_in_schema: group.column(k) for k in range(group.num_columns)}
    assert list(chunks) == geoparquet._leaf_paths(table.schema)
    repeating = {"tags.list.element", "meta.k", "pairs.key_value.key", "kind"}
    for path, chunk in chunks.items():
        assert ("RLE_DICTIONARY" in chunk.encodings) == (path in repeating), path
        assert chunk.is_stats_set or path == "none", path
    assert pq.read_table(tmp_path / "t.parquet").equals(table.cast(pq.read_schema(tmp_path / "t.parquet")))


def test_a_mixed_value_without_json_form_is_named():
    from tvoronoi.errors import TvoronoiError

    with pytest.raises(TvoronoiError, match="tag: the value <object"):
        geoparquet._typed_column(pa, [1, object()], "tag")
