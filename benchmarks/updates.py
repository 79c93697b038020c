"""Dynamic update cost against n: one insert, one small move, one remove, each until the changed cell is read back.

tvoronoi: ``tvoronoi.DynamicVoronoi`` with each engine (``insert(x, y)``,
``move(i, x, y)``, ``remove(i)``, then ``diagram().cell_polygon(i)``). Qhull:
``scipy.spatial.Delaunay(points, incremental=True).add_points`` with one point
a call (Qhull has no move or remove: those cost a rebuild, which the build
benchmark measures as qhull-delaunay).

Each (tool, n) runs in its own process on the uniform points of the build
benchmark; a few untimed operations come first. Every operation is checked
after the timed loop: an inserted or moved site lies in the cell read back,
and after a removal the removed site's place lies in the cell read back, that
of the nearest remaining site (always one of the cells that changed).

    python benchmarks/updates.py --sizes 1k,10k,100k
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import RESULTS, maxrss_mib, parse_sizes, reset_peak, rss_mib, subprocess_env, write_csv  # noqa: E402

SEED = 1  # the uniform points of the build benchmark
WARM_UP_OPS = 3
# The dynamic structure of each tvoronoi engine.
DYNAMIC_ENGINES = {"tvoronoi-dynamic": "incremental", "tvoronoi-dynamic-fortune": "fortune"}
# Qhull's add_points stops after this many seconds once it has this many timed calls.
QHULL_BUDGET = 60.0
QHULL_MIN_OPS = 7
# A small move: this fraction of the mean distance between sites, in a random direction.
MOVE_FRACTION = 0.1


def measure_dynamic(pts, box, ops: int, rng, engine: str) -> tuple[list, list]:
    """Time inserts, moves and removes on a DynamicVoronoi; return (rows, failures)."""
    import numpy as np
    import shapely

    import tvoronoi

    dv = tvoronoi.DynamicVoronoi(pts, engine=engine, bbox=box)

    def cell(i):
        """The read-back that each timing includes."""
        return dv.diagram().cell_polygon(i)

    n = len(pts)
    total = WARM_UP_OPS + ops
    xmin, ymin, xmax, ymax = pts.min(axis=0).tolist() + pts.max(axis=0).tolist()
    new = rng.uniform((xmin, ymin), (xmax, ymax), size=(total, 2))
    chosen = rng.choice(n, size=2 * total, replace=False)
    movers, removed = chosen[:total], chosen[total:]
    step = MOVE_FRACTION * np.sqrt((xmax - xmin) * (ymax - ymin) / n)
    angle = rng.uniform(0, 2 * np.pi, total)
    targets = pts[movers] + step * np.column_stack((np.cos(angle), np.sin(angle)))
    # where each site is now, by id, to find (untimed) the nearest survivor of a removed site
    ids = list(range(n))
    where = [p for p in pts]

    rows, cells = [], {"insert": [], "move": [], "remove": []}
    for k in range(total):
        t0 = time.perf_counter()
        i = dv.insert(*new[k])
        ring = cell(i)
        rows.append(("insert", time.perf_counter() - t0))
        cells["insert"].append((ring, new[k]))
        ids.append(i)
        where.append(new[k])
    for k in range(total):
        i = int(movers[k])
        t0 = time.perf_counter()
        dv.move(i, *targets[k])
        ring = cell(i)
        rows.append(("move", time.perf_counter() - t0))
        cells["move"].append((ring, targets[k]))
        where[i] = targets[k]
    alive = np.ones(len(ids), bool)
    xy = np.asarray(where)
    for k in range(total):
        i = int(removed[k])
        alive[i] = False
        d = np.hypot(*(xy - xy[i]).T)
        d[~alive] = np.inf
        j = ids[int(np.argmin(d))]  # the nearest survivor now owns the removed site's place
        t0 = time.perf_counter()
        dv.remove(i)
        ring = cell(j)
        rows.append(("remove", time.perf_counter() - t0))
        cells["remove"].append((ring, xy[i]))
    failures = [
        f"{op} {k}: the cell read back misses {tuple(p)}"
        for op, found in cells.items()
        for k, (ring, p) in enumerate(found)
        if not shapely.Polygon(np.asarray(ring)).covers(shapely.Point(p))
    ]
    # drop the warm-up operations of each kind
    timed = [r for op in ("insert", "move", "remove") for r in [x for x in rows if x[0] == op][WARM_UP_OPS:]]
    return timed, failures


def measure_qhull(pts, ops: int, rng) -> tuple[list, list]:
    """Time Delaunay(incremental=True).add_points, one point a call."""
    import numpy as np
    import scipy.spatial

    tri = scipy.spatial.Delaunay(pts, incremental=True)
    total = WARM_UP_OPS + ops
    new = rng.uniform(pts.min(axis=0), pts.max(axis=0), size=(total, 2))
    rows = []
    spent = 0.0
    for k in range(total):
        t0 = time.perf_counter()
        tri.add_points(new[k : k + 1])
        rows.append(("add_points", time.perf_counter() - t0))
        spent += rows[-1][1]
        if spent > QHULL_BUDGET and len(rows) >= WARM_UP_OPS + QHULL_MIN_OPS:
            break  # each call is O(n): enough for a median
    # every added point is a vertex of the triangulation, and no point was dropped
    used = np.zeros(len(tri.points), bool)
    used[tri.simplices.ravel()] = True
    failures = (
        []
        if len(tri.points) == len(pts) + len(rows) and used[len(pts) :].all()
        else ["Qhull: an added point is not a vertex of the triangulation"]
    )
    tri.close()
    return rows[WARM_UP_OPS:], failures


def worker(tool: str, n: int, ops: int) -> dict:
    import numpy as np

    from tvoronoi.api import default_bbox
    from tvoronoi.generators import generate

    pts = generate("uniform", n, seed=SEED)
    rng = np.random.default_rng(SEED + n)
    reset_peak()
    base = rss_mib()
    if tool in DYNAMIC_ENGINES:
        rows, failures = measure_dynamic(pts, default_bbox(pts), ops, rng, DYNAMIC_ENGINES[tool])
    else:
        rows, failures = measure_qhull(pts, ops, rng)
    return {"rows": rows, "failures": failures, "peak_mib": round(max(0.0, maxrss_mib() - base), 2)}


def run_all(sizes: list[int], ops: int, out: Path) -> list[dict]:
    """Measure every tool at every size, one process each; write updates.csv."""
    import statistics

    tools = [*DYNAMIC_ENGINES, "qhull-incremental"]
    print("update cost", flush=True)
    rows, notes = [], []
    for n in sizes:
        for tool in tools:
            cmd = [sys.executable, __file__, "--worker", json.dumps([tool, n, ops])]
            proc = subprocess.run(cmd, capture_output=True, text=True, env=subprocess_env(), check=False)
            if proc.returncode != 0:
                tail = " | ".join(proc.stderr.strip().splitlines()[-3:])
                notes.append(f"{tool} at n={n:,}: failed ({tail})")
                print(f"  {notes[-1]}", file=sys.stderr)
                continue
            res = json.loads(proc.stdout.strip().splitlines()[-1])
            notes.extend(f"{tool} at n={n:,}: {f}" for f in res["failures"])
            by_kind: dict = {}
            for kind, s in res["rows"]:
                by_kind.setdefault(kind, []).append(s)
                rows.append(
                    {
                        "engine": tool,
                        "distribution": "uniform",
                        "n": n,
                        "repeat": len(by_kind[kind]),
                        "seconds": f"{s:.6g}",
                        "peak_mib": res["peak_mib"],
                        "kind": kind,
                    }
                )
            for kind, ts in by_kind.items():
                print(f"  {tool:26s} {kind:10s} n={n:>9,}  median {statistics.median(ts) * 1e3:9.3f} ms", flush=True)
    write_csv(out / "updates.csv", rows)
    status = {"notes": notes}
    from common import atomic_write

    atomic_write(out / "updates.json", json.dumps(status, indent=2) + "\n")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="1k,10k,100k")
    ap.add_argument("--ops", type=int, default=25, help="timed operations of each kind")
    ap.add_argument("--out", type=Path, default=RESULTS)
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        tool, n, ops = json.loads(args.worker)
        print(json.dumps(worker(tool, n, ops)))
        return 0
    args.out.mkdir(parents=True, exist_ok=True)
    run_all(parse_sizes(args.sizes), args.ops, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
