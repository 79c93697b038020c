"""Build benchmarks: every tool on every (distribution, n), each in its own process, timings interleaved.

Usage:
    python benchmarks/run.py            # the full suite (up to 1,000,000 points) -> benchmarks/results/
    python benchmarks/run.py --quick    # up to 100,000 points, uniform + clustered -> benchmarks/results/quick/
    python benchmarks/run.py --sizes 100,1k,10k --dists uniform --tools tvoronoi-fortune,qhull-voronoi

For each case (distribution, n) one worker process per tool starts (two at
a time up to 200,000 points, else one by one): it imports its tool, builds a
tiny input (loading every code path), generates the case's points, then
builds the real input once per kind -- the warm-up, which also gives the peak
memory (the peak resident set of that build alone less the resident set
before it) -- and checks that output. Only then does
the parent time it: rounds of one build per (tool, kind), the order rotated
each round, so that any drift of the machine hits every tool alike. Imports,
warm-ups and checks are never timed. A tool whose output fails its check is
not timed at all; checks.csv says why.

Outputs (each written to a temporary file, then renamed): build.csv (one row
per timed build), checks.csv, machine.json, updates.csv, the step figures,
the plots and build.md (see report.py).
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import (  # noqa: E402
    CHECK_COLUMNS,
    RESULTS,
    atomic_write,
    machine,
    maxrss_mib,
    parse_sizes,
    release_free_memory,
    reset_peak,
    rss_mib,
    send,
    subprocess_env,
    write_csv,
)
from tools import TOOLS, CheckFailed  # noqa: E402

FULL = {
    "sizes": [100, 1_000, 10_000, 100_000, 1_000_000],
    "dists": ["uniform", "gaussian", "clustered"],
    "update_sizes": [1_000, 10_000, 100_000, 1_000_000],
    "update_ops": 25,
    "out": RESULTS,
}
QUICK = {
    "sizes": [100, 1_000, 10_000, 100_000],
    "dists": ["uniform", "clustered"],
    "update_sizes": [1_000, 10_000, 100_000],
    "update_ops": 15,
    "out": RESULTS / "quick",
}
# One seed per distribution: every tool sees the same points.
SEEDS = {"uniform": 1, "gaussian": 2, "clustered": 3}
# Sites of the tiny input that loads each tool's code paths before anything is measured.
TINY_N = 50
# Above this n workers warm up one at a time (their memory would add up).
SERIAL_ABOVE = 200_000
# Whether the workers could reset the peak resident set before each build (see serve).
PEAK_RESET: set = set()


def repeats_for(n: int, quick: bool) -> int:
    """Timed builds per (tool, kind): many for small n, where one build is noisy; at least 3."""
    table = ((100, 25, 9), (1_000, 9, 5), (10_000, 5, 3))
    for limit, full, fast in table:
        if n <= limit:
            return fast if quick else full
    return 3


# --- the worker (one tool, one distribution, one n) --------------------------------------------


def serve(tool_name: str, dist: str, n: int, seed: int) -> None:
    """Warm up, measure and check each kind, report, then time builds on request."""
    out = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)  # anything a library prints goes to stderr, not into the protocol
    import numpy as np
    import scipy.spatial

    from tvoronoi.api import default_bbox
    from tvoronoi.generators import generate

    tool = TOOLS[tool_name]
    tiny = generate(dist, TINY_N, seed=seed + 1000)
    for kind in tool.kinds():
        tool.run(kind, tiny, default_bbox(tiny))
    pts = generate(dist, n, seed=seed)
    box = default_bbox(pts)
    tree = scipy.spatial.cKDTree(pts)
    ready = {}
    for kind in tool.kinds():
        release_free_memory()
        # the peak of this build alone where the kernel can reset it, else the peak since start-up
        fresh = reset_peak()
        base = rss_mib()
        result = tool.run(kind, pts, box)
        peak = max(0.0, maxrss_mib() - base)
        try:
            tool.check(kind, result, pts, box, tree)
            status = "ok"
        except CheckFailed as exc:
            status = f"failed: {exc}"
        del result
        gc.collect()
        ready[kind] = {"peak_mib": round(peak, 2), "check": status, "fresh_peak": fresh}
    send(out, {"ready": ready, "points": int(np.asarray(pts).shape[0])})
    for line in sys.stdin:
        kind = json.loads(line)["time"]
        gc.collect()
        t0 = time.perf_counter()
        result = tool.run(kind, pts, box)
        seconds = time.perf_counter() - t0
        del result
        send(out, {"seconds": seconds})


class Worker:
    """A worker process seen from the parent."""

    def __init__(self, tool: str, dist: str, n: int, seed: int):
        self.tool, self.dist, self.n = tool, dist, n
        self.err = tempfile.TemporaryFile(mode="w+")
        cmd = [sys.executable, __file__, "--worker", json.dumps([tool, dist, n, seed])]
        self.proc = subprocess.Popen(
            cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.err, text=True, env=subprocess_env()
        )
        self.error = None
        self.ready = {}

    def wait_ready(self) -> None:
        """Wait for the warm-up builds and checks."""
        msg = self._read()
        self.ready = msg["ready"] if msg else {}

    def _read(self):
        line = self.proc.stdout.readline()
        if line:
            return json.loads(line)
        self.proc.wait()
        self.err.seek(0)
        tail = self.err.read().strip().splitlines()[-3:]
        self.error = f"worker exited with status {self.proc.returncode}: {' | '.join(tail)}"
        return None

    def time(self, kind: str) -> float | None:
        if self.error:
            return None
        try:
            send(self.proc.stdin, {"time": kind})
        except BrokenPipeError:
            self._read()
            return None
        msg = self._read()
        return msg["seconds"] if msg else None

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait()
        self.err.close()


# --- the parent ------------------------------------------------------------------------------


def started(dist: str, n: int, names: list[str], jobs: int):
    """Start the workers of a case, ``jobs`` at a time, and yield each once it is ready.

    Nothing is timed while workers start: their warm-ups and checks may overlap.
    """
    for k in range(0, len(names), jobs):
        batch = [Worker(name, dist, n, SEEDS.get(dist, 0)) for name in names[k : k + jobs]]
        for w in batch:
            w.wait_ready()
            yield w


def run_case(dist: str, n: int, tools: list[str], repeats: int, rows: list, checks: list, jobs: int) -> None:
    """Time every tool on one case, interleaved; append to rows and checks."""
    names = []
    for name in tools:
        tool = TOOLS[name]
        if tool.max_n is not None and n > tool.max_n:
            checks.extend(
                {
                    "engine": name,
                    "distribution": dist,
                    "n": n,
                    "kind": k,
                    "status": "skipped",
                    "detail": f"not run above n = {tool.max_n:,}",
                }
                for k in tool.kinds()
            )
        else:
            names.append(name)
    workers = []
    for w in started(dist, n, names, jobs):
        name = w.tool
        tool = TOOLS[name]
        if w.error:
            checks.extend(
                {"engine": name, "distribution": dist, "n": n, "kind": k, "status": "error", "detail": w.error}
                for k in tool.kinds()
            )
            print(f"  {name}: {w.error}", file=sys.stderr)
            w.close()
            continue
        for kind, r in w.ready.items():
            PEAK_RESET.add(r.get("fresh_peak", False))
            ok = r["check"] == "ok"
            checks.append(
                {
                    "engine": name,
                    "distribution": dist,
                    "n": n,
                    "kind": kind,
                    "status": "ok" if ok else "failed",
                    "detail": "" if ok else r["check"],
                }
            )
            if not ok:
                print(f"  {name} {kind}: {r['check']}", file=sys.stderr)
        workers.append(w)
    pairs = [(w, kind) for w in workers for kind, r in w.ready.items() if r["check"] == "ok"]
    times: dict = {(w.tool, kind): [] for w, kind in pairs}
    for r in range(repeats):
        shift = r % max(1, len(pairs))
        for w, kind in pairs[shift:] + pairs[:shift]:
            s = w.time(kind)
            if s is None:
                continue
            times[(w.tool, kind)].append(s)
            rows.append(
                {
                    "engine": w.tool,
                    "distribution": dist,
                    "n": n,
                    "repeat": len(times[(w.tool, kind)]),
                    "seconds": f"{s:.6g}",
                    "peak_mib": w.ready[kind]["peak_mib"],
                    "kind": kind,
                }
            )
    for w in workers:
        if w.error:
            checks.append(
                {"engine": w.tool, "distribution": dist, "n": n, "kind": "timing", "status": "error", "detail": w.error}
            )
            print(f"  {w.tool}: {w.error}", file=sys.stderr)
        w.close()
    peaks = {(w.tool, kind): r["peak_mib"] for w in workers for kind, r in w.ready.items()}
    for (tool, kind), ts in times.items():
        if ts:
            print(
                f"  {tool:22s} {kind:8s} median {statistics.median(ts):9.4f} s  "
                f"[{min(ts):.4f} .. {max(ts):.4f}] x{len(ts)}  peak {peaks[(tool, kind)]:8.1f} MiB",
                flush=True,
            )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument(
        "--quick",
        action="store_true",
        help="sizes up to 100k, uniform and clustered, fewer repeats; results in results/quick/",
    )
    ap.add_argument("--sizes", help="comma-separated sizes, e.g. 100,1k,10k")
    ap.add_argument("--dists", help="comma-separated distributions: uniform,gaussian,clustered")
    ap.add_argument("--tools", default=",".join(TOOLS), help="comma-separated tools (default: all)")
    ap.add_argument("--repeats", type=int, help="timed builds per case (default: by n)")
    ap.add_argument("--update-sizes", help="sizes of the update-cost runs ('' to skip them)")
    ap.add_argument("--out", type=Path, help="results directory")
    ap.add_argument("--no-figures", action="store_true", help="skip the step-by-step figures")
    ap.add_argument(
        "--jobs",
        type=int,
        default=2,
        help=f"workers warming up at once (never while timing; 1 above n = {SERIAL_ABOVE:,})",
    )
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        tool, dist, n, seed = json.loads(args.worker)
        serve(tool, dist, n, seed)
        return 0

    plan = QUICK if args.quick else FULL
    sizes = parse_sizes(args.sizes) if args.sizes else plan["sizes"]
    dists = args.dists.split(",") if args.dists else plan["dists"]
    tools = [t for t in args.tools.split(",") if t]
    unknown = [t for t in tools if t not in TOOLS]
    if unknown:
        ap.error(f"unknown tool {unknown[0]!r}; choose from {', '.join(TOOLS)}")
    out = args.out or plan["out"]
    out.mkdir(parents=True, exist_ok=True)

    info = machine()
    info["plan"] = {"sizes": sizes, "distributions": dists, "tools": tools, "quick": args.quick}
    checks = []
    for name in list(tools):
        why = TOOLS[name].missing()
        if why:
            print(f"# {name} left out: {why}")
            checks.append(
                {"engine": name, "distribution": "*", "n": "*", "kind": "*", "status": "unavailable", "detail": why}
            )
            tools.remove(name)
    atomic_write(out / "machine.json", json.dumps(info, indent=2) + "\n")
    print(f"# {info['cpu']}, {info['cores']} cores, Python {info['python']}; results in {out}", flush=True)

    rows: list = []
    t_start = time.perf_counter()
    for n in sizes:  # small cases first: a long run leaves usable results early
        for dist in dists:
            print(f"{dist} n={n:,}", flush=True)
            jobs = args.jobs if n <= SERIAL_ABOVE else 1
            run_case(dist, n, tools, args.repeats or repeats_for(n, args.quick), rows, checks, jobs)
            write_csv(out / "build.csv", rows)
            write_csv(out / "checks.csv", checks, CHECK_COLUMNS)
    print(f"# builds: {time.perf_counter() - t_start:.0f} s", flush=True)
    info["peak_memory"] = (
        "peak resident set of each warm-up build alone (reset through /proc/self/clear_refs), less the "
        "resident set before it"
        if PEAK_RESET == {True}
        else "process high-water mark less the resident set before the build (the peak could not be reset: "
        "small builds read as the import-time peak)"
    )
    atomic_write(out / "machine.json", json.dumps(info, indent=2) + "\n")

    update_sizes = (
        plan["update_sizes"]
        if args.update_sizes is None
        else (parse_sizes(args.update_sizes) if args.update_sizes.strip() else [])
    )
    if update_sizes:
        import updates

        updates.run_all(update_sizes, plan["update_ops"], out)
    if not args.no_figures:
        import figures

        figures.make_figures(out)
    import report

    report.write_report(out)
    print(f"# done in {time.perf_counter() - t_start:.0f} s: {out / 'build.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
