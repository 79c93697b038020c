"""The benchmark report: a markdown summary and plots, from the CSV files of run.py and updates.py.

    python benchmarks/report.py [--out benchmarks/results]

Writes build.md, time_vs_n.png, relative_to_qhull.png, memory_vs_n.png and
update_cost.png next to the CSV files (each through a temporary file).
"""

from __future__ import annotations

import argparse
import io
import json
import statistics
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import RESULTS, atomic_write, describe_machine, read_csv  # noqa: E402
from tools import KINDS, REFERENCE, TOOLS  # noqa: E402

KIND_TITLES = {"full": "time to the full diagram", "bounded": "time to bounded cells"}
DIST_ORDER = ("uniform", "gaussian", "clustered")
# A fixed colour per engine, the same in every plot.
COLOURS = {
    "tvoronoi-fortune": "tab:blue",
    "tvoronoi-incremental": "tab:orange",
    "tvoronoi-textbook": "tab:brown",
    "qhull-voronoi": "black",
    "qhull-delaunay": "tab:grey",
    "geos": "tab:green",
    "triangle": "tab:purple",
}
# Memory readings below this (MiB) are drawn at it on the log axis.
MEMORY_FLOOR = 0.1
HEATMAP_COLUMNS = 4
UPDATE_ENGINES = {
    "tvoronoi-dynamic": "tvoronoi incremental",
    "tvoronoi-dynamic-fortune": "tvoronoi Fortune",
    "qhull-incremental": "Qhull",
}
UPDATE_KINDS = {"insert": "insert", "move": "small move", "remove": "remove", "add_points": "add_points (1 point)"}
# Line colour per engine and marker per operation in the update plot.
UPDATE_COLOURS = {
    "tvoronoi-dynamic": "tab:orange",
    "tvoronoi-dynamic-fortune": "tab:blue",
    "qhull-incremental": "black",
}
UPDATE_MARKERS = {"insert": "o", "move": "s", "remove": "v", "add_points": "o"}


def summarise(rows: list[dict]) -> dict:
    """(engine, kind, distribution, n) -> {median, lo, hi, q1, q3, count, peak} in seconds and MiB."""
    groups = defaultdict(list)
    peaks = {}
    for r in rows:
        key = (r["engine"], r["kind"], r["distribution"], int(r["n"]))
        groups[key].append(float(r["seconds"]))
        peaks[key] = float(r["peak_mib"])
    return {
        k: {
            "median": statistics.median(v),
            "lo": min(v),
            "hi": max(v),
            "count": len(v),
            "peak": peaks[k],
            "q1": float(np.percentile(v, 25)),
            "q3": float(np.percentile(v, 75)),
        }
        for k, v in groups.items()
    }


def fmt_time(s: float) -> str:
    if s < 1e-3:
        return f"{s * 1e6:.0f} µs"
    if s < 1.0:
        return f"{s * 1e3:.3g} ms"
    return f"{s:.3g} s"


def short_n(n: int) -> str:
    """100, 1k, 10k, 1M."""
    for unit, div in (("M", 1_000_000), ("k", 1_000)):
        if n >= div and n % div == 0:
            return f"{n // div}{unit}"
    return f"{n:,}"


def speedup(stats: dict, engine: str, kind: str, dist: str, n: int) -> float | None:
    """Qhull's median over the engine's (above 1: faster than Qhull)."""
    ref = stats.get((REFERENCE[kind], kind, dist, n))
    own = stats.get((engine, kind, dist, n))
    return ref["median"] / own["median"] if ref and own else None


def label(engine: str) -> str:
    return TOOLS[engine].label if engine in TOOLS else engine


def present(stats: dict, kind: str):
    """Engines (in TOOLS order), distributions and sizes that have results for a kind."""
    keys = [k for k in stats if k[1] == kind]
    engines = [e for e in TOOLS if any(k[0] == e for k in keys)]
    dists = [d for d in DIST_ORDER if any(k[2] == d for k in keys)]
    sizes = sorted({k[3] for k in keys})
    return engines, dists, sizes


