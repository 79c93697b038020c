"""An engine on two halves of the sites: each half ordered, triangulated and renumbered on its own thread,
then the two joined along the seam between them (kernels/seam.pyx).

The cut, each half's order and the join read the sites alone, never the thread count: the same
triangulation, numbered the same way, on one thread or two. A build takes this path from
SPLIT_MIN_SITES sites on (tvoronoi.build).
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from tvoronoi import engines
from tvoronoi.kernels import STOPPING, incremental, order, pages, renumber, seam

# fewer sites: one triangulation (two halves and a seam cost more than they save on two threads)
SPLIT_MIN_SITES = 1 << 16
# a half with fewer than this share of the sites (many sites on the median line): no split on that axis
LEAST_SHARE = 0.25
# the runs in which a waiting thread faults in the dual's half-edge arrays (HalfEdgeFaults): a poll of the
# other half between them
FAULT_RUN = 2 << 20
# more than twice as many sites: the cut is at the median of this many of them, spread over the rows by
# a multiplicative hash (row k * SAMPLE_STEP mod n), not of all (at 10^6 sites in a build: 5 ms -> 0.7;
# the halves then differ by about n / (2 sqrt(SAMPLE_SITES)) sites, 0.2%)
SAMPLE_SITES = 1 << 16
SAMPLE_STEP = 2654435761


@dataclass(frozen=True)
class Cut:
    """The line the sites are cut by: coordinate ``axis`` (0: x, 1: y) below ``split`` on the left; the
    rows of each side (int32, in row order) and each side's bounding box, in the coordinates' own unit;
    ``sites``: each side's sites (xs, ys), in row order and in the unit the cut was asked for, until its
    half takes them (take_sites: each then None, so that they are freed as soon as they are used)."""

    axis: int
    split: float
    left: np.ndarray
    right: np.ndarray
    box_left: tuple[float, float, float, float]
    box_right: tuple[float, float, float, float]
    sites: list

    def take_sites(self, side: int) -> tuple[np.ndarray, np.ndarray]:
        """Side ``side``'s sites (0: left), handed over once."""
        xy, self.sites[side] = self.sites[side], None
        if xy is None:
            raise RuntimeError("a half's sites are taken once")
        return xy


