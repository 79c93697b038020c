"""The Voronoi tools under test, each with a full-diagram build, a bounded-cells build and a correctness check.

A tool turns an (n, 2) float64 array and a box (xmin, ymin, xmax, ymax) into
either its full diagram (whatever the tool natively returns) or one polygon
per site clipped to the box (what a user of cells needs). Every result is
checked before any timing: a wrong answer fast is not a result.

The checks, for a seeded sample of sites and vertices:
- a Voronoi vertex has (at least) three equidistant nearest sites;
- every corner of cell i has site i among its nearest sites, so the cell
  lies inside the true Voronoi cell (cells are convex);
- there is one cell per site, each contains its site, and the areas of the
  bounded cells add up to the area of the box: with the previous point this
  pins every cell down to the true one;
- a Delaunay triangle's circumcircle holds no site, and a triangulation of n
  sites with h on the hull has 2n - 2 - h triangles.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from tvoronoi.trace import circumcentres

# Relative tolerances of the checks: distances against the box size, areas against the box area.
DIST_TOL = 1e-9
AREA_TOL = 1e-9
# Sites, cells or vertices checked per result.
SAMPLE = 300
# Cells per chunk when summing the areas of a CSR cell array (bounds the check's memory).
AREA_CHUNK = 200_000
# Far points of unbounded Qhull regions go this many box diagonals past their finite vertex.
FAR_DIAGONALS = 4.0
KINDS = ("full", "bounded")


class CheckFailed(AssertionError):
    """A tool's output is not the Voronoi diagram of its input."""


@dataclass(frozen=True)
class Tool:
    """One engine under test.

    ``full`` / ``bounded`` map (points, box) to a result, ``check_full`` /
    ``check_bounded`` raise CheckFailed on a wrong one; None where the tool
    has no such output. ``max_n`` skips larger inputs (slow by design).
    """

    name: str
    label: str
    full: Callable | None
    bounded: Callable | None
    check_full: Callable | None
    check_bounded: Callable | None
    max_n: int | None = None
    requires: str | None = None  # an optional module the tool needs

    def kinds(self) -> tuple[str, ...]:
        return tuple(k for k in KINDS if getattr(self, k) is not None)

    def run(self, kind: str, pts: np.ndarray, box):
        return getattr(self, kind)(pts, box)

    def check(self, kind: str, result, pts: np.ndarray, box, tree) -> None:
        getattr(self, f"check_{kind}")(result, pts, box, tree)

    def missing(self) -> str | None:
        """Why the tool cannot run here, or None."""
        if self.requires is None:
            return None
        try:
            __import__(self.requires)
        except ImportError as exc:
            return f"{self.requires} is not installed ({exc})"
        return None


# --- the tools -------------------------------------------------------------------------------


def _tv_full(engine: str, insertion: str = "brio"):
    """tvoronoi's engine and DCEL (Voronoi vertices, half-edges), before cells are clipped."""

    def build(pts, box):
        from tvoronoi import engines
        from tvoronoi.api import as_points

        pts = as_points(pts)
        t = engines.run(pts[:, 0], pts[:, 1], engine=engine, insertion=insertion)
        return t.voronoi()  # its vertices in the points' own unit, whatever the engine's scale

    return build


def _tv_bounded(engine: str, insertion: str = "brio"):
    """tvoronoi's public call: it returns cells already clipped to the box."""

    def build(pts, box):
        import tvoronoi

        return tvoronoi.voronoi(pts, engine=engine, insertion=insertion, bbox=box)

    return build


def qhull_voronoi(pts, box):
    import scipy.spatial

    return scipy.spatial.Voronoi(pts)


def qhull_delaunay(pts, box):
    import scipy.spatial

    return scipy.spatial.Delaunay(pts)


