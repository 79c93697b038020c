"""The incremental engine's insertion order: a permutation, reproducible, and local at any scale."""

import numpy as np
import pytest

from conftest import DATASETS
from tvoronoi.kernels.order import brio_order


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_a_permutation_for_every_data_set(name):
    pts = DATASETS[name]
    perm = brio_order(np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1]), 0)
    assert perm.dtype == np.int32
    assert np.array_equal(np.sort(perm), np.arange(len(pts)))


def test_same_seed_same_order(rng):
    xs, ys = rng.random(5000), rng.random(5000)
    assert np.array_equal(brio_order(xs, ys, 7), brio_order(xs, ys, 7))
    assert not np.array_equal(brio_order(xs, ys, 7), brio_order(xs, ys, 8))
    assert np.array_equal(np.sort(brio_order(xs, ys, -1)), np.arange(5000))  # any int seeds


@pytest.mark.parametrize("kind", ["uniform", "clustered", "rows"])
def test_the_same_order_on_any_thread_count(rng, kind):
    """The rounds are ordered at once on several threads, each with its own pivots: the order does not
    depend on how many (40,000 sites: above the size that splits)."""
    n = 40_000
    if kind == "uniform":
        xs, ys = rng.random(n), rng.random(n)
    elif kind == "clustered":
        xs, ys = rng.normal(0, 1e-6, n) + rng.integers(0, 3, n), rng.normal(0, 1e-6, n)
    else:
        xs, ys = np.floor(rng.random(n) * 50), np.floor(rng.random(n) * 4)
    one = brio_order(xs, ys, 11, 1)
    assert np.array_equal(np.sort(one), np.arange(n))
    for threads in (2, 3, 8):
        assert np.array_equal(brio_order(xs, ys, 11, threads), one), threads


def test_repeats_and_ties(rng):
    """All sites at one place, and sites on a few rows and columns (ties on both axes)."""
    for xs, ys in [
        (np.full(1000, 0.25), np.full(1000, 0.25)),
        (np.floor(rng.random(20000) * 7), np.floor(rng.random(20000) * 5)),
    ]:
        perm = brio_order(xs, ys, 0)
        assert np.array_equal(np.sort(perm), np.arange(len(xs)))


def mean_step(xs, ys, perm, n):
    """Mean distance between consecutive sites of the last (largest) round, among the first n."""
    last = perm[len(perm) // 2 + len(perm) // 8 :]  # well inside the last round
    last = last[last < n]
    return np.hypot(np.diff(xs[last]), np.diff(ys[last])).mean()


@pytest.mark.parametrize("width", [1.0, 1e-9, 1e-300])
def test_consecutive_sites_are_near_at_any_scale(rng, width):
    """A square cluster of this width and two far sites: consecutive sites of a round are as near
    as in a uniform square (a curve of fixed resolution over the sites' box puts the whole cluster
    in one cell and visits it in random order)."""
    n = 40000
    xs = np.concatenate([width * (1 + rng.random(n)), [-1.0, 3.0]])
    ys = np.concatenate([width * (1 + rng.random(n)), [-1.0, 3.0]])
    step = mean_step(xs, ys, brio_order(xs, ys, 0), n)
    # about width / sqrt(sites in the round) along a Hilbert curve; random order: width / 2
    assert step < 4 * width / np.sqrt(n / 2)


def test_two_lines_are_followed_along(rng):
    """Two lines 1e-9 apart: consecutive sites are a few places apart along the lines."""
    n = 40000
    xs = rng.random(n)
    ys = np.where(np.arange(n) < n // 2, 0.5, 0.5 + 1e-9)
    perm = brio_order(xs, ys, 0)
    last = perm[n // 2 + n // 8 :]
    rank = np.argsort(np.argsort(xs[last]))
    assert np.abs(np.diff(rank)).mean() < 4
