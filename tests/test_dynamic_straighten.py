"""Dynamic cells where rounding bends rings: a cell read on its own is the batch build's cell, bit for bit.

The batch build straightens every ring that rounding made cross itself (clip.straighten), merging points
across neighbouring cells; a dynamic diagram reads a cell with its neighbours (dynamic.settled_cell).
Sessions of inserts, moves and removes on turned lattices rounded to decimals (where cells thinner
than rounding abound) are compared, cell by cell, with a fresh batch build of the live sites.
"""

from pathlib import Path

import numpy as np
import pytest

import tvoronoi
from tvoronoi.dynamic import DynamicVoronoi

ENGINES = ("incremental", "fortune")
DYNAMIC_FIXTURES = sorted((Path(__file__).resolve().parent / "fixtures" / "dynamic").glob("*.npz"))


def turned_lattice(rng) -> tuple[np.ndarray, float, int]:
    """A square lattice turned by a random angle, coordinates rounded to 1 to 3 decimals."""
    side, angle, decimals = int(rng.integers(6, 16)), rng.random() * np.pi, int(rng.integers(1, 4))
    step = float(rng.choice([0.5, 1.0, 0.7, 1.3]))
    grid = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2) * step
    turn = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    return np.round(grid @ turn.T, decimals), step, decimals


def session(seed: int, engine: str, read_as_it_goes: bool) -> DynamicVoronoi:
    """Random inserts, moves and removes, mostly onto lattice points (repeats, cocircular squares);
    with read_as_it_goes, the changed cells are read after each update (the cells a read keeps as
    known must be forgotten when an update changes them)."""
    rng = np.random.default_rng(seed)
    lattice, step, decimals = turned_lattice(rng)
    start = lattice[rng.choice(len(lattice), len(lattice) * 2 // 3, replace=False)]
    dv = DynamicVoronoi(start, engine=engine)
    ids = list(range(len(start)))
    view = dv.diagram()
    for _ in range(int(rng.integers(50, 300))):
        kind = rng.integers(0, 3)
        if rng.random() < 0.8:
            xy = lattice[rng.integers(len(lattice))]
        else:
            xy = np.round(lattice[rng.integers(len(lattice))] + rng.random(2) * step, decimals)
        if kind == 0 or len(ids) < 8:
            ids.append(dv.insert(*xy))
        elif kind == 1:
            dv.move(ids[rng.integers(len(ids))], *xy)
        else:
            dv.remove(ids.pop(rng.integers(len(ids))))
        if read_as_it_goes:
            for i in dv.changed.tolist():
                view.cell_polygon(i)
    return dv


def differing_cells(dv: DynamicVoronoi) -> list:
    """The places whose cell differs from a fresh batch build's of the live sites in the same box."""
    view = dv.diagram()
    live = np.flatnonzero(view.alive)
    sites = view.sites[live]
    fresh = tvoronoi.voronoi(sites, bbox=dv.bbox, engine=dv.engine)
    mine, theirs = {}, {}
    for row, i in enumerate(live):
        ring, want = view.cell_polygon(int(i)), fresh.cell_polygon(row)
        if len(ring):
            mine[tuple(sites[row])] = ring
        if len(want):
            theirs[tuple(sites[row])] = want
    return [
        p for p in set(mine) | set(theirs) if p not in mine or p not in theirs or not np.array_equal(mine[p], theirs[p])
    ]


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("path", DYNAMIC_FIXTURES, ids=[p.stem for p in DYNAMIC_FIXTURES])
def test_fixture_sessions_end_with_the_batch_cells(path, engine):
    """A recorded session (start; then per operation kind 0 insert xy, 1 move index to xy, 2 remove
    index) that once left cells holding a point the batch build merges."""
    with np.load(path) as z:
        dv = DynamicVoronoi(z["start"], engine=engine)
        for kind, index, xy in zip(z["kind"].tolist(), z["index"].tolist(), z["xy"]):
            if kind == 0:
                dv.insert(*xy)
            elif kind == 1:
                dv.move(index, *xy)
            else:
                dv.remove(index)
    assert differing_cells(dv) == []


@pytest.mark.parametrize("engine", ENGINES)
def test_sessions_on_rounded_turned_lattices_end_with_the_batch_cells(engine):
    """Seeds 721 and 1757 failed before cells were read with their neighbours (3 cells each); the
    others widen the hunt (about 1 session in 1,000 bends a ring where it matters)."""
    for seed in [721, 1757, *range(60)]:
        dv = session(seed, engine, read_as_it_goes=seed % 2 == 0)
        assert differing_cells(dv) == [], f"seed {seed}"


@pytest.mark.parametrize("engine", ENGINES)
def test_cells_read_as_the_session_goes_stay_right(engine):
    """Cells read after every update (and so remembered as not bent) and then read again at the end,
    in the sessions that bend rings."""
    for seed in (721, 1757):
        dv = session(seed, engine, read_as_it_goes=True)
        assert differing_cells(dv) == [], f"seed {seed}"


def test_a_bent_neighbourhood_is_straightened_with_the_cells_around_it():
    """The fixture's end state holds bent rings: a read there gathers the cells around (cells_near
    returns them) and straightens them; elsewhere the cell is read alone."""
    with np.load(DYNAMIC_FIXTURES[0]) as z:
        dv = DynamicVoronoi(z["start"])
        for kind, index, xy in zip(z["kind"].tolist(), z["index"].tolist(), z["xy"]):
            (dv.insert(*xy) if kind == 0 else dv.move(index, *xy) if kind == 1 else dv.remove(index))
    mesh, view = dv._mesh, dv.diagram()
    live = [i for i in np.flatnonzero(view.alive).tolist() if i not in dv._primary]
    patched = [i for i in live if mesh.cells_near(i, *dv.bbox, dv._e, 2)[1] is not None]
    assert 0 < len(patched) < len(live)
    for i in patched[:5]:
        ring, (ids, steps, offsets, xy) = mesh.cells_near(i, *dv.bbox, dv._e, 2)
        assert ids[0] == i and steps[0] == 0 and set(steps.tolist()) <= {0, 1, 2}
        assert np.array_equal(xy[offsets[0] : offsets[1]], ring)
        assert np.array_equal(ring, mesh.cell(i, *dv.bbox, dv._e))


def test_every_cell_by_triangles_finds_the_bent_cells_each_cell_finds():
    """A new mesh's cells are looked at by triangles (sure_cells: a cell strictly inside the box with
    every turn strictly left is not bent), the cells an update changed one by one: both name the same
    bent cells, on the recorded session and on the hunt's families that bend rings."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import adversarial

    meshes = []
    with np.load(DYNAMIC_FIXTURES[0]) as z:
        dv = DynamicVoronoi(z["start"])
        for kind, index, xy in zip(z["kind"].tolist(), z["index"].tolist(), z["xy"]):
            (dv.insert(*xy) if kind == 0 else dv.move(index, *xy) if kind == 1 else dv.remove(index))
        meshes.append(dv)
    for name in ("circle_rounded_offset", "rotated_grid_45deg", "triangular30_noise1e-15", "decimal_circles_3dec"):
        case = adversarial.make(name)
        meshes.append(DynamicVoronoi(case.points, bbox=case.bbox))
    found = 0
    for dv in meshes:
        box = (*dv.bbox, dv._e)
        by_triangles = dv._mesh.bent_sites(*box, True)
        one_by_one = dv._mesh.bent_sites(*box, False)
        assert np.array_equal(by_triangles, one_by_one)
        found += len(one_by_one)
    assert found > 0