def qhull_bounded(pts, box):
    """scipy.spatial.Voronoi, the usual finite-regions recipe, then shapely clips each region to the box."""
    import shapely

    vor = qhull_voronoi(pts, box)
    xmin, ymin, xmax, ymax = box
    radius = FAR_DIAGONALS * float(np.hypot(xmax - xmin, ymax - ymin))
    regions, vertices = finite_regions(vor, radius)
    lengths = np.fromiter((len(r) for r in regions), np.int64, len(regions))
    flat = np.fromiter((v for r in regions for v in r), np.int64, int(lengths.sum()))
    rings = shapely.linearrings(vertices[flat], indices=np.repeat(np.arange(len(regions)), lengths))
    return shapely.intersection(shapely.polygons(rings), shapely.box(*box))


def finite_regions(vor, radius: float):
    """Close every unbounded region of a scipy Voronoi diagram with far points (the widely used recipe).

    Returns (regions, vertices): regions[i] lists rows of ``vertices`` in
    counter-clockwise order for input point i. An unbounded region gets, for
    each of its two infinite ridges, a point ``radius`` beyond the ridge's
    finite vertex along the outward normal of the two sites.
    """
    center = vor.points.mean(axis=0)
    all_ridges: dict[int, list] = {}
    for (p1, p2), (v1, v2) in zip(vor.ridge_points.tolist(), vor.ridge_vertices):
        all_ridges.setdefault(p1, []).append((p2, v1, v2))
        all_ridges.setdefault(p2, []).append((p1, v1, v2))
    new_vertices = vor.vertices.tolist()
    new_regions = []
    for p1, region in enumerate(vor.point_region.tolist()):
        vertices = vor.regions[region]
        if all(v >= 0 for v in vertices):
            new_regions.append(vertices)  # a bounded region: as Qhull gave it
            continue
        new_region = [v for v in vertices if v >= 0]
        for p2, v1, v2 in all_ridges[p1]:
            if v2 < 0:
                v1, v2 = v2, v1
            if v1 >= 0:
                continue  # a finite ridge: already in the region
            t = vor.points[p2] - vor.points[p1]
            t /= np.linalg.norm(t)
            normal = np.array([-t[1], t[0]])
            midpoint = vor.points[[p1, p2]].mean(axis=0)
            direction = np.sign(np.dot(midpoint - center, normal)) * normal
            new_region.append(len(new_vertices))
            new_vertices.append((vor.vertices[v2] + direction * radius).tolist())
        # order the closed region counter-clockwise about its centroid
        vs = np.asarray([new_vertices[v] for v in new_region])
        c = vs.mean(axis=0)
        order = np.argsort(np.arctan2(vs[:, 1] - c[1], vs[:, 0] - c[0]))
        new_regions.append([new_region[k] for k in order])
    return new_regions, np.asarray(new_vertices)


def geos_full(pts, box):
    """shapely.voronoi_polygons (GEOS): cells in input order, extended to at least the box."""
    import shapely

    cells = shapely.voronoi_polygons(shapely.MultiPoint(pts), extend_to=shapely.box(*box), ordered=True)
    return shapely.get_parts(cells)


def geos_bounded(pts, box):
    import shapely

    return shapely.intersection(geos_full(pts, box), shapely.box(*box))


def triangle_full(pts, box):
    """Shewchuk's Triangle: Voronoi vertices, finite edges, and rays (no cells)."""
    import triangle

    return triangle.voronoi(pts)


# --- the checks ------------------------------------------------------------------------------


def _rng():
    return np.random.default_rng(12345)


def _scale(box) -> float:
    return float(max(box[2] - box[0], box[3] - box[1]))


def _fail(cond: bool, msg: str) -> None:
    if not cond:
        raise CheckFailed(msg)


def hull_size(pts: np.ndarray) -> int:
    """Number of convex hull vertices (GEOS, independent of the tools' own hull)."""
    import shapely

    hull = shapely.MultiPoint(pts).convex_hull
    return len(shapely.get_coordinates(hull)) - 1


