"""Invariants every Diagram must satisfy, checked without stored answers."""

import types

import numpy as np
import shapely

# Relative tolerances for floating-point geometry (coordinates are rounded,
# the topology is exact).
AREA_RTOL = 1e-9
DIST_RTOL = 1e-7


def check_dcel(d):
    """Twin symmetry, next/prev inverse, face cycles, Euler's formula."""
    h = np.arange(len(d.he_origin))
    assert np.all(d.he_twin[d.he_twin] == h), "twin of twin"
    assert np.all(d.he_twin != h)
    assert np.all(d.he_prev[d.he_next] == h), "prev of next"
    assert np.all(d.he_face[d.he_next] == d.he_face), "next stays in the face"
    assert np.all(d.he_face[d.he_twin] != d.he_face), "twins bound different cells"
    # the end of h is the start of next[h] (both may be at infinity)
    assert np.all(d.he_origin[d.he_next] == d.he_origin[d.he_twin])
    # the layout: each cell's half-edges are one run, starting at face_edge
    if len(h):
        starts = np.flatnonzero(np.r_[True, d.he_face[1:] != d.he_face[:-1]])
        assert len(np.unique(d.he_face[starts])) == len(starts), "a cell's half-edges are not consecutive"
        assert np.array_equal(np.sort(d.face_edge[d.face_edge >= 0]), starts), "face_edge is not a run's start"
    # each cell's cycle holds exactly the half-edges of that cell
    counts = np.bincount(d.he_face, minlength=d.n_sites) if len(h) else np.zeros(d.n_sites, int)
    for i in range(d.n_sites):
        cycle = d.half_edge_cycle(i)
        assert len(cycle) == counts[i], f"cell {i}: cycle of {len(cycle)} of {counts[i]} half-edges"
        assert np.all(d.he_face[cycle] == i)
    # no zero-length edge: the two ends of a finite edge differ
    o, t = d.he_origin, d.he_origin[d.he_twin]
    both = (o >= 0) & (t >= 0)
    assert np.all(o[both] != t[both]), "an edge from a vertex to itself"
    faces = int(np.sum(d.site_of == np.arange(d.n_sites)))
    if len(h):
        unbounded = np.any(d.he_origin < 0)
        v = d.n_vertices + (1 if unbounded else 0)
        assert v - len(h) // 2 + faces == 2, "Euler's formula V - E + F = 2"


def check_vertices(d):
    """Each Voronoi vertex is equidistant from the sites of the cells around it."""
    if d.n_vertices == 0:
        return
    scale = max(np.ptp(d.sites[:, 0]), np.ptp(d.sites[:, 1]))
    finite = d.he_origin >= 0
    v = d.he_origin[finite]
    s = d.sites[d.he_face[finite]]
    dist = np.hypot(*(d.vertices[v] - s).T)
    ref = np.zeros(d.n_vertices)
    np.maximum.at(ref, v, dist)
    lo = np.full(d.n_vertices, np.inf)
    np.minimum.at(lo, v, dist)
    assert np.all(ref - lo <= DIST_RTOL * (scale + ref)), "a vertex not equidistant from its sites"
    # and no other site is closer (the empty circle)
    from scipy.spatial import cKDTree

    nearest, _ = cKDTree(d.sites).query(d.vertices)
    assert np.all(nearest >= lo - DIST_RTOL * (scale + ref)), "a site inside a vertex's circle"


def box_frame(d):
    """Map coordinates into about the unit square by a power of two alone, so that areas of tiny or huge
    diagrams stay representable and every point keeps its exact value relative to the others: shapely's
    validity, orientation and coverage tests then judge the rings the Diagram holds, not a rounded copy
    (a translation, or a division by the box's width, rounds each point and can make a valid ring cross
    itself -- or an invalid one pass)."""
    corners = np.abs(np.asarray(d.bbox, float))
    top = float(corners.max()) if corners.size and np.isfinite(corners).all() else 0.0
    exponent = int(np.frexp(top)[1]) if top > 0.0 else 0
    every = np.concatenate([np.asarray(d.cell_points, float).ravel(), np.asarray(d.sites, float).ravel()])
    if not np.array_equal(np.ldexp(np.ldexp(every, -exponent), exponent), every, equal_nan=True):
        exponent = 0  # scaling would take some point below the normal range: the points as they are
    return lambda xy: np.ldexp(np.asarray(xy, float).reshape(-1, 2), -exponent)


