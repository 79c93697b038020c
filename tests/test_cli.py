"""The console script: batch runs end to end, every failure as one line and an exit status, outputs atomic."""

from __future__ import annotations

import errno
import io
import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

import tvoronoi
from conftest import DATASETS
from test_geojson import check_cells_document, grown_box, hull_size, load, temp_files
from tvoronoi import cli
from tvoronoi.writers import geojson_diagram

ROOT = Path(__file__).resolve().parents[1]
DUPLICATE_WARNING = (
    'tvoronoi: warning: 3 repeated points share the cell of an earlier point (see "duplicates" in the output)\n'
)


class FakeStdin:
    def __init__(self, data: bytes):
        self.buffer = io.BytesIO(data)


def run(capsys, *args) -> tuple[int, str, str]:
    """main(args) -> (exit status, stdout, stderr)."""
    status = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return status, out, err


def csv_text(sites: np.ndarray, names: list[str] | None = None) -> str:
    lines = ["x,y,name"]
    for i, (x, y) in enumerate(sites.tolist()):
        lines.append(f"{x!r},{y!r},{names[i] if names else f'p{i}'}")
    return "\n".join(lines) + "\n"


SITES = np.concatenate([DATASETS["uniform"][:60], DATASETS["uniform"][[4, 9, 4]]])  # rows 60-62 repeat 4, 9, 4


@pytest.fixture
def points_csv(tmp_path) -> Path:
    path = tmp_path / "points.csv"
    path.write_text(csv_text(SITES))
    return path


def snapshot(path: Path) -> tuple[bytes, int]:
    return path.read_bytes(), path.stat().st_mtime_ns


# ---------------------------------------------------------------------------
# success


def test_batch_writes_valid_cells_with_properties_and_duplicates(capsys, tmp_path, points_csv):
    out = tmp_path / "cells.geojson"
    status, stdout, stderr = run(capsys, "batch", points_csv, "-o", out)
    assert status == 0
    assert stdout == ""
    assert stderr == DUPLICATE_WARNING
    doc = load(out)
    check_cells_document(doc, SITES, grown_box(SITES))
    props = {f["properties"]["site"]: f["properties"] for f in doc["features"]}
    assert sorted(props) == list(range(60))
    assert all(p["name"] == f"p{i}" for i, p in props.items())
    assert props[4]["duplicates"] == [60, 62] and props[9]["duplicates"] == [61]
    assert sum("duplicates" in p for p in props.values()) == 2
    assert temp_files(tmp_path) == []


def test_quiet_prints_nothing(capsys, tmp_path, points_csv):
    status, stdout, stderr = run(capsys, "batch", points_csv, "-o", tmp_path / "c.geojson", "-q")
    assert (status, stdout, stderr) == (0, "", "")


def test_bbox_is_respected_and_may_start_negative(capsys, tmp_path, points_csv):
    out = tmp_path / "cells.geojson"
    box = (-0.5, -0.25, 2.0, 1.5)
    status, _, _ = run(capsys, "batch", points_csv, "-o", out, "--bbox", ",".join(map(str, box)))
    assert status == 0
    doc = load(out)
    assert doc["bbox"] == list(box)
    check_cells_document(doc, SITES, box)


def test_bbox_leaving_sites_out_writes_null_cells_and_warns(capsys, tmp_path, points_csv):
    out = tmp_path / "cells.geojson"
    box = (0.0, 0.0, 0.5, 0.5)
    status, _, stderr = run(capsys, "batch", points_csv, "-o", out, "--bbox=0,0,0.5,0.5")
    assert status == 0
    doc = load(out)
    nulls = [f["properties"]["site"] for f in doc["features"] if f["geometry"] is None]
    assert nulls and 'written with "geometry": null' in stderr and f"{len(nulls)} cells miss the box" in stderr
    check_cells_document(doc, SITES, box, sites_in_box=False)


def test_delaunay_file_has_2n_minus_2_minus_h_triangles(capsys, tmp_path, points_csv):
    cells, triangles = tmp_path / "cells.geojson", tmp_path / "tri.geojson"
    status, _, _ = run(capsys, "batch", points_csv, "-o", cells, "--delaunay", triangles, "-q")
    assert status == 0
    distinct = SITES[:60]
    assert len(load(triangles)["features"]) == 2 * len(distinct) - 2 - hull_size(distinct)
    assert len(load(cells)["features"]) == 60


