"""The braille rasterizer and the cell colouring of the terminal UI, without a terminal."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import tvoronoi
from conftest import DATASETS
from tvoronoi.generators import generate
from tvoronoi.tui.colours import DARK, LIGHT, cell_adjacency, cell_colours, colour_graph
from tvoronoi.tui.dots import BRAILLE_BLANK, DOT_COLS, DOT_ROWS, braille_text, pack_braille, point_dots, segment_dots
from tvoronoi.tui.layers import EDGE, SITE
from tvoronoi.tui.raster import rasterize
from tvoronoi.tui.scene import Scene
from tvoronoi.tui.styles import frame_lines
from tvoronoi.tui.viewport import View


def test_dot_bits_follow_the_braille_standard():
    """Each dot of a character lights the bit Unicode gives it."""
    expected = {
        (0, 0): 0x01,
        (0, 1): 0x02,
        (0, 2): 0x04,
        (1, 0): 0x08,
        (1, 1): 0x10,
        (1, 2): 0x20,
        (0, 3): 0x40,
        (1, 3): 0x80,
    }
    for (col, row), bit in expected.items():
        dots = np.zeros((4, 2), bool)
        dots[row, col] = True
        assert pack_braille(dots)[0, 0] == bit
    assert pack_braille(np.ones((4, 2), bool))[0, 0] == 0xFF
    assert braille_text(np.array([0xFF, 0, 0x01], np.uint8)) == "\u28ff \u2801"


def test_horizontal_segment_sets_one_dot_row():
    dots = np.zeros((8, 10), bool)
    segment_dots(dots, [0.5], [5.5], [9.5], [5.5])
    assert dots[5].all()
    assert dots.sum() == 10
    codes = pack_braille(dots)
    # dot row 5 is row 1 of the second character row: bits 0x02 and 0x10
    assert (codes[1] == 0x12).all()
    assert (codes[0] == 0).all()


def test_vertical_and_diagonal_segments_have_no_gaps():
    dots = np.zeros((20, 20), bool)
    segment_dots(dots, [2.5, 0.5], [0.5, 0.5], [2.5, 19.5], [19.5, 19.5])
    assert dots[:, 2].all()
    assert np.diag(dots).all()


def reference_dots(shape, u0, v0, u1, v1) -> np.ndarray:
    """One segment at a time, in plain Python: its ends, and a sample at every dot centre line of
    its longer axis between them (pulled back onto the segment at its ends)."""
    dots = np.zeros(shape, bool)

    def put(u, v):
        if 0 <= u < shape[1] and 0 <= v < shape[0]:
            dots[int(v), int(u)] = True

    for a in zip(u0, v0, u1, v1):
        x0, y0, x1, y1 = (float(c) for c in a)
        put(x0, y0)
        put(x1, y1)
        steep = abs(y1 - y0) > abs(x1 - x0)
        p0, p1 = ((y0, x0), (y1, x1)) if steep else ((x0, y0), (x1, y1))
        if p1[0] < p0[0]:
            p0, p1 = p1, p0
        k0, k1 = int(np.floor(p0[0])), int(np.floor(p1[0]))
        for k in range(k0, k1 + 1):
            a = min(max(k + 0.5, p0[0]), p1[0])
            span = p1[0] - p0[0]
            b = p0[1] + (a - p0[0]) * ((p1[1] - p0[1]) / span if span > 0 else 0.0)
            put(b, a) if steep else put(a, b)
    return dots


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0.2, 0.7, 1.5, 6.0]))
def test_many_short_and_long_segments_set_the_dots_of_each_drawn_alone(seed, length):
    """Sub-dot edges (most of a zoomed-out view) take a shortcut: the dots must stay those of
    the segment-by-segment reference."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.0, 30.0, (300, 2))
    q = p + rng.normal(0.0, length, (300, 2))
    half = rng.random(300) < 0.3  # ends on dot borders and centres too
    p[half], q[half] = np.round(p[half] * 2) / 2, np.round(q[half] * 2) / 2
    dots = np.zeros((28, 28), bool)
    segment_dots(dots, p[:, 0], p[:, 1], q[:, 0], q[:, 1])
    inside = (np.minimum(p, q) >= 0).all(axis=1) & (np.maximum(p, q) < 28).all(axis=1)
    expected = reference_dots((28, 28), *p[inside].T, *q[inside].T)
    alone = np.zeros((28, 28), bool)
    segment_dots(alone, *p[inside].T, *q[inside].T)
    assert (alone == expected).all()
    assert (dots | alone == dots).all()


