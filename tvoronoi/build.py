"""From checked points to a Diagram: run an engine (tvoronoi.engines), clip the cells, map back to input rows."""

from __future__ import annotations

import contextlib
import contextvars
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from tvoronoi import engines, halves
from tvoronoi.diagram import Diagram
from tvoronoi.errors import EngineError
from tvoronoi.kernels import clip, pages

# fewer sites: the layout is made after the triangulation (a thread costs more than it would save)
OVERLAP_MIN_SITES = 1 << 15


def build_arrays():
    """The context a build's arrays are made in: large ones in pages of their own, handed back to the
    system when freed, not kept as holes in the heap (kernels/pages.pyx)."""
    return pages.mapped()


def build_diagram(
    pts: np.ndarray, box, *, engine: str, insertion: str, seed: int, threads: int = 1, bounds=None
) -> Diagram:
    """Build the Diagram of checked points (n, 2) in the checked box (threads: see api.voronoi;
    bounds: the points' own box when known, api.checked_points)."""
    e = engines.scale_exponent(pts if bounds is None else bounds)
    engines.check_box_scale(box, e)
    # (on two threads, in pages of 4 KiB: huge pages faulted in by both threads at once cost more than
    # they save, pages.small_pages)
    with build_arrays(), pages.small_pages() if threads >= 2 else contextlib.nullcontext():
        t = triangulation(pts, e, engine=engine, insertion=insertion, seed=seed, threads=threads, bounds=bounds)
        s, out = dcel(t, threads)
        del t  # (its opp, written by the dual, is freed before the clipper's arrays are made)
        return assemble(pts, box, e, s.perm, s.xs, s.ys, out, engine=engine, threads=threads)


def dcel(t: engines.Triangulation, threads: int) -> tuple[engines.Sites, dict]:
    """A build's Voronoi DCEL (with room for the clipper's points) and its sites: the triangulation is
    given up to it (not to be used again: the Diagram's triangles are its tv, in place)."""
    pages.trim_heap()  # the triangulation's scratch, freed: the dual's peak need not stand on it
    return t.sites, t.voronoi(threads, clip_room=True, give_triangulation=True)


def triangulation(pts: np.ndarray, e: int, *, engine: str, insertion: str, seed: int, threads: int, bounds=None):
    """The triangulation of checked points, scaled by 2^-e, laid out for the dual: by halves
    (tvoronoi.halves) from SPLIT_MIN_SITES sites on, whatever the thread count (Fortune's sweep, or the
    incremental engine in BRIO order), else whole (triangulate_and_lay_out)."""
    if (engine == "fortune" or insertion == "brio") and len(pts) >= halves.SPLIT_MIN_SITES:
        t = halves.triangulate(pts[:, 0], pts[:, 1], e, engine=engine, seed=seed, threads=threads, bounds=bounds)
        if t is not None:
            return t
    s = engines.prepare(pts[:, 0], pts[:, 1], engine=engine, insertion=insertion, seed=seed, exponent=e)
    return triangulate_and_lay_out(s, engine=engine, insertion=insertion, threads=threads)


def triangulate_and_lay_out(s: engines.Sites, *, engine: str, insertion: str, threads: int) -> engines.Triangulation:
    """Triangulate prepared sites and renumber them for the dual and the clipper (engines.spatial), which
    walk the sites in order. The sites' new order reads their coordinates alone: on more than one
    thread it is made on a second one while the triangulation runs (both kernels release the GIL), in
    this context (the build's arrays are made as on the first). The same result either way."""
    if threads < 2 or engine != "incremental" or len(s) < OVERLAP_MIN_SITES:
        # (its dual follows: Fortune's closing guard is the dual's check, engines.Triangulation.voronoi)
        return engines.spatial(engines.triangulate(s, engine=engine, insertion=insertion, guard=False), threads)
    with ThreadPoolExecutor(max_workers=1) as pool:
        layout = pool.submit(contextvars.copy_context().run, engines.spatial_sites, s)
        t = engines.triangulate(s, engine=engine, insertion=insertion)
        return engines.spatial(t, threads, layout.result())


def assemble(
    pts, box, e, perm, exs, eys, out, *, engine, present=None, first_row_holds=True, threads: int = 1
) -> Diagram:
    """Clip an engine's DCEL and map it back to input rows.

    Parameters
    ----------
    pts : (n, 2) the input points; box : the box, unscaled; e : the scale exponent
        (the vertices in ``out`` are already in the user's unit)
    perm : (n,) engine site k is input row perm[k]; exs, eys : scaled sites in engine order
    out : the engine's DCEL dict (with ``dup``)
    present : (n,) bool in engine order, optional -- sites already in the
        diagram (the step trace shows diagrams of the first sites only)
    first_row_holds : bool
        A place shared by repeated points gets its cell under the first input
        row there (batch); False keeps it with the site the engine holds it by
        (dynamic diagrams, where the oldest copy at a place holds it).
    threads : int, threads for clipping the cells (the same cells for any count)
    """
    n = len(pts)
    dup = out["dup"]
    first = dup < 0 if present is None else (dup < 0) & present
    first8 = first.view(np.int8)
    owner = perm.astype(np.int32)  # engine site -> input row owning its cell (a copy)
    if first_row_holds and (dup >= 0).any():
        # the cell of a repeated point belongs to the first input row at that place
        np.minimum.at(owner, np.where(dup >= 0, dup, np.arange(n, dtype=np.int32)), perm)
    points, offsets, ring, status = clip.clip_cells(
        exs,
        eys,
        out["vertices"],
        out["he_origin"],
        out["he_twin"],
        out["he_face"],
        out["face_edge"],
        first8,
        box,
        e,
        threads,
        room=out.pop("vertex_room", None),
    )
    if status != 0:
        raise EngineError("the clipper found a cell whose edges do not chain: please report this input")

    # row maps (the row holding each row's cell, each row's first half-edge) and the cells in input-row
    # order: the clipper works in engine order, where a cell's edges and vertices lie near its
    # neighbours' in memory; the rings are read in that order and each written at its row's place
    site_of, face_edge, cell_offsets, cell_vertices = clip.rows_of_cells(
        owner,
        np.ascontiguousarray(perm, np.int32),
        np.ascontiguousarray(dup, np.int32),
        first8,
        np.ascontiguousarray(out["face_edge"], np.int32),
        offsets,
        ring,
        threads,
    )
    del ring, offsets

    # engine sites to input rows in place (out is this build's own), and the vertices are the first
    # rows of the clipper's points (the same doubles): no second copy of either
    he_face = clip.relabel(owner, out["he_face"], threads)
    triangles = clip.relabel(owner, out["triangles"].reshape(-1), threads)
    return Diagram(
        sites=pts,
        site_of=site_of,
        vertices=points[: len(out["vertices"])],
        he_origin=out["he_origin"],
        he_twin=out["he_twin"],
        he_face=he_face,
        face_edge=face_edge,
        triangles=triangles.reshape(-1, 3),
        bbox=tuple(float(v) for v in box),
        cell_points=points,
        cell_offsets=cell_offsets,
        cell_vertices=cell_vertices,
        engine=engine,
    )
