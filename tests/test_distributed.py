"""Tiles on a Dask LocalCluster (two worker processes): every cell equal, bit for bit, to one process's build."""

import subprocess
import sys

import dask.array as da
import dask.dataframe as dd
import numpy as np
import pandas as pd
import pytest
import shapely

import tvoronoi
from tvoronoi.distributed import local_client, voronoi
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import generate
from tvoronoi.tile_delaunay import canonical_triangles

# The proof runs 200,000 sites per distribution; the special cases (a 1e-9 cluster, a grid, a clip
# region) run on fewer, enough for several tiles of thousands of sites each.
N = 200_000
N_SMALL = 40_000


# Dask's worker and nanny configuration in this process before the first local_client (which sets
# some for its own workers only, and must leave these as they were)
CONFIG_BEFORE: dict = {}
WORKER_KEYS = ("distributed.worker", "distributed.nanny")


@pytest.fixture(scope="module")
def client():
    import copy

    import dask
    import distributed  # noqa: F401 (its configuration's defaults)

    CONFIG_BEFORE.update({key: copy.deepcopy(dask.config.get(key)) for key in WORKER_KEYS})
    c = local_client(2)
    yield c
    c.close()
    c.cluster.close()


def frame_of(pts: np.ndarray, partitions: int = 6, **columns) -> dd.DataFrame:
    return dd.from_pandas(pd.DataFrame({"x": pts[:, 0], "y": pts[:, 1], **columns}), npartitions=partitions)


def cells_of(result) -> pd.DataFrame:
    return result.cells.compute().sort_values("site").reset_index(drop=True)


def assert_same_cells(cells: pd.DataFrame, geoms: np.ndarray) -> None:
    """Every input row once, and each row's WKB (the exact doubles of its ring) equal to one process's."""
    assert cells["site"].to_numpy().tolist() == list(range(len(geoms)))
    got = cells["geometry"].to_numpy(dtype=object, na_value=None)
    want = shapely.to_wkb(geoms)
    bad = [i for i in range(len(geoms)) if got[i] != want[i]]
    assert not bad, f"{len(bad)} cells differ, first at site {bad[:5]}"


def assert_same_triangles(result, full) -> None:
    """Every triangle once, from one task, equal as site triples to one process's canonical triangles;
    each row's geometry the triangle of its three sites."""
    frame = result.triangles.compute()
    tri = frame[["a", "b", "c"]].to_numpy()
    assert (tri[:, 0] < tri[:, 1]).all() and (tri[:, 0] < tri[:, 2]).all()  # lowest first
    tri = tri[np.lexsort((tri[:, 2], tri[:, 1], tri[:, 0]))]
    want, _ = canonical_triangles(np.asarray(full.sites), full.triangles, len(full.vertices))
    assert tri.shape == want.shape and np.array_equal(tri, want)
    # counter-clockwise polygons of the sites' own coordinates
    geoms = shapely.from_wkb(frame["geometry"].to_numpy(dtype=object))
    rows = frame[["a", "b", "c"]].to_numpy()
    ring = shapely.get_coordinates(geoms).reshape(-1, 4, 2)
    assert np.array_equal(ring[:, :3], np.asarray(full.sites)[rows])
    assert (shapely.is_ccw(shapely.get_exterior_ring(geoms))).all()
    assert result.triangles_pending_after[-1] == 0


@pytest.mark.parametrize("distribution", ["uniform", "gaussian", "clustered"])
def test_distributions_equal_one_process(client, distribution):
    pts = generate(distribution, N, seed=12)
    result = voronoi(frame_of(pts), client=client, tiles=8, delaunay=True)
    full = tvoronoi.voronoi(pts, threads=1)
    assert_same_cells(cells_of(result), full.to_shapely())
    assert result.rounds == len(result.pending_after) and result.pending_after[-1] == 0
    if distribution == "gaussian":
        # the sparse corners of a gaussian cloud need a second round
        assert result.rounds > 1 and result.pending_after[0] > 0
    # no four sites cocircular: the canonical triangles are the engine's own
    assert len(full.vertices) == len(full.triangles)
    assert_same_triangles(result, full)


def test_a_1e9_cluster_with_repeats_equals_one_process(client):
    rng = np.random.default_rng(3)
    cluster = 0.5 + 1e-9 * rng.random((N_SMALL, 2))
    pts = np.concatenate([cluster, cluster[rng.integers(0, N_SMALL, 2_000)], generate("uniform", 2_000, seed=3)])
    result = voronoi(frame_of(pts), client=client, tiles=6, delaunay=True)
    full = tvoronoi.voronoi(pts, threads=1)
    assert_same_cells(cells_of(result), full.to_shapely())
    assert_same_triangles(result, full)