def check_vertices(vertices: np.ndarray, tree, box, what: str) -> None:
    """A sample of Voronoi vertices each has three equidistant nearest sites."""
    vertices = np.asarray(vertices, float).reshape(-1, 2)
    finite = vertices[np.isfinite(vertices).all(axis=1)]
    _fail(len(finite) > 0, f"{what}: no Voronoi vertices")
    pick = _rng().choice(len(finite), size=min(SAMPLE, len(finite)), replace=False)
    d, _ = tree.query(finite[pick], k=3)
    gap = d[:, 2] - d[:, 0]
    tol = DIST_TOL * (_scale(box) + d[:, 0])
    bad = np.flatnonzero(gap > tol)
    if len(bad):
        raise CheckFailed(
            f"{what}: vertex {finite[pick[bad[0]]]} is not equidistant from its three nearest "
            f"sites (gap {gap[bad[0]]:.3g})"
        )


def check_cells(n_cells: int, cell, areas: float, pts: np.ndarray, box, tree, what: str, *, area: bool = True) -> None:
    """One cell per site; sampled cells hold their site and lie in its Voronoi cell; areas tile the box.

    ``cell(i)`` gives the corners of cell i as a (k, 2) array (closed or not),
    ``areas`` the total area of all cells.
    """
    import shapely

    n = len(pts)
    _fail(n_cells == n, f"{what}: {n_cells} cells for {n} sites")
    if area:
        box_area = (box[2] - box[0]) * (box[3] - box[1])
        _fail(
            abs(areas - box_area) <= AREA_TOL * box_area,
            f"{what}: cell areas add up to {areas!r}, the box has {box_area!r}",
        )
    tol = DIST_TOL * _scale(box)
    for i in _rng().choice(n, size=min(SAMPLE, n), replace=False).tolist():
        ring = np.asarray(cell(i), float).reshape(-1, 2)
        _fail(len(ring) >= 3, f"{what}: cell {i} has {len(ring)} corners")
        _fail(shapely.Polygon(ring).covers(shapely.Point(pts[i])), f"{what}: cell {i} misses its site")
        own = np.hypot(*(ring - pts[i]).T)
        nearest, _ = tree.query(ring)
        _fail(bool(np.all(own - nearest <= tol)), f"{what}: a corner of cell {i} is nearer another site")


def csr_area(points: np.ndarray, offsets: np.ndarray, ring: np.ndarray) -> float:
    """Total area of CSR polygons (shoelace), a chunk of cells at a time."""
    total = 0.0
    n = len(offsets) - 1
    for lo in range(0, n, AREA_CHUNK):
        hi = min(n, lo + AREA_CHUNK)
        a, b = int(offsets[lo]), int(offsets[hi])
        if a == b:
            continue
        xy = points[ring[a:b]]
        nxt = np.arange(a, b) + 1
        ends = offsets[lo + 1 : hi + 1]
        starts = offsets[lo:hi]
        nonempty = ends > starts
        nxt[ends[nonempty] - 1 - a] = starts[nonempty]  # last corner of a ring wraps to its first
        nxy = points[ring[nxt]]
        total += 0.5 * float(np.sum(xy[:, 0] * nxy[:, 1] - nxy[:, 0] * xy[:, 1]))
    return total


def check_tv_full(out, pts, box, tree) -> None:
    faces = np.unique(out["he_face"])
    _fail(len(faces) == len(pts), f"tvoronoi DCEL: {len(faces)} faces for {len(pts)} sites")
    check_vertices(out["vertices"], tree, box, "tvoronoi DCEL")


def check_tv_bounded(d, pts, box, tree) -> None:
    area = csr_area(d.cell_points, d.cell_offsets, d.cell_vertices)
    check_cells(len(d.cell_offsets) - 1, d.cell_polygon, area, pts, box, tree, "tvoronoi cells")


def check_shapely_cells(cells, pts, box, tree, what: str, *, area: bool = True) -> None:
    import shapely

    check_cells(
        len(cells),
        lambda i: shapely.get_coordinates(cells[i]),
        float(shapely.area(cells).sum()),
        pts,
        box,
        tree,
        what,
        area=area,
    )