def test_output_to_stdout(capsys, tmp_path, points_csv):
    status, stdout, stderr = run(capsys, "batch", points_csv, "-o", "-")
    assert status == 0 and stderr == DUPLICATE_WARNING
    doc = load(stdout.encode())
    check_cells_document(doc, SITES, grown_box(SITES))
    assert os.listdir(tmp_path) == ["points.csv"]


def test_input_from_stdin(capsys, monkeypatch, tmp_path):
    sites = DATASETS["gaussian"][:50]
    monkeypatch.setattr(sys, "stdin", FakeStdin(csv_text(sites).encode()))
    out = tmp_path / "cells.geojson"
    status, _, stderr = run(capsys, "batch", "-", "-o", out, "--format", "csv")
    assert (status, stderr) == (0, "")
    check_cells_document(load(out), sites, grown_box(sites))


def test_semicolon_csv_from_stdin_is_recognised(capsys, monkeypatch, tmp_path):
    """A spreadsheet's export piped in, with no name to tell its format: its semicolons are found."""
    sites = DATASETS["uniform"][:30]
    text = "name;lon;lat\n" + "".join(
        f"s{i};{x!r};{y!r}\n".replace(".", ",") for i, (x, y) in enumerate(sites.tolist())
    )
    monkeypatch.setattr(sys, "stdin", FakeStdin(text.encode()))
    out = tmp_path / "cells.geojson"
    status, _, stderr = run(capsys, "batch", "-", "-o", out)
    assert status == 0, stderr
    doc = load(out)
    check_cells_document(doc, sites, grown_box(sites))
    assert {f["properties"]["name"] for f in doc["features"]} == {f"s{i}" for i in range(30)}


def test_columns_chosen_with_x_and_y(capsys, tmp_path):
    path = tmp_path / "t.txt"
    sites = DATASETS["clustered"][:40]
    path.write_text("".join(f"{i} {y!r} {x!r}\n" for i, (x, y) in enumerate(sites.tolist())))
    out = tmp_path / "cells.geojson"
    status, _, _ = run(capsys, "batch", path, "-o", out, "--x", "2", "--y", "1")
    assert status == 0
    doc = load(out)
    check_cells_document(doc, sites, grown_box(sites))
    assert [f["properties"]["col1"] for f in doc["features"]] == list(range(40))


def test_force_replaces_an_existing_output(capsys, tmp_path, points_csv):
    out = tmp_path / "cells.geojson"
    out.write_bytes(b"old")
    status, _, _ = run(capsys, "batch", points_csv, "-o", out, "--force", "-q")
    assert status == 0
    assert len(load(out)["features"]) == 60


def test_progress_on_a_terminal_only_and_not_with_quiet(capsys, monkeypatch, tmp_path, points_csv):
    monkeypatch.setattr(cli, "PROGRESS_MIN_POINTS", 10)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    status, _, stderr = run(capsys, "batch", points_csv, "-o", tmp_path / "a.geojson")
    assert status == 0 and "write cells" in stderr and "60/60" in stderr
    status, _, stderr = run(capsys, "batch", points_csv, "-o", tmp_path / "b.geojson", "-q")
    assert (status, stderr) == (0, "")
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    status, _, stderr = run(capsys, "batch", points_csv, "-o", tmp_path / "c.geojson")
    assert (status, stderr) == (0, DUPLICATE_WARNING)


def test_version_and_help(capsys):
    status, stdout, _ = run(capsys, "--version")
    assert (status, stdout) == (0, f"tvoronoi {tvoronoi.__version__}\n")
    status, stdout, _ = run(capsys, "batch", "--help")
    assert status == 0 and "--force" in stdout and "exit status" in stdout


def test_without_a_command_the_tui_starts(capsys, monkeypatch):
    calls = []
    monkeypatch.setitem(
        sys.modules, "tvoronoi.tui.app", types.SimpleNamespace(main=lambda path=None: calls.append(path))
    )
    assert run(capsys) == (0, "", "")
    assert calls == [None]


