"""The Open dialog browses (a directory tree, path completion, the last folder remembered) and asks
which columns are x and y when a table leaves that ambiguous."""

from pathlib import Path

import numpy as np
from textual.widgets import Button, DirectoryTree, Input, Select

from test_tui import SIZE, make_app, pilot_test
from tvoronoi.readers import read_points
from tvoronoi.tui.screens import ColumnsDialog, OpenDialog, complete_path

AMBIGUOUS = "a,b,c,name\n1,10,100,u\n2,20,200,v\n3,30,300,w\n4,40,250,z\n"


def test_path_completion(tmp_path):
    (tmp_path / "points.csv").write_text("x,y\n0,0\n")
    (tmp_path / "plots").mkdir()
    (tmp_path / ".hidden.csv").write_text("x,y\n0,0\n")
    base = str(tmp_path)
    # the first entry that starts with what is typed; a folder ends with a slash
    assert complete_path(f"{base}/pl") == f"{base}/plots/"
    assert complete_path(f"{base}/po") == f"{base}/points.csv"
    assert complete_path(f"{base}/") == f"{base}/plots/"  # hidden entries only when asked for
    assert complete_path(f"{base}/.h") == f"{base}/.hidden.csv"
    # nothing to add, nothing that matches, a folder that is not there
    assert complete_path(f"{base}/points.csv") is None
    assert complete_path(f"{base}/q") is None
    assert complete_path(f"{base}/nowhere/p") is None
    assert complete_path("") is None


async def open_file(app, pilot, path, *, x="", y=""):
    await pilot.press("o")
    await pilot.pause()
    app.screen.query_one("#path", Input).value = str(path)
    app.screen.query_one("#x-column", Input).value = x
    app.screen.query_one("#y-column", Input).value = y
    await pilot.press("enter")
    await app.workers.wait_for_complete()
    await pilot.pause()


@pilot_test
async def test_the_tree_starts_in_the_last_folder_and_a_file_chosen_there_opens(tmp_path):
    first = tmp_path / "one"
    first.mkdir()
    (first / "a.csv").write_text("x,y\n0,0\n1,0\n0,1\n")
    (first / "b.csv").write_text("x,y\n0,0\n2,0\n0,2\n1,1\n")
    (first / "notes.md").write_text("not points")
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await open_file(app, pilot, first / "a.csv")
        assert app.built.source == "a.csv"
        await pilot.press("o")
        await pilot.pause()
        dialog = app.screen
        assert isinstance(dialog, OpenDialog)
        tree = dialog.query_one(DirectoryTree)
        assert tree.path == first.resolve()
        for _ in range(50):  # the tree lists its folder in a worker
            await pilot.pause(0.02)
            if tree.root.children:
                break
        listed = [node.data.path.name for node in tree.root.children]
        assert listed == ["a.csv", "b.csv"]  # point files only
        # choose b.csv in the tree: into the field; Enter on it again opens it
        tree.focus()
        tree.move_cursor(tree.root.children[1])
        await pilot.press("enter")
        await pilot.pause()
        assert dialog.query_one("#path", Input).value == str((first / "b.csv").resolve())
        await pilot.press("enter")
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert app.built.source == "b.csv" and app.built.diagram.n_sites == 4
        assert app.focused is app.canvas


@pilot_test
async def test_ambiguous_columns_are_asked_for_and_the_choice_reopens_the_file(tmp_path):
    path = tmp_path / "table.csv"
    path.write_text(AMBIGUOUS)
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await open_file(app, pilot, path)
        # the reader's choice is shown, and the question asked
        np.testing.assert_array_equal(app.built.diagram.sites, read_points(str(path)).xy)
        dialog = app.screen
        assert isinstance(dialog, ColumnsDialog)
        assert dialog.candidates == ("a", "b", "c")
        assert dialog.query_one("#x-choice", Select).value == "a"
        assert dialog.query_one("#y-choice", Select).value == "b"
        dialog.query_one("#x-choice", Select).value = "c"
        dialog.query_one("#y-choice", Select).value = "a"
        dialog.query_one("#use", Button).press()
        await pilot.pause()
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert not isinstance(app.screen, ColumnsDialog)  # asked once: the columns are given now
        assert app.built.point_set.xy_columns == ("c", "a")
        np.testing.assert_array_equal(app.built.diagram.sites, read_points(str(path), x="c", y="a").xy)
        assert app.focused is app.canvas
        # the Open dialog offers the columns chosen
        await pilot.press("o")
        await pilot.pause()
        assert app.screen.query_one("#x-column", Input).value == "c"


@pilot_test
async def test_escape_keeps_the_readers_columns_and_clear_files_ask_nothing(tmp_path):
    path = tmp_path / "table.csv"
    path.write_text(AMBIGUOUS)
    named = tmp_path / "named.csv"
    named.write_text("lon,lat,pop\n1,2,3\n4,5,6\n7,0,9\n")
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await open_file(app, pilot, path)
        assert isinstance(app.screen, ColumnsDialog)
        built = app.built
        await pilot.press("escape")
        await pilot.pause()
        assert app.built is built and app.built.point_set.xy_columns == ("a", "b")
        await open_file(app, pilot, named)
        assert not isinstance(app.screen, ColumnsDialog)
        # columns given in the Open dialog: nothing to ask
        await open_file(app, pilot, path, x="b", y="c")
        assert not isinstance(app.screen, ColumnsDialog)
        assert app.built.point_set.xy_columns == ("b", "c")


@pilot_test
async def test_the_same_column_twice_is_refused_in_the_dialog(tmp_path):
    path = tmp_path / "table.csv"
    path.write_text(AMBIGUOUS)
    app = make_app()
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await open_file(app, pilot, path)
        dialog = app.screen
        dialog.query_one("#y-choice", Select).value = "a"
        dialog.query_one("#use", Button).press()
        await pilot.pause()
        assert app.screen is dialog
        assert "must differ" in str(dialog.query_one("#dialog-hint").render())


DATA = Path(__file__).resolve().parent.parent / "data"


def test_snapshot_open_dialog_browsing_at_80x24(snap_compare):
    """80 x 24, the Open dialog after a file of data/ was opened: the path field (completion
    offered as typed), below it the directory tree of data/ (folders and point files only),
    the x and y column fields and the hint, all within the terminal."""

    async def open_dialog(pilot):
        pilot.app.files.last_folder = DATA
        await pilot.press("o")
        tree = pilot.app.screen.query_one(DirectoryTree)
        for _ in range(50):
            await pilot.pause(0.02)
            if tree.root.children:
                break

    assert snap_compare(make_app(), run_before=open_dialog, terminal_size=(80, 24))


def test_snapshot_columns_dialog(snap_compare, tmp_path):
    """A table of three numeric columns named neither x/y nor lon/lat, just opened: the dialog
    says which two were taken and offers each column for x and for y, with a Use button."""
    path = tmp_path / "table.csv"
    path.write_text(AMBIGUOUS)

    async def open_table(pilot):
        await open_file(pilot.app, pilot, path)

    assert snap_compare(make_app(), run_before=open_table, terminal_size=SIZE)
