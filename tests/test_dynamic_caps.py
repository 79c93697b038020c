"""Dynamic updates around a site with 10,000 neighbours: no fixed cap on a star, a hole or a swept region.

Each update must stay local (the mesh is not rebuilt) and every cell it changed must equal the
cell of a fresh batch build of the same sites.
"""

import numpy as np
import pytest
import shapely

import tvoronoi

ENGINES = ("incremental", "fortune")
N = 10_000
# cells read through the view at each check (all of them are read through the export)
VIEW_SAMPLE = 500


def rounded_circle():
    """N sites on the unit circle, rounded to doubles (nearly cocircular), and the radius."""
    t = 2 * np.pi * np.arange(N) / N
    return np.column_stack([np.cos(t), np.sin(t)]), 1.0


def lattice_circle():
    """N of the 14,580 integer points on the circle of radius r = 5^2 * 13 * 17 * 29 * 37 * 41 * 53
    (exactly cocircular: r^2 is a sum of two squares in 4 * 5 * 3^6 ways), and r.

    The points are the Gaussian integers of norm r^2: products over the primes p = a^2 + b^2 of
    (a + bi)^j (a - bi)^(2e - j), times a unit."""
    primes = [((2, 1), 2), ((3, 2), 1), ((4, 1), 1), ((5, 2), 1), ((6, 1), 1), ((5, 4), 1), ((7, 2), 1)]

    def mul(u, w):
        return (u[0] * w[0] - u[1] * w[1], u[0] * w[1] + u[1] * w[0])

    def power(u, k):
        out = (1, 0)
        for _ in range(k):
            out = mul(out, u)
        return out

    zs = [(1, 0), (0, 1), (-1, 0), (0, -1)]
    r = 1
    for (a, b), e in primes:
        r *= (a * a + b * b) ** e
        zs = [mul(z, mul(power((a, b), j), power((a, -b), 2 * e - j))) for z in zs for j in range(2 * e + 1)]
    pts = sorted(set(zs))
    assert len(pts) == 14_580 and all(x * x + y * y == r * r for x, y in pts)
    assert r < 2**53  # exact as doubles
    keep = np.sort(np.random.default_rng(0).choice(len(pts), N, replace=False))
    return np.array(pts, float)[keep], float(r)


CIRCLES = {"rounded": rounded_circle, "lattice": lattice_circle}


def box_of(r):
    return (-1.5 * r, -1.5 * r, 1.5 * r, 1.5 * r)


def as_polygons(rings):
    """Shapely polygons of non-empty rings (one vectorized call)."""
    lengths = [len(ring) for ring in rings]
    coords = np.concatenate(rings)
    return shapely.polygons(shapely.linearrings(coords, indices=np.repeat(np.arange(len(rings)), lengths)))


def assert_rings_match(got, want, ids, tol):
    """Rings equal up to rounding: both empty, or same area and every vertex of each within tol
    of the other's boundary. (Vertex distances through prepared boundaries rather than a
    Hausdorff distance, which costs the product of the sizes on a 10,000-sided cell; rather than
    an overlay, which is unreliable on rings that differ in the last bit.)"""
    for i, g, w in zip(ids, got, want):
        assert (len(g) == 0) == (len(w) == 0), f"site {i}: {len(g)} vertices, a fresh build has {len(w)}"
    full = [k for k, w in enumerate(want) if len(w)]
    if not full:
        return
    got = [got[k] for k in full]
    want = [want[k] for k in full]
    g, w = as_polygons(got), as_polygons(want)
    ok = np.abs(shapely.area(g) - shapely.area(w)) <= tol * (shapely.length(g) + shapely.length(w))
    for rings, other in ((got, shapely.boundary(w)), (want, shapely.boundary(g))):
        shapely.prepare(other)
        which = np.repeat(np.arange(len(rings)), [len(ring) for ring in rings])
        near = shapely.dwithin(other[which], shapely.points(np.concatenate(rings)), tol)  # prepared first
        ok &= np.bincount(which[~near], minlength=len(rings)) == 0
    bad = [int(ids[full[k]]) for k in np.flatnonzero(~ok)]
    assert not bad, f"{len(bad)} cells differ from a fresh build, e.g. site {bad[0]}"