def test_a_grid_with_a_tight_halo_needs_a_second_round_and_equals_one_process(client):
    side = 200
    pts = np.stack(np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float)), -1).reshape(-1, 2)
    result = voronoi(frame_of(pts), client=client, tiles=5, halo_scale=0.1, delaunay=True)
    assert result.rounds > 1 and result.pending_after[0] > 0 and result.triangles_pending_after[0] > 0
    full = tvoronoi.voronoi(pts, threads=1)
    assert_same_cells(cells_of(result), full.to_shapely())
    # every square's four corners are cocircular: each square cut along the diagonal from its lowest corner
    assert len(full.vertices) < len(full.triangles)
    assert_same_triangles(result, full)
    tri = result.triangles.compute()[["a", "b", "c"]].to_numpy()
    assert {int(t[2] - t[0]) for t in tri} | {int(t[1] - t[0]) for t in tri} == {1, side, side + 1}


def test_cocircular_sites_on_circles_across_tiles_equal_the_canonical_triangles(client):
    # concentric rings of 24 sites (every ring's sites cocircular), on a grid of centres spanning the tiles,
    # and regular polygons sharing the circle of their neighbours
    angles = 2 * np.pi * np.arange(24) / 24
    ring = np.column_stack([np.cos(angles), np.sin(angles)])
    centres = np.stack(np.meshgrid(np.arange(12.0) * 3, np.arange(12.0) * 3), -1).reshape(-1, 2)
    pts = np.concatenate([c + ring for c in centres] + [centres])
    pts = pts[np.random.default_rng(1).permutation(len(pts))]
    result = voronoi(frame_of(pts), client=client, tiles=6, delaunay=True)
    full = tvoronoi.voronoi(pts, threads=1)
    assert len(full.vertices) < len(full.triangles)
    assert_same_triangles(result, full)


def test_a_clip_region_equals_one_process(client):
    pts = generate("uniform", N_SMALL, seed=5, bounds=(0, 0, 10, 10))
    region = shapely.Polygon([(1, 1), (9, 2), (8, 9), (2, 7)], holes=[[(4, 4), (6, 4), (5, 6)]])
    result = voronoi(frame_of(pts, id=np.arange(N_SMALL) * 3), client=client, tiles=6, clip=region, delaunay=True)
    cells = cells_of(result)
    full = tvoronoi.voronoi(pts, clip=region, threads=1)
    assert_same_cells(cells, full.to_shapely())
    # the triangles of the sites inside the region, as one process gives them
    assert_same_triangles(result, full)
    # properties travel with their sites
    assert (cells["id"].to_numpy() == cells["site"].to_numpy() * 3).all()


def test_local_workers_run_without_the_nannys_malloc_trim_threshold_and_the_profiler(client):
    # Dask's nanny sets MALLOC_TRIM_THRESHOLD_ in its workers unless told not to; local_client's run as
    # this process does (the value here, normally none), and without the statistical profiler
    import os

    import dask

    got = client.run(lambda: os.environ.get("MALLOC_TRIM_THRESHOLD_"))
    assert len(got) == 2 and set(got.values()) == {os.environ.get("MALLOC_TRIM_THRESHOLD_")}
    profiling = client.run(lambda dask_worker: dask_worker.periodic_callbacks.get("profile") is not None)
    assert set(profiling.values()) == {False}
    assert client.run(lambda: dask.config.get("distributed.worker.profile.enabled")) == dict.fromkeys(got, False)
    # this process's configuration is left as it was
    assert {key: dask.config.get(key) for key in WORKER_KEYS} == CONFIG_BEFORE