# --- markdown ------------------------------------------------------------------------------


def time_table(stats: dict, kind: str, dist: str, *, spread: bool) -> list[str]:
    engines, _, sizes = present(stats, kind)
    lines = ["| n | " + " | ".join(label(e) for e in engines) + " |", "|---:|" + "---:|" * len(engines)]
    for n in sizes:
        cells = []
        for e in engines:
            s = stats.get((e, kind, dist, n))
            if not s:
                cells.append("—")
                continue
            text = fmt_time(s["median"])
            if spread:
                text += f" [{fmt_time(s['lo'])}–{fmt_time(s['hi'])}]"
            r = speedup(stats, e, kind, dist, n)
            if r is not None and e != REFERENCE[kind]:
                text += f" (×{r:.3g})"
            cells.append(text)
        lines.append(f"| {n:,} | " + " | ".join(cells) + " |")
    return lines


def memory_table(stats: dict, kind: str, dist: str) -> list[str]:
    engines, _, sizes = present(stats, kind)
    lines = ["| n | " + " | ".join(label(e) for e in engines) + " |", "|---:|" + "---:|" * len(engines)]
    for n in sizes:
        cells = [f"{stats[(e, kind, dist, n)]['peak']:.1f}" if (e, kind, dist, n) in stats else "—" for e in engines]
        lines.append(f"| {n:,} | " + " | ".join(cells) + " |")
    return lines


def update_medians(updates: list[dict]) -> dict:
    """(engine, kind, n) -> median seconds of one operation."""
    groups = defaultdict(list)
    for row in updates:
        groups[(row["engine"], row["kind"], int(row["n"]))].append(float(row["seconds"]))
    return {k: statistics.median(v) for k, v in groups.items()}


def update_series(med: dict) -> list[tuple[str, str]]:
    """(engine, kind) pairs present, in a fixed order."""
    return [(e, k) for e in UPDATE_ENGINES for k in UPDATE_KINDS if any(key[:2] == (e, k) for key in med)]


def update_section(updates: list[dict], status: dict, stats: dict) -> list[str]:
    lines = ["## Update cost", ""]
    if not updates:
        return lines + ["No update-cost results in this run.", ""]
    med = update_medians(updates)
    series = update_series(med)
    sizes = sorted({key[2] for key in med})
    rebuild = {n: stats.get(("qhull-delaunay", "full", "uniform", n)) for n in sizes}
    head = [f"{UPDATE_ENGINES[e]}: {UPDATE_KINDS[k]}" for e, k in series] + ["Qhull: Delaunay rebuild"]
    lines += [
        "Median time of one operation on uniform points. tvoronoi's include reading the changed cell "
        "back (`diagram().cell_polygon(i)`: the new or moved site's, or after a removal the cell of "
        "the nearest remaining site); Qhull's `add_points` is timed alone, without reading anything "
        "back, which favours it. Qhull cannot move or remove a point: that is a rebuild (the build "
        "benchmark's `scipy.spatial.Delaunay` median).",
        "",
        "| n | " + " | ".join(head) + " |",
        "|---:|" + "---:|" * len(head),
    ]
    for n in sizes:
        cells = [fmt_time(med[(e, k, n)]) if (e, k, n) in med else "—" for e, k in series]
        cells.append(fmt_time(rebuild[n]["median"]) if rebuild[n] else "—")
        lines.append(f"| {n:,} | " + " | ".join(cells) + " |")
    for note in status.get("notes", []):
        lines.append(f"- {note}")
    return lines + [""]


def check_section(checks: list[dict]) -> list[str]:
    ok = sum(1 for c in checks if c["status"] == "ok")
    bad = [c for c in checks if c["status"] in ("failed", "error")]
    other = [c for c in checks if c["status"] in ("skipped", "unavailable")]
    lines = [
        "## Correctness checks",
        "",
        f"{ok} results checked before timing, {len(bad)} failed (a failed result is not timed).",
    ]
    for c in bad:
        lines.append(f"- **{c['engine']}** {c['kind']}, {c['distribution']} n={c['n']}: {c['detail']}")
    seen = set()
    for c in other:
        key = (c["engine"], c["detail"])
        if key not in seen:
            seen.add(key)
            lines.append(f"- {c['engine']}: {c['status']} ({c['detail']})")
    return lines + [""]


