"""Where one build's time goes, kernel by kernel: every compiled kernel called by `tvoronoi.voronoi()`,
timed around each call, and on more than one thread a timeline of the calls on each thread.

For profiling, not for the record (phases.py is the benchmark): the figures of one build on this
machine swing by 20-30% from run to run, so compare a change with several builds of each, or with
whole processes. The last of --repeats builds is reported (the first ones warm the process up).

    python benchmarks/kernel_times.py --n 1M --engine incremental --threads 2 --repeats 3 --timeline
"""

from __future__ import annotations

import argparse
import collections
import importlib
import pkgutil
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from benchmarks.common import parse_sizes  # noqa: E402
from benchmarks.phases import DISTS, points  # noqa: E402


def instrument(calls: list) -> None:
    """Wrap every public function of every kernel module so that each call appends (start, end, thread
    ident, name) to calls. The wrappers replace the module attributes: code calling a kernel through
    its module (every Python layer of tvoronoi does) goes through them."""
    import tvoronoi.kernels as kernels

    for info in pkgutil.iter_modules(kernels.__path__):
        module = importlib.import_module(f"tvoronoi.kernels.{info.name}")
        for name in dir(module):
            fn = getattr(module, name)
            if name.startswith("_") or type(fn).__name__ not in (
                "builtin_function_or_method",
                "cython_function_or_method",
            ):
                continue

            def timed(*args, _fn=fn, _name=f"{info.name}.{name}", **kwargs):
                start = time.perf_counter()
                try:
                    return _fn(*args, **kwargs)
                finally:
                    calls.append((start, time.perf_counter(), threading.get_ident(), _name))

            setattr(module, name, timed)


def profile(pts, *, engine: str, threads: int, repeats: int) -> tuple[float, float, list]:
    """(start, end, calls) of the last of `repeats` builds of pts."""
    import tvoronoi

    calls: list = []
    instrument(calls)
    for _ in range(repeats):
        calls.clear()
        start = time.perf_counter()
        d = tvoronoi.voronoi(pts, engine=engine, threads=threads)
        end = time.perf_counter()
        del d
    return start, end, list(calls)


def totals(calls: list) -> list[tuple[str, float, int]]:
    """(kernel, total ms, calls), the largest first (calls on several threads add up)."""
    ms: dict[str, float] = collections.defaultdict(float)
    count: dict[str, int] = collections.Counter()
    for s, e, _, name in calls:
        ms[name] += (e - s) * 1e3
        count[name] += 1
    return sorted(((k, ms[k], count[k]) for k in ms), key=lambda row: -row[1])


def report(start: float, end: float, calls: list, *, timeline: bool, least_ms: float = 0.5) -> str:
    """The table of every kernel called (ms, calls) and, with timeline, the calls of least_ms or more in
    time order, a column per thread."""
    lines = [f"build: {(end - start) * 1e3:.1f} ms", "", "| kernel | ms | calls |", "|---|---:|---:|"]
    lines += [f"| {name} | {ms:.1f} | {n} |" for name, ms, n in totals(calls)]
    if timeline:
        lines += ["", "timeline (ms from the build's start; one column per thread):"]
        column: dict[int, int] = {}
        for s, e, ident, name in sorted(calls):
            if (e - s) * 1e3 < least_ms:
                continue
            k = column.setdefault(ident, len(column))
            lines.append(f"{' ' * 44 * k}{(s - start) * 1e3:6.0f}-{(e - start) * 1e3:5.0f} {name}")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", default="1M", help="sites (k and M allowed)")
    ap.add_argument("--dist", default="uniform", choices=DISTS)
    ap.add_argument("--engine", default="incremental", choices=("incremental", "fortune"))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeats", type=int, default=3, help="builds in this process; the last is reported")
    ap.add_argument("--timeline", action="store_true", help="also list the calls in time order, by thread")
    args = ap.parse_args(argv)
    (n,) = parse_sizes(args.n)
    start, end, calls = profile(points(args.dist, n), engine=args.engine, threads=args.threads, repeats=args.repeats)
    print(report(start, end, calls, timeline=args.timeline))


if __name__ == "__main__":
    main()