def assert_cells_match(dv, ids, box):
    """The cells of ids in the dynamic diagram's export, and in its view for a sample of them,
    equal the cells of a fresh build of the live sites."""
    view = dv.diagram()
    alive = np.flatnonzero(view.alive)
    fresh = tvoronoi.voronoi(view.sites[alive], bbox=box)
    row = np.full(view.n_sites, -1)
    row[alive] = np.arange(len(alive))
    ids = np.asarray(sorted(set(int(i) for i in ids) & set(alive.tolist())), dtype=int)
    tol = 1e-9 * (box[2] - box[0])
    want = [fresh.cell_polygon(row[i]) for i in ids]
    full = view.to_diagram()
    assert_rings_match([full.cell_polygon(i) for i in ids], want, ids, tol)
    sample = np.random.default_rng(1).permutation(len(ids))[:VIEW_SAMPLE]
    assert_rings_match([view.cell_polygon(ids[k]) for k in sample], [want[k] for k in sample], ids[sample], tol)


@pytest.mark.parametrize("circle", sorted(CIRCLES))
@pytest.mark.parametrize("engine", ENGINES)
def test_centre_of_a_circle_inserted_moved_removed(engine, circle):
    """The centre of 10,000 sites on a circle takes all of them as neighbours: insert it, move it
    a little (its 10,000-sided hole, then its 10,000-edge cavity), move it far, remove it."""
    pts, r = CIRCLES[circle]()
    box = box_of(r)
    dv = tvoronoi.DynamicVoronoi(pts, engine=engine, bbox=box)
    mesh = dv._mesh
    everyone = set(range(N))

    c = dv.insert(0.0, 0.0)
    assert dv._mesh is mesh, "the insertion rebuilt the mesh"
    assert set(dv.diagram().neighbours(c).tolist()) == everyone
    assert set(dv.changed.tolist()) == everyone | {c}
    if engine == "fortune":
        assert mesh.swept_ok, "the region was not swept"
    assert_cells_match(dv, dv.changed, box)

    # a small move keeps the centre's 10,000 neighbours (a lattice point stays a lattice point)
    dv.move(c, 1.0 if circle == "lattice" else 1e-9, -2.0 if circle == "lattice" else -2e-9)
    assert dv._mesh is mesh, "the move rebuilt the mesh"
    assert set(dv.diagram().neighbours(c).tolist()) == everyone
    assert set(dv.changed.tolist()) == everyone | {c}
    if engine == "fortune":
        assert mesh.swept_ok, "the hole or the region was not swept"
    assert_cells_match(dv, dv.changed, box)

    dv.move(c, 0.3 * r, 0.2 * r)
    assert dv._mesh is mesh
    assert_cells_match(dv, dv.changed, box)
    dv.move(c, 0.0, 0.0)
    assert dv._mesh is mesh

    dv.remove(c)
    assert dv._mesh is mesh, "the removal rebuilt the mesh"
    assert set(dv.changed.tolist()) == everyone | {c}
    if engine == "fortune":
        assert mesh.swept_ok, "the hole was not swept"
    assert_cells_match(dv, dv.changed, box)


@pytest.mark.parametrize("engine", ENGINES)
def test_hull_site_with_10000_neighbours(engine):
    """A site on the hull whose hole is open to infinity: the origin below an arc of 10,000 sites."""
    t = np.pi * (np.arange(N) + 0.5) / N
    pts = np.vstack([[[0.0, 0.0]], np.column_stack([np.cos(t), np.sin(t)])])
    box = box_of(1.0)
    dv = tvoronoi.DynamicVoronoi(pts, engine=engine, bbox=box)
    mesh = dv._mesh
    assert len(dv.diagram().neighbours(0)) == N
    dv.remove(0)
    assert dv._mesh is mesh, "the removal rebuilt the mesh"
    assert set(dv.changed.tolist()) == set(range(N + 1))
    assert_cells_match(dv, dv.changed, box)
    i = dv.insert(0.0, 0.0)
    assert dv._mesh is mesh
    assert len(dv.diagram().neighbours(i)) == N
    # the new site's own cell meets the box with N edges: compared too
    assert_cells_match(dv, dv.changed, box)


