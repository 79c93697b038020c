"""Where a build's time goes: each phase of tvoronoi.voronoi() in ns per site, next to other tools.

For each distribution and size, and each engine and thread count, the phases of a build to bounded
cells are timed one after the other, in interleaved repeats (each configuration once per round, their
order rotated from round to round; the median is reported):

  order     the check of the points that tvoronoi.voronoi() makes (one pass, which also finds their
            bounds), exact scaling and the engine's insertion order (BRIO, or the sweep's sort)
  tri       the Delaunay triangulation (Bowyer-Watson walking, or Fortune's sweep), then for the
            incremental engine its sites and triangles renumbered along a Z-curve. From
            halves.SPLIT_MIN_SITES sites on, both engines go by halves (tvoronoi.halves): each half
            ordered, triangulated and laid out on its own thread (the incremental engine's sites numbered
            along their BRIO curve), then joined; the order is then part of tri, and the order column
            reads "-"
  dual      the Voronoi half-edge structure and its correctly rounded vertices
  cells     clipping every cell to the box and gathering the cells into input order

and, on the same points, whole calls of other tools: Shewchuk's Triangle (`triangle.voronoi`: vertices
and edges, no cells; the issue's yardstick, so it is timed in the same interleaved repeats, warm, and
each tvoronoi build's median is also given as a multiple of its median), Qhull (`scipy.spatial.Delaunay`, the triangulation alone), CGAL's
`Delaunay_triangulation_2` through its Python bindings (the `cgal` package, if installed: the points
made as CGAL objects, then inserted; both timed) and, up to --geos-max sites, GEOS
(`shapely.voronoi_polygons`, cells). The peak memory of a whole `tvoronoi.voronoi()` build is measured
in a fresh process for each engine (its maximum resident set, less that of the same process before the
build), and so is the time of that first build, where all of the process's memory is fresh.

    python benchmarks/phases.py --sizes 1M --out benchmarks/results/phases
"""

from __future__ import annotations

import argparse
import gc
import json
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.common import atomic_write, describe_machine, machine, parse_sizes, subprocess_env  # noqa: E402
from tvoronoi import build, engines, halves  # noqa: E402
from tvoronoi.api import checked_points, default_bbox  # noqa: E402
from tvoronoi.generators import generate  # noqa: E402

PHASES = ("order", "tri", "dual", "cells")
DISTS = ("uniform", "gaussian", "clustered", "cluster_1e-9", "grid")


def points(dist: str, n: int) -> np.ndarray:
    """The benchmark's points: seeded, the same for every tool."""
    if dist == "grid":
        side = int(round(n**0.5))
        g = np.arange(float(side))
        x, y = np.meshgrid(g, g)
        return np.c_[x.ravel(), y.ravel()]
    if dist == "cluster_1e-9":
        return 0.5 + 1e-9 * generate("uniform", n, seed=11)
    return generate(dist, n, seed=11)


def time_phases(pts: np.ndarray, engine: str, threads: int) -> dict:
    """One build to bounded cells, phase by phase (seconds), as tvoronoi.voronoi() makes it: its check of
    the points (one pass, which also finds their bounds: counted in the first phase), then
    tvoronoi.build.build_diagram's phases."""
    with build.build_arrays():
        k0 = resource.getrusage(resource.RUSAGE_SELF).ru_stime
        t0 = time.perf_counter()
        pts, bounds = checked_points(pts)
        box = default_bbox(pts, bounds)
        e = engines.scale_exponent(bounds)
        by_halves = len(pts) >= halves.SPLIT_MIN_SITES
        if by_halves:  # each half is ordered and triangulated on its own thread: one figure for both
            t1 = t0
            t = build.triangulation(pts, e, engine=engine, insertion="brio", seed=0, threads=threads, bounds=bounds)
        else:
            s = engines.prepare(pts[:, 0], pts[:, 1], engine=engine, exponent=e)
            t1 = time.perf_counter()
            t = build.triangulate_and_lay_out(s, engine=engine, insertion="brio", threads=threads)
        t2 = time.perf_counter()
        s, out = build.dcel(t, threads)
        del t
        t3 = time.perf_counter()
        d = build.assemble(pts, box, e, s.perm, s.xs, s.ys, out, engine=engine, threads=threads)
        t4 = time.perf_counter()
        k1 = resource.getrusage(resource.RUSAGE_SELF).ru_stime
        assert d.cell_offsets[-1] > 0
        del d, out
    order = None if by_halves else t1 - t0
    return {"order": order, "tri": t2 - t1, "dual": t3 - t2, "cells": t4 - t3, "system": k1 - k0}


