"""Point generators: shapes, seeds, the statistics of each distribution, and bad parameters."""

from __future__ import annotations

import doctest

import numpy as np
import pytest

from tvoronoi import generators
from tvoronoi.errors import TvoronoiError
from tvoronoi.generators import DISTRIBUTIONS, clustered, gaussian, generate, uniform


def mean_nearest_neighbour_distance(points: np.ndarray) -> float:
    """Brute force, in blocks: fine for a few thousand points."""
    nearest = np.empty(len(points))
    for start in range(0, len(points), 500):
        block = points[start : start + 500]
        d2 = ((block[:, None, :] - points[None, :, :]) ** 2).sum(axis=2)
        d2[np.arange(len(block)), np.arange(start, start + len(block))] = np.inf
        nearest[start : start + len(block)] = np.sqrt(d2.min(axis=1))
    return float(nearest.mean())


@pytest.mark.parametrize("name", sorted(DISTRIBUTIONS))
@pytest.mark.parametrize("n", [0, 1, 2, 1000])
def test_shape_dtype_and_layout(name, n):
    points = generate(name, n, seed=3)
    assert points.shape == (n, 2)
    assert points.dtype == np.float64
    assert points.flags.c_contiguous
    assert np.isfinite(points).all()


def test_distributions_table_and_dispatch():
    assert set(DISTRIBUTIONS) == {"uniform", "gaussian", "clustered"}
    assert DISTRIBUTIONS["uniform"] is uniform
    np.testing.assert_array_equal(generate("gaussian", 50, seed=4, sigma=0.3), gaussian(50, seed=4, sigma=0.3))
    np.testing.assert_array_equal(
        generate("clustered", 50, seed=4, clusters=3, spread=0.1), clustered(50, seed=4, clusters=3, spread=0.1)
    )
    np.testing.assert_array_equal(generate("uniform", 50), uniform(50, seed=0))


@pytest.mark.parametrize("name", sorted(DISTRIBUTIONS))
def test_same_seed_same_points_other_seed_other_points(name):
    a = generate(name, 500, seed=11)
    b = generate(name, 500, seed=11)
    c = generate(name, 500, seed=12)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert len(np.unique(a, axis=0)) == 500


def test_uniform_stays_in_its_bounds_and_fills_them():
    points = uniform(20_000, seed=1, bounds=(-3.0, 10.0, 5.0, 12.0))
    assert (points[:, 0] >= -3.0).all() and (points[:, 0] < 5.0).all()
    assert (points[:, 1] >= 10.0).all() and (points[:, 1] < 12.0).all()
    # each quarter of the box holds about a quarter of the points
    left, low = points[:, 0] < 1.0, points[:, 1] < 11.0
    for quarter in (left & low, left & ~low, ~left & low, ~left & ~low):
        assert abs(quarter.mean() - 0.25) < 0.02
    unit = uniform(1000, seed=2)
    assert unit.min() >= 0.0 and unit.max() < 1.0


def test_gaussian_mean_and_std_match_the_parameters():
    points = gaussian(40_000, seed=5, center=(2.0, -1.0), sigma=0.1)
    # standard error of the mean: 0.1 / 200 = 5e-4
    np.testing.assert_allclose(points.mean(axis=0), [2.0, -1.0], atol=3e-3)
    np.testing.assert_allclose(points.std(axis=0), [0.1, 0.1], rtol=0.03)
    default = gaussian(40_000, seed=6)
    np.testing.assert_allclose(default.mean(axis=0), [0.5, 0.5], atol=5e-3)
    np.testing.assert_allclose(default.std(axis=0), [0.15, 0.15], rtol=0.03)


def test_clustered_points_concentrate():
    n = 2000
    spread_out = mean_nearest_neighbour_distance(uniform(n, seed=7))
    tight = mean_nearest_neighbour_distance(clustered(n, seed=7, clusters=10, spread=0.02))
    assert tight < 0.5 * spread_out


def test_clustered_one_cluster_is_gaussian_about_its_centre():
    points = clustered(20_000, seed=8, clusters=1, spread=0.05)
    np.testing.assert_allclose(points.std(axis=0), [0.05, 0.05], rtol=0.03)
    centre = points.mean(axis=0)
    assert (0.0 <= centre).all() and (centre <= 1.0).all()


def test_clustered_points_come_in_random_order():
    points = clustered(2000, seed=9, clusters=2, spread=0.001)
    # two tight clusters: label each point by its cluster and count the label changes
    labels = np.linalg.norm(points - points[0], axis=1) < 0.05
    changes = np.count_nonzero(labels[1:] != labels[:-1])
    assert changes > 100


@pytest.mark.parametrize(
    "call, message",
    [
        (
            lambda: generate("poisson", 10),
            r"unknown distribution 'poisson'; choose one of: uniform, gaussian, clustered",
        ),
        (lambda: generate(None, 10), r"unknown distribution None; choose one of"),
        (lambda: generate("uniform", -1), r"n must be >= 0, got -1"),
        (lambda: generate("uniform", 2.5), r"n must be an integer, got 2.5"),
        (lambda: generate("uniform", True), r"n must be an integer, got True"),
        (lambda: generate("gaussian", 10, sigma=0), r"sigma must be a positive finite number, got 0"),
        (lambda: generate("gaussian", 10, sigma=-1.0), r"sigma must be a positive finite number, got -1.0"),
        (lambda: generate("gaussian", 10, sigma=float("nan")), r"sigma must be a positive finite number, got nan"),
        (lambda: generate("gaussian", 10, sigma="wide"), r"sigma must be a positive number, got 'wide'"),
        (lambda: generate("gaussian", 10, center=(0.0,)), r"center must be two numbers \(x, y\)"),
        (lambda: generate("clustered", 10, spread=0.0), r"spread must be a positive finite number, got 0.0"),
        (lambda: generate("clustered", 10, clusters=0), r"clusters must be >= 1, got 0"),
        (lambda: generate("clustered", 10, clusters=-3), r"clusters must be >= 1, got -3"),
        (lambda: generate("clustered", 10, clusters=2.5), r"clusters must be an integer, got 2.5"),
        (lambda: generate("uniform", 10, sigma=0.1), r"uniform has no parameter 'sigma'; its parameters are: bounds"),
        (lambda: generate("gaussian", 10, spread=0.1), r"its parameters are: center, sigma"),
        (lambda: uniform(10, bounds=(0, 0, 0, 1)), r"is an empty box"),
        (lambda: uniform(10, bounds=(0, 0, 1)), r"bounds must be four numbers"),
        (lambda: uniform(10, bounds=(0, 0, float("inf"), 1)), r"bounds must be finite"),
    ],
)
def test_bad_parameters(call, message):
    with pytest.raises(TvoronoiError, match=message):
        call()


def test_numpy_integers_are_counts():
    assert generate("clustered", np.int64(5), clusters=np.int32(2)).shape == (5, 2)


def test_docstring_examples():
    result = doctest.testmod(generators, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 3
    assert result.failed == 0
