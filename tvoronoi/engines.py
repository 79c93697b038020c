"""Run an engine: scale the sites exactly, put them in the engine's order, triangulate, and return a typed result.

Every caller that needs a triangulation (batch builds, dynamic diagrams, the step traces, the benchmarks)
goes through here, so the range rule, the insertion order and the status handling are written once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tvoronoi.errors import TvoronoiError
from tvoronoi.kernels import dual, fortune, incremental, order, renumber
from tvoronoi.kernels import sweep_order as event_order

# Box sides in the sites' scaled unit. From above, the exact products split a box coordinate into
# halves by multiplying it with 2^27 + 1 (Dekker), which must not overflow: about 2^997, a little
# under (1.3e300 for sites of unit size). From below, a side times a coordinate difference (down to
# 2^-223) must not underflow. Ring tests between points of the box and the sites, whose magnitudes
# may then span 2^1700, are exact at any span (clipper.turn).
BOX_SCALED_MIN = 2.0**-700
BOX_SCALED_MAX = math.ldexp(1.0 - 2.0**-20, 997)


def scale_exponent(*values) -> int:
    """The exponent e of the scale 2^e of these coordinates: the largest magnitude is below 2^e.

    Scaling by 2^-e is exact, and keeps the predicates' products (degree four in incircle) far from
    overflow and underflow at any scale. For a batch diagram only the sites set it: a box far larger
    or smaller than the sites costs no precision, within the limits of check_box_scale.
    """
    top = max((_largest_magnitude(np.asarray(v, np.float64)) for v in values if np.size(v)), default=0.0)
    return math.frexp(top)[1] if top > 0 else 0


def _largest_magnitude(v: np.ndarray) -> float:
    """max |v| from two passes without a temporary (NaN if v holds one)."""
    lo, hi = float(v.min()), float(v.max())
    return lo if math.isnan(lo) else max(-lo, hi)


def check_box_scale(box, e: int) -> None:
    """Refuse a box whose sides the exact tests could not handle in the sites' scaled unit."""
    for name, v in zip(("xmin", "ymin", "xmax", "ymax"), box):
        if v == 0.0:
            continue
        # |v| * 2^-e without overflow or underflow, whatever e: compare the exponents first
        k = math.frexp(v)[1] - e
        s = abs(math.ldexp(math.frexp(v)[0], k)) if -1000 < k < 1000 else math.inf if k > 0 else 0.0
        if not (BOX_SCALED_MIN <= s <= BOX_SCALED_MAX):
            raise TvoronoiError(
                f"bbox {name} = {v!r} is beyond the exact range for these sites (their largest "
                f"coordinate is about 2^{e}): a nonzero box side must lie between 2^-700 and about "
                f"2^997 (1.3e300) times that; choose a box nearer the sites' scale"
            )