def test_crossing_lines_keep_all_their_dots():
    """Where two lines meet in one character, both keep every dot (bit patterns are OR-ed)."""
    alone_h = np.zeros((8, 8), bool)
    alone_v = np.zeros((8, 8), bool)
    segment_dots(alone_h, [0.5], [3.5], [7.5], [3.5])
    segment_dots(alone_v, [3.5], [0.5], [3.5], [7.5])
    both = np.zeros((8, 8), bool)
    segment_dots(both, [0.5, 3.5], [3.5, 0.5], [7.5, 3.5], [3.5, 7.5])
    assert (both == (alone_h | alone_v)).all()
    assert (pack_braille(both) == (pack_braille(alone_h) | pack_braille(alone_v))).all()


def test_segments_are_clipped_to_the_canvas():
    dots = np.zeros((8, 8), bool)
    # far outside both ways, through the middle row
    segment_dots(dots, [-1e9], [4.5], [1e9], [4.5])
    assert dots[4].all() and dots.sum() == 8
    dots[:] = False
    # wholly outside
    segment_dots(dots, [-10, 20], [-10, -5], [-1, 30], [-1, 5])
    assert not dots.any()


def test_points_off_the_canvas_are_ignored():
    dots = np.zeros((8, 4), bool)
    point_dots(dots, [-1, 1.2, 10], [1, 6.7, 1])
    assert dots.sum() == 1 and dots[6, 1]


def test_view_zoom_keeps_the_point_under_the_pointer():
    view = View(0.5, 0.5, 0.01)
    about = view.char_to_world(10, 5, 40, 20)
    zoomed = view.zoomed(2.0, about)
    assert zoomed.char_to_world(10, 5, 40, 20) == pytest.approx(about)
    assert zoomed.scale == pytest.approx(0.005)


def test_fit_shows_the_whole_box():
    view = View.fit((0, 0, 2, 1), 40, 20)
    u, v = view.to_dots([0, 2], [0, 1], 40, 20)
    assert 0 <= u.min() and u.max() <= 80
    assert 0 <= v.min() and v.max() <= 80


def test_frame_of_a_diagram_draws_sites_edges_and_fills():
    diagram = tvoronoi.voronoi(generate("uniform", 50, seed=3))
    scene = Scene.from_diagram(diagram)
    view = View.fit(scene.bbox, 60, 20)
    frame = rasterize(scene, view, 60, 20, delaunay=True)
    assert frame.codes.shape == frame.mark.shape == frame.fill.shape == (20, 60)
    assert (frame.mark == SITE).sum() >= 40  # a few sites may share a character
    assert (frame.mark == EDGE).any()
    assert (frame.fill >= 0).any() and (frame.fill < len(DARK.fills)).all()
    lines = frame_lines(frame, DARK)
    assert len(lines) == 20
    for line in lines:
        text = "".join(seg.text for seg in line)
        assert len(text) == 60
        assert all(c == " " or BRAILLE_BLANK <= ord(c) <= BRAILLE_BLANK + 0xFF for c in text)


