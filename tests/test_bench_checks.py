"""The benchmark harness's own correctness checks (benchmarks/tools.py): every tool passes them on every
distribution it is timed on, at any scale of the coordinates, and they fail on a wrong diagram."""

from __future__ import annotations

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
