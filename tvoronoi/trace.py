"""Step-by-step traces of both engines, for playback: the state after any number of events.

``steps(points, engine=..., bbox=..., seed=...)`` is the one entry, with the same arguments for
both engines. A trace reruns its engine up to the requested step, which costs well under a
millisecond per thousand sites, so a timeline can be scrubbed freely.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from tvoronoi import engines
from tvoronoi.api import as_bbox, as_points, check_engine, default_bbox
from tvoronoi.build import assemble
from tvoronoi.diagram import Diagram
from tvoronoi.kernels import dual, fortune, incremental
from tvoronoi.kernels.predicates import orient2d_sign

KIND_NAMES = {0: "site", 1: "circle", 2: "repeat"}


def parabola_y(sx, sy, x, sweep_y):
    """Height of the beach-line parabola of site (sx, sy) above x, for the sweep line at sweep_y.

    The parabola is the set of points as far from the site as from the
    sweep line (which lies above the site); it opens downwards.
    """
    d = 2.0 * (sy - sweep_y)
    with np.errstate(divide="ignore", invalid="ignore"):
        return ((x - sx) ** 2 + sy * sy - sweep_y * sweep_y) / d


def breakpoint_xy(a, b, sweep_y):
    """Where the arcs of sites a (left) and b (right) meet, for the sweep line at sweep_y."""
    (ax, ay), (bx, by) = a, b
    da, db = 2.0 * (ay - sweep_y), 2.0 * (by - sweep_y)
    if da == 0.0 and db == 0.0:
        return 0.5 * (ax + bx), -math.inf  # two sites on the sweep line: a vertical line
    if da == 0.0:
        return ax, float(parabola_y(bx, by, ax, sweep_y))
    if db == 0.0:
        return bx, float(parabola_y(ax, ay, bx, sweep_y))
    # db ((x - ax)^2 + ay^2 - L^2) = da ((x - bx)^2 + by^2 - L^2)
    qa = db - da
    qb = -2.0 * (db * ax - da * bx)
    qc = db * (ax * ax + ay * ay - sweep_y**2) - da * (bx * bx + by * by - sweep_y**2)
    if qa == 0.0:
        x = -qc / qb
    else:
        root = math.sqrt(max(qb * qb - 4.0 * qa * qc, 0.0))
        x1, x2 = sorted(((-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)))
        # the narrower parabola (site nearer the line) is above between the crossings
        x = x2 if ay > by else x1
    return x, float(parabola_y(ax, ay, x, sweep_y))


def circumcentres(p, q, r):
    """Circumcentres of triangles (p, q, r), each a (k, 2) array, correctly rounded (the kernels' construction)."""
    p, q, r = (np.asarray(a, np.float64).reshape(-1, 2) for a in (p, q, r))
    k = len(p)
    xs = np.ascontiguousarray(np.concatenate((p[:, 0], q[:, 0], r[:, 0])))
    ys = np.ascontiguousarray(np.concatenate((p[:, 1], q[:, 1], r[:, 1])))
    tri = np.ascontiguousarray(np.arange(3 * k, dtype=np.int32).reshape(3, k).T)
    return dual.circumcentres(xs, ys, tri, 0)


@dataclass(frozen=True)
class FortuneStep:
    """The sweep after ``index`` events (0: before the first).

    Sites are input rows. Edges are (k, 2, 2) arrays of segments; a growing
    edge runs from where it began (a Voronoi vertex, or the point where a site
    event started it; y = -inf for the first row's vertical edges) to its
    breakpoint on the beach line now.
    """

    index: int
    n_steps: int
    kind: str  # "start", "site", "circle", "repeat"
    site: int  # the new site, or the site whose arc vanished
    position: tuple  # the event's point: the site, or the circle's top
    vertex: tuple | None  # the Voronoi vertex a circle event created
    sweep_y: float
    beach: np.ndarray  # (k,) sites of the arcs, left to right
    breakpoints: np.ndarray  # (k - 1, 2) where consecutive arcs meet
    circles: np.ndarray  # (m, 3) pending circle events: centre x, y, radius
    circle_arcs: np.ndarray  # (m,) index in beach of the arc each would remove
    vertices: np.ndarray  # (v, 2) Voronoi vertices so far
    finished_edges: np.ndarray  # (f, 2, 2)
    growing_edges: np.ndarray  # (g, 2, 2)

    def describe(self) -> str:
        """One line saying what this step did."""
        if self.kind == "start":
            return f"before the sweep: {self.n_steps} events to come"
        x, y = self.position
        if self.kind == "site":
            return f"site event at ({x:.4g}, {y:.4g}): site {self.site} splits an arc"
        if self.kind == "repeat":
            return f"site {self.site} repeats an earlier site at ({x:.4g}, {y:.4g}): no new arc"
        assert self.vertex is not None, "a circle event creates a vertex"
        vx, vy = self.vertex
        return (
            f"circle event at ({vx:.4g}, {vy:.4g}): vertex {len(self.vertices) - 1} created, "
            f"arc of site {self.site} vanishes"
        )


class FortuneTrace:
    """Replay Fortune's sweep over a point set, one event at a time.

    The sweep takes the sites in the order of y then x, so ``seed`` changes nothing (it is taken so
    that both traces are made alike); ``bbox`` is checked and kept as ``self.bbox``, the box the
    playback draws in.

    >>> import tvoronoi.trace as tr
    >>> t = tr.FortuneTrace([[0, 0], [2, 0], [1, 2]])
    >>> len(t), t.step(len(t)).kind
    (4, 'circle')
    """

    engine = "fortune"

    def __init__(self, points, *, bbox=None, seed: int = 0):
        self.points = as_points(points)
        self.bbox = default_bbox(self.points) if bbox is None else as_bbox(bbox)
        # the kernel sweeps sites scaled by 2^-e, as in a batch build (the one range rule); what a
        # step shows is in the user's unit
        sites = engines.prepare(self.points[:, 0], self.points[:, 1], engine="fortune", seed=seed)
        self._perm, self._e, self._xs, self._ys = sites.perm, sites.exponent, sites.xs, sites.ys
        engines.check_box_scale(self.bbox, self._e)
        self.n_steps = int(fortune.sweep(self._xs, self._ys)["steps"])

    def __len__(self) -> int:
        return self.n_steps

    def step(self, k: int) -> FortuneStep:
        """The state after k events, 0 <= k <= len(self)."""
        k = max(0, min(int(k), self.n_steps))
        st = fortune.sweep(self._xs, self._ys, k)
        perm, e = self._perm, self._e
        pts = self.points[perm]
        xs, ys = pts[:, 0], pts[:, 1]
        tri = np.ascontiguousarray(st["triangles"], dtype=np.int32).reshape(-1, 3)
        centres = dual.circumcentres(self._xs, self._ys, tri, e)
        beach = st["beach"]
        sweep_y = math.ldexp(float(st["sweep_y"]), e)
        bps = np.array(
            [breakpoint_xy(pts[beach[i]], pts[beach[i + 1]], sweep_y) for i in range(len(beach) - 1)]
        ).reshape(-1, 2)
        rec = st["records"]
        closed = rec["e1"] >= 0
        finished = np.stack((centres[rec["e0"][closed] // 3], centres[rec["e1"][closed] // 3]), axis=1)
        live = st["beach_edges"]
        e0 = rec["e0"][live]
        starts = np.ldexp(np.column_stack((rec["x"][live], rec["y"][live])), e)
        if len(live):
            starts[e0 >= 0] = centres[e0[e0 >= 0] // 3]
        growing = np.stack((starts, bps), axis=1) if len(live) else np.empty((0, 2, 2))
        events = st["events"]
        if len(events):
            arcs = events[:, 0].astype(int)
            ev = np.ldexp(events[:, 1:4], e)
            radius = ev[:, 2] - ev[:, 1]
            circles = np.column_stack((ev[:, 0], ev[:, 1], radius))
        else:
            arcs, circles = np.empty(0, int), np.empty((0, 3))
        kind, site, t = st["last"]
        name = "start" if k == 0 else KIND_NAMES[kind]
        if name == "circle":
            position = (float(centres[t][0]), float(sweep_y))
            vertex = (float(centres[t][0]), float(centres[t][1]))
        elif name == "start":
            position, vertex = (math.nan, math.nan), None
        else:
            position, vertex = (float(xs[site]), float(ys[site])), None
        return FortuneStep(
            index=k,
            n_steps=self.n_steps,
            kind=name,
            site=int(perm[site]) if site >= 0 else -1,
            position=position,
            vertex=vertex,
            sweep_y=float(sweep_y),
            beach=perm[beach].astype(np.int32),
            breakpoints=bps,
            circles=circles,
            circle_arcs=arcs,
            vertices=centres,
            finished_edges=np.asarray(finished, float).reshape(-1, 2, 2),
            growing_edges=np.asarray(growing, float).reshape(-1, 2, 2),
        )


@dataclass(frozen=True)
class IncrementalStep:
    """The randomized incremental engine after ``index`` sites were inserted.

    ``conflict`` holds the Delaunay triangles the new site destroyed (its
    conflict region, as (c, 3) input rows), ``stolen_from`` the sites whose
    cells it took area from, and ``diagram`` the Voronoi diagram of the sites
    inserted so far (the others have empty cells).

    ``walk`` is the point location that found the new site: the triangles of
    the triangulation before the step that the engine's visibility walk
    visited, in order, as (w, 3) input rows (-1 for the vertex at infinity).
    It starts at the last finite triangle the previous insertion created (the
    first triangle for the fourth site), moves across the first edge the site
    lies strictly right of, and ends in a triangle that contains the site, or
    in the infinite triangle beyond a hull edge the site sees. Empty for the
    first three sites, which make the first triangle without a walk.
    """

    index: int
    n_steps: int
    site: int
    conflict: np.ndarray
    new_triangles: np.ndarray
    stolen_from: np.ndarray
    inserted: np.ndarray
    diagram: Diagram
    walk: np.ndarray = dataclasses.field(default_factory=lambda: np.empty((0, 3), np.int32))

    def describe(self) -> str:
        if self.index == 0:
            return f"before the first insertion: {self.n_steps} sites to insert"
        x, y = self.diagram.sites[self.site]
        if len(self.conflict) == 0:
            return f"site {self.site} inserted at ({x:.4g}, {y:.4g})"
        return (
            f"site {self.site} inserted at ({x:.4g}, {y:.4g}): {len(self.conflict)} triangles "
            f"in conflict, cells taken from {len(self.stolen_from)} sites"
        )


class IncrementalTrace:
    """Replay the randomized incremental engine, one insertion at a time.

    The sites are inserted in the batch engine's order for ``seed``; each step's diagram is clipped
    to ``bbox`` (kept as ``self.bbox``).
    """

    engine = "incremental"

    def __init__(self, points, *, bbox=None, seed: int = 0):
        self.points = as_points(points)
        self.bbox = default_bbox(self.points) if bbox is None else as_bbox(bbox)
        n = len(self.points)
        # the batch engine's insertion order and scale
        sites = engines.prepare(self.points[:, 0], self.points[:, 1], engine="incremental", seed=seed)
        self._perm, self._e, self._xs, self._ys = sites.perm, sites.exponent, sites.xs, sites.ys
        engines.check_box_scale(self.bbox, self._e)
        self.n_steps = n

    def __len__(self) -> int:
        return self.n_steps

    def step(self, k: int) -> IncrementalStep:
        """The state after k insertions, 0 <= k <= len(self)."""
        n = self.n_steps
        k = max(0, min(int(k), n))
        res = incremental.triangulate(self._xs, self._ys, stop_after=k) if n >= 3 else (incremental.STATUS_COLLINEAR,)
        if res[0] == incremental.STATUS_OK and k >= 3:
            _, tv, opp, dup, trace = res
            order = trace["order"]
            present = np.zeros(n, bool)
            present[order[:k]] = True
            out = dual.voronoi_from_delaunay(self._xs, self._ys, tv, opp, self._e)
            out["dup"] = dup
            cavity = trace["cavity"] if k > 3 else np.empty((0, 3), np.int32)
            fan = tv.reshape(-1, 3)[trace["fan"]] if k > 3 else tv.reshape(-1, 3)[:1]
            new_site = order[k - 1]
        else:
            # the first sites (or a collinear start): strips between them
            order = np.arange(n) if res[0] != incremental.STATUS_OK else res[-1]["order"]
            present = np.zeros(n, bool)
            present[order[:k]] = True
            idx = np.flatnonzero(present)
            out = engines.lift_dcel(engines.collinear_dcel(self._xs[idx], self._ys[idx]), idx, n)
            cavity = fan = np.empty((0, 3), np.int32)
            new_site = order[k - 1] if k else -1
        d = assemble(
            self.points, self.bbox, self._e, self._perm, self._xs, self._ys, out, engine="incremental", present=present
        )
        # vertex n is the vertex at infinity: the finite triangles are the ones to show
        conflict = _finite(cavity, n)
        stolen = np.unique(cavity[cavity != n])
        stolen = stolen[stolen != new_site]
        to_row = self._perm
        walk = self._walk(k, new_site) if res[0] == incremental.STATUS_OK and k > 3 else np.empty((0, 3), np.int32)
        return IncrementalStep(
            index=k,
            n_steps=n,
            site=int(to_row[new_site]) if new_site >= 0 else -1,
            conflict=to_row[conflict].reshape(-1, 3),
            new_triangles=to_row[_finite(fan, n)].reshape(-1, 3),
            stolen_from=to_row[stolen],
            inserted=np.sort(to_row[present]),
            diagram=d,
            walk=np.where(walk == n, -1, to_row[np.minimum(walk, n - 1)]).reshape(-1, 3),
        )

    def _walk(self, k: int, site: int) -> np.ndarray:
        """The triangles (vertex triples, n for infinity) the engine's walk visits to locate the k-th
        site (``site``, a kernel index), replayed on the triangulation of the k - 1 sites before it."""
        res = incremental.triangulate(self._xs, self._ys, stop_after=k - 1)
        _, tv, opp, _, trace = res
        start = 0  # the fourth site walks from the first triangle
        if k - 1 > 3:
            # the kernel walks from the last finite triangle of the previous fan (fill.pxd: m.last)
            fan = trace["fan"]
            finite = fan[(tv[3 * fan] != self.n_steps) & (tv[3 * fan + 1] != self.n_steps)]
            if len(finite):
                start = int(finite[-1])
        return visibility_walk(self._xs, self._ys, tv, opp, start, self._xs[site], self._ys[site])


def visibility_walk(xs, ys, tv, opp, start: int, px: float, py: float) -> np.ndarray:
    """The triangles a visibility walk visits from triangle ``start`` towards the point (px, py).

    The walk of the incremental engine (``location.pxd``'s ``locate``), step for step: in each
    triangle it tests the edges in order, skipping the one it came through, and crosses the first
    edge that has p strictly on its right (exact orientation); it stops in a triangle with no such
    edge (p inside or on it) or on reaching an infinite triangle (beyond a hull edge p sees).

    Parameters
    ----------
    xs, ys : (n,) float64
        The sites; the vertex at infinity is numbered n.
    tv, opp : (3 t,) int
        The triangulation: triangle t's vertices ``tv[3t:3t+3]`` counter-clockwise, twin half-edges.
    start : int
        A finite triangle.

    Returns
    -------
    (w, 3) int32
        The visited triangles' vertex triples, in order, ``start`` first.
    """
    inf = len(xs)
    tri = np.asarray(tv, np.int64).reshape(-1, 3)
    t, came = int(start), -1
    visited = [t]
    while not (tri[t] == inf).any():
        for k in range(3):
            e = 3 * t + k
            if e == came:
                continue
            a, b = tri[t, k], tri[t, (k + 1) % 3]
            if orient2d_sign(xs[a], ys[a], xs[b], ys[b], px, py) < 0:
                came = int(opp[e])
                t = came // 3
                visited.append(t)
                break
        else:
            break
    return tri[visited].astype(np.int32)


Trace = FortuneTrace | IncrementalTrace


def steps(points, *, engine: str = "incremental", bbox=None, seed: int = 0) -> Trace:
    """A step-by-step trace of an engine over a point set, for playback and teaching.

    Parameters
    ----------
    points : array_like, shape (n, 2), or shapely / geopandas / pandas points
        As for :func:`tvoronoi.voronoi`.
    engine : {"incremental", "fortune"}
        The randomized incremental algorithm (a step inserts a site), or Fortune's sweepline
        (a step is a site or circle event).
    bbox : (xmin, ymin, xmax, ymax), optional
        The box of the trace's diagrams; by default the points' bounding box grown by 10% of its
        larger side on every side, as for ``voronoi``. The trace keeps it as ``bbox``.
    seed : int
        Seed of the incremental engine's insertion order (the batch build's for the same seed);
        Fortune's sweep takes the sites by y then x whatever the seed.

    Returns
    -------
    FortuneTrace or IncrementalTrace
        ``len(trace)`` steps; ``trace.step(k)`` the state after k of them (0: before the first),
        whose ``describe()`` says in one line what the step did; ``trace.engine``, ``trace.points``
        and ``trace.bbox`` as checked.

    Raises
    ------
    TvoronoiError
        Bad points or box, an unknown engine.

    Examples
    --------
    >>> import tvoronoi
    >>> t = tvoronoi.steps([[0, 0], [2, 0], [1, 2]], engine="fortune")
    >>> len(t), t.step(len(t)).describe()
    (4, 'circle event at (1, 0.75): vertex 0 created, arc of site 0 vanishes')
    >>> t = tvoronoi.steps([[0, 0], [2, 0], [1, 2]])
    >>> len(t), t.step(0).describe()
    (3, 'before the first insertion: 3 sites to insert')
    """
    check_engine(engine)
    trace_class = FortuneTrace if engine == "fortune" else IncrementalTrace
    return trace_class(points, bbox=bbox, seed=seed)


def fortune_steps(points, *, bbox=None, seed: int = 0) -> FortuneTrace:
    """``steps(points, engine="fortune", ...)``: the name callers used before ``steps``."""
    return FortuneTrace(points, bbox=bbox, seed=seed)


def incremental_steps(points, *, bbox=None, seed: int = 0) -> IncrementalTrace:
    """``steps(points, engine="incremental", ...)``: the name callers used before ``steps``."""
    return IncrementalTrace(points, bbox=bbox, seed=seed)


def _finite(tri: np.ndarray, inf: int) -> np.ndarray:
    """The rows of a (k, 3) triangle array that do not use the vertex at infinity."""
    tri = tri.reshape(-1, 3)
    return tri[np.all(tri != inf, axis=1)]
