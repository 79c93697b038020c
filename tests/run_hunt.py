"""Run every adversarial family (and every fixture) with both engines in a child process; print a table.

Usage: python tests/run_hunt.py [--timeout S] [--kernels DIR] [--only SUBSTRING] [--json FILE] [--fixtures]
                                [--checked]

Each row is family x engine; each column a check: ``ok``, ``FAIL: <first message>``, ``CRASH``, ``TIMEOUT``.
The ``agree`` column compares the two engines' cells bit for bit; ``uninit`` rebuilds with np.empty's arrays
filled with a few bytes and wants the same output (``hunt_worker.uninit_result``); ``checked`` (with
--checked) is the build alone on the bounds-checked ASan kernels (``checked_build``).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import adversarial  # noqa: E402
import exact_checks  # noqa: E402
from checked_build import build_only, checked_worker  # noqa: E402
from fixtures_io import FIXTURES, load_fixture  # noqa: E402
from hunt_worker import CHECK_NAMES, Worker, load_cells, uninit_result  # noqa: E402

ENGINES = ("fortune", "incremental")


def short(result: str, width: int = 90) -> str:
    if result == "ok":
        return "ok"
    tag = "CRASH" if result.startswith("crash") else "TIMEOUT" if result.startswith("timeout") else "FAIL"
    text = f"{tag}: {result}"
    return text if len(text) <= width else text[: width - 3] + "..."


def agree(worker: Worker, answers: dict) -> str:
    try:
        cells = [load_cells(answers[e]["saved"]) for e in ENGINES]
    except KeyError:
        return "not run (an engine gave no diagram)"
    try:
        exact_checks.check_same_cells(*cells, names=ENGINES)
        return "ok"
    except AssertionError as exc:
        return str(exc)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--kernels")
    ap.add_argument("--only", default="")
    ap.add_argument("--json")
    ap.add_argument("--fixtures", action="store_true", help="run the fixtures instead of the families")
    ap.add_argument("--checked", action="store_true", help="add a column: the build on build/checked (ASan)")
    args = ap.parse_args(argv)

    worker = Worker(kernels=args.kernels)
    checked = contextlib.ExitStack()
    cw = checked.enter_context(checked_worker()) if args.checked else None
    cols = (*CHECK_NAMES, "agree", "uninit") + (("checked",) if cw else ())
    rows = []
    print("| family | engine | " + " | ".join(cols) + " | s |")
    print("|---" * (len(cols) + 3) + "|")
    names = sorted(FIXTURES) if args.fixtures else list(adversarial.FAMILIES)
    try:
        for name in names:
            if args.only not in name:
                continue
            answers = {}
            for engine in ENGINES:
                key = f"{name}-{engine}"
                if args.fixtures:
                    case = load_fixture(name)
                    req = {"points": case.points.tolist(), "bbox": case.bbox}
                else:
                    req = {"family": name}
                req |= {"engine": engine, "save": worker.cells_path(key)}
                answers[engine] = worker.run(req, timeout=args.timeout)
            a = agree(worker, answers)
            for engine in ENGINES:
                base = {k: v for k, v in req.items() if k not in ("engine", "save")} | {"engine": engine}
                u = uninit_result(worker, base, answers[engine], timeout=min(args.timeout, 20.0))
                row = {
                    "family": name,
                    "engine": engine,
                    **{c: answers[engine][c] for c in CHECK_NAMES},
                    "agree": a,
                    "uninit": u,
                    "seconds": answers[engine]["seconds"],
                }
                if cw:
                    row["checked"] = build_only(cw, base)
                rows.append(row)
                text = " | ".join(short(row[c]) for c in cols)
                print(f"| {name} | {engine} | {text} | {row['seconds']} |", flush=True)
    finally:
        worker.close()
        checked.close()
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
