"""Shared test data: a seeded rng and named point sets, degenerate ones included."""

import os

import numpy as np
import pytest
from hypothesis import settings

# CI replays the same examples every run (a red CI then always means a change broke something);
# a developer's runs keep exploring new ones.
settings.register_profile("ci", derandomize=True, deadline=None)
if os.environ.get("CI"):
    settings.load_profile("ci")

from tvoronoi.generators import clustered, gaussian, uniform  # noqa: E402

SEED = 20261122


def _lattice_circle():
    """The 20 integer points on x^2 + y^2 = 625, exactly cocircular, and the centre."""
    r = 25
    pts = {(x, y) for x in range(-r, r + 1) for y in range(-r, r + 1) if x * x + y * y == r * r}
    return np.array(sorted(pts) + [(0, 0)], float)


def _datasets():
    rng = np.random.default_rng(SEED)
    grid = np.array([(i, j) for i in range(12) for j in range(9)], float)
    base = uniform(150, seed=SEED)
    repeats = np.concatenate([base[:60], base[rng.integers(0, 60, 40)], base[5:6]])
    line = np.array([(i, 2 * i + 1) for i in range(40)], float)[rng.permutation(40)]
    data = {
        "uniform": uniform(200, seed=SEED),
        "gaussian": gaussian(200, seed=SEED + 1),
        "clustered": clustered(200, seed=SEED + 2),
        "grid": grid,
        "grid_jittered": grid + rng.normal(0, 1e-12, grid.shape),
        "circle": _lattice_circle(),
        "collinear": line,
        "collinear_repeats": np.concatenate([line[:10], line[:4]]),
        "vertical": np.array([(3.0, float(y)) for y in rng.permutation(25)]),
        "duplicates": repeats,
        "all_same": np.full((7, 2), 2.5),
        "one": np.array([[0.3, 0.7]]),
        "two": np.array([[0.0, 0.0], [1.0, 2.0]]),
        "three_collinear": np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]),
        "on_bisector": np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 3.0], [1.0, -3.0], [1.0, 0.0]]),
        "hull_collinear": np.array([(i, 0) for i in range(10)] + [(i, 5) for i in range(10)] + [(4.5, 2.5)], float),
        "tiny": uniform(120, seed=SEED + 3) * 1e-9,
        "huge": 1e9 + uniform(120, seed=SEED + 4) * 100.0,
        "huge_grid": 1e9 + np.array([(i, j) for i in range(6) for j in range(6)], float) * 0.5,
    }
    return data


DATASETS = _datasets()
GENERAL_POSITION = ("uniform", "gaussian", "clustered", "tiny", "huge")


@pytest.fixture
def rng():
    return np.random.default_rng(SEED)


@pytest.fixture(params=sorted(DATASETS))
def dataset(request):
    return request.param, DATASETS[request.param]
