"""Exporting the view: the SVG holds the cells, edges and sites the canvas shows, in their colours; the
PNG is a valid image of the canvas's size; the key, the palette command and the dialog."""

import struct
import xml.etree.ElementTree as ET
import zlib

import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree
from textual.widgets import Input

import tvoronoi
from test_tui import SIZE, error_toasts, make_app, pilot_test
from tvoronoi.generators import generate
from tvoronoi.tui.colours import DARK, LIGHT
from tvoronoi.tui.commands import app_commands
from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
from tvoronoi.tui.export import PX_PER_DOT, picture, png_bytes, rasterise, to_svg, view_window
from tvoronoi.tui.scene import Scene
from tvoronoi.tui.screens import PathDialog
from tvoronoi.tui.viewport import View

SVG = "{http://www.w3.org/2000/svg}"
COLS, ROWS = 90, 30


@pytest.fixture(scope="module")
def zoomed():
    """A diagram of 400 sites and a view zoomed on part of it."""
    diagram = tvoronoi.voronoi(generate("uniform", 400, seed=8))
    scene = Scene.from_diagram(diagram)
    view = View.fit(diagram.bbox, COLS, ROWS).zoomed(2.5, about=(0.3, 0.6))
    return diagram, scene, view


def cells_in_window(diagram, window):
    """Ids of the cells that meet the window, by shapely."""
    box = shapely.box(*window)
    return [
        i
        for i in range(diagram.n_sites)
        if len(diagram.cell_polygon(i)) and shapely.Polygon(diagram.cell_polygon(i)).intersects(box)
    ]


def parse_svg(text: str):
    root = ET.fromstring(text)
    polygons = root.findall(f".//{SVG}polygon")
    circles = root.findall(f".//{SVG}circle")
    lines = root.findall(f".//{SVG}line")
    return root, polygons, circles, lines


def test_the_svg_holds_the_visible_cells_in_their_colours(zoomed):
    diagram, scene, view = zoomed
    pic = picture(scene, view, COLS, ROWS, DARK, dark=True, delaunay=False, diagram=diagram)
    root, polygons, circles, lines = parse_svg(to_svg(pic))
    assert (
        int(root.get("width")) == COLS * DOT_COLS * PX_PER_DOT
        and int(root.get("height")) == ROWS * DOT_ROWS * PX_PER_DOT
    )
    window = view_window(view, COLS, ROWS)
    expected = cells_in_window(diagram, window)
    assert 20 < len(expected) < diagram.n_sites  # zoomed: some cells, not all
    assert len(polygons) == len(expected)
    assert [p.get("fill") for p in polygons] == [DARK.fills[scene.colours[i]] for i in expected]
    # each polygon is its cell's ring, in the canvas's pixels
    for p, i in zip(polygons, expected):
        xy = np.array([[float(c) for c in pair.split(",")] for pair in p.get("points").split()])
        u, v = view.to_dots(*diagram.cell_polygon(i).T, COLS, ROWS)
        assert np.allclose(xy, np.column_stack([u, v]) * PX_PER_DOT, atol=0.01)
    # the sites in the window, and no Delaunay edges when they are hidden
    x0, y0, x1, y1 = window
    s = diagram.sites
    assert len(circles) == int(((s[:, 0] >= x0) & (s[:, 0] <= x1) & (s[:, 1] >= y0) & (s[:, 1] <= y1)).sum())
    assert not lines


def test_the_svg_draws_the_delaunay_edges_when_shown_and_the_light_theme(zoomed):
    diagram, scene, view = zoomed
    pic = picture(scene, view, COLS, ROWS, LIGHT, dark=False, delaunay=True, diagram=diagram)
    _, polygons, _, lines = parse_svg(to_svg(pic))
    assert len(lines) == len(pic.delaunay) > 0
    assert {p.get("fill") for p in polygons} <= set(LIGHT.fills)


def test_an_edited_scene_exports_the_diagram_of_its_sites(zoomed):
    """A scene whose rows are not a diagram's cells (edited): its cells are built from its sites."""
    diagram, scene, view = zoomed
    pic = picture(scene, view, COLS, ROWS, DARK, dark=True, delaunay=False)
    _, polygons, _, _ = parse_svg(to_svg(pic))
    assert len(polygons) == len(cells_in_window(diagram, view_window(view, COLS, ROWS)))


