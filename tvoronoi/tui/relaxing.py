"""Relax: one Lloyd step on the sites shown, so the user watches the diagram become centroidal."""

from __future__ import annotations

import numpy as np

from tvoronoi.diagram import Diagram
from tvoronoi.relax import cell_centroids, lloyd


def relaxed_points(diagram: Diagram, points: np.ndarray) -> np.ndarray:
    """The sites of ``diagram`` (rows of ``points``) moved to the centroids of their cells; a site
    without a cell (a repeated point, a cell that misses the box) stays where it is."""
    centroids, has_cell = cell_centroids(diagram)
    moved = np.array(points, np.float64, copy=True)
    moved[has_cell] = centroids[has_cell]
    return moved


def relaxed_live(points: np.ndarray, bbox: tuple[float, ...], engine: str) -> np.ndarray:
    """One Lloyd step on edited sites, whose whole diagram is not built yet."""
    return lloyd(points, 1, bbox=bbox, engine=engine)


def relaxed_source(source: str) -> str:
    """What the status line says of the sites after one more step: '... (relaxed ×k)'."""
    head, sep, tail = source.rpartition(" (relaxed ×")
    if sep and tail.endswith(")") and tail[:-1].isdigit():
        return f"{head} (relaxed ×{int(tail[:-1]) + 1})"
    return f"{source} (relaxed ×1)"