def time_triangle(pts: np.ndarray) -> float | None:
    """One warm call of Triangle's `triangle.voronoi` on the points (seconds), None if not installed."""
    try:
        import triangle
    except ImportError:
        return None
    t0 = time.perf_counter()
    triangle.voronoi(pts)
    return time.perf_counter() - t0


def others(pts: np.ndarray, geos_max: int) -> dict:
    """Whole calls of the other tools on the same points (seconds), where they are installed (Triangle is
    timed with the repeats, time_triangle)."""
    out = {}
    from scipy.spatial import Delaunay

    t0 = time.perf_counter()
    Delaunay(pts)
    out["Qhull Delaunay"] = time.perf_counter() - t0
    try:
        from CGAL.CGAL_Kernel import Point_2
        from CGAL.CGAL_Triangulation_2 import Delaunay_triangulation_2

        t0 = time.perf_counter()
        cgal_points = [Point_2(float(x), float(y)) for x, y in pts]
        t1 = time.perf_counter()
        dt = Delaunay_triangulation_2()
        dt.insert(cgal_points)
        t2 = time.perf_counter()
        out["CGAL points"] = t1 - t0
        out["CGAL Delaunay insert"] = t2 - t1
        del dt, cgal_points
    except ImportError:
        pass
    if len(pts) <= geos_max:
        import shapely

        t0 = time.perf_counter()
        shapely.voronoi_polygons(shapely.multipoints(pts), extend_to=shapely.box(*default_bbox(pts)), ordered=True)
        out["GEOS voronoi_polygons"] = time.perf_counter() - t0
    gc.collect()
    return out


PEAK = """
import sys
import time
sys.path.insert(0, {repo!r})
from benchmarks.phases import points
import tvoronoi

def hwm():
    # this process's own peak resident set (VmHWM, KiB): unlike ru_maxrss, not raised by the peak of
    # the process it was forked from
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1])

pts = points({dist!r}, {n})
before = hwm()
t0 = time.perf_counter()
tvoronoi.voronoi(pts, engine={engine!r}, threads={threads})
seconds = time.perf_counter() - t0
print((hwm() - before) / 1024, seconds)
"""


def fresh_build(dist: str, n: int, engine: str, threads: int) -> tuple[float, float]:
    """(MiB a whole build adds to a fresh process's peak, the seconds of that first build). A process's
    first build is slower than the warm ones the phases time: on a virtual machine whose host takes
    back freed memory, its first touches of memory cost the most (one build per process: the batch)."""
    code = PEAK.format(repo=str(Path(__file__).resolve().parent.parent), dist=dist, n=n, engine=engine, threads=threads)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=subprocess_env(), check=True)
    peak, seconds = res.stdout.split()
    return float(peak), float(seconds)