def cell_polygons(d):
    frame = box_frame(d)
    return {i: shapely.Polygon(frame(d.cell_polygon(i))) for i in range(d.n_sites) if len(d.cell_polygon(i))}


def check_cells(d, *, sites_in_box=True):
    """Valid CCW cells, each holding its site, tiling the box exactly once."""
    polys = cell_polygons(d)
    frame = box_frame(d)
    xmin, ymin, xmax, ymax = frame([d.bbox[:2], d.bbox[2:]]).ravel()
    box_area = (xmax - xmin) * (ymax - ymin)
    for i in range(d.n_sites):
        first = d.site_of[i] == i
        if not first:
            assert len(d.cell_polygon(i)) == 0, f"repeated point {i} has a cell of its own"
            continue
        if sites_in_box:
            assert i in polys, f"site {i} has no cell"
    for i, p in polys.items():
        assert p.is_valid, f"cell {i} invalid: {shapely.is_valid_reason(p)}"
        assert p.exterior.is_ccw, f"cell {i} is clockwise"
        assert p.area > 0
        if sites_in_box:
            assert p.covers(shapely.Point(frame(d.sites[i])[0])), f"site {i} outside its cell"
    check_ring_starts(d)
    total = sum(p.area for p in polys.values())
    if d.n_sites == 0:
        assert total == 0
        return
    assert abs(total - box_area) <= AREA_RTOL * box_area, f"cells cover {total}, box {box_area}"
    assert shapely.coverage_is_valid(shapely.GeometryCollection(list(polys.values())))


def check_ring_starts(d):
    """Every ring starts at its lowest point (smallest y, then smallest x), as the clipper promises: the
    same ring from either engine, whichever half-edge its cell began with."""
    offsets = np.asarray(d.cell_offsets)
    lengths = np.diff(offsets)
    starts = offsets[:-1][lengths > 0]
    if len(starts) == 0:
        return
    xy = np.asarray(d.cell_points)[np.asarray(d.cell_vertices)]
    low_y = np.minimum.reduceat(xy[:, 1], starts)
    ring_of = np.repeat(np.arange(len(starts)), lengths[lengths > 0])
    low_x = np.minimum.reduceat(np.where(xy[:, 1] == low_y[ring_of], xy[:, 0], np.inf), starts)
    bad = np.flatnonzero((xy[starts, 1] != low_y) | (xy[starts, 0] != low_x))
    assert len(bad) == 0, f"{len(bad)} rings do not start at their lowest point, the first at {starts[bad[0]]}"


def validate(d, *, sites_in_box=True):
    check_dcel(d)
    check_vertices(d)
    check_cells(d, sites_in_box=sites_in_box)


# every array of a Diagram, for comparing two builds bit for bit
FIELDS = (
    "sites",
    "site_of",
    "vertices",
    "he_origin",
    "he_twin",
    "he_next",
    "he_prev",
    "he_face",
    "face_edge",
    "triangles",
    "cell_points",
    "cell_offsets",
    "cell_vertices",
)


def assert_same_diagram(a, b):
    """Two Diagrams equal bit for bit: every array (dtype, shape, values) and the box."""
    for name in FIELDS:
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x, y), f"{name} differs"
    assert a.bbox == b.bbox


def with_rings(d, rings):
    """A stand-in for Diagram d with its sites and box and the given rings (one per site, in site order,
    empty for none): for tests that spoil a cell and expect a check to catch it."""
    lengths = [len(r) for r in rings]
    offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
    points = np.vstack([np.asarray(r, float).reshape(-1, 2) for r in rings]) if sum(lengths) else np.zeros((0, 2))
    return types.SimpleNamespace(
        sites=d.sites,
        site_of=d.site_of,
        n_sites=d.n_sites,
        bbox=d.bbox,
        cell_points=points,
        cell_vertices=np.arange(len(points), dtype=np.int32),
        cell_offsets=offsets,
        cell_polygon=lambda i: points[offsets[i] : offsets[i + 1]],
    )
