"""Terminal UI speed: how long each key takes to show its frame, and how long a large diagram takes to
appear, driving the app headless (Textual's run_test and pilot).

A key's time runs from the press until the canvas's frame is drawn (the press, the app's handling,
the canvas drawing every line); each key is pressed ``--repeats`` times after one untimed press, and
the median is reported. Two clocks: the CPU time of the process (the work a key costs, what a
terminal user waits for on an idle machine) and the wall time, which adds the pilot's waits for
the app to go idle (about one screen refresh) and, on a busy machine, the other processes' share.
The start time runs from creating the app with the points until the first frame of their diagram
is drawn (the build, in a worker for large inputs, included); next to it, the CPU time of all the
process's threads meanwhile (the work: other processes inflate it far less than the wall
time).

    python benchmarks/tui.py --sites 100k --size 120x40
    python benchmarks/tui.py --sites 100k --start 1M          # also time 1,000,000 sites shown
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import RESULTS, parse_sizes  # noqa: E402
from tvoronoi.generators import generate  # noqa: E402
from tvoronoi.tui.app import VoronoiApp  # noqa: E402

SEED = 1
# The keys timed, in order: (label, keys pressed before the timed one, the timed key).
KEYS = (
    ("pan", (), "right"),
    ("zoom in", (), "plus"),
    ("zoom out", (), "minus"),
    ("Delaunay on", (), "d"),  # with "off": timed in turns
    ("fit", ("plus",), "0"),
)
EDITS = 13


async def _drawn(app, pilot) -> None:
    """Wait until the app has handled everything and the canvas's frame is drawn."""
    await pilot.pause()
    canvas = app.canvas
    canvas._draw(canvas.content_size)  # a no-op when the pause drew it already


class Clocks:
    """CPU and wall time of a stretch of code, in ms."""

    def __init__(self) -> None:
        self.cpu, self.wall = time.process_time(), time.perf_counter()

    def ms(self) -> tuple[float, float]:
        return (time.process_time() - self.cpu) * 1000, (time.perf_counter() - self.wall) * 1000


def median(times: list[tuple[float, float]]) -> dict:
    return {"cpu_ms": statistics.median(t[0] for t in times), "wall_ms": statistics.median(t[1] for t in times)}


async def _time_key(app, pilot, before, key, repeats: int) -> dict:
    times = []
    for k in range(repeats + 1):
        for b in before:
            await pilot.press(b)
            await _drawn(app, pilot)
        clocks = Clocks()
        await pilot.press(key)
        await _drawn(app, pilot)
        if k:  # the first press warms up
            times.append(clocks.ms())
    return median(times)


async def keys(n: int, cols: int, rows: int, repeats: int) -> dict:
    points = generate("uniform", n, seed=SEED)
    app = VoronoiApp(points=points)
    results: dict[str, dict] = {}
    async with app.run_test(size=(cols, rows)) as pilot:
        while app.built is None:
            await pilot.pause(0.05)
        await app.workers.wait_for_complete()
        await _drawn(app, pilot)
        for label, before, key in KEYS:
            if label == "Delaunay on":
                # each timed press toggles: time on and off separately
                on: list[tuple[float, float]] = []
                off: list[tuple[float, float]] = []
                for k in range(repeats + 1):
                    for bucket in (on, off):
                        clocks = Clocks()
                        await pilot.press("d")
                        await _drawn(app, pilot)
                        if k:
                            bucket.append(clocks.ms())
                results["Delaunay on"] = median(on)
                results["Delaunay off"] = median(off)
                continue
            results[label] = await _time_key(app, pilot, before, key, repeats)
        # edits with the keyboard cursor: add sites, then time the keys again
        await pilot.press("0", "c")
        await _drawn(app, pilot)
        edit_ms = []
        for _ in range(EDITS):
            await pilot.press("shift+right")
            await _drawn(app, pilot)
            clocks = Clocks()
            await pilot.press("a")
            await _drawn(app, pilot)
            edit_ms.append(clocks.ms())
        assert app.live is not None and app.live.n_sites == n + EDITS, "the edits did not land"
        results["add a site (edit)"] = median(edit_ms[1:])  # the first builds the dynamic diagram
        results[f"pan after {EDITS} edits"] = await _time_key(app, pilot, (), "right", repeats)
        results[f"zoom after {EDITS} edits"] = await _time_key(app, pilot, (), "plus", repeats)
        results[f"Delaunay on/off after {EDITS} edits"] = await _time_key(app, pilot, (), "d", repeats)
    return results


async def start(n: int, cols: int, rows: int) -> tuple[float, float]:
    """The wall time until the first frame of ``n`` sites is drawn, and the CPU time of the process
    (every thread) meanwhile, in ms."""
    points = generate("uniform", n, seed=SEED)
    clocks = Clocks()
    app = VoronoiApp(points=points)
    async with app.run_test(size=(cols, rows)) as pilot:
        while app.built is None or app.canvas.scene is not app.built.scene:
            await pilot.pause(0.01)
        await _drawn(app, pilot)
        cpu, wall = clocks.ms()
        return wall, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sites", default="100k", help="sites for the key timings (k, M suffixes)")
    parser.add_argument("--size", default="120x40", help="terminal size, COLSxROWS")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--start", default="", help="also time this many sites shown from start (e.g. 1M)")
    parser.add_argument("--start-only", action="store_true", help="time only the start (--start), no keys")
    parser.add_argument("--out", type=Path, default=RESULTS / "tui.json")
    args = parser.parse_args()
    if args.start_only and not args.start:
        parser.error("--start-only needs --start")
    cols, rows = (int(v) for v in args.size.lower().split("x"))
    (n,) = parse_sizes(args.sites)
    report = {
        "sites": n,
        "terminal": f"{cols}x{rows}",
        "repeats": args.repeats,
        "load_average": os.getloadavg()[0],
        "keys_ms": {} if args.start_only else asyncio.run(keys(n, cols, rows, args.repeats)),
    }
    if args.start:
        (big,) = parse_sizes(args.start)
        wall, cpu = asyncio.run(start(big, cols, rows))
        report["start_ms"] = {str(big): wall}
        report["start_cpu_ms"] = {str(big): cpu}
    print(f"{'key':<32} {'CPU ms':>8} {'wall ms':>8}")
    for label, ms in report["keys_ms"].items():
        print(f"{label:<32} {ms['cpu_ms']:8.1f} {ms['wall_ms']:8.1f}")
    for big, ms in report.get("start_ms", {}).items():
        print(
            f"{int(big):,} sites shown in {ms / 1000:.2f} s ({report['start_cpu_ms'][big] / 1000:.2f} s CPU, "
            f"all threads)"
        )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n")


if __name__ == "__main__":
    main()