def fmt_ns(seconds: float | None, n: int) -> str:
    return "-" if seconds is None else f"{seconds / n * 1e9:,.0f}"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="1M")
    ap.add_argument("--dists", default=",".join(DISTS))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--geos-max", type=int, default=1_000_000)
    ap.add_argument("--out", default="benchmarks/results/phases")
    args = ap.parse_args(argv)
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    info = machine()
    thread_counts = [int(t) for t in args.threads.split(",")]
    rows = []
    for n in parse_sizes(args.sizes):
        for dist in args.dists.split(","):
            pts = points(dist, n)
            n_pts = len(pts)
            runs = {}
            triangle_runs: list[float] = []
            for engine in ("incremental", "fortune"):  # warm-up, not timed: the process's memory, the caches
                time_phases(pts, engine, 1)
            time_triangle(pts)
            configs = [(engine, threads) for engine in ("incremental", "fortune") for threads in thread_counts]
            for r in range(args.repeats):
                # interleaved: every configuration once per round, their order rotated from round to round,
                # so that none always comes first, after Triangle's call (a build that follows a pause
                # or another tool's memory pays most for fresh memory on a virtual machine)
                for engine, threads in configs[r % len(configs) :] + configs[: r % len(configs)]:
                    gc.collect()
                    runs.setdefault((engine, threads), []).append(time_phases(pts, engine, threads))
                gc.collect()
                seconds = time_triangle(pts)
                if seconds is not None:
                    triangle_runs.append(seconds)
            triangle_median = statistics.median(triangle_runs) if triangle_runs else None
            for (engine, threads), reps in runs.items():
                med = {p: None if reps[0][p] is None else statistics.median(r[p] for r in reps) for p in PHASES}
                med["total"] = statistics.median(sum(r[p] or 0.0 for p in PHASES) for r in reps)
                med["system"] = statistics.median(r["system"] for r in reps)
                rows.append(
                    {
                        "n": n_pts,
                        "dist": dist,
                        "tool": f"tvoronoi {engine}",
                        "threads": threads,
                        **{p: med[p] for p in (*PHASES, "total", "system")},
                        "x_triangle": None if triangle_median is None else med["total"] / triangle_median,
                    }
                )
                rows[-1]["peak_mib"], rows[-1]["first_build"] = fresh_build(dist, n, engine, threads)
                print(
                    f"{dist:>13} n={n_pts:>9,} {engine:>11} threads={threads}: "
                    + " ".join(f"{p}={(med[p] or 0.0) * 1e3:.0f}ms" for p in (*PHASES, "total", "system")),
                    flush=True,
                )
            if triangle_median is not None:
                rows.append(
                    {"n": n_pts, "dist": dist, "tool": "Triangle voronoi", "threads": 1, "total": triangle_median}
                )
                print(f"{dist:>13} n={n_pts:>9,} Triangle voronoi: {triangle_median * 1e3:.0f}ms", flush=True)
            for tool, seconds in others(pts, args.geos_max).items():
                rows.append({"n": n_pts, "dist": dist, "tool": tool, "threads": 1, "total": seconds})
                print(f"{dist:>13} n={n_pts:>9,} {tool}: {seconds * 1e3:.0f}ms", flush=True)
    atomic_write(out_dir / "phases.json", json.dumps({"machine": info, "rows": rows}, indent=1))
    atomic_write(out_dir / "phases.md", report(rows, info))
    print(f"# wrote {out_dir / 'phases.md'}")


def report(rows: list[dict], info: dict) -> str:
    lines = [
        "# Where a build's time goes",
        "",
        f"Machine: {describe_machine(info)}",
        "",
        "Medians of interleaved repeats (each configuration once per round, in an order rotated from round "
        "to round, Triangle last), each phase in **ns per site** (ms in brackets for the total). "
        "`tvoronoi.voronoi()` to bounded cells = order + tri + dual + cells (by halves, each half is "
        "ordered within tri: order reads -). The other tools are "
        "whole calls on the same points: Triangle's `triangle.voronoi` (no cells), Qhull's "
        "triangulation, CGAL's `Delaunay_triangulation_2` (making its points, then inserting them), "
        "GEOS's `voronoi_polygons` (cells). Peak: MiB a whole build adds to a fresh process; first build: "
        "that build's time (the process's first, where its memory is fresh; the phases are warm builds, "
        "as are the other tools' calls). x Triangle: the build's total over the median of Triangle's calls, "
        "timed warm in the same interleaved repeats (the others are timed once, after them). System: the "
        "kernel's time within a build (all threads, ms), mostly first touches of fresh memory: on a "
        "virtual machine whose host takes back freed memory it varies from run to run, and explains "
        "most of the swings of the phases.",
        "",
    ]
    for n in sorted({r["n"] for r in rows}):
        for dist in dict.fromkeys(r["dist"] for r in rows if r["n"] == n):
            sub = [r for r in rows if r["n"] == n and r["dist"] == dist]
            lines += [
                f"## {dist}, n = {n:,}",
                "",
                "| build | threads | order | tri | dual | cells | total | x Triangle | system ms | peak MiB "
                "| first build |",
                "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
            ]
            for r in sub:
                if "order" in r:
                    lines.append(
                        f"| {r['tool']} | {r['threads']} | "
                        + " | ".join(fmt_ns(r[p], n) for p in PHASES)
                        + f" | {fmt_ns(r['total'], n)} ({r['total'] * 1e3:.0f} ms) | "
                        + (f"{r['x_triangle']:.2f}x" if r.get("x_triangle") is not None else "")
                        + " | "
                        + (f"{r['system'] * 1e3:.0f}" if "system" in r else "")
                        + f" | {r['peak_mib']:.0f} | "
                        + (f"{r['first_build'] * 1e3:.0f} ms" if "first_build" in r else "")
                        + " |"
                    )
            for r in sub:
                if "order" not in r:
                    lines.append(
                        f"| {r['tool']} | 1 | | | | | {fmt_ns(r['total'], n)} ({r['total'] * 1e3:.0f} ms) | | | | |"
                    )
            lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
