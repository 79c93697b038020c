"""Step-by-step figures of both engines on a small input, drawn from the step traces.

    python benchmarks/figures.py [--out DIR] [--n 25] [--seed 7]

fortune_steps.png: Fortune's sweep at several events -- the sweep line, the
beach line (one parabolic arc per site), pending circle events (dashed
circles; the cross marks where the sweep line will meet them), finished
edges (black) and growing edges (orange, from where they began to their
breakpoint on the beach line).

incremental_steps.png: randomized incremental insertion -- the new site
(red star), its conflict region (the Delaunay triangles whose circumcircles
hold it, hatched red, with those circles dashed), the new triangles around it (blue),
and the cells it took area from (yellow).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import RESULTS, atomic_write  # noqa: E402
from tvoronoi.trace import circumcentres

N_SITES = 25
SEED = 7
PANELS = 6
ARC_SAMPLES = 200


def _figure(rows: int, cols: int):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(rows, cols, figsize=(4.4 * cols, 4.6 * rows), constrained_layout=True)
    return plt, fig, np.atleast_1d(axes).ravel()


def _frame(ax, box) -> None:
    xmin, ymin, xmax, ymax = box
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def _save(plt, fig, path: Path) -> None:
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    atomic_write(path, buf.getvalue())


def _title(ax, head: str, text: str) -> None:
    import textwrap

    ax.set_title("\n".join([head, *textwrap.wrap(text, 56)]), fontsize=8.5)


def fortune_panel(ax, pts, step, box) -> None:
    """Draw one step of Fortune's sweep."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle

    from tvoronoi.trace import parabola_y

    xmin, ymin, xmax, ymax = box
    L = step.sweep_y
    below = pts[:, 1] <= L
    # edges: finished (black), growing towards the beach line (orange)
    if len(step.finished_edges):
        ax.add_collection(LineCollection(step.finished_edges, colors="black", linewidths=1.2))
    if len(step.growing_edges):
        growing = step.growing_edges.copy()
        growing[~np.isfinite(growing)] = ymin - (ymax - ymin)  # edges that began at y = -inf
        ax.add_collection(LineCollection(growing, colors="tab:orange", linewidths=1.6))
    # the beach line: arc k of site beach[k] runs between breakpoints k - 1 and k
    if len(step.beach) and np.isfinite(L):
        bx = step.breakpoints[:, 0] if len(step.breakpoints) else np.empty(0)
        lefts = np.concatenate(([xmin], bx))
        rights = np.concatenate((bx, [xmax]))
        for site, lo, hi in zip(step.beach.tolist(), lefts, rights):
            sx, sy = pts[site]
            if sy == L:  # a site on the sweep line: a vertical arc
                k = int(np.argmin(np.abs(bx - sx))) if len(bx) else -1
                y0 = step.breakpoints[k, 1] if k >= 0 else ymin
                ax.plot([sx, sx], [y0, sy], color="tab:blue", lw=1.4)
                continue
            lo, hi = max(lo, xmin), min(hi, xmax)
            if hi <= lo:
                continue
            xs = np.linspace(lo, hi, ARC_SAMPLES)
            ax.plot(xs, parabola_y(sx, sy, xs, L), color="tab:blue", lw=1.4)
        ax.axhline(L, color="tab:red", lw=1.0)
    # pending circle events
    for cx, cy, r in step.circles:
        ax.add_patch(Circle((cx, cy), r, fill=False, ls="--", lw=0.8, color="tab:purple"))
        ax.plot(cx, cy + r, marker="x", color="tab:purple", ms=5)
    if len(step.vertices):
        ax.plot(*step.vertices.T, "o", color="black", ms=2.5)
    ax.plot(*pts[below].T, "o", color="black", ms=4)
    ax.plot(*pts[~below].T, "o", mfc="white", mec="grey", ms=4)
    _frame(ax, box)
    _title(ax, f"step {step.index}/{step.n_steps}", step.describe())