def test_every_site_lies_in_a_character_of_its_own_fill():
    """The fill comes from the nearest site, so a site's own character shows its cell's colour."""
    diagram = tvoronoi.voronoi(generate("uniform", 30, seed=5))
    scene = Scene.from_diagram(diagram)
    cols, rows = 120, 40
    view = View.fit(scene.bbox, cols, rows)
    frame = rasterize(scene, view, cols, rows)
    u, v = view.to_dots(scene.sites[:, 0], scene.sites[:, 1], cols, rows)
    col, row = (u // 2).astype(int), (v // 4).astype(int)
    # a character whose centre is nearer another site may differ; nearly all agree
    agree = frame.fill[row, col] == scene.colours
    assert agree.mean() > 0.8


def test_a_dense_diagram_fills_every_character_inside_its_box():
    """Zoomed out on many sites, the characters without a dot (inside the large cells of the
    box's corners, beyond the sites' extent) still show their cell's colour: every character
    whose centre lies in the box has the fill of the cell of the nearest site, and the others
    none."""
    from scipy.spatial import cKDTree

    from tvoronoi.tui.viewport import char_centres

    points = generate("uniform", 60_000, seed=2)
    scene = Scene.from_diagram(tvoronoi.voronoi(points))
    cols, rows = 80, 22
    view = View.fit(scene.bbox, cols, rows)
    frame = rasterize(scene, view, cols, rows)
    xs, ys = char_centres(view, cols, rows)
    gx, gy = np.meshgrid(xs, ys)
    x0, y0, x1, y1 = scene.bbox
    inside = (gx >= x0) & (gx <= x1) & (gy >= y0) & (gy <= y1)
    _, nearest = cKDTree(points).query(np.column_stack([gx[inside], gy[inside]]))
    assert np.array_equal(frame.fill[inside], scene.colours[nearest])
    assert (frame.fill[~inside] == -1).all()
    assert ((frame.codes == 0) & inside).any()  # some characters inside are blank and filled


@pytest.mark.parametrize("name", ["uniform", "clustered", "grid", "circle", "collinear", "duplicates", "two"])
def test_neighbouring_cells_never_share_a_colour(name):
    diagram = tvoronoi.voronoi(DATASETS[name])
    colours = cell_colours(diagram)
    a, b = cell_adjacency(diagram)
    assert len(colours) == diagram.n_sites
    assert colours.min() >= 0 and colours.max() < len(DARK.fills)
    assert not (colours[a] == colours[b]).any()
    # a repeated point shows its first copy's colour
    assert (colours == colours[diagram.site_of]).all()


def test_colouring_of_a_large_diagram_uses_the_palette_and_has_no_clash():
    diagram = tvoronoi.voronoi(generate("clustered", 20_000, seed=11))
    colours = cell_colours(diagram)
    a, b = cell_adjacency(diagram)
    assert not (colours[a] == colours[b]).any()
    assert len(np.unique(colours)) == len(DARK.fills)


def test_adjacency_comes_from_the_half_edges():
    diagram = tvoronoi.voronoi([[0, 0], [2, 0], [1, 2]])
    a, b = cell_adjacency(diagram)
    assert sorted(zip(a.tolist(), b.tolist())) == [(0, 1), (0, 2), (1, 2)]


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_adjacency_lists_each_pair_of_neighbours_once(name):
    """Every (face, twin's face) pair of the half-edges, once each, against a set built in Python."""
    diagram = tvoronoi.voronoi(DATASETS[name])
    a, b = cell_adjacency(diagram)
    faces, twins = diagram.he_face.tolist(), diagram.he_twin.tolist()
    expected = {
        (min(f, faces[t]), max(f, faces[t]))
        for f, t in zip(faces, twins)
        if t >= 0 and f >= 0 and faces[t] >= 0 and f != faces[t]
    }
    pairs = list(zip(a.tolist(), b.tolist()))
    assert (a < b).all()
    assert len(pairs) == len(set(pairs))
    assert set(pairs) == expected


def test_colour_graph_on_a_wheel():
    """A hub with 12 spokes and a rim: the hub needs a colour none of the rim uses."""
    rim = np.arange(1, 13)
    a = np.concatenate([np.zeros(12, int), rim])
    b = np.concatenate([rim, np.roll(rim, 1)])
    colours = colour_graph(13, a, b)
    assert not (colours[a] == colours[b]).any()


def test_palettes_have_eight_distinct_fills():
    for palette in (DARK, LIGHT):
        assert len(set(palette.fills)) == 8
        assert palette.edge not in palette.fills


coordinates = st.floats(-30, 60, allow_nan=False, allow_infinity=False)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(coordinates, coordinates, coordinates, coordinates), min_size=1, max_size=8))
@example([(0.0, -1 / 3, 0.0, 4.0)])  # clipped at one end: the other came back an ulp short of 4.0
def test_segment_dots_match_the_segments(segments):
    """Every dot lies within one dot of some segment; ends on the canvas are drawn; no gaps."""
    height, width = 24, 32
    dots = np.zeros((height, width), bool)
    seg = np.array(segments, float)
    segment_dots(dots, seg[:, 0], seg[:, 1], seg[:, 2], seg[:, 3])
    rows, cols = np.nonzero(dots)
    centres = np.column_stack([cols + 0.5, rows + 0.5])
    a, b = seg[:, :2], seg[:, 2:]
    ab = b - a
    length2 = np.maximum((ab**2).sum(1), 1e-12)
    t = np.clip(((centres[:, None, :] - a) * ab).sum(2) / length2, 0, 1)
    nearest = a + t[..., None] * ab
    distance = np.sqrt(((centres[:, None, :] - nearest) ** 2).sum(2)).min(1)
    assert (distance <= np.sqrt(0.5) + 1e-6).all()
    for x, y in np.concatenate([a, b]):
        if 0 <= x < width and 0 <= y < height:
            assert dots[int(y), int(x)]
    # a segment wholly on the canvas: every step along its longer axis has a dot
    x0, y0, x1, y1 = seg[0]
    if all(0 <= x < width for x in (x0, x1)) and all(0 <= y < height for y in (y0, y1)):
        alone = np.zeros_like(dots)
        segment_dots(alone, [x0], [y0], [x1], [y1])
        if abs(x1 - x0) >= abs(y1 - y0):
            lo, hi = sorted((int(x0), int(x1)))
            assert alone[:, lo : hi + 1].any(axis=0).all()
        else:
            lo, hi = sorted((int(y0), int(y1)))
            assert alone[lo : hi + 1, :].any(axis=1).all()


