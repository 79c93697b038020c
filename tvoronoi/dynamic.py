"""Dynamic Voronoi diagrams: insert, move and remove sites with local work, and read cells as they change."""

from __future__ import annotations

import math

import numpy as np

from tvoronoi import engines
from tvoronoi.api import as_bbox, as_points, check_engine, check_range, default_bbox
from tvoronoi.build import assemble
from tvoronoi.diagram import Diagram
from tvoronoi.errors import TvoronoiError
from tvoronoi.kernels import clip, dual, dynamic


def check_coordinate(x: float, y: float, e: int) -> tuple[float, float]:
    """A new site's coordinates: numbers, finite, and within the range rule of a diagram of scale 2^e."""
    try:
        x, y = float(x), float(y)
    except (TypeError, ValueError):
        raise TvoronoiError(f"coordinates must be numbers, got ({x!r}, {y!r})") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise TvoronoiError(f"coordinates must be finite, got ({x!r}, {y!r})")
    check_range(np.array([[x, y]]), e, what="the new site", scale_of="the diagram")
    return x, y


# a cell is read with the cells within this many Delaunay steps: a bent ring among them means the batch
# build's straightening may reach it
SETTLE_RADIUS = 2


def settled_cell(mesh: dynamic.DynamicMesh, i: int, bbox, e: int) -> np.ndarray:
    """Cell i of the mesh as the batch build makes it (tvoronoi.build): clipped and, where rounding made
    rings cross themselves, straightened (clip.straighten) as the batch straightens every ring.

    The mesh keeps count of its bent cells (DynamicMesh.cells_near looks again at the cells each update
    changed, and at every cell of a new mesh): with none, the cell as clipped. A merge changes a ring
    only through a bent ring that shares one of its points (its own or a neighbour's), and a ring that
    was not bent bends only through such a merge: a chain of bends moves one cell a round. So with no
    bent cell within SETTLE_RADIUS steps, again the cell as clipped; otherwise those cells are
    straightened together, the patch grown until every ring it bends lies two steps inside its edge (or
    it holds the whole mesh). A chain of three rounds or more arriving from beyond SETTLE_RADIUS would
    not be seen; the hunts (66,000 sessions on rounded lattices) met none.

    Steps are not the whole story: nearly cocircular sites share one rounded vertex across their whole
    circle, and a merge renames a point in every cell that has it. So a cell that shares a vertex with a
    bent cell however far away is read with a patch that reaches it (shares_a_bent_vertex), and a
    patch is kept only when it holds every cell that has a point of a ring it found bent
    (holds_sharers); otherwise it grows."""
    radius = SETTLE_RADIUS
    x0, y0, x1, y1 = bbox
    ring, patch = mesh.cells_near(i, x0, y0, x1, y1, e, radius)
    if patch is None and mesh.shares_a_bent_vertex(i, e):
        # a bent cell further away has a vertex of this one: a patch that reaches it
        while patch is None:
            radius *= 2
            ring, patch = mesh.cells_near(i, x0, y0, x1, y1, e, radius)
    while patch is not None:
        ids, steps, offsets, xy = patch
        was_bent = np.zeros(len(steps), np.int8)
        new_offsets, rings = clip.straighten(xy, offsets, np.arange(len(xy), dtype=np.int32), bbox, was_bent)
        whole = int(steps.max()) < radius
        if whole or (
            not (was_bent.view(bool) & (steps >= radius - 1)).any() and holds_sharers(mesh, patch, was_bent, e)
        ):
            return xy[rings[new_offsets[0] : new_offsets[1]]]
        radius *= 2
        ring, patch = mesh.cells_near(i, x0, y0, x1, y1, e, radius)
    return ring


def holds_sharers(mesh: dynamic.DynamicMesh, patch, was_bent: np.ndarray, e: int) -> bool:
    """Every cell that has a point of a ring the straightening found bent as a vertex is in the patch: a
    merge renames that point in every cell that has it, however many steps away (nearly cocircular
    sites share one rounded vertex across their whole circle)."""
    ids, _steps, offsets, xy = patch
    have = set(ids.tolist())
    for k in np.flatnonzero(was_bent):
        for x, y in xy[offsets[k] : offsets[k + 1]].tolist():
            if not mesh.sites_at_point(int(ids[k]), x, y, e) <= have:
                return False
    return True