@pytest.mark.parametrize("layout", ["uniform", "one column", "rounded", "one point"])
def test_many_regions_select_the_rows_each_region_tests_on_every_site(layout):
    # a partition serving many regions bins its sites first: every region still gets exactly the rows
    # of the sites in it (closed sides, infinite sides, regions beyond the sites), ascending
    from tvoronoi.distributed import FEW_REGIONS, _select
    from tvoronoi.tiles import in_region

    rng = np.random.default_rng(8)
    pts = rng.random((5_000, 2))
    if layout == "one column":
        pts[:, 0] = 0.25
    elif layout == "rounded":  # sites on region sides
        pts = np.round(pts, 1)
    elif layout == "one point":
        pts[:] = 0.5
    corners = np.round(rng.random((4 * FEW_REGIONS, 2, 2)) * 1.4 - 0.2, 1)
    regions = [(float(a[0].min()), float(a[1].min()), float(a[0].max()), float(a[1].max())) for a in corners]
    regions += [
        (-np.inf, -np.inf, 0.3, np.inf),
        (0.5, -np.inf, np.inf, 0.5),
        (2.0, 2.0, 3.0, 3.0),
        (0.25, 0.5, 0.25, 0.5),
    ]
    part = pd.DataFrame({"x": pts[:, 0], "y": pts[:, 1], "w": np.arange(len(pts)) * 2})
    many = _select(part, 100, "x", "y", regions, ["w"], None)
    for region, frame in zip(regions, many):
        rows = np.flatnonzero(in_region(pts[:, 0], pts[:, 1], region))
        assert frame["__tvoronoi_site"].tolist() == (rows + 100).tolist()
        assert (frame["w"].to_numpy() == rows * 2).all()
        assert np.array_equal(frame["__tvoronoi_x"].to_numpy(), pts[rows, 0])
    # the same frames as a few regions at a time (each tested on every site)
    for k in range(0, len(regions), FEW_REGIONS):
        few = _select(part, 100, "x", "y", regions[k : k + FEW_REGIONS], ["w"], None)
        for a, b in zip(few, many[k : k + FEW_REGIONS]):
            pd.testing.assert_frame_equal(a, b)


def test_a_dask_array_and_a_user_box(client):
    pts = generate("gaussian", N_SMALL, seed=7)
    bbox = (-1.0, -1.0, 2.0, 2.0)
    result = voronoi(da.from_array(pts, chunks=(7_000, 2)), client=client, bbox=bbox, tiles=4)
    assert_same_cells(cells_of(result), tvoronoi.voronoi(pts, bbox=bbox, threads=1).to_shapely())


def test_geoparquet_directory_reads_as_one_table(client, tmp_path):
    import geopandas
    import pyarrow as pa
    import pyarrow.dataset as ds
    import pyarrow.parquet as pq

    pts = generate("clustered", N_SMALL - 500, seed=9)
    pts = np.concatenate([pts, pts[:500]])  # repeated points: rows without a cell (null)
    names = np.array([f"p{i}" for i in range(N_SMALL)], object)
    out = tmp_path / "cells"
    result = voronoi(frame_of(pts, name=names), client=client, tiles=4, to=out)
    assert result.cells is None and len([p for p in result.parts if p]) >= 4
    frame = geopandas.read_parquet(out).sort_values("site").reset_index(drop=True)
    full = tvoronoi.voronoi(pts, threads=1)
    assert frame["site"].tolist() == list(range(N_SMALL))
    assert (frame["name"].to_numpy() == names).all()
    want = full.to_shapely()
    assert frame.geometry.isna().to_numpy().tolist() == [g is None for g in want]
    present = ~frame.geometry.isna().to_numpy()
    assert shapely.equals_exact(frame.geometry.to_numpy()[present], want[present], tolerance=0).all()
    # _metadata alone opens every part, and the common schema carries the dataset's geo metadata
    table = ds.parquet_dataset(str(out / "_metadata")).to_table().sort_by("site")
    assert table.num_rows == N_SMALL
    # the parts' WKB, byte for byte, and their bbox columns: one process's cells
    assert table["geometry"].to_pylist() == list(shapely.to_wkb(want))
    bbox = table["bbox"].combine_chunks().filter(pa.array(present))
    bounds = np.column_stack([bbox.field(k).to_numpy() for k in ("xmin", "ymin", "xmax", "ymax")])
    assert np.array_equal(bounds, shapely.bounds(want[present]))
    geo = pq.read_schema(out / "_common_metadata").metadata[b"geo"]
    assert b'"geometry_types":["Polygon"]' in geo