def incremental_panel(ax, pts, step, box) -> None:
    """Draw one insertion of the randomized incremental engine."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.patches import Circle

    d = step.diagram
    inserted = step.inserted.tolist()
    stolen = set(step.stolen_from.tolist())
    cells = {i: d.cell_polygon(i) for i in inserted}
    ax.add_collection(
        PolyCollection(
            [cells[i] for i in inserted if i in stolen and len(cells[i])], facecolors="#fff2a8", edgecolors="none"
        )
    )
    if step.site >= 0 and len(cells.get(step.site, [])):
        ax.add_collection(PolyCollection([cells[step.site]], facecolors="#cfe3ff", edgecolors="none"))
    ax.add_collection(
        PolyCollection([c for c in cells.values() if len(c)], facecolors="none", edgecolors="grey", linewidths=0.9)
    )
    tri = d.delaunay_triangles()
    if len(tri):
        ax.add_collection(
            PolyCollection(pts[tri], facecolors="none", edgecolors="#bbbbbb", linewidths=0.5, linestyles=":")
        )
    if len(step.conflict):
        corners = pts[step.conflict]
        ax.add_collection(
            PolyCollection(corners, facecolors="none", edgecolors="tab:red", hatch="////", linewidths=1.3)
        )
        centres = circumcentres(corners[:, 0], corners[:, 1], corners[:, 2])
        for (cx, cy), p in zip(centres, corners[:, 0]):
            ax.add_patch(
                Circle((cx, cy), float(np.hypot(*(p - (cx, cy)))), fill=False, ls="--", lw=0.7, color="tab:red")
            )
    if len(step.new_triangles):
        edges = pts[step.new_triangles][:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2, 2)
        ax.add_collection(LineCollection(edges, colors="tab:blue", linewidths=1.2))
    done = np.zeros(len(pts), bool)
    done[inserted] = True
    ax.plot(*pts[done].T, "o", color="black", ms=4)
    ax.plot(*pts[~done].T, "o", mfc="white", mec="grey", ms=4)
    if step.site >= 0:
        ax.plot(*pts[step.site], "*", color="tab:red", ms=13, mec="black", mew=0.6)
    _frame(ax, box)
    _title(ax, f"insertion {step.index}/{step.n_steps}", step.describe())


def pick_fortune_steps(trace, panels: int) -> list[int]:
    """Steps spread over the sweep (its first tenth is mostly site events), and the last."""
    n = len(trace)
    ks = np.linspace(n * 0.1, n * 0.85, panels - 1).round().astype(int).tolist()
    return ks + [n]


def make_figures(out: Path, n: int = N_SITES, seed: int = SEED) -> list[Path]:
    """Write fortune_steps.png and incremental_steps.png into out."""
    import tvoronoi

    pts = tvoronoi.generate("uniform", n, seed=seed)
    paths = []

    trace = tvoronoi.steps(pts, engine="fortune")
    box = trace.bbox
    plt, fig, axes = _figure(2, PANELS // 2)
    for ax, k in zip(axes, pick_fortune_steps(trace, PANELS)):
        fortune_panel(ax, pts, trace.step(k), box)
    fig.suptitle(
        f"Fortune's sweepline on {n} sites: sweep line (red), beach line (blue), circle events "
        f"(purple), finished edges (black), growing edges (orange)",
        fontsize=10,
    )
    paths.append(out / "fortune_steps.png")
    _save(plt, fig, paths[-1])

    trace = tvoronoi.steps(pts, engine="incremental")
    plt, fig, axes = _figure(2, PANELS // 2)
    ks = np.linspace(5, n, PANELS).round().astype(int)
    for ax, k in zip(axes, ks.tolist()):
        incremental_panel(ax, pts, trace.step(k), box)
    fig.suptitle(
        f"Randomized incremental insertion on {n} sites: new site (star), conflict region (hatched red, with "
        f"circumcircles), new triangles (blue), cells it took area from (yellow)",
        fontsize=10,
    )
    paths.append(out / "incremental_steps.png")
    _save(plt, fig, paths[-1])
    return paths


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=RESULTS)
    ap.add_argument("--n", type=int, default=N_SITES)
    ap.add_argument("--seed", type=int, default=SEED)
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for p in make_figures(args.out, args.n, args.seed):
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