def decode_png(data: bytes) -> np.ndarray:
    """A minimal PNG reader for the files export writes (8-bit RGB, filter 0)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at, chunks = 8, []
    while at < len(data):
        (length,) = struct.unpack(">I", data[at : at + 4])
        kind, body = data[at + 4 : at + 8], data[at + 8 : at + 8 + length]
        (crc,) = struct.unpack(">I", data[at + 8 + length : at + 12 + length])
        assert crc == zlib.crc32(kind + body) & 0xFFFFFFFF
        chunks.append((kind, body))
        at += 12 + length
    assert chunks[0][0] == b"IHDR" and chunks[-1][0] == b"IEND"
    w, h, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
    assert (depth, colour, interlace) == (8, 2, 0)
    raw = np.frombuffer(zlib.decompress(b"".join(b for k, b in chunks if k == b"IDAT")), np.uint8)
    rows = raw.reshape(h, 1 + 3 * w)
    assert (rows[:, 0] == 0).all()
    return rows[:, 1:].reshape(h, w, 3)


def test_the_png_is_the_canvas_size_and_shows_each_cell_in_its_colour(zoomed):
    diagram, scene, view = zoomed
    pic = picture(scene, view, COLS, ROWS, DARK, dark=True, delaunay=False, diagram=diagram)
    image = decode_png(png_bytes(rasterise(pic)))
    h, w = image.shape[:2]
    assert (w, h) == (COLS * DOT_COLS * PX_PER_DOT, ROWS * DOT_ROWS * PX_PER_DOT)
    # every pixel: the fill of the cell of its nearest site (brute force), or an edge or a site
    u = (np.arange(w) + 0.5) / PX_PER_DOT
    v = (np.arange(h) + 0.5) / PX_PER_DOT
    xs, _ = view.to_world(u, 0 * u, COLS, ROWS)
    _, ys = view.to_world(0 * v, v, COLS, ROWS)
    gx, gy = np.meshgrid(xs, ys)
    _, owner = cKDTree(diagram.sites).query(np.column_stack([gx.ravel(), gy.ravel()]))
    fills = np.array([[int(c[k : k + 2], 16) for k in (1, 3, 5)] for c in DARK.fills], np.uint8)
    expected = fills[scene.colours[owner]].reshape(h, w, 3)
    same = (image == expected).all(axis=2)
    marks = np.array([[int(c[k : k + 2], 16) for k in (1, 3, 5)] for c in (DARK.edge, DARK.site)], np.uint8)
    marked = (image[:, :, None, :] == marks[None, None]).all(axis=3).any(axis=2)
    assert (same | marked).all()
    assert same.mean() > 0.8


# -- in the app ------------------------------------------------------------------------------------


async def export_through_dialog(app, pilot, path):
    await pilot.press("e")
    await pilot.pause()
    assert isinstance(app.screen, PathDialog)
    field = app.screen.query_one("#path", Input)
    field.value = str(path)
    await pilot.press("enter")
    await app.workers.wait_for_complete()
    await pilot.pause()


@pilot_test
async def test_e_exports_the_view_as_svg_and_png(tmp_path):
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        await pilot.press("plus", "plus", "right", "d")
        await pilot.pause()
        await export_through_dialog(app, pilot, tmp_path / "view.svg")
        assert app.focused is app.canvas
        canvas = app.canvas
        cols, rows = canvas.content_size.width, canvas.content_size.height
        _, polygons, circles, lines = parse_svg((tmp_path / "view.svg").read_text())
        diagram = app.built.diagram
        expected = cells_in_window(diagram, view_window(canvas.view, cols, rows))
        assert len(polygons) == len(expected) < diagram.n_sites
        assert [p.get("fill") for p in polygons] == [DARK.fills[app.built.scene.colours[i]] for i in expected]
        assert lines  # Delaunay shown
        await export_through_dialog(app, pilot, tmp_path / "view.png")
        image = decode_png((tmp_path / "view.png").read_bytes())
        assert image.shape == (rows * DOT_ROWS * PX_PER_DOT, cols * DOT_COLS * PX_PER_DOT, 3)
        assert not error_toasts(app)


@pilot_test
async def test_export_refuses_another_format_and_playback(tmp_path):
    app = make_app()
    async with app.run_test(size=SIZE, notifications=True) as pilot:
        await pilot.pause()
        await export_through_dialog(app, pilot, tmp_path / "view.jpg")
        assert not (tmp_path / "view.jpg").exists()
        assert any(".svg or .png" in " ".join(text.split()) for text in error_toasts(app))
        assert "Export" in [c.title for c in app_commands(app)]
        await pilot.press("t")
        await pilot.pause()
        assert app.check_action("export", ()) is False
        assert "Export" not in [c.title for c in app_commands(app)]