def markdown(stats: dict, checks: list[dict], info: dict, updates: list[dict], status: dict, figures: list[str]) -> str:
    plan = info.get("plan", {})
    lines = [
        "# tvoronoi build benchmarks",
        "",
        f"Machine: {describe_machine(info)}",
        "",
        "Each (tool, distribution, n) runs in its own process: imports, a warm-up build (which gives the "
        "peak memory) and a correctness check come first and are never timed; then the tools of a case "
        "are timed in interleaved rounds. Times are medians, with [min–max] over the repeats; "
        "**×r** is Qhull's median divided by the tool's (×8: eight times faster than Qhull, "
        "×0.5: twice as slow). Points come from `tvoronoi.generators` with fixed seeds; every tool "
        "gets the same points and the same box (the sites' bounding box grown by 10%).",
        "",
    ]
    if plan:
        lines += [
            f"Sizes {', '.join(f'{n:,}' for n in plan.get('sizes', []))}; distributions "
            f"{', '.join(plan.get('distributions', []))}.",
            "",
        ]
    for kind in KINDS:
        _, dists, _ = present(stats, kind)
        if not dists:
            continue
        head = "uniform" if "uniform" in dists else dists[0]
        lines += [f"## Headline: {KIND_TITLES[kind]}, {head} points", ""]
        lines += time_table(stats, kind, head, spread=False) + [""]
    lines += [
        "## What is timed",
        "",
        "- **Full diagram**: tvoronoi -- the engine and its half-edge structure (Voronoi vertices, "
        "edges, faces), before cells are clipped; Qhull -- `scipy.spatial.Voronoi(points)` (its "
        "defaults, `Qbb Qc Qz`) and, as a lower bound, `scipy.spatial.Delaunay(points)` (the "
        "triangulation alone); GEOS -- `shapely.voronoi_polygons(MultiPoint(points), "
        "extend_to=box, ordered=True)`, polygons in input order; Triangle -- `triangle.voronoi(points)` "
        "(vertices, edges and rays, no cells).",
        "- **Bounded cells** (one polygon per site, clipped to the box): tvoronoi -- "
        "`tvoronoi.voronoi(points, bbox=box)`, which returns clipped cells (CSR arrays); Qhull -- "
        "`Voronoi`, the widely used finite-regions recipe (far points on the unbounded ridges), "
        "then `shapely.intersection` with the box; GEOS -- `voronoi_polygons` then "
        "`shapely.intersection` with the box. Qhull and GEOS return shapely polygons, tvoronoi numpy "
        "arrays. Triangle has no cells and is not in this table.",
        "- The textbook incremental order (fully random, conflict lists) is slow by design and runs "
        "up to 200,000 points only.",
        "",
    ]
    for kind in KINDS:
        engines, dists, _ = present(stats, kind)
        if not dists:
            continue
        lines += [f"## {KIND_TITLES[kind].capitalize()}, every distribution", ""]
        for dist in dists:
            lines += [f"### {dist}", ""] + time_table(stats, kind, dist, spread=True) + [""]
    for kind in KINDS:
        engines, dists, _ = present(stats, kind)
        if not dists:
            continue
        lines += [
            f"## Peak memory (MiB), {KIND_TITLES[kind]}",
            "",
            f"Measured as the {info.get('peak_memory', 'peak resident set of the warm-up build')} "
            "(the points and a k-d tree for the checks are already in place).",
            "",
        ]
        for dist in dists:
            lines += [f"### {dist}", ""] + memory_table(stats, kind, dist) + [""]
    lines += update_section(updates, status, stats)
    lines += check_section(checks)
    if figures:
        lines += ["## Figures", ""] + [f"![{f}]({f})" for f in figures] + [""]
    return "\n".join(lines)