class DynamicVoronoi:
    """A Voronoi diagram that follows insertions, moves and removals of sites.

    Each update changes the Delaunay triangulation only around the sites it
    touches (the conflict region of a new site, the hole of a removed one),
    and reading a cell computes that cell alone, so an update followed by
    reading the changed cells costs only the local work.

    Parameters
    ----------
    points : array_like (n, 2)
        The initial sites, ids 0 .. n-1.
    engine : {"incremental", "fortune"}
        "incremental": Bowyer-Watson insertion, ear-by-ear Delaunay removal.
        "fortune": the changed region's sites are swept by Fortune's algorithm
        and the result is spliced into the triangulation.
    bbox : (xmin, ymin, xmax, ymax), optional
        Fixed at creation; by default the initial points' box grown by 10%.

    Examples
    --------
    >>> dv = DynamicVoronoi([[0, 0], [2, 0], [0, 2]])
    >>> i = dv.insert(1.5, 1.5)
    >>> sorted(dv.changed.tolist())  # the new site and the cells it took area from
    [0, 1, 2, 3]
    >>> dv.move(i, 3, 3)
    ... dv.remove(0)
    >>> len(dv.diagram().cell_polygon(0)), len(dv.diagram().cell_polygon(1)) > 0
    (0, True)
    """

    def __init__(self, points=(), *, engine: str = "incremental", bbox=None):
        pts = as_points(points)
        check_engine(engine)
        self.engine = engine
        self.bbox = default_bbox(pts) if bbox is None else as_bbox(bbox)
        # the one range rule (tvoronoi.api): the mesh holds sites scaled by 2^-e, e fixed by the box and
        # the first sites, so later sites anywhere within 2^170 of that scale stay exact
        self._e = engines.scale_exponent(pts, self.bbox)
        if len(pts) and engines.scale_exponent(pts) < self._e:
            # the box sets the scale: measure against it, not against the largest of the points
            check_range(pts, self._e, scale_of="the box", remedy="choose a box nearer the points' scale")
        else:
            check_range(pts, self._e)
        engines.check_box_scale(self.bbox, self._e)
        n = len(pts)
        self._xy = np.full((max(2 * n, 16), 2), np.nan)
        self._xy[:n] = pts
        self._alive = np.zeros(len(self._xy), bool)
        self._alive[:n] = True
        self._n_ids = n
        self._primary: dict[int, int] = {}  # a repeated point's id -> the id holding the place
        self._copies: dict[int, list[int]] = {}  # the holder -> its repeats, oldest first
        self._mesh: dynamic.DynamicMesh | None = None
        self._flat: Diagram | None = None  # the diagram while the sites are collinear
        self.changed = np.arange(n, dtype=np.int32)
        self._rebuild()

    # -- bookkeeping -------------------------------------------------------------------------------

    def _check_id(self, i) -> int:
        try:
            i = int(i)
        except (TypeError, ValueError):
            raise TvoronoiError(f"site id must be an integer, got {i!r}") from None
        if not 0 <= i < self._n_ids:
            raise TvoronoiError(f"no site {i}: ids run from 0 to {self._n_ids - 1}")
        if not self._alive[i]:
            raise TvoronoiError(f"site {i} was removed")
        return i

    def _new_id(self) -> int:
        i = self._n_ids
        if i == len(self._xy):
            grow = len(self._xy)
            self._xy = np.concatenate([self._xy, np.full((grow, 2), np.nan)])
            self._alive = np.concatenate([self._alive, np.zeros(grow, bool)])
        self._n_ids += 1
        return i

    def _holders(self) -> np.ndarray:
        """Alive ids that hold a place (not repeats), ascending."""
        ids = np.flatnonzero(self._alive[: self._n_ids])
        if self._primary:
            ids = ids[~np.isin(ids, list(self._primary))]
        return ids.astype(np.int32)

    def _rebuild(self) -> None:
        """Build the triangulation of all holders at once (the start, or after the sites were flat)."""
        self._mesh, self._flat = None, None
        ids = np.flatnonzero(self._alive[: self._n_ids]).astype(np.int32)
        self._primary.clear()
        self._copies.clear()
        if len(ids) == 0:
            return
        # the batch engine's order (a biased randomized insertion order, or the sweep's)
        t = engines.run(self._xy[ids, 0], self._xy[ids, 1], engine=self.engine, exponent=self._e)
        sx, sy, dup = t.sites.xs, t.sites.ys, t.dup
        order_ids = ids[t.sites.perm]
        # repeats: the smallest id at a place holds it
        groups: dict[int, list[int]] = {}
        for k in np.flatnonzero(dup >= 0).tolist():
            groups.setdefault(int(dup[k]), []).append(int(order_ids[k]))
        holder_of_vertex = {}
        for k, copies in groups.items():
            everyone = sorted(copies + [int(order_ids[k])])
            holder_of_vertex[k] = everyone[0]
            self._copies[everyone[0]] = everyone[1:]
            for c in everyone[1:]:
                self._primary[c] = everyone[0]
        if t.tv is None or t.opp is None:
            return  # the distinct sites are collinear (t.flat): no mesh until a site leaves the line
        mesh = dynamic.DynamicMesh(max(len(self._xy), 16))
        mesh.load(sx, sy, order_ids.astype(np.int32), t.tv, t.opp, len(sx))
        for k, holder in holder_of_vertex.items():
            if holder != int(order_ids[k]):
                mesh.relabel(int(order_ids[k]), holder)
        for c, p in self._primary.items():
            mesh.set_site(c, *np.ldexp(self._xy[c], -self._e))
        self._mesh = mesh

    # -- updates -----------------------------------------------------------------------------------

    def insert(self, x, y) -> int:
        """Add a site at (x, y); returns its id."""
        x, y = check_coordinate(x, y, self._e)
        i = self._new_id()
        self._place(i, x, y)
        return i

    def _place(self, i: int, x: float, y: float) -> None:
        self._flat = None
        self._xy[i] = (x, y)
        self._alive[i] = True
        if self._mesh is None:
            self._rebuild()
            self.changed = np.union1d(self._holders(), [i]).astype(np.int32)
            return
        sx, sy = math.ldexp(x, -self._e), math.ldexp(y, -self._e)
        if self.engine == "fortune":
            held = self._mesh.insert_swept(i, sx, sy)
        else:
            held = self._mesh.insert(i, sx, sy)
        if held >= 0:
            # a repeated point: it shares the cell of the site already there
            holder = self._primary.get(held, held)
            self._primary[i] = holder
            self._copies.setdefault(holder, []).append(i)
            self.changed = np.array([i], np.int32)
        else:
            self.changed = self._mesh.changed()

    def remove(self, i) -> None:
        """Remove site i (its id is not reused)."""
        i = self._check_id(i)
        changed = self._unplace(i)
        self._alive[i] = False
        self._xy[i] = np.nan
        self.changed = changed

    def _unplace(self, i: int) -> np.ndarray:
        self._flat = None
        if i in self._primary:
            holder = self._primary.pop(i)
            self._copies[holder].remove(i)
            if not self._copies[holder]:
                del self._copies[holder]
            return np.array([i], np.int32)
        if i in self._copies:
            # the oldest repeat takes the place over
            copies = self._copies.pop(i)
            heir = copies[0]
            del self._primary[heir]
            if copies[1:]:
                self._copies[heir] = copies[1:]
                for c in copies[1:]:
                    self._primary[c] = heir
            if self._mesh is not None:
                self._mesh.relabel(i, heir)
            return np.array([i, heir], np.int32)
        if self._mesh is None:
            self._alive[i] = False
            self._rebuild()
            return np.append(self._holders(), i).astype(np.int32)
        status = self._mesh.remove_swept(i) if self.engine == "fortune" else self._mesh.remove(i)
        if status == dynamic.NO_MEMORY:
            raise MemoryError(f"no memory to remove site {i}: the diagram is unchanged")
        if status != 0:
            # the sites left are collinear (or the hole was beyond the local repair): start again
            self._alive[i] = False
            self._rebuild()
            return np.append(self._holders(), i).astype(np.int32)
        return np.append(self._mesh.changed(), i).astype(np.int32)

    def move(self, i, x, y) -> None:
        """Move site i to (x, y), keeping its id."""
        i = self._check_id(i)
        x, y = check_coordinate(x, y, self._e)
        gone = self._unplace(i)
        self._alive[i] = False
        self._place(i, x, y)
        self.changed = np.union1d(gone, self.changed).astype(np.int32)

    # -- reading -----------------------------------------------------------------------------------

    def diagram(self) -> "DynamicDiagram":
        """The current diagram, as a cheap view (no copy, no rebuild)."""
        return DynamicDiagram(self)

    def __len__(self) -> int:
        return int(self._alive[: self._n_ids].sum())