@settings(max_examples=25, deadline=None)
@given(st.integers(3, 400), st.integers(0, 2**32 - 1), st.sampled_from(["uniform", "gaussian", "clustered"]))
def test_colouring_has_no_clash_on_random_diagrams(n, seed, distribution):
    diagram = tvoronoi.voronoi(generate(distribution, n, seed=seed))
    colours = cell_colours(diagram)
    a, b = cell_adjacency(diagram)
    assert not (colours[a] == colours[b]).any()
    assert colours.max() < len(DARK.fills)


def test_the_keyboard_cursor_lights_up_its_cell_and_keeps_the_site_under_it():
    """The cursor on a site: the site's character keeps its mark and the cell's own colour,
    lit up, not a block of the cursor's colour."""
    from tvoronoi.tui.dots import DOT_COLS, DOT_ROWS
    from tvoronoi.tui.layers import CURSOR, HIGHLIGHTED, N_FILLS

    diagram = tvoronoi.voronoi(generate("uniform", 30, seed=3))
    scene = Scene.from_diagram(diagram)
    cols, rows = 60, 20
    view = View.fit(scene.bbox, cols, rows)
    x, y = scene.sites[7]
    plain = rasterize(scene, view, cols, rows)
    frame = rasterize(scene, view, cols, rows, cursor=(x, y))
    u, v = view.to_dots(x, y, cols, rows)
    col, row = int(u // DOT_COLS), int(v // DOT_ROWS)
    assert frame.mark[row, col] == SITE
    assert frame.fill[row, col] == HIGHLIGHTED + scene.colours[7]
    # the cross changed a few characters only, and each keeps its cell's colour, lit up
    changed = (frame.fill != plain.fill) | (frame.mark != plain.mark)
    assert 1 <= changed.sum() <= 6
    assert (frame.fill[changed] - HIGHLIGHTED == plain.fill[changed]).all()
    assert (plain.fill[changed] < N_FILLS).all()
    assert ((frame.mark[changed] == CURSOR) | (frame.mark[changed] == plain.mark[changed])).all()
    for palette in (DARK, LIGHT):
        line = frame_lines(frame, palette)[row]
        style = next(seg.style for seg, start in _with_starts(line) if start <= col < start + len(seg.text))
        assert style.bgcolor.name != palette.cursor
        assert style.color.name == palette.site
        assert style.bgcolor.name == palette.highlights[scene.colours[7]]


def _with_starts(line):
    start = 0
    for seg in line:
        yield seg, start
        start += len(seg.text)


def test_the_layer_cache_draws_the_same_frames_and_skips_layers_drawn_before(monkeypatch):
    """Frames drawn through a LayerCache equal frames drawn afresh; a frame that only shows the
    Delaunay edges again draws no other layer, and another scene, view or size draws all."""
    from tvoronoi.tui import raster
    from tvoronoi.tui.layers import LayerCache

    diagram = tvoronoi.voronoi(generate("uniform", 500, seed=3))
    scene = Scene.from_diagram(diagram)
    other = Scene.from_diagram(tvoronoi.voronoi(generate("uniform", 500, seed=4)))
    view = View.fit(diagram.bbox, 60, 24)
    calls = []
    real = raster.segment_dots
    monkeypatch.setattr(raster, "segment_dots", lambda *a, **k: (calls.append(len(a[1])), real(*a, **k)))
    cache = LayerCache()
    steps = [
        (scene, view, 60, 24, False),
        (scene, view, 60, 24, True),  # Delaunay on: only its layer is new
        (scene, view, 60, 24, False),  # off: nothing to draw
        (scene, view.panned(3, 0), 60, 24, False),
        (other, view, 60, 24, False),
        (other, view, 50, 24, False),
    ]
    drawn = []
    for sc, v, cols, rows, tri in steps:
        calls.clear()
        cached = rasterize(sc, v, cols, rows, delaunay=tri, layers=cache)
        drawn.append(len(calls))
        fresh = rasterize(sc, v, cols, rows, delaunay=tri)
        for a, b in ((cached.codes, fresh.codes), (cached.mark, fresh.mark), (cached.fill, fresh.fill)):
            assert np.array_equal(a, b)
    # segment_dots calls through the cache: the edges; the Delaunay edges only; none; then the
    # edges again for a new view, scene and size
    assert drawn == [1, 1, 0, 1, 1, 1]


def test_the_layer_cache_keeps_recent_views_and_lets_other_scenes_go(monkeypatch):
    """Coming back to a view of the last few frames (fit after a zoom, Delaunay shown again)
    draws nothing again and gives the same frame as a fresh drawing; an older view, or a view of
    a scene replaced since, is drawn again."""
    from tvoronoi.tui import raster
    from tvoronoi.tui.layers import LAYER_FRAMES_KEPT, LayerCache

    scene = Scene.from_diagram(tvoronoi.voronoi(generate("uniform", 400, seed=6)))
    other = Scene.from_diagram(tvoronoi.voronoi(generate("uniform", 400, seed=7)))
    fit = View.fit(scene.bbox, 60, 24)
    calls = []
    real = raster.segment_dots
    monkeypatch.setattr(raster, "segment_dots", lambda *a, **k: (calls.append(len(a[1])), real(*a, **k)))
    cache = LayerCache()

    def drawn(sc, view, tri=False) -> int:
        calls.clear()
        cached = rasterize(sc, view, 60, 24, delaunay=tri, layers=cache)
        count = len(calls)
        fresh = rasterize(sc, view, 60, 24, delaunay=tri)
        assert np.array_equal(cached.codes, fresh.codes) and np.array_equal(cached.mark, fresh.mark)
        return count

    assert drawn(scene, fit, True) == 2  # edges and Delaunay edges
    assert drawn(scene, fit.zoomed(2)) == 1  # a new view: its edges
    assert drawn(scene, fit) == 0  # fit again: kept
    assert drawn(scene, fit.zoomed(2), True) == 1  # the Delaunay edges of that view are new
    for k in range(LAYER_FRAMES_KEPT):
        drawn(scene, fit.zoomed(3 + k))
    assert drawn(scene, fit) == 1  # too many frames ago: drawn again
    drawn(other, fit)
    assert drawn(scene, fit) == 1  # the other scene's frame let this one go


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(-9, 30), st.integers(-9, 30), st.sampled_from([0, 2]))
def test_a_window_of_the_dot_plane_gets_the_dots_of_the_whole(seed, ou, ov, dash):
    """Segments drawn into a window of the dot plane (any origin, segments crossing its sides)
    set exactly the dots a larger window sets there, and those of the segment-by-segment
    reference: no sample depends on where the window cuts a segment."""
    rng = np.random.default_rng(seed)
    p = rng.uniform(-20.0, 60.0, (200, 2))
    q = p + rng.normal(0.0, rng.choice([0.5, 4.0, 40.0]), (200, 2))
    half = rng.random(200) < 0.3  # ends on dot borders and centres too
    p[half], q[half] = np.round(p[half] * 2) / 2, np.round(q[half] * 2) / 2
    whole = np.zeros((48, 40), bool)  # the plane's dots (0, 0) .. (40, 48)
    segment_dots(whole, p[:, 0], p[:, 1], q[:, 0], q[:, 1], dash=dash)
    if not dash:
        assert (whole == reference_dots(whole.shape, *p.T, *q.T)).all()
    part = np.zeros((12, 16), bool)
    segment_dots(part, p[:, 0], p[:, 1], q[:, 0], q[:, 1], dash=dash, origin=(ou, ov))
    rows, cols = np.mgrid[ov : ov + 12, ou : ou + 16]
    on_whole = (rows >= 0) & (rows < 48) & (cols >= 0) & (cols < 40)
    assert (part[on_whole] == whole[rows[on_whole], cols[on_whole]]).all()