# --- plots ---------------------------------------------------------------------------------


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> None:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    _plt().close(fig)
    atomic_write(path, buf.getvalue())


def plot_lines(stats: dict, value: str, path: Path, ylabel: str, title: str) -> bool:
    """One panel per (kind, distribution), one line per engine, log-log."""
    plt = _plt()
    kinds = [k for k in KINDS if present(stats, k)[1]]
    dists = [d for d in DIST_ORDER if any(key[2] == d for key in stats)]
    if not kinds or not dists:
        return False
    fig, axes = plt.subplots(
        len(kinds),
        len(dists),
        figsize=(4.6 * len(dists), 3.9 * len(kinds)),
        squeeze=False,
        sharex=True,
        constrained_layout=True,
    )
    for row, kind in enumerate(kinds):
        engines, _, _ = present(stats, kind)
        for col, dist in enumerate(dists):
            ax = axes[row][col]
            for e in engines:
                pts = sorted((n, s) for (en, k, d, n), s in stats.items() if en == e and k == kind and d == dist)
                if not pts:
                    continue
                xs = [n for n, _ in pts]
                if value == "median":
                    ys = [s["median"] for _, s in pts]
                    ax.fill_between(
                        xs, [s["q1"] for _, s in pts], [s["q3"] for _, s in pts], color=COLOURS.get(e), alpha=0.15, lw=0
                    )
                else:
                    ys = [max(s["peak"], MEMORY_FLOOR) for _, s in pts]
                ax.plot(
                    xs,
                    ys,
                    "o-",
                    ms=3.5,
                    color=COLOURS.get(e),
                    label=label(e),
                    lw=2.2 if e.startswith("tvoronoi") else 1.3,
                )
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.grid(True, which="major", alpha=0.3)
            ax.set_title(f"{KIND_TITLES[kind]} — {dist}", fontsize=10)
            if col == 0:
                ax.set_ylabel(ylabel)
            if row == len(kinds) - 1:
                ax.set_xlabel("n (sites)")
        axes[row][0].legend(fontsize=7.5, loc="upper left")
    fig.suptitle(title, fontsize=11)
    _save(fig, path)
    return True


