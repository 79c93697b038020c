"""Builds on several threads give the same Diagram, bit for bit, as on one.

The split phases are the Voronoi vertices and the cocircular test (dual.voronoi_from_delaunay) and the
clipping of the cells (clip.clip_cells). The API tests use enough sites for the clipper to split; the
kernel tests force the split on every adversarial family, small as they are.
"""

import numpy as np
import pytest

import tvoronoi
from tests import adversarial
from tests.invariants import assert_same_diagram as assert_same
from tvoronoi import engines
from tvoronoi.api import as_bbox, default_bbox
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import generate
from tvoronoi.kernels import clip, dual


def grid(side: int) -> np.ndarray:
    g = np.arange(float(side))
    x, y = np.meshgrid(g, g)
    return np.c_[x.ravel(), y.ravel()]


LARGE = {
    "uniform": lambda: generate("uniform", 40_000, seed=3),
    "clustered": lambda: generate("clustered", 40_000, seed=4),
    # every square cocircular: the merged vertices and dropped zero-length edges
    "grid": lambda: grid(200),
    "rounded": lambda: np.round(generate("uniform", 40_000, seed=5), 2),  # repeats and cocircular ties
}


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
@pytest.mark.parametrize("name", sorted(LARGE))
def test_api_threads_give_the_same_diagram(name, engine):
    pts = LARGE[name]()
    one = tvoronoi.voronoi(pts, engine=engine, threads=1)
    for threads in (2, 3):
        assert_same(one, tvoronoi.voronoi(pts, engine=engine, threads=threads))


def test_api_threads_with_a_box_that_cuts():
    pts = generate("uniform", 40_000, seed=6)
    box = (0.2, 0.1, 0.7, 0.95)
    assert_same(tvoronoi.voronoi(pts, bbox=box, threads=1), tvoronoi.voronoi(pts, bbox=box, threads=2))


def test_default_threads_match_one_thread():
    pts = generate("gaussian", 40_000, seed=7)
    assert_same(tvoronoi.voronoi(pts, threads=1), tvoronoi.voronoi(pts))


@pytest.mark.parametrize("bad", [0, -1, 1.5, "2", True])
def test_bad_thread_counts_are_refused(bad):
    with pytest.raises(TvoronoiError, match="threads"):
        tvoronoi.voronoi([[0, 0], [1, 0], [0, 1]], threads=bad)


@pytest.mark.parametrize("name", sorted(adversarial.FAMILIES))
def test_kernels_split_on_every_family(name):
    case = adversarial.make(name)
    pts = case.points
    assert_same(tvoronoi.voronoi(pts, bbox=case.bbox, threads=1), tvoronoi.voronoi(pts, bbox=case.bbox, threads=2))
    box = default_bbox(pts) if case.bbox is None else as_bbox(case.bbox)
    e = engines.scale_exponent(pts)
    t = engines.run(pts[:, 0], pts[:, 1], engine="incremental", exponent=e)
    if t.flat:
        return  # collinear sites: parallel strips, no triangles and nothing split
    s = t.sites
    outs = [dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1) for threads in (1, 2, 3)]
    # the walks in runs of 1 to 5 sites: a run's lookups into the runs before it wait for the pass after
    outs += [
        dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, threads, parallel_min=1, walk_chunk=chunk)
        for threads, chunk in ((2, 1), (2, 3), (3, 2), (2, 5))
    ]
    for out in outs[1:]:
        for key in outs[0]:
            assert np.array_equal(outs[0][key], out[key]), key
    out = outs[0]
    active = (t.dup < 0).astype(np.int8)
    cells = [
        clip.clip_cells(
            s.xs,
            s.ys,
            out["vertices"],
            out["he_origin"],
            out["he_twin"],
            out["he_face"],
            out["face_edge"],
            active,
            box,
            e,
            threads,
            parallel_min=1,
        )
        for threads in (1, 2, 3)
    ]
    for got in cells[1:]:
        assert got[3] == cells[0][3] == 0
        for x, y in zip(got[:3], cells[0][:3]):
            assert np.array_equal(x, y)
    # the new points written into the dual's room after the vertices: the same points and rings
    roomy = dual.voronoi_from_delaunay(s.xs, s.ys, t.tv, t.opp, e, 2, parallel_min=1, clip_room=True)
    room = roomy["vertex_room"]

    def clip_into(buffer):
        keys = ("vertices", "he_origin", "he_twin", "he_face", "face_edge")
        return clip.clip_cells(s.xs, s.ys, *(roomy[k] for k in keys), active, box, e, 2, parallel_min=1, room=buffer)

    got = clip_into(room)
    assert np.shares_memory(got[0], room)
    for x, y in zip(got[:3], cells[0][:3]):
        assert np.array_equal(x, y)
    # room that does not start with the vertices, or is too small: a copy, the same result
    for other in (room.copy(), room[: len(roomy["vertices"]) + 3]):
        got = clip_into(other)
        assert not np.shares_memory(got[0], other)
        for x, y in zip(got[:3], cells[0][:3]):
            assert np.array_equal(x, y)