@pytest.mark.parametrize("zoom", [1.0, 3.0, 40.0])
def test_a_panned_layer_shifted_from_the_cache_equals_a_fresh_drawing(monkeypatch, zoom):
    """Panning by whole characters moves the cached layers and draws only the characters they
    lack: every frame equals one drawn afresh, dot for dot, in every direction and by more than
    the canvas; only the strips are drawn (few sites and edges), and a pan by part of a
    character draws the whole layer."""
    from tvoronoi.tui import raster
    from tvoronoi.tui.layers import LayerCache

    diagram = tvoronoi.voronoi(generate("uniform", 3000, seed=8))
    scene = Scene.from_diagram(diagram)
    cols, rows = 48, 20
    view = View.fit(diagram.bbox, cols, rows).zoomed(zoom)
    sizes = []
    real = raster.segment_dots
    monkeypatch.setattr(raster, "segment_dots", lambda *a, **k: (sizes.append(a[0].size), real(*a, **k)))
    cache = LayerCache()
    rasterize(scene, view, cols, rows, delaunay=True, layers=cache)
    sizes.clear()
    rasterize(scene, view.panned(1, 0), cols, rows, delaunay=True, layers=cache)
    assert sizes == [cols * rows * DOT_COLS * DOT_ROWS] * 2
    for dx, dy in [(1, 0), (0, 1), (-3, 2), (5, -4), (-1, -1), (cols + 2, 0), (0, -rows - 1), (7, 3)]:
        view = view.panned(dx * DOT_COLS, dy * DOT_ROWS)
        sizes.clear()
        cached = rasterize(scene, view, cols, rows, delaunay=True, layers=cache)
        drawn = sum(sizes)
        fresh = rasterize(scene, view, cols, rows, delaunay=True)
        for a, b in ((cached.codes, fresh.codes), (cached.mark, fresh.mark), (cached.fill, fresh.fill)):
            assert np.array_equal(a, b)
        if abs(dx) < cols and abs(dy) < rows:
            # the dots drawn: those of the strips the pan uncovered, for the two layers
            strips = (abs(dx) * rows + abs(dy) * cols) * DOT_COLS * DOT_ROWS
            assert drawn <= 2 * strips


