"""Time and memory of a full Voronoi build: tvoronoi's engines against scipy.spatial.Voronoi (Qhull).

Usage:
    python benchmarks/bench_build.py [--quick] [--sizes 1000,100000] [--repeat 3]

Each (tool, n) case runs in a fresh subprocess so that its peak memory
(maximum resident set, less the process's resident set before the build) is
its own. Inside the subprocess the build is run once untimed (warm-up), then
timed `repeat` times; the median and the spread are reported. Results go to
benchmarks/results/build.csv and build.md.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / "results"
QUICK_SIZES = (10_000, 100_000, 200_000)
FULL_SIZES = (1_000, 10_000, 100_000, 200_000, 1_000_000)
TOOLS = ("tvoronoi-incremental", "tvoronoi-incremental-random", "scipy-voronoi")


def build_once(tool: str, pts):
    """Build one diagram with the named tool; return something that holds it."""
    if tool == "tvoronoi-incremental":
        import tvoronoi

        return tvoronoi.voronoi(pts, engine="incremental")
    if tool == "tvoronoi-incremental-random":
        import tvoronoi

        return tvoronoi.voronoi(pts, engine="incremental", insertion="random")
    if tool == "tvoronoi-fortune":
        import tvoronoi

        return tvoronoi.voronoi(pts, engine="fortune")
    if tool == "scipy-voronoi":
        import scipy.spatial

        return scipy.spatial.Voronoi(pts)
    raise ValueError(f"unknown tool {tool!r}")


def check(tool: str, result, pts) -> None:
    """A wrong answer fast is not a result: spot-check the diagram before timing."""
    import numpy as np

    n = len(pts)
    if tool.startswith("tvoronoi"):
        # each sampled site lies in its own cell, and the cells tile the box
        import shapely

        idx = np.random.default_rng(0).choice(n, size=min(n, 200), replace=False)
        for i in idx:
            poly = shapely.Polygon(result.cell_polygon(int(i)))
            assert poly.is_valid and poly.covers(shapely.Point(pts[i])), f"{tool}: bad cell {i}"
        counts = np.diff(result.cell_offsets)
        assert np.all(counts >= 3), f"{tool}: a site without a cell"
    else:
        assert len(result.point_region) == n


def worker(tool: str, n: int, repeat: int, seed: int) -> dict:
    """Run in a subprocess: time `repeat` builds after one warm-up, report peak memory."""
    import numpy as np

    from tvoronoi.generators import uniform

    pts = uniform(n, seed=seed)
    base_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    result = build_once(tool, pts)          # warm-up, and the memory measurement
    peak_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    check(tool, result, pts)
    del result
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = build_once(tool, pts)
        times.append(time.perf_counter() - t0)
        del result
    return {"tool": tool, "n": n, "times": times, "peak_mib": (peak_rss - base_rss) / 1024.0}


def run_case(tool: str, n: int, repeat: int, seed: int) -> dict:
    cmd = [sys.executable, __file__, "--worker", json.dumps([tool, n, repeat, seed])]
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parent.parent))
    out = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"{tool} at n={n} failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def machine() -> str:
    import numpy as np

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"numpy {np.__version__}, OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', 'unset')}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="sizes up to 200,000 only")
    ap.add_argument("--sizes", help="comma-separated sizes")
    ap.add_argument("--tools", default=",".join(TOOLS), help="comma-separated tools")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        tool, n, repeat, seed = json.loads(args.worker)
        print(json.dumps(worker(tool, n, repeat, seed)))
        return 0

    sizes = [int(s) for s in args.sizes.split(",")] if args.sizes else (QUICK_SIZES if args.quick else FULL_SIZES)
    tools = args.tools.split(",")
    RESULTS.mkdir(exist_ok=True)
    rows = []
    print(f"# {machine()}")
    for n in sizes:
        for tool in tools:            # tools interleaved per size: drift hits all alike
            if tool == "tvoronoi-incremental-random" and n > 200_000:
                continue              # the textbook order is for comparison, not for 10^6
            r = run_case(tool, n, args.repeat, args.seed)
            med = statistics.median(r["times"])
            spread = max(r["times"]) - min(r["times"])
            rows.append({"tool": tool, "distribution": "uniform", "n": n, "median_s": med,
                         "spread_s": spread, "peak_mib": r["peak_mib"], "repeats": len(r["times"])})
            print(f"{tool:30s} n={n:>9,}  {med:8.3f} s  (±{spread / 2:.3f})  peak {r['peak_mib']:8.1f} MiB",
                  flush=True)
    write_results(rows)
    return 0


def write_results(rows) -> None:
    path = RESULTS / "build.csv"
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, path)
    by = {(r["tool"], r["n"]): r for r in rows}
    lines = [f"Machine: {machine()}", "", "| n | tool | median s | peak MiB | vs Qhull |", "|---|---|---|---|---|"]
    for r in rows:
        q = by.get(("scipy-voronoi", r["n"]))
        ratio = f"{q['median_s'] / r['median_s']:.1f}x faster" if q and r["tool"] != "scipy-voronoi" else ""
        lines.append(f"| {r['n']:,} | {r['tool']} | {r['median_s']:.3f} | {r['peak_mib']:.0f} | {ratio} |")
    md = RESULTS / "build.md"
    tmp = md.with_suffix(".md.tmp")
    tmp.write_text("\n".join(lines) + "\n")
    os.replace(tmp, md)
    print("\n".join(lines[2:]))


if __name__ == "__main__":
    sys.exit(main())
