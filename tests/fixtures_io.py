"""Regression inputs in tests/fixtures/: one file per bug, named for it.

``NAME.npy`` holds the points (n, 2) float64, run with the default box; ``NAME.npz`` holds ``points`` and
``bbox`` (4,) for a user box. ``load_fixture(NAME)`` gives an ``adversarial.Case``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from adversarial import Case

FIXTURE_DIR = Path(__file__).resolve().parent / "fixtures"


def _names() -> dict[str, Path]:
    return {p.stem: p for p in sorted(FIXTURE_DIR.glob("*.np[yz]"))}


FIXTURES = _names()


def load_fixture(name: str) -> Case:
    """The points (and box) of a fixture."""
    path = FIXTURES[name]
    if path.suffix == ".npy":
        return Case(np.ascontiguousarray(np.load(path), np.float64).reshape(-1, 2), note=name)
    with np.load(path) as z:
        bbox = tuple(float(v) for v in z["bbox"]) if "bbox" in z else None
        return Case(np.ascontiguousarray(z["points"], np.float64).reshape(-1, 2), bbox=bbox, note=name)


def save_fixture(name: str, points, bbox=None) -> Path:
    """Write a fixture: .npy without a box, .npz with one."""
    FIXTURE_DIR.mkdir(exist_ok=True)
    pts = np.ascontiguousarray(points, np.float64).reshape(-1, 2)
    if bbox is None:
        path = FIXTURE_DIR / f"{name}.npy"
        np.save(path, pts)
    else:
        path = FIXTURE_DIR / f"{name}.npz"
        np.savez(path, points=pts, bbox=np.asarray(bbox, np.float64))
    return path