def check_qhull_voronoi(vor, pts, box, tree) -> None:
    _fail(len(vor.point_region) == len(pts), f"Qhull: {len(vor.point_region)} regions for {len(pts)} sites")
    check_vertices(vor.vertices, tree, box, "Qhull Voronoi")


def check_qhull_delaunay(tri, pts, box, tree) -> None:
    n, h = len(pts), hull_size(pts)
    _fail(
        len(tri.simplices) == 2 * n - 2 - h,
        f"Qhull Delaunay: {len(tri.simplices)} triangles, expected 2n - 2 - h = {2 * n - 2 - h}",
    )
    pick = _rng().choice(len(tri.simplices), size=min(SAMPLE, len(tri.simplices)), replace=False)
    p, q, r = (pts[tri.simplices[pick, k]] for k in range(3))
    centre = circumcentres(p, q, r)
    radius = np.hypot(*(centre - p).T)
    nearest, _ = tree.query(centre)
    _fail(
        bool(np.all(nearest >= radius - DIST_TOL * (_scale(box) + radius))),
        "Qhull Delaunay: a site lies inside a triangle's circumcircle",
    )


def check_geos_full(cells, pts, box, tree) -> None:
    # GEOS extends the diagram past the box by its own margin: no area to compare
    check_shapely_cells(cells, pts, box, tree, "GEOS cells", area=False)


def check_bounded_cells(what: str):
    return lambda cells, pts, box, tree: check_shapely_cells(cells, pts, box, tree, what)


def check_triangle(result, pts, box, tree) -> None:
    vertices, edges, ray_origin, _ = result
    n, h = len(pts), hull_size(pts)
    _fail(
        len(vertices) == 2 * n - 2 - h,
        f"Triangle: {len(vertices)} Voronoi vertices, expected 2n - 2 - h = {2 * n - 2 - h}",
    )
    _fail(
        len(edges) + len(ray_origin) == 3 * n - 3 - h,
        f"Triangle: {len(edges) + len(ray_origin)} edges and rays, expected 3n - 3 - h = {3 * n - 3 - h}",
    )
    check_vertices(vertices, tree, box, "Triangle")


# Textbook insertion (fully random order, conflict lists) is the slow reference; not run above this.
TEXTBOOK_MAX_N = 200_000

TOOLS: dict[str, Tool] = {
    t.name: t
    for t in (
        Tool(
            "tvoronoi-fortune",
            "tvoronoi Fortune",
            _tv_full("fortune"),
            _tv_bounded("fortune"),
            check_tv_full,
            check_tv_bounded,
        ),
        Tool(
            "tvoronoi-incremental",
            "tvoronoi incremental (BRIO)",
            _tv_full("incremental"),
            _tv_bounded("incremental"),
            check_tv_full,
            check_tv_bounded,
        ),
        Tool(
            "tvoronoi-textbook",
            "tvoronoi incremental (textbook)",
            _tv_full("incremental", "random"),
            _tv_bounded("incremental", "random"),
            check_tv_full,
            check_tv_bounded,
            max_n=TEXTBOOK_MAX_N,
        ),
        Tool(
            "qhull-voronoi",
            "Qhull Voronoi (scipy)",
            qhull_voronoi,
            qhull_bounded,
            check_qhull_voronoi,
            check_bounded_cells("Qhull cells"),
        ),
        Tool("qhull-delaunay", "Qhull Delaunay (scipy)", qhull_delaunay, None, check_qhull_delaunay, None),
        Tool("geos", "GEOS (shapely)", geos_full, geos_bounded, check_geos_full, check_bounded_cells("GEOS cells")),
        Tool("triangle", "Triangle", triangle_full, None, check_triangle, None, requires="triangle"),
    )
}
# The reference every ratio is taken against, per kind.
REFERENCE = {"full": "qhull-voronoi", "bounded": "qhull-voronoi"}