class DynamicDiagram:
    """A view of a DynamicVoronoi: cells are computed when read, each on its own."""

    def __init__(self, owner: DynamicVoronoi):
        self._owner = owner
        self.bbox = owner.bbox

    @property
    def n_sites(self) -> int:
        """Ids issued so far (removed ones included)."""
        return self._owner._n_ids

    @property
    def sites(self) -> np.ndarray:
        """(n_sites, 2) coordinates by id; NaN rows for removed ids."""
        return self._owner._xy[: self._owner._n_ids]

    @property
    def alive(self) -> np.ndarray:
        return self._owner._alive[: self._owner._n_ids]

    def cell_polygon(self, i: int) -> np.ndarray:
        """Cell of site i, clipped to the box: (k, 2), counter-clockwise; empty for a removed
        id and for a repeated point (the site holding the place has the cell)."""
        o = self._owner
        i = int(i)
        if not 0 <= i < o._n_ids:
            raise IndexError(f"no site {i}: ids run from 0 to {o._n_ids - 1}")
        if not o._alive[i] or i in o._primary:
            return np.empty((0, 2))
        if o._mesh is not None:
            return settled_cell(o._mesh, i, self.bbox, o._e)
        if o._flat is None:
            o._flat = self.to_diagram()
        return o._flat.cell_polygon(i)

    def neighbours(self, i: int) -> np.ndarray:
        """Sites whose cells share an edge with cell i (its Delaunay neighbours)."""
        o = self._owner
        if o._mesh is None:
            d = self.to_diagram()
            cyc = d.half_edge_cycle(i)
            return np.unique(d.he_face[d.he_twin[cyc]])
        return o._mesh.neighbours(int(i))

    def to_diagram(self) -> Diagram:
        """The whole diagram as a Diagram (O(n): for saving or comparing, not for every update)."""
        o = self._owner
        n = o._n_ids
        pts = np.where(o._alive[:n, None], o._xy[:n], 0.0)
        xs = np.ascontiguousarray(np.ldexp(pts[:, 0], -o._e))
        ys = np.ascontiguousarray(np.ldexp(pts[:, 1], -o._e))
        dup = np.full(n, -1, np.int32)
        for c, p in o._primary.items():
            dup[c] = p
        present = o._alive[:n].copy()
        if o._mesh is not None:
            tv, opp = o._mesh.export()
            tv = np.where(tv == dynamic.INFINITE, n, tv).astype(np.int32)
            out = dual.voronoi_from_delaunay(xs, ys, tv, opp, o._e)
        else:
            holders = o._holders()
            out = engines.lift_dcel(engines.collinear_dcel(xs[holders], ys[holders]), holders, n)
        out["dup"] = dup
        return assemble(
            pts,
            self.bbox,
            o._e,
            np.arange(n, dtype=np.int32),
            xs,
            ys,
            out,
            engine=o.engine,
            present=present,
            first_row_holds=False,
        )

    def delaunay_triangles(self) -> np.ndarray:
        return self.to_diagram().delaunay_triangles()