def first_copies(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """For each point, the first earlier index with identical coordinates, or -1."""
    n = len(xs)
    dup = np.full(n, -1, np.int32)
    if n < 2:
        return dup
    by_place = np.lexsort((ys, xs))  # stable: earlier indices first within a tie
    same = (xs[by_place][1:] == xs[by_place][:-1]) & (ys[by_place][1:] == ys[by_place][:-1])
    if not same.any():
        return dup
    # the start of each run of equal points, carried along the run
    start = np.maximum.accumulate(np.where(np.concatenate(([True], ~same)), np.arange(n), 0))
    first = by_place[start]
    dup[by_place] = np.where(first != by_place, first, -1)
    return dup


def collinear_dcel(xs: np.ndarray, ys: np.ndarray) -> dict:
    """Voronoi DCEL of 0, 1, 2 or more collinear sites (parallel strips), repeats included."""
    dup = first_copies(xs, ys)
    distinct = np.flatnonzero(dup < 0)
    line = distinct[np.lexsort((ys[distinct], xs[distinct]))]  # sorted by x then y: line order
    out = dual.voronoi_collinear(np.ascontiguousarray(xs[line]), np.ascontiguousarray(ys[line]))
    out["he_face"] = line[out["he_face"]].astype(np.int32)
    face_edge = np.full(len(xs), -1, np.int32)
    face_edge[line] = out["face_edge"]
    out["face_edge"] = face_edge
    out["dup"] = dup
    return out


def lift_dcel(sub: dict, idx: np.ndarray, n: int) -> dict:
    """A DCEL over the sites idx of n (a subset, numbered 0..len(idx)-1), renumbered to all n sites."""
    out = dict(sub)
    out["he_face"] = idx[sub["he_face"]].astype(np.int32)
    face_edge = np.full(n, -1, np.int32)
    face_edge[idx] = sub["face_edge"]
    out["face_edge"] = face_edge
    dup = np.full(n, -1, np.int32)
    sd = sub["dup"]
    dup[idx[sd >= 0]] = idx[sd[sd >= 0]]
    out["dup"] = dup
    out["triangles"] = np.empty((0, 3), np.int32)
    return out


def sweep_order(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Event order of Fortune's sweep: by y, then x, then input row (int32).

    One sort of 64-bit integers, each a site's y as an unsigned integer of the same order (-0.0 read
    as +0.0), less the smallest, shifted right just enough that the row fits below it, and the row
    (sweep_order.sweep_keys); the rows read off after it, and each run of equal keys (equal y, or y a
    few units apart when the span of y needs the shift) sorted again by y, x and row
    (sweep_order.sweep_rows)."""
    n = len(ys)
    if n < 2:
        return np.arange(n, dtype=np.int32)
    xs = np.ascontiguousarray(xs, dtype=np.float64)
    ys = np.ascontiguousarray(ys, dtype=np.float64)
    key = np.empty(n, np.uint64)
    row_bits = event_order.sweep_keys(ys, key)
    key.sort()
    perm = np.empty(n, np.int32)
    event_order.sweep_rows(key, row_bits, xs, ys, perm)
    return perm


def engine_order(xs: np.ndarray, ys: np.ndarray, *, engine: str, insertion: str = "brio", seed: int = 0) -> np.ndarray:
    """The order in which an engine takes the sites: perm[k] is the k-th site (int32).

    Fortune's sweep takes them by y then x; the incremental engine in a biased randomized
    insertion order along a space-filling curve ("brio"), or fully at random ("random").
    """
    if engine == "fortune":
        return sweep_order(xs, ys)
    if insertion == "brio":
        return order.brio_order(np.ascontiguousarray(xs), np.ascontiguousarray(ys), seed)
    return np.random.default_rng(seed).permutation(len(xs)).astype(np.int32)


@dataclass(frozen=True)
class Sites:
    """Sites ready for an engine: scaled by 2^-exponent (exact) and in the engine's order."""

    exponent: int
    perm: np.ndarray  # (n,) int32: engine site k is input site perm[k]
    xs: np.ndarray  # (n,) float64 scaled coordinates, in engine order, C-contiguous
    ys: np.ndarray

    def __len__(self) -> int:
        return len(self.perm)


def prepare(
    xs: np.ndarray,
    ys: np.ndarray,
    *,
    engine: str,
    insertion: str = "brio",
    seed: int = 0,
    exponent: int | None = None,
) -> Sites:
    """Scale the sites (input order) by 2^-exponent (default: their own scale) and order them for an engine."""
    xs = np.asarray(xs, np.float64)
    ys = np.asarray(ys, np.float64)
    e = scale_exponent(xs, ys) if exponent is None else exponent
    if e == 0:  # scaled already (tvoronoi.halves), or of unit size: no copy
        sx, sy = np.ascontiguousarray(xs), np.ascontiguousarray(ys)
    else:
        sx, sy = np.ldexp(xs, -e), np.ldexp(ys, -e)
    perm = engine_order(sx, sy, engine=engine, insertion=insertion, seed=seed)
    ox, oy = renumber.take_sites(sx, sy, perm)
    return Sites(e, perm, ox, oy)


@dataclass(frozen=True)
class Triangulation:
    """An engine's result on prepared sites, numbered in engine order.

    tv, opp are the triangles' vertices (n stands for the vertex at infinity) and twin half-edges, or
    None when the distinct sites are collinear (fewer than three, or all on one line); dup[k] is the
    earlier site that site k repeats, or -1. checked is False for Fortune's sweep without its closing
    guard (``triangulate(..., guard=False)``): ``voronoi`` then checks every edge in the dual.
    he_room: arrays for the dual's half-edges, when the maker has them (dual.voronoi_from_delaunay).
    """

    engine: str
    sites: Sites
    tv: np.ndarray | None
    opp: np.ndarray | None
    dup: np.ndarray
    checked: bool = True
    he_room: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def flat(self) -> bool:
        """True when the distinct sites are collinear: no triangle, parallel strips for cells."""
        return self.tv is None

    def voronoi(self, threads: int = 1, clip_room: bool = False, give_triangulation: bool = False) -> dict:
        """The Voronoi DCEL (vertices in the user's unit, correctly rounded) with ``dup``, in engine order;
        the same for any thread count (clip_room: see dual.voronoi_from_delaunay). give_triangulation:
        this triangulation is not used again: the DCEL's triangles are its own tv, compacted in place,
        and the dual writes in its opp (restored if the triangulation needs a repair).

        An unchecked triangulation is checked as the dual walks it; were some edge not locally
        Delaunay (never seen: the sweep's decisions are exact), it is repaired by exact flips in
        place (fortune.legalize, the sweep's own guard) and the dual made again."""
        s = self.sites
        if self.flat:
            return collinear_dcel(s.xs, s.ys)
        args = (s.xs, s.ys, self.tv, self.opp, s.exponent, threads)
        given = {"clip_room": clip_room, "give_triangulation": give_triangulation, "he_room": self.he_room}
        out = dual.voronoi_from_delaunay(*args, check=not self.checked, **given)
        if "illegal" in out:
            if fortune.legalize(s.xs, s.ys, self.tv, self.opp, bounded=True) < 0:
                raise TvoronoiError(
                    f"{fortune.STATUS_MESSAGES[fortune.STATUS_NO_REPAIR]} on {len(s.xs)} points; "
                    "build with engine='incremental' instead, and please report the input"
                )
            out = dual.voronoi_from_delaunay(*args, **given)
        out["dup"] = self.dup
        return out


@dataclass(frozen=True)
class SiteLayout:
    """Sites renumbered along a Z-curve (kernels/renumber.pyx): new site k is old site new_to_old[k]."""

    new_to_old: np.ndarray  # (n,) int32
    old_to_new: np.ndarray  # (n,) int32, its inverse
    sites: Sites  # the same sites in the new order (perm still maps each to its input row)


def spatial_sites(s: Sites) -> SiteLayout:
    """The sites' Z-curve order and the sites in it. It reads their coordinates alone, so a build on
    more than one thread makes it while the triangulation runs (build.build_diagram)."""
    new_to_old, old_to_new = renumber.site_order(s.xs, s.ys)
    return SiteLayout(new_to_old, old_to_new, Sites(s.exponent, s.perm[new_to_old], s.xs[new_to_old], s.ys[new_to_old]))


def spatial(t: Triangulation, threads: int = 1, layout: SiteLayout | None = None) -> Triangulation:
    """The triangulation the dual and the clipper read best: they walk the sites in order, so neighbours
    should be near in memory.

    The incremental engine's is renumbered (``renumbered``, with ``layout`` if it is made already);
    Fortune's is returned as it is: its sites come in sweep order and its triangles are stored as the
    sweep makes them, next to their sites already (renumbering it cost 50 ms more than it saved at
    10^6 sites).
    """
    return renumbered(t, threads, layout) if t.engine == "incremental" else t


def renumbered(t: Triangulation, threads: int = 1, layout: SiteLayout | None = None) -> Triangulation:
    """The same triangulation with its sites and triangles renumbered along a Z-curve (kernels/renumber.pyx).

    Only the numbering changes (``sites.perm`` still maps each site to its input row); the result is the
    same for any thread count, and with or without a ``layout`` made beforehand (``spatial_sites`` of
    ``t.sites``). A flat triangulation is returned as it is.
    """
    if t.flat:
        return t
    if layout is None:
        layout = spatial_sites(t.sites)
    tv, opp = renumber.triangle_order(t.tv, t.opp, layout.old_to_new, threads)
    dup = t.dup[layout.new_to_old]
    repeats = dup >= 0
    dup[repeats] = layout.old_to_new[dup[repeats]]
    return Triangulation(t.engine, layout.sites, tv, opp, dup, checked=t.checked)


def triangulate(sites: Sites, *, engine: str, insertion: str = "brio", guard: bool = True) -> Triangulation:
    """Run an engine on prepared sites.

    guard=False: Fortune's sweep leaves out its closing repair (a guard that never flips), and the
    triangulation is returned unchecked: its ``voronoi`` checks every edge instead, at a fraction of the
    cost. Only for a triangulation whose next step is that dual (build.triangulation).

    Raises
    ------
    TvoronoiError
        Fortune's sweep reached a state it could not complete (a defect to report; the
        incremental engine is the fallback the message names).
    """
    if engine == "fortune":
        result = fortune.sweep(sites.xs, sites.ys, guard=guard)
        if result["status"] != fortune.STATUS_OK:
            raise TvoronoiError(
                f"{fortune.STATUS_MESSAGES[result['status']]} on {len(sites)} points; "
                "build with engine='incremental' instead, and please report the input"
            )
        if "tv" not in result:
            return Triangulation(engine, sites, None, None, first_copies(sites.xs, sites.ys))
        return Triangulation(engine, sites, result["tv"], result["opp"], result["dup"], checked=guard)
    status, tv, opp, dup = incremental.triangulate(sites.xs, sites.ys, conflict_lists=(insertion == "random"))
    if status != incremental.STATUS_OK:
        return Triangulation(engine, sites, None, None, first_copies(sites.xs, sites.ys))
    return Triangulation(engine, sites, tv, opp, dup)


def run(
    xs: np.ndarray,
    ys: np.ndarray,
    *,
    engine: str,
    insertion: str = "brio",
    seed: int = 0,
    exponent: int | None = None,
) -> Triangulation:
    """prepare, then triangulate: the Delaunay triangulation of sites given in input order."""
    sites = prepare(xs, ys, engine=engine, insertion=insertion, seed=seed, exponent=exponent)
    return triangulate(sites, engine=engine, insertion=insertion)