def test_geojsonseq_parts(client, tmp_path):
    import orjson

    pts = generate("uniform", 5_000, seed=2)
    out, triangles = tmp_path / "seq", tmp_path / "triangles"
    result = voronoi(frame_of(pts, 3), client=client, tiles=3, to=out, format="geojsonseq", delaunay=triangles)
    assert result.triangles is None and any(result.triangle_parts)
    # the triangles' parts: features with "sites", as one process's GeoJSON --delaunay writes them
    rows = [
        orjson.loads(line.lstrip(b"\x1e"))
        for part in sorted(triangles.iterdir())
        for line in part.read_bytes().splitlines()
    ]
    sites = np.array([f["properties"]["sites"] for f in rows])
    full_triangles = tvoronoi.voronoi(pts, threads=1).triangles
    assert len(sites) == len(full_triangles)
    assert {tuple(sorted(t)) for t in sites.tolist()} == {tuple(sorted(t)) for t in full_triangles.tolist()}
    ring = np.array([f["geometry"]["coordinates"][0] for f in rows])
    assert np.array_equal(ring[:, :3], pts[sites]) and np.array_equal(ring[:, 3], ring[:, 0])
    features = [
        orjson.loads(line.lstrip(b"\x1e")) for part in sorted(out.iterdir()) for line in part.read_bytes().splitlines()
    ]
    features.sort(key=lambda f: f["properties"]["site"])
    assert [f["properties"]["site"] for f in features] == list(range(5_000))
    full = tvoronoi.voronoi(pts, threads=1)
    for f in features[::97]:
        ring = np.array(f["geometry"]["coordinates"][0][:-1])
        assert np.array_equal(ring, full.cell_polygon(f["properties"]["site"]))


def test_bad_input_is_named(client, tmp_path):
    pts = generate("uniform", 1_000, seed=1)
    pts[700] = np.nan
    with pytest.raises(TvoronoiError, match=r"partition \d, row \d+ \(index 700\): x is nan, not a finite number"):
        voronoi(frame_of(pts, 4), client=client, tiles=2)
    with pytest.raises(TvoronoiError, match="Dask DataFrame or a Dask array"):
        voronoi(pts, client=client)
    with pytest.raises(TvoronoiError, match="no column names the y coordinate"):
        voronoi(dd.from_pandas(pd.DataFrame({"x": [1.0], "height": [2.0]}), npartitions=1), client=client)
    # a failure while the parts are written leaves no directory behind
    with pytest.raises(TvoronoiError, match="cannot be written as JSON"):
        voronoi(frame_of(pts[:100], 2, z=np.arange(100) * 1j), client=client, to=tmp_path / "seq", format="geojsonseq")
    assert not (tmp_path / "seq").exists()
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "old.parquet").write_bytes(b"x")
    with pytest.raises(TvoronoiError, match="not empty"):
        voronoi(frame_of(pts[:10], 1), client=client, to=tmp_path / "full")
    with pytest.raises(TvoronoiError, match="not empty"):
        voronoi(frame_of(pts[:10], 1), client=client, to=tmp_path / "new", delaunay=tmp_path / "full")
    assert not (tmp_path / "new").exists()  # the cells' directory made first is removed again
    with pytest.raises(TvoronoiError, match="would go to one directory"):
        voronoi(frame_of(pts[:10], 1), client=client, to=tmp_path / "same", delaunay=tmp_path / "same")


