"""End to end: a CSV of points with text columns in, cells out, as a GIS user runs it.

Times whole processes (start-up included) and their peak memory, for
  tvoronoi batch points.csv -o cells.geojson
  tvoronoi batch points.csv -o cells.parquet          (GeoParquet, needs the parquet extra)
  pandas.read_csv -> shapely.voronoi_polygons -> geopandas.to_file (GeoJSON), the usual pipeline
on the same file of n points (x, y and two text columns).

    python benchmarks/batch.py --n 1M --out benchmarks/results
    python benchmarks/batch.py --n 1M --before /tmp/old --before-label 'before, fbb596b'

--before DIR runs an older checkout's package as well (``git archive REV tvoronoi | tar -x -C DIR``,
its compiled kernels copied in), interleaved with this one, so that the two meet the same load.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.common import (  # noqa: E402
    atomic_write,
    describe_machine,
    machine,
    parse_sizes,
    subprocess_env,
    write_csv,
)

PANDAS_SHAPELY = """
import sys
import geopandas, pandas, shapely
frame = pandas.read_csv(sys.argv[1])
points = shapely.points(frame["x"].to_numpy(), frame["y"].to_numpy())
cells = shapely.voronoi_polygons(shapely.multipoints(points), ordered=True)
out = geopandas.GeoDataFrame(frame[["name", "kind"]], geometry=list(shapely.get_parts(cells)))
out.to_file(sys.argv[2], driver="GeoJSON")
"""


def write_points(path: Path, n: int) -> None:
    rng = np.random.default_rng(17)
    xy = rng.random((n, 2)) * 1000.0
    kinds = np.array(["shop", "school", "clinic", "park"])[rng.integers(0, 4, n)]
    with open(path, "w") as f:
        f.write("x,y,name,kind\n")
        for k in range(0, n, 100_000):
            block = range(k, min(n, k + 100_000))
            f.write("".join(f"{xy[i, 0]:.6f},{xy[i, 1]:.6f},site {i},{kinds[i]}\n" for i in block))


def run(cmd: list[str], path: str | None = None) -> tuple[float, float, float]:
    """Wall seconds, peak MiB and CPU seconds (user + system, all threads) of one whole process,
    its own peak and CPU from wait4. CPU time shows the work where other processes share the cores.
    ``path``: the directory of an older checkout, run from there and first on PYTHONPATH (``-m``
    puts the working directory first)."""
    env = subprocess_env()
    if path is not None:
        env["PYTHONPATH"] = os.pathsep.join([path, env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, env=env, cwd=path, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if status != 0:
        raise RuntimeError(f"{cmd} failed: {proc.stderr.read().decode()[-2000:]}")
    return wall, usage.ru_maxrss / 1024, usage.ru_utime + usage.ru_stime


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", default="1M")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only-tvoronoi", action="store_true", help="leave out the pandas + shapely pipeline")
    ap.add_argument("--out", default="benchmarks/results/batch")
    ap.add_argument(
        "--before",
        metavar="DIR",
        help="also run the tvoronoi package found in DIR (an older "
        "checkout, its kernels built), interleaved with this one: before/after on the same load",
    )
    ap.add_argument("--before-label", default="before", help="how the rows of --before are named")
    args = ap.parse_args(argv)
    n = parse_sizes(args.n)[0]
    info = machine()
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "points.csv"
        write_points(src, n)
        tv = [sys.executable, "-m", "tvoronoi", "batch", "-q", "--force", str(src), "-o"]
        cases = {
            "tvoronoi batch -> GeoJSON": tv + [str(Path(tmp) / "cells.geojson")],
            "tvoronoi batch -> GeoParquet": tv + [str(Path(tmp) / "cells.parquet")],
            "pandas + shapely.voronoi_polygons + to_file (GeoJSON)": [
                sys.executable,
                "-c",
                PANDAS_SHAPELY,
                str(src),
                str(Path(tmp) / "shapely.geojson"),
            ],
        }
        if args.before:
            before = {
                f"{name} ({args.before_label})": cmd for name, cmd in cases.items() if name.startswith("tvoronoi")
            }
            cases = {
                **{
                    name: cmd[:-1] + [str(Path(cmd[-1]).with_name("before-" + Path(cmd[-1]).name))]
                    for name, cmd in before.items()
                },
                **cases,
            }
        if args.only_tvoronoi:
            cases = {name: cmd for name, cmd in cases.items() if name.startswith("tvoronoi")}
        rows: dict[str, list] = {name: [] for name in cases}
        for _ in range(args.repeats):  # interleaved rounds
            for name, cmd in cases.items():
                rows[name].append(run(cmd, args.before if name.endswith(f"({args.before_label})") else None))
                print(
                    f"{name}: {rows[name][-1][0]:.2f} s, {rows[name][-1][1]:.0f} MiB, {rows[name][-1][2]:.2f} s CPU",
                    flush=True,
                )
        sizes = {name: (Path(cmd[-1]).stat().st_size if Path(cmd[-1]).exists() else 0) for name, cmd in cases.items()}
    lines = [
        "# Batch end to end",
        "",
        f"Machine: {describe_machine(info)}",
        "",
        f"{n:,} points in a CSV (x, y and two text columns), cells out; whole processes, start-up included; "
        f"median of {args.repeats} interleaved runs, peak resident memory of the largest of its processes; CPU is user + "
        f"system time of all its threads and processes (the work done, whatever else runs on the "
        f"machine); load average at the end {[round(v, 2) for v in os.getloadavg()]}.",
        "",
        "| pipeline | wall s | CPU s | peak MiB | output MB |",
        "|---|---:|---:|---:|---:|",
    ]
    table = []
    for name, runs in rows.items():
        wall, peak, cpu = (statistics.median(r[k] for r in runs) for k in range(3))
        lines.append(f"| {name} | {wall:.2f} | {cpu:.2f} | {peak:.0f} | {sizes[name] / 1e6:.0f} |")
        table.append(
            {
                "pipeline": name,
                "n": n,
                "repeats": len(runs),
                "wall_s": round(wall, 3),
                "cpu_s": round(cpu, 3),
                "peak_mib": round(peak, 1),
                "output_bytes": sizes[name],
            }
        )
    atomic_write(out_dir / "batch.md", "\n".join(lines) + "\n")
    write_csv(out_dir / "batch.csv", table, columns=list(table[0]))
    print(f"# wrote {out_dir / 'batch.md'}")


if __name__ == "__main__":
    main()