def plot_relative(stats: dict, path: Path) -> bool:
    """A heatmap per (engine, kind): speed-up over Qhull across distribution x n."""
    plt = _plt()
    from matplotlib.colors import LogNorm

    panels = [(e, k) for k in KINDS for e in present(stats, k)[0] if e != REFERENCE[k]]
    panels = [(e, k) for e, k in panels if any(speedup(stats, e, k, d, n) for (_, _, d, n) in stats)]
    if not panels:
        return False
    # each kind starts a new row of at most HEATMAP_COLUMNS panels
    cols = min(HEATMAP_COLUMNS, max(sum(1 for p in panels if p[1] == k) for k in KINDS))
    slots, row = [], 0
    for k in KINDS:
        mine = [p for p in panels if p[1] == k]
        slots += [(row + j // cols, j % cols, p) for j, p in enumerate(mine)]
        row += -(-len(mine) // cols)
    rows = row
    dists = [d for d in DIST_ORDER if any(key[2] == d for key in stats)]
    sizes = sorted({key[3] for key in stats})
    values = [[speedup(stats, e, k, d, n) for d in dists for n in sizes] for e, k in panels]
    flat = [v for vs in values for v in vs if v]
    span = max(max(flat), 1 / min(flat), 2.0)
    norm = LogNorm(1 / span, span)
    size = (0.75 * len(sizes) * cols + 1.5, (0.55 * len(dists) + 1.4) * rows)
    fig, axes = plt.subplots(rows, cols, figsize=size, squeeze=False, constrained_layout=True)
    used = {(r, c) for r, c, _ in slots}
    for (r, c), ax in np.ndenumerate(axes):
        if (r, c) not in used:
            ax.axis("off")
    for r, c, (e, k) in slots:
        ax = axes[r][c]
        grid = np.array([[speedup(stats, e, k, d, n) or np.nan for n in sizes] for d in dists], float)
        im = ax.imshow(grid, cmap="RdBu", norm=norm, aspect="auto")
        for (i, j), v in np.ndenumerate(grid):
            if np.isfinite(v):
                strong = abs(np.log(v)) > 0.6 * np.log(span)
                ax.text(j, i, f"×{v:.2g}", ha="center", va="center", fontsize=7.5, color="white" if strong else "black")
        ax.set_xticks(range(len(sizes)), [short_n(n) for n in sizes], fontsize=7)
        ax.set_yticks(range(len(dists)), dists, fontsize=7.5)
        ax.set_title(f"{label(e)}\n{KIND_TITLES[k]}", fontsize=8.5)
    fig.colorbar(im, ax=axes.ravel().tolist(), shrink=0.8, label="speed-up over Qhull Voronoi (log)")
    fig.suptitle(
        "Each engine against Qhull (scipy.spatial.Voronoi; bounded: plus clipping): blue is faster, red slower",
        fontsize=10,
    )
    _save(fig, path)
    return True


def plot_updates(updates: list[dict], stats: dict, path: Path) -> bool:
    plt = _plt()
    if not updates:
        return False
    med = update_medians(updates)
    fig, ax = plt.subplots(figsize=(7.4, 5.0), constrained_layout=True)
    for e, k in update_series(med):
        pts = sorted((n, s) for (en, kind, n), s in med.items() if en == e and kind == k)
        ax.plot(
            *zip(*pts),
            "-",
            marker=UPDATE_MARKERS[k],
            color=UPDATE_COLOURS[e],
            label=f"{UPDATE_ENGINES[e]}: {UPDATE_KINDS[k]}",
        )
    sizes = sorted({key[2] for key in med})
    for engine, kind, name, colour in (
        ("qhull-delaunay", "full", "Qhull: Delaunay rebuild", "tab:grey"),
        ("tvoronoi-incremental", "bounded", "tvoronoi: voronoi() rebuild", "tab:orange"),
    ):
        pts = [
            (n, stats[(engine, kind, "uniform", n)]["median"]) for n in sizes if (engine, kind, "uniform", n) in stats
        ]
        if pts:
            ax.plot(*zip(*pts), "--", color=colour, alpha=0.7, label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.grid(True, alpha=0.3)
    ax.set_xlabel("n (sites)")
    ax.set_ylabel("median seconds per operation")
    ax.set_title("One update on uniform points (tvoronoi: until the changed cell is read back)", fontsize=10)
    ax.legend(fontsize=7.5, ncol=2)
    _save(fig, path)
    return True


def write_report(out: Path = RESULTS) -> Path:
    """Read the results in out and write build.md and the plots there."""
    out = Path(out)
    stats = summarise(read_csv(out / "build.csv"))
    checks = read_csv(out / "checks.csv")
    updates = read_csv(out / "updates.csv")
    info = json.loads((out / "machine.json").read_text()) if (out / "machine.json").exists() else {}
    status = json.loads((out / "updates.json").read_text()) if (out / "updates.json").exists() else {}
    made = []
    if plot_lines(stats, "median", out / "time_vs_n.png", "seconds (median; band: quartiles)", "Build time against n"):
        made.append("time_vs_n.png")
    if plot_relative(stats, out / "relative_to_qhull.png"):
        made.append("relative_to_qhull.png")
    if plot_lines(
        stats,
        "peak",
        out / "memory_vs_n.png",
        "peak MiB above the baseline",
        f"Peak memory of one build against n (readings under {MEMORY_FLOOR} MiB drawn at it)",
    ):
        made.append("memory_vs_n.png")
    if plot_updates(updates, stats, out / "update_cost.png"):
        made.append("update_cost.png")
    made += [f for f in ("fortune_steps.png", "incremental_steps.png") if (out / f).exists()]
    path = out / "build.md"
    atomic_write(path, markdown(stats, checks, info, updates, status, made) + "\n")
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=RESULTS)
    args = ap.parse_args(argv)
    print(write_report(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