def test_the_core_package_works_without_dask():
    code = (
        "import sys; sys.modules['dask'] = None; sys.modules['distributed'] = None\n"
        "import tvoronoi, tvoronoi.distributed as d\n"
        "assert tvoronoi.voronoi([[0, 0], [1, 0], [0, 1]]).n_vertices == 1\n"
        "try:\n    d.require_dask()\nexcept tvoronoi.TvoronoiError as e:\n    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "pip install 'tvoronoi[dask]'" in out


# ---------------------------------------------------------------------------------------------
# the command line: tvoronoi batch INPUT -o DIR --dask ...


def write_csv_parts(directory, pts: np.ndarray, parts: int) -> None:
    for k, chunk in enumerate(np.array_split(np.arange(len(pts)), parts)):
        pd.DataFrame({"label": [f"r{i}" for i in chunk], "x": pts[chunk, 0], "y": pts[chunk, 1]}).to_csv(
            directory / f"points-{k}.csv", index=False
        )


def test_cli_reads_a_glob_of_csv_files_on_a_running_scheduler(client, tmp_path, capsys):
    import geopandas

    from tvoronoi.cli import main

    pts = generate("gaussian", 20_000, seed=4)
    write_csv_parts(tmp_path, pts, 3)
    out, triangles = tmp_path / "cells.parquet", tmp_path / "triangles"
    status = main(
        [
            "batch",
            str(tmp_path / "points-*.csv"),
            "-o",
            str(out),
            "--dask",
            client.scheduler.address,
            "--tiles",
            "5",
            "--delaunay",
            str(triangles),
        ]
    )
    err = capsys.readouterr().err
    assert status == 0, err
    assert "3 file(s)" in err and f"Delaunay triangles -> {triangles}" in err
    frame = geopandas.read_parquet(out).sort_values("site").reset_index(drop=True)
    assert frame["label"].tolist() == [f"r{i}" for i in range(len(pts))]
    full = tvoronoi.voronoi(pts)
    assert shapely.equals_exact(frame.geometry.to_numpy(), full.to_shapely(), tolerance=0).all()
    # the triangles' parts read as one table: the same site triples as one process's --delaunay output
    tri = geopandas.read_parquet(triangles)
    sites = np.stack(tri["sites"].to_numpy())
    assert {tuple(sorted(t)) for t in sites.tolist()} == {tuple(sorted(t)) for t in full.triangles.tolist()}
    assert len(sites) == len(full.triangles)
    assert np.array_equal(shapely.get_coordinates(tri.geometry.to_numpy()).reshape(-1, 4, 2)[:, :3], pts[sites])


def test_cli_reads_a_directory_of_geoparquet_points_on_a_local_cluster(tmp_path):
    import geopandas

    from tvoronoi.cli import main

    pts = generate("clustered", 10_000, seed=6)
    source = tmp_path / "points"
    source.mkdir()
    for k, chunk in enumerate(np.array_split(np.arange(len(pts)), 2)):
        geopandas.GeoDataFrame({"w": chunk * 2.0}, geometry=geopandas.points_from_xy(*pts[chunk].T)).to_parquet(
            source / f"part{k}.parquet"
        )
    out = tmp_path / "cells"
    assert main(["batch", str(source), "-o", str(out), "--dask", "local:2", "--to", "geojsonseq", "-q"]) == 0
    import orjson

    features = [orjson.loads(line.lstrip(b"\x1e")) for part in out.iterdir() for line in part.read_bytes().splitlines()]
    assert sorted(f["properties"]["site"] for f in features) == list(range(len(pts)))
    full = tvoronoi.voronoi(pts)
    for f in features[::50]:
        i = f["properties"]["site"]
        assert f["properties"]["w"] == 2.0 * i
        assert np.array_equal(np.array(f["geometry"]["coordinates"][0][:-1]), full.cell_polygon(i))


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--dask", "loc"], "--dask 'loc': give local"),
        (["--dask", "local:0"], "needs at least one worker"),
        (["--dask", "tcp://127.0.0.1:9"], "cannot reach the Dask scheduler at tcp://127.0.0.1:9"),
        (["--tiles", "3"], "--tiles goes with --dask"),
        (["--dask", "local", "--lloyd", "2"], "--lloyd is not available with --dask"),
        (["--dask", "local", "--to", "geojson"], "OUTPUT is a directory of parts"),
        (["--dask", "local", "--delaunay", "-"], "--delaunay names a new directory of parts"),
    ],
)
def test_cli_errors_are_named(tmp_path, capsys, argv, message):
    from tvoronoi.cli import main

    write_csv_parts(tmp_path, generate("uniform", 100, seed=1), 1)
    assert main(["batch", str(tmp_path / "points-0.csv"), "-o", str(tmp_path / "out"), *argv]) == 2
    assert message in capsys.readouterr().err


def test_cli_names_a_value_that_is_not_a_number_and_writes_nothing(tmp_path, capsys):
    from tvoronoi.cli import main

    (tmp_path / "bad.csv").write_text("x,y\n1,2\n3,abc\n5,6\n")
    out = tmp_path / "cells"
    assert main(["batch", str(tmp_path / "bad.csv"), "-o", str(out), "--dask", "local:1"]) == 2
    err = capsys.readouterr().err
    assert "bad.csv, line 3: y is 'abc', not a finite number" in err
    assert "Traceback" not in err and not out.exists()


def test_cli_names_the_file_and_line_of_a_bad_value_in_a_later_block(tmp_path, capsys, monkeypatch):
    from tvoronoi import cli_distributed
    from tvoronoi.cli import main

    # small blocks: each file is read in several partitions, and the bad row lies in a later one
    monkeypatch.setattr(cli_distributed, "CSV_BLOCKSIZE", 20_000)
    write_csv_parts(tmp_path, generate("uniform", 6_000, seed=3), 3)
    path = tmp_path / "points-1.csv"
    lines = path.read_text().splitlines()
    lines.insert(1500, "")  # a blank line, skipped by the reader, counted as a line
    lines[1700] = "r9999,0.5,not-a-number"
    path.write_text("\n".join(lines) + "\n")
    out = tmp_path / "cells"
    assert main(["batch", str(tmp_path / "points-*.csv"), "-o", str(out), "--dask", "local:1"]) == 2
    err = capsys.readouterr().err
    assert f"{path}, line 1701: y is 'not-a-number', not a finite number" in err, err
    assert not out.exists()


