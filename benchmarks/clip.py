"""Clip to a detailed outline: voronoi(points, clip=region) on a country-like coastline.

The region is tvoronoi.generators.coastline(): 4,000 coast vertices with 300 thin spikes, lakes and
islands (about 4,400 vertices); the sites are uniform in its bounds (about half inside). For each n it
times, in this process:
  plain   voronoi(sites) in the region's box, no clip
  clip    voronoi(sites, clip=region): sites inside, their diagram, the crossing cells cut locally
  whole   the same with every crossing cell cut against the whole outline (the former way), --whole

    python benchmarks/clip.py --n 100k,1M --whole 100k --out benchmarks/results
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.common import (  # noqa: E402
    atomic_write,
    describe_machine,
    machine,
    parse_sizes,
    release_free_memory,
    write_csv,
)


def timed(fn, *args, **kwargs):
    release_free_memory()
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn(*args, **kwargs)
    return out, time.perf_counter() - wall, time.process_time() - cpu


def main(argv=None) -> None:
    import shapely

    import tvoronoi
    from tvoronoi import region as region_module
    from tvoronoi.generators import coastline
    from tvoronoi.region import region_box

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", default="100k,1M")
    ap.add_argument("--whole", default="100k", help="sizes also cut against the whole outline ('' for none)")
    ap.add_argument("--out", default="benchmarks/results")
    args = ap.parse_args(argv)
    info = machine()
    region = coastline()
    n_vertices = int(shapely.get_num_coordinates(region))
    xmin, ymin, xmax, ymax = region.bounds
    whole_sizes = set(parse_sizes(args.whole)) if args.whole else set()
    rows = []
    for n in parse_sizes(args.n):
        pts = np.random.default_rng(11).uniform([xmin, ymin], [xmax, ymax], (n, 2))
        _, wall, cpu = timed(tvoronoi.voronoi, pts, bbox=region_box(region))
        rows.append({"n": n, "case": "plain", "wall_s": round(wall, 3), "cpu_s": round(cpu, 3)})
        d, wall, cpu = timed(tvoronoi.voronoi, pts, clip=region)
        crossing = int(np.count_nonzero(d.reshaped & (d.clipped != None)))  # noqa: E711
        rows.append(
            {
                "n": n,
                "case": "clip",
                "wall_s": round(wall, 3),
                "cpu_s": round(cpu, 3),
                "inside": int(d.inside.sum()),
                "crossing": crossing,
            }
        )
        del d
        if n in whole_sizes:
            local = region_module.local_intersection
            region_module.local_intersection = shapely.intersection
            try:
                _, wall, cpu = timed(tvoronoi.voronoi, pts, clip=region)
            finally:
                region_module.local_intersection = local
            rows.append({"n": n, "case": "whole", "wall_s": round(wall, 3), "cpu_s": round(cpu, 3)})
        for row in rows[-3:]:
            if row["n"] == n:
                print(row, flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    columns = ["n", "case", "wall_s", "cpu_s", "inside", "crossing"]
    write_csv(out / "clip.csv", rows, columns=columns)
    names = {
        "plain": "voronoi(sites), no clip",
        "clip": "voronoi(sites, clip=coast): cells cut locally",
        "whole": "the same, each crossing cell cut against the whole outline",
    }
    lines = [
        "# Clip to a detailed outline",
        "",
        f"Machine: {describe_machine(info)}",
        "",
        f"Region: `tvoronoi.generators.coastline()`, {n_vertices:,} vertices (a coast of 4,000 with 300 "
        f"thin spikes, lakes, islands). Sites uniform in its bounds; one run each, in one process.",
        "",
        "| sites | case | wall s | CPU s | inside | cut cells |",
        "|---:|---|---:|---:|---:|---:|",
    ]
    for row in rows:
        lines.append(
            f"| {row['n']:,} | {names[row['case']]} | {row['wall_s']:.2f} | {row['cpu_s']:.2f} | "
            f"{row.get('inside', '')} | {row.get('crossing', '')} |"
        )
    atomic_write(out / "clip.md", "\n".join(lines) + "\n")
    print(f"# wrote {out / 'clip.md'}")


if __name__ == "__main__":
    main()