def test_the_layer_cache_follows_a_live_scene_edited_in_place():
    from tvoronoi.tui.building import build
    from tvoronoi.tui.editing import make_live
    from tvoronoi.tui.layers import LayerCache

    built = build(generate("uniform", 200, seed=5), "incremental", "test", clock=lambda: 0.0)
    live = make_live(built)
    view = View.fit(built.diagram.bbox, 60, 24)
    cache = LayerCache()
    before = rasterize(live, view, 60, 24, layers=cache)
    live.insert(0.5, 0.5)
    after = rasterize(live, view, 60, 24, layers=cache)
    fresh = rasterize(live, view, 60, 24)
    assert np.array_equal(after.codes, fresh.codes) and np.array_equal(after.mark, fresh.mark)
    assert not np.array_equal(after.codes, before.codes)


def test_ring_next_goes_round_each_ring_and_skips_empty_ones():
    """The one rings-to-sides routine: each entry's successor is the next of its ring, the last
    going back to the first, whatever the empty rings between."""
    from tvoronoi.tui.scene import ring_next, ring_segments

    sizes = [3, 0, 1, 4, 0, 2]
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    expected = np.concatenate([np.roll(np.arange(a, b), -1) for a, b in zip(offsets[:-1], offsets[1:])])
    assert np.array_equal(ring_next(offsets, offsets[-1]), expected)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    sides = ring_segments(square)
    assert np.array_equal(sides[:, 2:], np.roll(square, -1, axis=0)) and np.array_equal(sides[:, :2], square)
    assert ring_segments(square[:1]).shape == (0, 4)


@pytest.mark.parametrize("name", sorted(name for name, pts in DATASETS.items() if len(pts) >= 2))
def test_scene_edges_are_each_cell_side_once(name):
    """The scene keeps each side of the cells once (a side between two cells from one of them, a
    side along the box from its cell): the same set as sorting every side and dropping repeats."""
    from tvoronoi.tui.scene import _unique_pairs, ring_next

    diagram = tvoronoi.voronoi(DATASETS[name])
    offsets = np.asarray(diagram.cell_offsets, np.int64)
    ring = np.asarray(diagram.cell_vertices, np.int64)
    points = np.asarray(diagram.cell_points)
    a, b = _unique_pairs(ring, ring[ring_next(offsets, ring.size)], len(points))
    expected = {tuple(sorted(map(tuple, s.reshape(2, 2).tolist()))) for s in np.hstack([points[a], points[b]])}
    edges = Scene.from_diagram(diagram).edges
    got = [tuple(sorted(map(tuple, s.reshape(2, 2).tolist()))) for s in edges]
    assert len(got) == len(set(got)) == len(expected)
    assert set(got) == expected