def test_cli_names_the_parquet_file_and_row_of_a_bad_value(tmp_path, capsys):
    from tvoronoi.cli import main

    pts = generate("uniform", 3_000, seed=5)
    for k, chunk in enumerate(np.array_split(np.arange(len(pts)), 3)):
        x = pts[chunk, 0].copy()
        if k == 2:
            x[417] = np.inf
        pd.DataFrame({"x": x, "y": pts[chunk, 1]}).to_parquet(tmp_path / f"p{k}.parquet", row_group_size=300)
    assert main(["batch", str(tmp_path), "-o", str(tmp_path / "cells"), "--dask", "local:1"]) == 2
    err = capsys.readouterr().err
    assert f"{tmp_path / 'p2.parquet'}, row 417 (0-based): x is inf, not a finite number" in err, err


def test_cli_names_a_csv_file_that_cannot_be_parsed(tmp_path, capsys):
    from tvoronoi.cli import main

    write_csv_parts(tmp_path, generate("uniform", 40_000, seed=2), 2)
    path = tmp_path / "points-1.csv"
    lines = path.read_text().splitlines()
    lines[15_000] += ",1,2"  # a row with extra fields, past the sample dask reads first
    path.write_text("\n".join(lines) + "\n")
    assert main(["batch", str(tmp_path / "points-*.csv"), "-o", str(tmp_path / "cells"), "--dask", "local:1"]) == 2
    err = capsys.readouterr().err
    assert f"{path}: cannot be read (ParserError: " in err and "line 15001" in err, err


def test_a_rounds_units_go_to_the_threads_as_they_free_up(client):
    # every unit's input held by one worker: the scheduler alone would put the units there, where their
    # data is; handed out as threads free up, each worker runs its share (3 of 6 equal units)
    import time

    from tvoronoi.distributed import _run_units

    workers = sorted(client.nthreads())
    assert len(workers) == 2
    pieces = [[client.scatter(np.zeros(200_000), workers=[workers[0]])] for _ in range(6)]

    def unit(held, g):
        from distributed import get_worker

        time.sleep(0.3)
        return get_worker().address, g, None, None

    outputs = _run_units(client, pieces, [(g,) for g in range(6)], "balance-test", run=unit)
    ran = client.gather([out[0] for out in outputs])
    assert client.gather([out[1] for out in outputs]) == list(range(6))
    assert sorted(ran.count(w) for w in workers) == [3, 3], ran


def test_a_failing_unit_stops_its_round_at_once(client):
    # unit 0 fails at once, the others take 2 s each (8 of them on 2 threads: 8 s to run them all): the
    # error comes back when unit 0 ends, not once every unit has run
    import time

    from tvoronoi.distributed import _run_units

    def unit(held, g):
        if g == 0:
            raise ValueError("unit 0 cannot be built")
        time.sleep(2.0)
        return None, None, None, None

    t0 = time.perf_counter()
    with pytest.raises(ValueError, match="unit 0"):
        _run_units(client, [[] for _ in range(8)], [(g,) for g in range(8)], "failure-test", run=unit)
    assert time.perf_counter() - t0 < 4.0


def test_workers_that_join_during_a_round_get_units():
    # a cluster without workers when the round starts, two joining 0.3 s later: the round waits for them
    # and runs its units two at a time (one at a time, six units of 0.5 s would take 3 s)
    import threading
    import time

    import distributed

    from tvoronoi.distributed import _run_units

    def unit(held, g):
        time.sleep(0.5)
        return distributed.get_worker().address, g, None, None

    with distributed.LocalCluster(
        n_workers=0, processes=False, threads_per_worker=1, dashboard_address=None
    ) as cluster:
        with distributed.Client(cluster) as c:
            threading.Timer(0.3, lambda: cluster.scale(2)).start()
            t0 = time.perf_counter()
            outputs = _run_units(c, [[] for _ in range(6)], [(g,) for g in range(6)], "join-test", run=unit)
            ran = c.gather([out[0] for out in outputs])
            elapsed = time.perf_counter() - t0
    assert len(set(ran)) == 2, ran
    assert elapsed < 2.7, elapsed
