"""The benchmark harness's own correctness checks (benchmarks/tools.py): every tool passes them on every
distribution it is timed on, at any scale of the coordinates, and they fail on a wrong diagram."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.spatial

from benchmarks import tools
from tvoronoi.api import default_bbox
from tvoronoi.generators import DISTRIBUTIONS, generate

# (clustered points span more than [0, 1]: the engines scale them by 2^-1 inside, and a full diagram's
# vertices come back in the points' own unit)
SCALES = (1.0, 3.0e5, 2.0**-40)


@pytest.mark.parametrize("dist", sorted(DISTRIBUTIONS))
@pytest.mark.parametrize("scale", SCALES)
@pytest.mark.parametrize("name", ["tvoronoi-fortune", "tvoronoi-incremental", "tvoronoi-textbook", "qhull-voronoi"])
def test_every_tool_passes_its_checks(name, dist, scale):
    tool = tools.TOOLS[name]
    pts = generate(dist, 3000, seed=7) * scale
    box, tree = default_bbox(pts), scipy.spatial.cKDTree(pts)
    for kind in tool.kinds():
        tool.check(kind, tool.run(kind, pts, box), pts, box, tree)


def test_the_vertex_check_fails_on_vertices_off_by_a_factor():
    pts = generate("clustered", 3000, seed=7)
    box, tree = default_bbox(pts), scipy.spatial.cKDTree(pts)
    out = tools.TOOLS["tvoronoi-incremental"].run("full", pts, box)
    tools.check_tv_full(out, pts, box, tree)
    wrong = dict(out, vertices=np.ldexp(out["vertices"], 1))  # as the harness once read them
    with pytest.raises(tools.CheckFailed, match="not equidistant"):
        tools.check_tv_full(wrong, pts, box, tree)


@pytest.mark.parametrize("engine", ["incremental", "fortune"])
def test_kernel_times_accounts_for_the_build(engine):
    """benchmarks/kernel_times.py (in a process of its own: it wraps the kernel modules' functions):
    the engine's kernels, the dual and the clipper are in its table, and on one thread their calls
    add up to no more than the build."""
    root = Path(__file__).resolve().parents[1]
    res = subprocess.run(
        [
            sys.executable,
            str(root / "benchmarks" / "kernel_times.py"),
            "--n",
            "5000",
            "--engine",
            engine,
            "--repeats",
            "2",
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    build = float(re.search(r"build: ([\d.]+) ms", res.stdout).group(1))
    rows = dict(re.findall(r"^\| ([\w.]+) \| ([\d.]+) \|", res.stdout, re.M))
    first = "incremental.triangulate" if engine == "incremental" else "fortune.sweep"
    for kernel in (first, "dual.voronoi_from_delaunay", "clip.clip_cells"):
        assert kernel in rows, (kernel, res.stdout)
    assert 0 < sum(float(ms) for ms in rows.values()) <= build
