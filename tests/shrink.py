"""Shrink a failing input to a small one that fails the same way, and save it as a fixture.

Usage: python tests/shrink.py FAMILY ENGINE CHECK NAME [--match TEXT] [--timeout S] [--other-ok] [--poison B]

FAMILY is a family of ``adversarial`` (or ``fixture:NAME``); ENGINE ``fortune``/``incremental``; CHECK one of
the worker's checks, or ``agree`` (both engines' cells bit for bit). A subset "fails the same way" when the
check's message starts with the same kind (crash / timeout / other) and contains TEXT if given (and,
with --other-ok, the other engine passes that check: a bug of one engine). Removal is
delta debugging (halves, quarters, ... then single points); the user box is kept. The result is saved as
tests/fixtures/NAME.npy (or .npz with the box).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import adversarial  # noqa: E402
import exact_checks  # noqa: E402
from fixtures_io import load_fixture, save_fixture  # noqa: E402
from hunt_worker import Worker, load_cells  # noqa: E402


def kind(msg: str) -> str:
    return (
        "ok"
        if msg == "ok"
        else "crash"
        if msg.startswith("crash")
        else "timeout"
        if msg.startswith("timeout")
        else "fail"
    )


def outcome(worker: Worker, pts, bbox, engine: str, check: str, timeout: float, poison=None) -> str:
    req = {"points": np.asarray(pts).tolist(), "bbox": bbox, "poison": poison}
    if check != "agree":
        return worker.run(req | {"engine": engine}, timeout=timeout)[check]
    answers = [
        worker.run(req | {"engine": e, "save": worker.cells_path(f"shrink-{e}")}, timeout=timeout)
        for e in ("fortune", "incremental")
    ]
    if not all("saved" in a for a in answers):
        return "crash or error: " + " / ".join(a["build"] for a in answers)
    try:
        exact_checks.check_same_cells(*(load_cells(a["saved"]) for a in answers))
        return "ok"
    except AssertionError as exc:
        return str(exc)


def ddmin(pts: np.ndarray, fails, min_points: int = 1) -> np.ndarray:
    """Zeller's delta debugging: a 1-minimal subset (order kept) on which fails() still holds."""
    n_chunks = 2
    while len(pts) > min_points:
        chunks = np.array_split(np.arange(len(pts)), min(n_chunks, len(pts)))
        for c in chunks:
            rest = np.delete(pts, c, axis=0)
            if len(rest) >= min_points and fails(rest):
                pts = rest
                n_chunks = max(n_chunks - 1, 2)
                break
        else:
            if n_chunks >= len(pts):
                break
            n_chunks = min(2 * n_chunks, len(pts))
        print(f"  {len(pts)} points", flush=True)
    return pts


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("family")
    ap.add_argument("engine")
    ap.add_argument("check")
    ap.add_argument("name")
    ap.add_argument("--match", default="")
    ap.add_argument("--timeout", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=adversarial.SEED)
    ap.add_argument("--other-ok", action="store_true", help="the other engine must pass the same check")
    ap.add_argument("--poison", type=int, help="fill np.empty's arrays with this byte (deterministic garbage)")
    args = ap.parse_args(argv)

    case = (
        load_fixture(args.family[8:])
        if args.family.startswith("fixture:")
        else adversarial.make(args.family, args.seed)
    )
    worker = Worker()
    try:
        first = outcome(worker, case.points, case.bbox, args.engine, args.check, args.timeout, args.poison)
        print(f"{len(case.points)} points: {first}")
        want = kind(first)
        if want == "ok":
            print("it does not fail")
            return 1

        other = "incremental" if args.engine == "fortune" else "fortune"

        def fails(pts):
            got = outcome(worker, pts, case.bbox, args.engine, args.check, args.timeout, args.poison)
            if kind(got) != want or args.match not in got:
                return False
            return (
                not args.other_ok
                or outcome(worker, pts, case.bbox, other, args.check, args.timeout, args.poison) == "ok"
            )

        small = ddmin(case.points, fails)
        last = outcome(worker, small, case.bbox, args.engine, args.check, args.timeout, args.poison)
        print(f"{len(small)} points: {last}")
        print(repr(small.tolist()))
        print("saved", save_fixture(args.name, small, case.bbox))
    finally:
        worker.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
