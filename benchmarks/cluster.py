"""More than one core: threads=2 against threads=1, and tiles on a Dask LocalCluster against one process.

    python benchmarks/cluster.py --threads-n 1M --cluster-n 10M --workers 2 --out benchmarks/results/cluster

1. ``tvoronoi.voronoi(points, threads=N)`` at ``--threads-n`` uniform sites, N = 1 and 2 (the OpenMP phases
   of the kernels), and next to it the same sites as two tiles built in two Python threads (build_tile
   with threads=1 each, the kernels releasing the GIL) -- the alternative the threads could take.
2. ``--cluster-n`` uniform sites generated in partitions of 10^6: one process (generate, build, write
   GeoParquet; a fresh subprocess, its peak memory from VmHWM) against ``tvoronoi.distributed.voronoi`` on a
   LocalCluster of ``--workers`` single-threaded worker processes writing a partitioned GeoParquet directory
   (peak memory of each worker from its VmHWM). Parallel efficiency = t_one / (workers * t_cluster).

Writes OUT.md (with the machine and the estimates for 10^9 and 10^10 sites) and OUT.json.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.common import atomic_write, describe_machine, machine, parse_sizes, subprocess_env  # noqa: E402

PARTITION = 1_000_000

ONE_PROCESS = f"""
import sys, time, json
import numpy as np
sys.path.insert(0, sys.argv[3])
from benchmarks.cluster import partition_points
from benchmarks.common import maxrss_mib
import tvoronoi
from tvoronoi.writers.geoparquet import write_cells_parquet
n, out = int(sys.argv[1]), sys.argv[2]
c0 = time.process_time()
t0 = time.perf_counter()
pts = np.concatenate([partition_points(k, n) for k in range((n + {PARTITION} - 1) // {PARTITION})])
t1 = time.perf_counter()
d = tvoronoi.voronoi(pts, threads=1)
t2 = time.perf_counter()
write_cells_parquet(d, None, out)
t3 = time.perf_counter()
print(json.dumps({{"generate": t1 - t0, "build": t2 - t1, "write": t3 - t2, "total": t3 - t0,
                  "cpu": time.process_time() - c0, "peak_mib": maxrss_mib()}}))
"""


def partition_points(k: int, n: int) -> np.ndarray:
    """Partition k of n uniform sites (the same in one process and on the cluster)."""
    size = min(PARTITION, n - k * PARTITION)
    return np.random.default_rng([17, k]).random((size, 2))


def time_threads(n: int, repeats: int = 3) -> dict:
    import tvoronoi
    from tvoronoi.api import default_bbox
    from tvoronoi.tiles import build_tile, grown, in_region, kd_rects, tile_of

    pts = np.random.default_rng(5).random((n, 2))
    out: dict = {"n": n}
    runs: dict[int, list[float]] = {1: [], 2: []}
    for threads in (1, 2):
        tvoronoi.voronoi(pts[:10_000], threads=threads)
    for _ in range(repeats):  # interleaved, so that a slow spell of the machine falls on both
        for threads in (1, 2):
            t0 = time.perf_counter()
            tvoronoi.voronoi(pts, threads=threads)
            runs[threads].append(time.perf_counter() - t0)
    for threads in (1, 2):
        out[f"threads_{threads}"] = statistics.median(runs[threads])
        out[f"threads_{threads}_runs"] = runs[threads]
    # two tiles in two threads, each built with threads=1 (halo: 4 spacings)
    box = default_bbox(pts)
    rects = kd_rects(pts[:: max(1, n // 2000)], 2)
    owner = tile_of(pts[:, 0], pts[:, 1], rects)
    halo = 4 / np.sqrt(n)
    ids = np.arange(n, dtype=np.int64)

    def one(t: int):
        region = grown(rects[t], halo)
        rows = np.flatnonzero(in_region(pts[:, 0], pts[:, 1], region))
        return build_tile(pts[rows], ids[rows], owner[rows] == t, region, box)

    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        with ThreadPoolExecutor(2) as pool:
            cells = list(pool.map(one, range(2)))
        times.append(time.perf_counter() - t0)
    out["tiles_in_2_threads"] = statistics.median(times)
    out["tiles_pending"] = int(sum(len(c.pending) for c in cells))
    return out


def one_process(n: int) -> dict:
    import os

    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        run = subprocess.run(
            [
                sys.executable,
                "-c",
                ONE_PROCESS,
                str(n),
                str(Path(tmp) / "cells.parquet"),
                str(Path(__file__).resolve().parent.parent),
            ],
            capture_output=True,
            text=True,
            env=subprocess_env(),
        )
    if run.returncode != 0:
        raise RuntimeError(run.stderr)
    return {**json.loads(run.stdout.strip().splitlines()[-1]), "load_before": load, "load_after": os.getloadavg()[0]}


def _median_run(runs: list[dict], key: str) -> dict | None:
    """The run whose ``key`` is the median of the runs (the lower middle one of an even count)."""
    if not runs:
        return None
    return sorted(runs, key=lambda r: r[key])[(len(runs) - 1) // 2]


def _worker_peak() -> float:
    from benchmarks.common import maxrss_mib

    return maxrss_mib()


def _worker_cpu() -> float:
    return time.process_time()


def on_cluster(n: int, workers: int, tiles: int | None) -> dict:
    import dask
    import dask.dataframe as dd
    import pandas as pd

    from tvoronoi.distributed import local_client, voronoi

    def part(k: int) -> pd.DataFrame:
        xy = partition_points(k, n)
        return pd.DataFrame({"x": xy[:, 0], "y": xy[:, 1]})

    n_parts = (n + PARTITION - 1) // PARTITION
    frame = dd.from_delayed(
        [dask.delayed(part)(k) for k in range(n_parts)], meta=pd.DataFrame({"x": np.empty(0), "y": np.empty(0)})
    )
    import os

    client = local_client(workers)
    try:
        client.run(lambda: sys.path.insert(0, str(Path(__file__).resolve().parent.parent)))
        load = os.getloadavg()[0]
        with tempfile.TemporaryDirectory() as tmp:
            cpu0 = client.run(_worker_cpu)
            c0 = time.process_time()  # this process: the client and the LocalCluster's scheduler
            t0 = time.perf_counter()
            result = voronoi(frame, client=client, tiles=tiles, to=Path(tmp) / "cells")
            elapsed = time.perf_counter() - t0
            here = time.process_time() - c0
            cpu1 = client.run(_worker_cpu)
            written = sum(1 for p in result.parts if p)
            size = sum(f.stat().st_size for f in (Path(tmp) / "cells").rglob("*") if f.is_file())
        peaks = client.run(_worker_peak)
    finally:
        cluster = client.cluster
        client.close()
        cluster.close()
    return {
        "seconds": elapsed,
        "worker_cpu": sorted(round(cpu1[w] - cpu0[w], 1) for w in cpu1),
        "scheduler_client_cpu": here,
        "load_before": load,
        "load_after": os.getloadavg()[0],
        "tiles": result.n_tiles,
        "rounds": result.rounds,
        "pending_after": list(result.pending_after),
        "parts": written,
        "bytes_written": size,
        "worker_peak_mib": sorted(round(v, 1) for v in peaks.values()),
    }


ESTIMATES = """\
## On paper: 10^9 and 10^10 sites

Measured here: a task holds about {per_site:.0f} bytes per site of its tile at its peak (engine, clipped
cells, WKB and the Arrow table of its part), and builds about {rate:,.0f} sites per second on one core
(build, certification, WKB and the GeoParquet part together).

| sites | tiles of 10^6 sites | peak memory per task | halo sites read twice | input moved to the tasks | core-hours (one round) |
| --- | --- | --- | --- | --- | --- |
| 10^9 | 1,000 | {mem_gib:.1f} GiB | 1.6% (16 million) | about 24 GB (x, y, row: 24 bytes a site) | {h9:.1f} |
| 10^10 | 10,000 | {mem_gib:.1f} GiB | 1.6% (160 million) | about 240 GB | {h10:.0f} |

- Tasks: one per tile in the first round; then one per group of uncertified cells (box corners and
  edges, sparse places: {pending} of {n:,} cells after the first round here), each a few thousand sites.
  With ~10^6 sites a tile, memory per task stays at the figure above whatever n: a cluster of workers with
  2-4 GiB each, one task per core, suffices; the output is written by the tasks (one part each).
- Halos: a halo of 4 site spacings around a square tile of 10^6 sites (1,000 spacings a side) adds
  (1008^2 - 1000^2) / 1000^2 = 1.6% of the sites, read by a second task.
- What does not scale as written: each partition is read once a round (one task serving every tile
  whose region it reaches; partitions whose extent misses a region are skipped), but for shuffled input
  every tile still takes a piece from every partition: tiles x partitions pieces a round, 10^6 at 10^9
  sites with partitions of 10^6, 10^8 at 10^10 -- beyond what one Dask scheduler handles (~1 ms a
  task). At that scale the sites must first be shuffled to their tile once (dask.dataframe's shuffle on
  the tile number, n x 24 bytes over the network), the halos then taken from the 8 neighbouring tiles
  only (1.6% more); then 10^4 tasks a round at 10^10.
- Rounds: with the first halo of 4 spacings, uniform data finishes in 2 rounds: the second rebuilds
  each group of leftover cells (box corners and edges) with just the sites their disks reach, a few
  thousand per group.
- 10^8 here, predicted from this run: ~100 tiles of 10^6, peak ~{mem_gib:.1f} GiB per task (goal < 4 GB),
  about {h8:.1f} hours on these 2 cores; the input (2.4 GB of x/y/row) never sits in one process. Measured:
  cluster_1e8.md (`--cluster-n 100M --no-one-process`).
"""


def report(
    info: dict, threads: dict | None, one: dict | None, cluster: dict | None, n: int | None, workers: int
) -> str:
    import os

    lines = [
        "# Tiles on more than one core",
        "",
        describe_machine(info),
        f"Load average at the end: {[round(v, 2) for v in os.getloadavg()]} (the machine is shared: other "
        f"work ran on the same 2 cores during these runs, so the figures are upper bounds).",
        "",
    ]
    if threads:
        ratio = threads["threads_2"] / threads["threads_1"]
        tiles_ratio = threads["tiles_in_2_threads"] / threads["threads_1"]
        lines += [
            f"## threads at {threads['n']:,} uniform sites (median of {len(threads.get('threads_1_runs', [0] * 3))}, "
            "threads=1 and threads=2 interleaved)",
            "",
            "| build | seconds | vs threads=1 |",
            "| --- | --- | --- |",
            f"| voronoi(threads=1) | {threads['threads_1']:.3f} | 1.00 |",
            f"| voronoi(threads=2): the two halves on two threads, then the OpenMP phases (dual, clip) | {threads['threads_2']:.3f} | {ratio:.2f} |",
            f"| two tiles in two Python threads (build_tile, threads=1 each; "
            f"{threads['tiles_pending']} cells left for a second round) | {threads['tiles_in_2_threads']:.3f} | "
            f"{tiles_ratio:.2f} |",
            "",
        ]
        if "threads_1_runs" in threads:
            each = ", ".join(
                f"{a:.3f} / {b:.3f} = {b / a:.2f}" for a, b in zip(threads["threads_1_runs"], threads["threads_2_runs"])
            )
            lines += [f"Each round, threads=1 / threads=2 in seconds: {each}.", ""]
    if cluster and n and not one:
        lines += [
            f"## {n:,} uniform sites out of core: {workers} Dask workers, no one-process run",
            "",
            "The sites are generated in partitions of 10^6 by the workers; no process ever holds them all, and",
            "each task writes its own GeoParquet part.",
            "",
            "| run | seconds | peak memory per worker | sites per second per core | CPU seconds |",
            "| --- | --- | --- | --- | --- |",
            f"| LocalCluster, {workers} worker processes, {cluster['tiles']} tiles, {cluster['rounds']} rounds "
            f"(cells left after each: {cluster['pending_after']}), {cluster['parts']} parts written "
            f"({cluster.get('bytes_written', 0) / 2**30:.1f} GiB) | {cluster['seconds']:,.1f} | "
            f"{' / '.join(f'{v:,.0f}' for v in cluster['worker_peak_mib'])} MiB | "
            f"{n / cluster['seconds'] / workers:,.0f} | workers "
            f"{' + '.join(f'{v:,.1f}' for v in cluster['worker_cpu'])}, scheduler and client "
            f"{cluster['scheduler_client_cpu']:.1f} |",
            "",
            f"Load average (1 min) before / after: {cluster['load_before']:.1f} / {cluster['load_after']:.1f}.",
            "",
        ]
    if one and cluster and n:
        efficiency = one["total"] / (workers * cluster["seconds"])
        lines += [
            f"## {n:,} uniform sites: one process against {workers} Dask workers",
            "",
            "| run | seconds | peak memory | sites per second per core |",
            "| --- | --- | --- | --- |",
            f"| one process: generate {one['generate']:.1f} s, build {one['build']:.1f} s, write GeoParquet "
            f"{one['write']:.1f} s | {one['total']:.1f} | {one['peak_mib']:,.0f} MiB | {n / one['total']:,.0f} |",
            f"| LocalCluster, {workers} worker processes, {cluster['tiles']} tiles, {cluster['rounds']} rounds "
            f"(cells left after each: {cluster['pending_after']}), {cluster['parts']} parts written | "
            f"{cluster['seconds']:.1f} | {' / '.join(f'{v:,.0f}' for v in cluster['worker_peak_mib'])} MiB per worker "
            f"| {n / cluster['seconds'] / workers:,.0f} |",
            "",
            f"Parallel efficiency: {efficiency:.0%} (t_one / ({workers} x t_cluster)).",
            "",
        ]
        if "runs" in one and "runs" in cluster:
            each = ", ".join(
                f"{a:.1f} / {b:.1f} s = {a / (workers * b):.0%}" for a, b in zip(one["runs"], cluster["runs"])
            )
            lines += [
                f"The rows above are the median runs of {len(one['runs'])}, one process and cluster interleaved. "
                f"Each pair, one process / cluster and its efficiency: {each}; efficiency of the medians "
                f"{statistics.median(one['runs']) / (workers * statistics.median(cluster['runs'])):.0%}.",
                "",
            ]
        if "cpu" in one and "worker_cpu" in cluster:
            spent = sum(cluster["worker_cpu"]) + cluster["scheduler_client_cpu"]
            lines += [
                f"CPU seconds: one process {one['cpu']:.1f}; the cluster {spent:.1f} (workers "
                f"{' + '.join(f'{v:.1f}' for v in cluster['worker_cpu'])}, scheduler and client "
                f"{cluster['scheduler_client_cpu']:.1f}): the tiles cost {spent / one['cpu']:.2f}x the work of one "
                f"process, so on {workers} free cores the efficiency would be at most {one['cpu'] / spent:.0%}.",
                f"Load average (1 min) before / after: one process {one['load_before']:.1f} / "
                f"{one['load_after']:.1f}, cluster {cluster['load_before']:.1f} / {cluster['load_after']:.1f} on "
                f"{info.get('cores_usable', 2)} cores: the machine was shared with other work, so the wall-clock "
                f"figures above measure the share each run got, not the cores.",
                "",
            ]
        per_site = max(cluster["worker_peak_mib"]) * 2**20 / (n / cluster["tiles"] * 1.016)
        rate = n / cluster["seconds"] / workers
        lines.append(
            ESTIMATES.format(
                per_site=per_site,
                rate=rate,
                mem_gib=per_site * 1.016e6 / 2**30,
                h8=1e8 / rate / 3600 / workers,
                h9=1e9 / rate / 3600,
                h10=1e10 / rate / 3600,
                pending=cluster["pending_after"][0],
                n=n,
            )
        )
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--threads-n", default="1M")
    parser.add_argument("--cluster-n", default="10M", help="0 to skip the cluster run")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--tiles", type=int, default=None)
    parser.add_argument(
        "--no-one-process",
        action="store_true",
        help="skip the one-process run (for sizes one process cannot hold, such as 10^8: the out-of-core run)",
    )
    parser.add_argument(
        "--repeats", type=int, default=1, help="runs of the one process and the cluster, interleaved; medians"
    )
    parser.add_argument("--out", default=str(Path(__file__).resolve().parent / "results" / "cluster"))
    parser.add_argument("--report-only", action="store_true", help="rewrite OUT.md from OUT.json (no run)")
    args = parser.parse_args(argv)
    if args.report_only:
        out = Path(args.out)
        saved = json.loads(out.with_suffix(".json").read_text())
        atomic_write(
            out.with_suffix(".md"),
            report(
                saved["machine"], saved["threads"], saved["one_process"], saved["cluster"], saved["n"], saved["workers"]
            ),
        )
        print(out.with_suffix(".md").read_text())
        return 0
    info = machine()
    threads = time_threads(parse_sizes(args.threads_n)[0]) if args.threads_n != "0" else None
    print(json.dumps(threads), flush=True)
    n = parse_sizes(args.cluster_n)[0] if args.cluster_n != "0" else None
    one = cluster = None
    ones: list[dict] = []
    clusters: list[dict] = []
    if n:
        for _ in range(args.repeats):  # interleaved: one process, then the cluster, then again
            if not args.no_one_process:
                ones.append(one_process(n))
                print(json.dumps(ones[-1]), flush=True)
            clusters.append(on_cluster(n, args.workers, args.tiles))
            print(json.dumps(clusters[-1]), flush=True)
        one = _median_run(ones, "total")
        cluster = _median_run(clusters, "seconds")
        if cluster is not None and len(clusters) > 1:
            cluster = {**cluster, "runs": [c["seconds"] for c in clusters]}
        if one is not None and len(ones) > 1:
            one = {**one, "runs": [o["total"] for o in ones]}
    out = Path(args.out)
    atomic_write(
        out.with_suffix(".json"),
        json.dumps(
            {
                "machine": info,
                "threads": threads,
                "one_process": one,
                "cluster": cluster,
                "n": n,
                "workers": args.workers,
            },
            indent=1,
        ),
    )
    atomic_write(out.with_suffix(".md"), report(info, threads, one, cluster, n, args.workers))
    print(out.with_suffix(".md").read_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
