"""Terminal UI speed: how long each key takes to show its frame, and how long a large diagram takes to
appear, driving the app headless (Textual's run_test and pilot).

A key's time runs from the press until the canvas's frame is drawn (the press, the app's handling,
the canvas drawing every line); each key is pressed ``--repeats`` times after one untimed press, and
the median is reported. The start time runs from creating the app with the points until the first
frame of their diagram is drawn (the build, in a worker for large inputs, included).

    python benchmarks/tui.py --sites 100k --size 120x40
    python benchmarks/tui.py --sites 100k --start 1M          # also time 1,000,000 sites shown
"""

from __future__ import annotations

import argparse
import asyncio
import json
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


async def _time_key(app, pilot, before, key, repeats: int) -> list[float]:
    times = []
    for k in range(repeats + 1):
        for b in before:
            await pilot.press(b)
            await _drawn(app, pilot)
        start = time.perf_counter()
        await pilot.press(key)
        await _drawn(app, pilot)
        if k:  # the first press warms up
            times.append((time.perf_counter() - start) * 1000)
    return times


async def keys(n: int, cols: int, rows: int, repeats: int) -> dict:
    points = generate("uniform", n, seed=SEED)
    app = VoronoiApp(points=points)
    results: dict[str, float] = {}
    async with app.run_test(size=(cols, rows)) as pilot:
        while app.built is None:
            await pilot.pause(0.05)
        await app.workers.wait_for_complete()
        await _drawn(app, pilot)
        for label, before, key in KEYS:
            if label == "Delaunay on":
                # each timed press toggles: time on and off separately
                on, off = [], []
                for k in range(repeats + 1):
                    for bucket in (on, off):
                        start = time.perf_counter()
                        await pilot.press("d")
                        await _drawn(app, pilot)
                        if k:
                            bucket.append((time.perf_counter() - start) * 1000)
                results["Delaunay on"] = statistics.median(on)
                results["Delaunay off"] = statistics.median(off)
                continue
            results[label] = statistics.median(await _time_key(app, pilot, before, key, repeats))
        # edits with the keyboard cursor: add sites, then time the keys again
        await pilot.press("0", "c")
        await _drawn(app, pilot)
        edit_ms = []
        for _ in range(EDITS):
            await pilot.press("shift+right")
            await _drawn(app, pilot)
            start = time.perf_counter()
            await pilot.press("a")
            await _drawn(app, pilot)
            edit_ms.append((time.perf_counter() - start) * 1000)
        assert app.live is not None and app.live.n_sites == n + EDITS, "the edits did not land"
        results["add a site (edit)"] = statistics.median(edit_ms)
        results[f"pan after {EDITS} edits"] = statistics.median(await _time_key(app, pilot, (), "right", repeats))
        results[f"zoom after {EDITS} edits"] = statistics.median(await _time_key(app, pilot, (), "plus", repeats))
        results[f"Delaunay on/off after {EDITS} edits"] = statistics.median(await _time_key(app, pilot, (), "d", repeats))
    return results


async def start(n: int, cols: int, rows: int) -> float:
    points = generate("uniform", n, seed=SEED)
    begin = time.perf_counter()
    app = VoronoiApp(points=points)
    async with app.run_test(size=(cols, rows)) as pilot:
        while app.built is None or app.canvas.scene is not app.built.scene:
            await pilot.pause(0.01)
        await _drawn(app, pilot)
        return (time.perf_counter() - begin) * 1000


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sites", default="100k", help="sites for the key timings (k, M suffixes)")
    parser.add_argument("--size", default="120x40", help="terminal size, COLSxROWS")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--start", default="", help="also time this many sites shown from start (e.g. 1M)")
    parser.add_argument("--out", type=Path, default=RESULTS / "tui.json")
    args = parser.parse_args()
    cols, rows = (int(v) for v in args.size.lower().split("x"))
    (n,) = parse_sizes(args.sites)
    report = {"sites": n, "terminal": f"{cols}x{rows}", "repeats": args.repeats,
              "keys_ms": asyncio.run(keys(n, cols, rows, args.repeats))}
    if args.start:
        (big,) = parse_sizes(args.start)
        report["start_ms"] = {str(big): asyncio.run(start(big, cols, rows))}
    for label, ms in report["keys_ms"].items():
        print(f"{label:<24} {ms:8.1f} ms")
    for big, ms in report.get("start_ms", {}).items():
        print(f"{int(big):,} sites shown in {ms / 1000:.2f} s")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=2) + "\n")


if __name__ == "__main__":
    main()