def test_the_scene_finds_its_delaunay_edges_when_first_shown():
    """A scene from a diagram finds its Delaunay edges only when asked, and they are scipy's
    Delaunay edges, each once."""
    from scipy.spatial import Delaunay

    points = generate("uniform", 700, seed=9)
    scene = Scene.from_diagram(tvoronoi.voronoi(points))
    assert scene.delaunay_edges is None and scene.triangles is not None
    edges = scene.delaunay
    assert scene.delaunay is edges and scene.triangles is None
    tri = Delaunay(points).simplices
    expected = {
        frozenset(map(tuple, points[[a, b]].tolist()))
        for t in tri
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))
    }
    got = [frozenset(map(tuple, (e[:2].tolist(), e[2:].tolist()))) for e in edges]
    assert len(got) == len(set(got)) and set(got) == expected


@pytest.mark.parametrize("name", ["uniform-2000", "clustered", "grid"])
def test_a_scene_drawn_from_its_edge_mesh_equals_one_drawn_from_its_segments(name):
    """The edges drawn as pairs of points (each point mapped once, a side within one dot left to
    its ends) set the same dots as the same edges drawn as segments, zoomed out and in, panned
    by parts of characters, and in windows of the canvas."""
    from tvoronoi.tui.raster import redraw_part

    points = generate("uniform", 2000, seed=12) if name == "uniform-2000" else DATASETS[name]
    scene = Scene.from_diagram(tvoronoi.voronoi(points))
    assert scene.edge_mesh is not None
    plain = Scene(
        sites=scene.sites,
        edges=scene.edge_mesh.segments(),
        vertices=scene.vertices,
        colours=scene.colours,
        bbox=scene.bbox,
    )
    cols, rows = 50, 20
    fit = View.fit(scene.bbox, cols, rows)
    x0, y0, x1, y1 = scene.bbox
    views = [
        fit,
        fit.zoomed(0.3),
        fit.zoomed(7.0),
        fit.zoomed(60.0, (x0, y1)),
        fit.zoomed(4.0).panned(3.5, -17.25),
        fit.zoomed(2.0, (x1, y0)).panned(2, 4),
    ]
    for view in views:
        got = rasterize(scene, view, cols, rows, vertices=False)
        want = rasterize(plain, view, cols, rows, vertices=False)
        assert np.array_equal(got.codes, want.codes) and np.array_equal(got.mark, want.mark)
        assert got.codes.any()
        for span in [(0, 0, 7, 5), (13, 4, 40, 19), (cols - 3, rows - 2, cols, rows)]:
            redraw_part(got, scene, view, cols, rows, span, vertices=False)
            assert np.array_equal(got.codes, want.codes)


def test_an_edge_mesh_sets_the_ends_it_names_and_no_other_point():
    """A mesh draws the dots of its sides (a long one: the dots between its ends; a short one
    crossing into the next dot row: its two ends) and no dot of a point that ends no side."""
    from tvoronoi.tui.raster import Painter
    from tvoronoi.tui.scene import EdgeMesh

    view = View.fit((0.0, 0.0, 1.0, 1.0), 20, 10)
    # in dots: a long flat side, a short side across a dot row, a lone point
    u = np.array([3.5, 30.5, 5.2, 5.8, 12.5])
    v = np.array([20.5, 21.5, 5.9, 6.3, 30.5])
    points = np.column_stack(view.to_world(u, v, 20, 10))
    mesh = EdgeMesh(points, np.array([0, 2]), np.array([1, 3]), ends=np.array([0, 1, 2, 3]))
    paint = Painter(view, 20, 10)
    paint.mesh(EDGE, mesh)
    dots = np.zeros((40, 40), bool)
    segment_dots(dots, u[[0, 2]], v[[0, 2]], u[[1, 3]], v[[1, 3]])
    assert dots[5, 5] and dots[6, 5] and not dots[30, 12]
    assert np.array_equal(paint.codes, pack_braille(dots))