def test_without_a_tui_one_line_error(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tvoronoi.tui.app", None)  # import fails
    status, _, stderr = run(capsys)
    assert status == 1
    assert stderr.startswith("tvoronoi: error: the terminal UI cannot start") and stderr.count("\n") == 1


# ---------------------------------------------------------------------------
# errors: one line, exit 2 for input and options, nothing written


def assert_error(capsys, tmp_path, *args, status=2, contains=()):
    out = tmp_path / "cells.geojson"
    code, stdout, stderr = run(capsys, "batch", *args, "-o", out)
    assert code == status
    assert stderr.startswith("tvoronoi: error: ") and stderr.count("\n") == 1, stderr
    assert "Traceback" not in stderr
    for text in contains:
        assert text in stderr
    assert not out.exists()
    assert temp_files(tmp_path) == []
    return stderr


def test_missing_file(capsys, tmp_path):
    assert_error(capsys, tmp_path, tmp_path / "nope.csv", contains=["nope.csv", "no such file"])


def test_empty_file(capsys, tmp_path):
    path = tmp_path / "empty.csv"
    path.write_text("")
    assert_error(capsys, tmp_path, path, contains=["empty.csv", "no points"])


def test_bad_row_names_file_and_line(capsys, tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("x,y\n0,0\n1,0\n0,one\n1,1\n")
    assert_error(capsys, tmp_path, path, contains=["bad.csv", "line 4"])


def test_nan_coordinate(capsys, tmp_path):
    path = tmp_path / "nan.csv"
    path.write_text("x,y\n0,0\n1,0\nnan,1\n1,1\n")
    assert_error(capsys, tmp_path, path, contains=["nan.csv", "line 4", "finite"])


@pytest.mark.parametrize(
    "value, why",
    [
        ("1,2,3", "expected four numbers XMIN,YMIN,XMAX,YMAX, got 3"),
        ("0,0,a,1", "'a' is not a number; expected XMIN,YMIN,XMAX,YMAX"),
        ("0,0,inf,1", "'inf' is not a finite number"),
        ("0, 0,nan ,1", "'nan' is not a finite number"),
        ("1,0,0,1", "the box is empty; it needs XMIN < XMAX and YMIN < YMAX"),
        ("0,1,1,1", "the box is empty; it needs XMIN < XMAX and YMIN < YMAX"),
        ("", "expected four numbers XMIN,YMIN,XMAX,YMAX, got 1"),
    ],
)
def test_bad_bbox_names_the_value(capsys, tmp_path, points_csv, value, why):
    """The API's box check (tvoronoi.api.as_bbox) in the CLI's words: the option, the text given, upper-case names."""
    stderr = assert_error(capsys, tmp_path, points_csv, f"--bbox={value}", contains=[why])
    assert stderr == f"tvoronoi: error: --bbox {value!r}: {why}\n"


def test_a_tiny_bbox_around_tiny_sites_is_accepted(capsys, tmp_path):
    """The box's range is judged against the sites read, not before reading them."""
    path = tmp_path / "tiny.csv"
    sites = np.array([[1e-250, 1e-250], [3e-250, 2e-250], [2e-250, 4e-250]])
    path.write_text(csv_text(sites))
    out = tmp_path / "cells.geojson"
    status, _, stderr = run(capsys, "batch", path, "-o", out, "--bbox", "0,0,5e-250,5e-250")
    assert status == 0, stderr
    doc = load(out)
    assert doc["bbox"] == [0.0, 0.0, 5e-250, 5e-250]
    assert all(f["geometry"]["type"] == "Polygon" for f in doc["features"])


def test_a_bbox_out_of_range_for_the_sites_is_refused(capsys, tmp_path, points_csv):
    assert_error(
        capsys, tmp_path, points_csv, "--bbox=0,0,1e-250,1", contains=["xmax = 1e-250 is beyond the exact range"]
    )


def test_engine_fortune_writes_the_same_valid_cells(capsys, tmp_path, points_csv):
    out = tmp_path / "cells.geojson"
    status, _, _ = run(capsys, "batch", points_csv, "-o", out, "--engine", "fortune", "-q")
    assert status == 0
    doc = load(out)
    check_cells_document(doc, SITES, grown_box(SITES))
    ref = tmp_path / "ref.geojson"
    assert run(capsys, "batch", points_csv, "-o", ref, "-q")[0] == 0
    rings = [len(f["geometry"]["coordinates"][0]) for f in doc["features"]]
    assert rings == [len(f["geometry"]["coordinates"][0]) for f in load(ref)["features"]]


def test_unknown_engine_is_a_usage_error(capsys, tmp_path, points_csv):
    status, _, stderr = run(capsys, "batch", points_csv, "-o", tmp_path / "c.geojson", "--engine", "bogus")
    assert status == 2 and "invalid choice" in stderr
    assert not (tmp_path / "c.geojson").exists()


def test_stdout_cannot_take_both_outputs(capsys, tmp_path, points_csv):
    status, stdout, stderr = run(capsys, "batch", points_csv, "-o", "-", "--delaunay", "-")
    assert status == 2 and stdout == "" and "stdout" in stderr


# ---------------------------------------------------------------------------
# existing outputs are never harmed


@pytest.fixture
def existing(tmp_path) -> Path:
    path = tmp_path / "cells.geojson"
    path.write_bytes(b'{"precious": true}\n')
    os.utime(path, ns=(1_000_000_000, 1_000_000_000))
    return path


def test_existing_output_is_refused_without_force(capsys, tmp_path, points_csv, existing):
    before = snapshot(existing)
    status, _, stderr = run(capsys, "batch", points_csv, "-o", existing)
    assert status == 2 and "exists" in stderr and "--force" in stderr
    assert snapshot(existing) == before
    assert temp_files(tmp_path) == []


@pytest.mark.parametrize("content", ["", "x,y\n0,0\n1,zero\n"])
def test_failing_run_leaves_existing_output_untouched(capsys, tmp_path, existing, content):
    bad = tmp_path / "bad.csv"
    bad.write_text(content)
    before = snapshot(existing)
    status, _, stderr = run(capsys, "batch", bad, "-o", existing, "--delaunay", tmp_path / "tri.geojson", "--force")
    assert status == 2
    assert stderr.startswith("tvoronoi: error: ") and str(bad) in stderr
    assert snapshot(existing) == before
    assert not (tmp_path / "tri.geojson").exists()
    assert temp_files(tmp_path) == []


def test_write_failure_exits_1_and_leaves_files_untouched(capsys, monkeypatch, tmp_path, points_csv, existing):
    def disk_full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(geojson_diagram, "write_delaunay", disk_full)
    before = snapshot(existing)
    tri = tmp_path / "tri.geojson"
    status, _, stderr = run(capsys, "batch", points_csv, "-o", existing, "--delaunay", tri, "--force")
    assert status == 1
    assert stderr.endswith(f"tvoronoi: error: cannot write {tri}: No space left on device\n")
    # the cells were written in full, but are not renamed into place when the triangles fail
    assert snapshot(existing) == before
    assert temp_files(tmp_path) == []


def test_missing_output_directory_exits_1(capsys, tmp_path, points_csv):
    status, _, stderr = run(capsys, "batch", points_csv, "-o", tmp_path / "no" / "cells.geojson")
    assert status == 1 and "cannot write" in stderr and "No such file or directory" in stderr


def test_interrupt_removes_the_temporary_file(capsys, monkeypatch, tmp_path, points_csv, existing):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(geojson_diagram, "write_cells", interrupted)
    before = snapshot(existing)
    status, _, stderr = run(capsys, "batch", points_csv, "-o", existing, "--force")
    assert status == 130 and stderr.endswith("tvoronoi: error: interrupted\n")
    assert snapshot(existing) == before
    assert temp_files(tmp_path) == []


# ---------------------------------------------------------------------------
# the real process


def test_subprocess_exit_status_and_no_traceback(tmp_path, existing):
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y\n0,0\n1,1\n2,oops\n")
    before = snapshot(existing)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run(
        [sys.executable, "-m", "tvoronoi.cli", "batch", str(bad), "-o", str(existing), "--force"],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
        timeout=120,
    )
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.startswith("tvoronoi: error: ") and "line 4" in proc.stderr
    assert "Traceback" not in proc.stderr and proc.stderr.count("\n") == 1
    assert snapshot(existing) == before
    assert temp_files(tmp_path) == []


# ---------------------------------------------------------------------------
# column choice and coordinate errors, as a user sees them


def test_chosen_columns_are_reported_unless_quiet(capsys, tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("id,easting,northing,name\n1,0,0,a\n2,10,0,b\n3,0,10,c\n4,7,7,d\n")
    status, _, err = run(capsys, "batch", path, "-o", tmp_path / "a.geojson")
    assert status == 0
    assert err == f'tvoronoi: {path}: x = "easting", y = "northing" (by name); choose others with --x/--y\n'
    status, _, err = run(capsys, "batch", path, "-o", tmp_path / "b.geojson", "-q")
    assert (status, err) == (0, "")


def test_id_column_is_skipped_and_said(capsys, tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("fid,a,b\n1,0,0\n2,10,0\n3,0,10\n")
    status, _, err = run(capsys, "batch", path, "-o", tmp_path / "a.geojson")
    assert status == 0 and 'x = "a", y = "b" (the first numeric columns); skipped the id-like column "fid"' in err
    doc = load(tmp_path / "a.geojson")
    assert [f["properties"]["fid"] for f in doc["features"]] == [1, 2, 3]


def test_semicolon_file_with_delimiter_option(capsys, tmp_path):
    path = tmp_path / "p.txt"
    path.write_text("x;y;zip\n0;0;01000\n1;0;02000\n0;1;03000\n")
    status, _, err = run(capsys, "batch", path, "--delimiter", ";", "-o", tmp_path / "a.geojson")
    assert (status, err) == (0, "")
    doc = load(tmp_path / "a.geojson")
    assert [f["properties"]["zip"] for f in doc["features"]] == ["01000", "02000", "03000"]


def test_range_error_names_file_line_and_value_without_numpy_warnings(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("x,y\n1,1\n2,3\n1e60,2\n3,3\n")
    proc = subprocess.run(
        [sys.executable, "-m", "tvoronoi", "batch", str(path), "-o", str(tmp_path / "o.geojson")],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        timeout=120,
    )
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"tvoronoi: error: {path}, line 2: coordinate 1.0 is over 1e51 times smaller")
    assert "1e+60 (line 4)" in proc.stderr and "np.float64" not in proc.stderr
    assert proc.stderr.count("\n") == 1


def test_values_at_the_edge_of_the_double_range_leak_no_warning(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("x,y\n1e308,1e308\n-1.7e308,-1e308\n1e308,-1.5e308\n")
    proc = subprocess.run(
        [sys.executable, "-m", "tvoronoi", "batch", str(path), "-o", str(tmp_path / "o.geojson")],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        timeout=120,
    )
    assert "Warning" not in proc.stderr and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.count("\n") <= 1


def test_unsupported_format_is_a_usage_error(capsys, tmp_path):
    path = tmp_path / "points.gpkg"
    path.write_bytes(b"SQLite format 3\x00" + bytes(200))
    status, _, err = run(capsys, "batch", path, "-o", tmp_path / "a.geojson")
    assert status == 2 and "GeoPackage" in err and "ogr2ogr" in err and err.count("\n") == 1


def test_tvoronoi_file_opens_the_ui_on_that_file(monkeypatch, tmp_path, capsys):
    """`tvoronoi FILE` starts the terminal UI on FILE; a missing FILE is a usage error naming it."""
    import tvoronoi.tui.app as app

    seen = []
    monkeypatch.setattr(app, "main", lambda path=None: seen.append(path) or 0)
    src = tmp_path / "pts.csv"
    src.write_text("x,y\n0,0\n1,0\n0,1\n")
    assert cli.main([str(src)]) == 0
    assert seen == [str(src)]
    assert cli.main([]) == 0 and seen[-1] is None
    code = cli.main([str(tmp_path / "nope.csv")])
    assert code != 0 and seen == [str(src), None]
    assert "nope.csv: no such file" in capsys.readouterr().err


def test_a_usage_error_names_the_batch_command_alone(capsys, tmp_path, points_csv):
    """argparse's message for a bad option of batch: 'tvoronoi batch', not the main usage line pasted in."""
    status, _, err = run(capsys, "batch", points_csv, "-o", tmp_path / "c.geojson", "--to", "gpkg")
    assert status == 2
    assert err.startswith("usage: tvoronoi batch [-h]")
    assert "tvoronoi batch: error: argument --to: invalid choice: 'gpkg'" in err
    assert "FILE |" not in err
