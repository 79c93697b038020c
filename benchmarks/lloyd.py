"""Lloyd steps: a rebuild per step against moving sites through DynamicVoronoi, measured.

After a few Lloyd steps on uniform sites, it times (in this process) one rebuild with the centroids of
every cell, a dynamic diagram's moves of a sample of sites to their centroids (per move), and the
conversion of the dynamic diagram to the CSR cells the centroids are read from. It reports the fraction
of sites below which moving them would beat a rebuild, and how far sites still move late in the
relaxation (in cell sizes): the figures behind tvoronoi.relax.lloyd rebuilding at every step.

    python benchmarks/lloyd.py --n 100k --out benchmarks/results
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.common import atomic_write, describe_machine, machine, parse_sizes, write_csv  # noqa: E402

WARM_STEPS = 5
SAMPLE_MOVES = 2000


def main(argv=None) -> None:
    import tvoronoi
    from tvoronoi.relax import cell_centroids

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", default="100k")
    ap.add_argument("--out", default="benchmarks/results")
    args = ap.parse_args(argv)
    info = machine()
    rows = []
    for n in parse_sizes(args.n):
        rng = np.random.default_rng(3)
        pts, box = rng.random((n, 2)), (0.0, 0.0, 1.0, 1.0)
        for _ in range(WARM_STEPS):
            centroids, has = cell_centroids(tvoronoi.voronoi(pts, bbox=box))
            pts[has] = centroids[has]
        t = time.perf_counter()
        centroids, has = cell_centroids(tvoronoi.voronoi(pts, bbox=box))
        rebuild = time.perf_counter() - t
        steps = np.linalg.norm(centroids - pts, axis=1) / np.sqrt(1.0 / n)
        dynamic = tvoronoi.DynamicVoronoi(pts, bbox=box)
        sample = rng.choice(n, min(SAMPLE_MOVES, n), replace=False)
        t = time.perf_counter()
        for i in sample.tolist():
            dynamic.move(i, float(centroids[i, 0]), float(centroids[i, 1]))
        per_move = (time.perf_counter() - t) / len(sample)
        t = time.perf_counter()
        cell_centroids(dynamic.diagram().to_diagram())
        convert = time.perf_counter() - t
        row = {
            "n": n,
            "rebuild_and_centroids_s": round(rebuild, 4),
            "move_us": round(per_move * 1e6, 1),
            "move_all_s": round(per_move * n, 3),
            "dynamic_cells_and_centroids_s": round(convert, 4),
            "break_even_fraction": round(rebuild / (per_move * n), 4),
            "step_median_cells": round(float(np.median(steps)), 4),
            "step_p10_cells": round(float(np.quantile(steps, 0.1)), 4),
        }
        rows.append(row)
        print(row, flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "lloyd.csv", rows, columns=list(rows[0]))
    lines = [
        "# Lloyd steps: rebuild or move",
        "",
        f"Machine: {describe_machine(info)}",
        "",
        f"Uniform sites in the unit square after {WARM_STEPS} Lloyd steps; moves of {SAMPLE_MOVES} sites "
        "through DynamicVoronoi.move; one run, in one process. A dynamic step would also need the cells "
        "of the moved sites' neighbours for their centroids: reading the whole diagram costs more than "
        "a rebuild, so moves pay off only below the break-even fraction, and then only if the centroids "
        "were read cell by cell.",
        "",
        "| sites | rebuild + centroids s | one move us | moving all s | dynamic cells + centroids s | "
        "break-even fraction of sites moved | median step (cell sizes) | 10% step |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['n']:,} | {r['rebuild_and_centroids_s']:.3f} | {r['move_us']:.0f} | {r['move_all_s']:.2f} "
            f"| {r['dynamic_cells_and_centroids_s']:.3f} | {r['break_even_fraction']:.1%} | "
            f"{r['step_median_cells']:.3f} | {r['step_p10_cells']:.3f} |"
        )
    atomic_write(out / "lloyd.md", "\n".join(lines) + "\n")
    print(f"# wrote {out / 'lloyd.md'}")


if __name__ == "__main__":
    main()