@pytest.mark.parametrize("engine", ENGINES)
def test_down_to_a_few_sites_and_back(engine):
    """Remove the sites of a circle and its centre in random order down to five, then insert them
    back around the circle, comparing with fresh builds along the way."""
    pts, r = lattice_circle()
    box = box_of(r)
    dv = tvoronoi.DynamicVoronoi(np.vstack([pts, [[0.0, 0.0]]]), engine=engine, bbox=box)
    mesh = dv._mesh
    order = np.random.default_rng(3).permutation(N + 1)
    checks = {N + 1 - k for k in (1, 10, 100, 1000, 5000)}
    for count, i in enumerate(order[:-5].tolist(), start=1):
        dv.remove(i)
        if count in checks or i == N:
            assert_cells_match(dv, np.flatnonzero(dv.diagram().alive), box)
    assert len(dv) == 5
    assert dv._mesh is mesh, "a removal rebuilt the mesh"
    back = order[:-5]
    coords = np.vstack([pts, [[0.0, 0.0]]])[back]
    back = back[np.argsort(np.arctan2(coords[:, 1], coords[:, 0]))]  # around the circle: short walks
    for count, i in enumerate(back.tolist(), start=1):
        dv.insert(*(pts[i] if i < N else (0.0, 0.0)))
        if count in checks:
            assert_cells_match(dv, np.flatnonzero(dv.diagram().alive), box)
    assert len(dv) == N + 1
    assert_cells_match(dv, np.flatnonzero(dv.diagram().alive), box)


@pytest.mark.parametrize("engine", ENGINES)
def test_out_of_memory_changes_nothing(engine):
    """When the scratch memory of a removal cannot grow, remove() raises MemoryError and the
    diagram is unchanged; an insertion falls back on the cavity fan, which needs none."""
    pts, r = rounded_circle()
    box = box_of(r)
    dv = tvoronoi.DynamicVoronoi(np.vstack([pts, [[0.0, 0.0]]]), engine=engine, bbox=box)
    before = dv.diagram().to_diagram()
    dv._mesh._limit_scratch(100)
    with pytest.raises(MemoryError, match=f"remove site {N}"):
        dv.remove(N)
    with pytest.raises(MemoryError):
        dv.move(N, 0.5 * r, 0.0)
    assert len(dv) == N + 1 and tuple(dv.diagram().sites[N]) == (0.0, 0.0)
    after = dv.diagram().to_diagram()
    assert np.array_equal(after.cell_offsets, before.cell_offsets)
    assert np.array_equal(after.cell_points, before.cell_points)
    assert len(dv.diagram().neighbours(N)) == N
    dv.remove(5)  # a small hole fits in the scratch
    dv.insert(0.0, 0.5 * r)  # beside the centre: the cavity fan, no scratch
    if engine == "fortune":
        assert not dv._mesh.swept_ok
    dv._mesh._limit_scratch(-1)
    dv.remove(N)
    assert_cells_match(dv, dv.changed, box)


@pytest.mark.parametrize("engine", ENGINES)
def test_cell_of_a_site_with_10000_neighbours(engine):
    """The view's cell of the centre of 10,000 sites on a circle: a 10,000-gon."""
    pts, r = rounded_circle()
    box = box_of(r)
    dv = tvoronoi.DynamicVoronoi(pts, engine=engine, bbox=box)
    c = dv.insert(0.0, 0.0)
    assert len(dv.diagram().cell_polygon(c)) == N
    assert_cells_match(dv, [c], box)


def test_batch_cell_of_a_hull_site_with_10000_edges():
    """The batch build's cell of the origin below an arc of 10,000 sites: N Voronoi edges
    (one per neighbour), unbounded, so clipped to the box (its corners below the origin)."""
    t = np.pi * (np.arange(N) + 0.5) / N
    pts = np.vstack([[[0.0, 0.0]], np.column_stack([np.cos(t), np.sin(t)])])
    cell = tvoronoi.voronoi(pts, bbox=box_of(1.0)).cell_polygon(0)
    assert len(cell) >= N