def median(c: np.ndarray) -> float:
    """The median of c, or from 2 SAMPLE_SITES values on the median of SAMPLE_SITES of them (a function of
    the values and their order alone): a value of c either way."""
    n = len(c)
    if n <= 2 * SAMPLE_SITES:
        return float(np.partition(c, n // 2)[n // 2])
    sample = c[np.arange(SAMPLE_SITES, dtype=np.int64) * SAMPLE_STEP % n]
    return float(np.partition(sample, SAMPLE_SITES // 2)[SAMPLE_SITES // 2])


def cut(
    xs: np.ndarray, ys: np.ndarray, bounds=None, *, sweep: bool = False, exponent: int = 0, threads: int = 1
) -> Cut | None:
    """The cut at the median of the longer side of the sites' box (else of the other side; halves.median:
    of a sample of many sites), or None when neither gives two halves of at least LEAST_SHARE of the
    sites each (xs, ys may be strided; bounds: the sites' box (xmin, ymin, xmax, ymax) when known).
    Each side's sites come with it, scaled by 2^-exponent (renumber.split_sites, on ``threads``
    threads: the same cut for any count).

    sweep: for Fortune's sweep, which goes up in y and whose beach line grows with the width of what
    it sweeps (its arcs about sqrt(k w / h) for k sites in a box w by h): the x median first unless the
    box is more than twice as tall as wide, so that each half is narrow (at 10^6 uniform sites a
    half swept 7% faster than a wide one)."""
    n = len(xs)
    if n < 4:
        return None
    if bounds is None:
        bounds = (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))
    # (half spans: a span of the unscaled coordinates may overflow, as from -1e308 to 1e308)
    spans = (bounds[2] / 2 - bounds[0] / 2, bounds[3] / 2 - bounds[1] / 2)
    x_first = spans[0] >= (spans[1] / 2 if sweep else spans[1])
    least = math.ceil(LEAST_SHARE * n)
    for axis in (0, 1) if x_first else (1, 0):
        c = xs if axis == 0 else ys
        split = median(c)
        parts = renumber.split_sites(xs, ys, axis, split, exponent, least, threads)
        if parts is not None:
            (rows_l, xl, yl), (rows_r, xr, yr), box_left, box_right = parts
            return Cut(axis, split, rows_l, rows_r, box_left, box_right, [(xl, yl), (xr, yr)])
    return None


def scaled(c: Cut, exponent: int) -> Cut:
    """The cut's line and boxes in the unit 2^exponent (exact: the range rule keeps scaled coordinates
    normal doubles); its sites are in that unit already (cut's exponent)."""
    return Cut(
        c.axis,
        math.ldexp(c.split, -exponent),
        c.left,
        c.right,
        tuple(math.ldexp(v, -exponent) for v in c.box_left),  # type: ignore[arg-type]
        tuple(math.ldexp(v, -exponent) for v in c.box_right),  # type: ignore[arg-type]
        c.sites,
    )


@dataclass(frozen=True)
class Joined:
    """The arrays the two halves write into, each its own part, and the seam then joins in place."""

    xs: np.ndarray  # (n,) float64: the left half's sites first, each half along a Z-curve
    ys: np.ndarray
    perm: np.ndarray  # (n,) int32: site k is input site perm[k]
    dup: np.ndarray  # (n,) int32
    tv: np.ndarray  # (3 (2 n - 2),) int32: the left half's triangles from the start, the right's at the end
    opp: np.ndarray
    keep: np.ndarray  # (2 n - 2,) int8: seam.kept_triangles
    seam: np.ndarray  # (n,) int8: the seam sites, marked by seam.kept_triangles
    # on two threads, the dual's half-edge arrays (origin, twin, face: 3 (2 n - 2) int32 each), faulted in
    # by a thread that waits for the other half (fault_in_half_edges); else None
    he_room: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @classmethod
    def empty(cls, n: int, *, he_room: bool = False) -> Joined:
        cap = max(2 * n - 2, 1)
        return cls(
            np.empty(n, np.float64),
            np.empty(n, np.float64),
            np.empty(n, np.int32),
            np.empty(n, np.int32),
            np.empty(3 * cap, np.int32),
            np.empty(3 * cap, np.int32),
            np.zeros(cap, np.int8),
            np.zeros(n, np.int8),
            half_edge_room(3 * cap) if he_room else None,
        )


def half_edge_room(length: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Three int32 arrays for the dual's half-edges, in pages of 4 KiB (pages.small_pages): a thread
    waiting for the other half faults them in (HalfEdgeFaults)."""
    with pages.small_pages():
        return (np.empty(length, np.int32), np.empty(length, np.int32), np.empty(length, np.int32))


class HalfEdgeFaults:
    """The pages of a Joined's he_room faulted in a run at a time (FAULT_RUN bytes of each array), by
    whichever thread waits for the other half, up to the half-edges the dual can need: 3 (2 d - 2) for
    d distinct sites (bound: ``distinct``). Calls after the last run, or without he_room, do nothing.
    The dual faults in what is left (its own populate finds the rest resident): the same arrays either
    way."""

    def __init__(self, out: Joined):
        self.out = out
        self.lock = threading.Lock()
        self.done = 0  # bytes of each array faulted in
        self.limit = 0

    def bound(self, distinct: int) -> None:
        """At most ``distinct`` distinct sites (set once, by the first thread to wait)."""
        with self.lock:
            if self.limit == 0:
                self.limit = 4 * 3 * max(2 * distinct - 2, 1)

    def run(self) -> bool:
        """Fault in the next run of each array; False when there is nothing more to do."""
        room = self.out.he_room
        if room is None:
            return False
        with self.lock:
            lo = self.done
            hi = min(lo + FAULT_RUN, self.limit)
            if lo >= hi:
                return False
            self.done = hi
        for a in room:
            pages.populate_pages(a.view(np.int8)[lo:hi])
        return True


def half(
    engine: str,
    side: int,
    rows,
    other_box: tuple[float, float, float, float],
    c: Cut,
    out: Joined,
    first: int,
    *,
    seed: int,
    threads: int,
):
    """Order, triangulate and renumber the sites of side ``side`` of the cut c (input rows ``rows``, taken
    scaled from c), as sites first.. of ``out``, their triangles at its start (first == 0, the left half)
    or at its end; mark the triangles it keeps (c and other_box, the other half's bounding box: scaled).
    Returns the slots its triangles take (lo, hi), or None when its sites are collinear: half_triangles,
    then lay_out."""
    t = half_triangles(engine, c, side, rows, out, first, seed=seed)
    return None if t is None else lay_out(t, other_box, c, out, first, threads=threads)


@dataclass(frozen=True)
class HalfTriangles:
    """A half's triangulation as its engine made it (vertex k at infinity, k its sites), not yet laid out."""

    tv: np.ndarray
    opp: np.ndarray
    dup: np.ndarray
    k: int


def half_triangles(engine: str, c: Cut, side: int, rows, out: Joined, first: int, *, seed: int):
    """The first step of half(): the sites of side ``side`` of c (input rows ``rows``) ordered into their
    part of ``out`` and triangulated; a HalfTriangles, or None when they are collinear."""
    hx, hy = c.take_sites(side)
    k = len(rows)
    mine = slice(first, first + k)
    if engine == "fortune":
        # the sites in sweep order, gathered straight into their part of the joined arrays, where the
        # sweep reads them
        sweep = engines.sweep_order(hx, hy)
        renumber.sites_into(hx, hy, rows, None, sweep, out.xs[mine], out.ys[mine], out.perm[mine])
        del hx, hy
        s = engines.Sites(0, sweep, out.xs[mine], out.ys[mine])
        t = engines.triangulate(s, engine=engine, guard=False)  # (the joined one is checked in its dual)
        if t.tv is None or t.opp is None:
            return None
        return HalfTriangles(t.tv, t.opp, t.dup, k)
    # the sites numbered along the curve that orders their insertion (BRIO), inserted in that order:
    # the numbering the dual and the clipper walk best, with no renumbering after the triangulation
    insertion, curve = order.brio_order(hx, hy, seed, True)
    renumber.sites_into(hx, hy, rows, None, curve, out.xs[mine], out.ys[mine], out.perm[mine])
    del hx, hy, curve
    status, tv_h, opp_h, dup_h = incremental.triangulate(out.xs[mine], out.ys[mine], order=insertion)
    if status != incremental.STATUS_OK:
        return None
    return HalfTriangles(tv_h, opp_h, dup_h, k)


def lay_out(
    t: HalfTriangles, other_box: tuple[float, float, float, float], c: Cut, out: Joined, first: int, *, threads: int
) -> tuple[int, int]:
    """The second step of half(): a half's triangles sorted into their part of ``out``, its repeated sites
    and the triangles it keeps marked; the slots its triangles take (lo, hi). threads: for the sort and
    the judging of the triangles (the same result for any count)."""
    n = len(out.xs)
    n_tri = len(t.tv) // 3
    lo = 0 if first == 0 else len(out.keep) - n_tri
    tv, opp = out.tv[3 * lo : 3 * (lo + n_tri)], out.opp[3 * lo : 3 * (lo + n_tri)]
    # the sites keep their order (the sweep's, or along the BRIO curve), and the triangles are sorted by
    # their first site, so that each site's lie together: the dual numbers the vertices in the
    # triangles' order, and the walks and the clipper then find a cell's vertices near its neighbours'
    # (a Z-curve renumbering of Fortune's sites cost its builds more than it saved, see engines.spatial)
    renumber.triangle_order_into(t.tv, t.opp, None, tv, opp, first, lo, n, threads, n_sites=t.k)
    out.dup[first : first + t.k] = np.where(t.dup >= 0, t.dup + first, -1)
    keep = out.keep[lo : lo + n_tri]
    seam.kept_triangles(
        out.xs, out.ys, tv, opp, lo, n, c.split, c.axis, first == 0, *other_box, keep, out.seam, threads
    )
    return lo, lo + n_tri


def on_two_halves(engine: str, c: Cut, out: Joined, *, seed: int, threads: int):
    """The slots of both halves (half() of each), made on two threads: the left half on this one, the
    right half's triangles on a second. That thread lays them out too if the left half is not done by
    then; else this one does, on ``threads`` threads (with huge pages, the second's first touches of
    fresh pages cost it up to 3-4 times what they cost this thread, at 10^6 sites 50-90 ms against
    20-25 for the same sort; in the small pages a build on two threads now uses, 4-12 ms of system
    time either way). The thread done first faults in the dual's half-edge arrays while it waits
    (HalfEdgeFaults)."""
    lock = threading.Lock()
    left_done = [False]
    each = max(threads // 2, 1)
    faults = HalfEdgeFaults(out)
    n_left, n_right = len(c.left), len(c.right)

    def repeats(lo: int, hi: int) -> int:
        return int(np.count_nonzero(out.dup[lo:hi] >= 0))

    def left():
        try:
            return half(engine, 0, c.left, c.box_right, c, out, 0, seed=seed, threads=each)
        finally:
            with lock:
                left_done[0] = True

    def right():
        t = half_triangles(engine, c, 1, c.right, out, n_left, seed=seed)
        with lock:
            mine = not left_done[0]
        if t is None or not mine:
            return t
        slots = lay_out(t, c.box_left, c, out, n_left, threads=each)
        faults.bound(n_left + n_right - repeats(n_left, n_left + n_right))
        while not left_done[0] and faults.run():
            pass
        return slots

    def wait() -> bool:
        faults.bound(n_left - repeats(0, n_left) + n_right)
        return faults.run()

    slots = on_two_threads([left, right], wait)
    if isinstance(slots[1], HalfTriangles):
        slots[1] = lay_out(slots[1], c.box_left, c, out, n_left, threads=threads)
    return slots


def triangulate(
    xs: np.ndarray,
    ys: np.ndarray,
    exponent: int,
    *,
    engine: str = "incremental",
    seed: int = 0,
    threads: int = 1,
    bounds=None,
):
    """The Delaunay triangulation of sites (input order, unscaled; xs, ys may be strided) scaled by
    2^-exponent, by halves, renumbered for the dual.

    Returns an engines.Triangulation whose ``sites.perm`` maps its sites to input rows, or None when the
    sites do not split (too many on the median lines, a half's sites collinear): the caller then
    triangulates them whole. Two threads work when ``threads`` is 2 or more, each half then ordered on
    half of them. Each half's sites are scaled as the cut gathers them: no scaled copy of all of them.
    bounds: the sites' box (xmin, ymin, xmax, ymax), unscaled, when known (api.checked_points).
    """
    c = cut(xs, ys, bounds, sweep=engine == "fortune", exponent=exponent, threads=threads)
    if c is None:
        return None
    c = scaled(c, exponent)
    out = Joined.empty(len(xs), he_room=threads >= 2)
    if threads >= 2:
        slots = on_two_halves(engine, c, out, seed=seed, threads=threads)
    else:
        slots = [
            half(engine, side, rows, other, c, out, first, seed=seed, threads=1)
            for side, rows, other, first in ((0, c.left, c.box_right, 0), (1, c.right, c.box_left, len(c.left)))
        ]
    left, right = slots
    if left is None or right is None:
        return None
    return joined(out, left[1], right[0], exponent, seed, engine)


def on_two_threads(calls: list, wait=None):
    """[calls[0](), calls[1]()], the second on a second thread, in this context (a build's arrays are made
    there as here, in pages of the same size: pages.small_pages). If the first raises (Ctrl-C), the second thread's kernels are asked to stop at their
    next poll (tvoronoi.kernels.STOPPING) rather than run to their end before the exception goes on.
    wait: called again and again while the first is done and the second is not, until it returns False
    (a short piece of work each time)."""
    ident: list[int] = []
    stopped = threading.Event()
    small = pages.small_pages_on()  # (the pages this thread's arrays come in, for the second's too)

    def second():
        ident.append(threading.get_ident())
        if stopped.is_set():  # asked to stop before it started
            raise KeyboardInterrupt("the build this thread works for was interrupted")
        with pages.small_pages() if small else contextlib.nullcontext():
            return calls[1]()

    try:
        with ThreadPoolExecutor(max_workers=1) as pool:
            job = pool.submit(contextvars.copy_context().run, second)
            try:
                first = calls[0]()
                while wait is not None and not job.done() and wait():
                    pass
            except BaseException:
                stopped.set()
                job.cancel()
                STOPPING.update(ident)
                raise
            return [first, job.result()]
    finally:
        STOPPING.difference_update(ident)


def joined(
    out: Joined, gap_lo: int, gap_hi: int, exponent: int, seed: int, engine: str
) -> engines.Triangulation | None:
    """The two halves joined: the seam sites triangulated (by the same engine), then seam.join in place."""
    n = len(out.xs)
    sites_m = np.flatnonzero(out.seam.view(np.bool_)).astype(np.int32)  # (as bool: 10x faster than on int8)
    m = engines.triangulate(
        engines.prepare(out.xs[sites_m], out.ys[sites_m], engine=engine, seed=seed, exponent=0),
        engine=engine,
        guard=False,
    )
    if m.tv is None or m.opp is None:
        return None  # the seam sites are collinear
    sites_m = sites_m[m.sites.perm]  # seam site k, in the engine's order, is site sites_m[k]
    tv_m, opp_m = m.tv, m.opp
    expected = 2 * int(np.count_nonzero(out.dup < 0)) - 2
    holes = np.flatnonzero(out.keep == 0).astype(np.int32)  # the triangles not kept, and the gap
    if seam.join(out.tv, out.opp, out.keep, holes, gap_lo, gap_hi, n, tv_m, opp_m, sites_m, expected) != seam.STATUS_OK:
        return None  # a defect: the tests hunt for it; the whole triangulation is still right
    sites = engines.Sites(exponent, out.perm, out.xs, out.ys)
    # (Fortune's halves and seam were swept without their closing guard: the dual checks every edge)
    return engines.Triangulation(
        engine,
        sites,
        out.tv[: 3 * expected],
        out.opp[: 3 * expected],
        out.dup,
        checked=engine != "fortune",
        he_room=out.he_room,
    )
