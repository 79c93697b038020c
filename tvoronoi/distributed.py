"""The same exact cells on a Dask cluster: tiles with halos (tvoronoi.tiles), one task per tile and round.

``voronoi(points, client=...)`` takes a Dask DataFrame (x/y columns and properties) or a Dask array of
shape (n, 2). One pass over the partitions counts the rows (their order numbers the sites, as in
``tvoronoi.voronoi``), finds the sites' extent and draws a sample, from which the tiles are cut. Then
each round runs one task per tile that still has cells to emit: it gathers the sites of its region from
every partition, builds their diagram, and emits the certified cells of its own sites with their
properties (or writes them: ``to=``), and with ``delaunay`` the final triangles whose lowest site is
its own (tvoronoi.tile_delaunay). No process ever holds the whole input or output.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from tvoronoi.errors import TvoronoiError
from tvoronoi.tile_delaunay import Hull, tile_triangles
from tvoronoi.tiles import (
    MAX_ROUNDS,
    SAMPLE_PER_TILE,
    Plan,
    Region,
    build_tile,
    default_tiles,
    group_reaches,
    in_region,
    plan_tiles,
    tile_of,
)

INSTALL_HINT = "pip install 'tvoronoi[dask]' (or pip install 'dask[distributed,dataframe]')"
# the columns of the sites inside tasks: the input row, and the coordinates
ID, X, Y = "__tvoronoi_site", "__tvoronoi_x", "__tvoronoi_y"
# the cell columns tvoronoi adds; a property of the same name is renamed
SITE, GEOMETRY = "site", "geometry"
FORMATS = ("parquet", "geojsonseq")
# What Dask's nanny sets in a worker's environment by default and ``local_client`` leaves unset:
# MALLOC_TRIM_THRESHOLD_ (64 KiB, to hand freed memory back sooner) also turns off glibc's adaptive
# mmap threshold, so every block over 128 KiB (each array a task makes between the kernels' phases, a
# row group's WKB) is mapped afresh and page-faulted again: three tiles of 10^6 sites spent 4.3-5.7 CPU s
# in the kernel with it, 1.3-1.6 without. The builds hand their large arrays back themselves
# (kernels/pages.pyx). Workers started by ``dask worker`` set it unless configured not to (see the README).
WORKER_ENVIRON_UNSET = ("MALLOC_TRIM_THRESHOLD_",)
# The Dask configuration of ``local_client``'s workers: no statistical profiler (it samples the task's
# stack on the worker's event loop every 10 ms: 0.4 CPU s per 20 s in an idle worker, more in a busy
# one; about 1 CPU s per worker, 3% of the work, in the 10^7-site benchmark).
LOCAL_WORKER_CONFIG = {"distributed.worker.profile.enabled": False}
# A partition serving at most this many regions in one round tests each region on every site (a few
# ms per region at 10^6 sites); one serving more first puts its sites in the bins of a GRID x GRID grid
# (one stable sort of small integers, about 20 ms at 10^6 sites), and each region tests only the sites
# of the bins it meets: a later round's many small groups, or many tiles, cost little.
FEW_REGIONS = 16
GRID = 128


def require_dask():
    """Import dask.dataframe and distributed, or say how to install them."""
    try:
        import dask.dataframe  # noqa: F401
        import distributed
    except ImportError:
        raise TvoronoiError(
            f"running on Dask needs dask and distributed, which are not installed: {INSTALL_HINT}"
        ) from None
    return distributed


class PartitionError(TvoronoiError):
    """A partition of the points that cannot be read, or a row of it without finite coordinates.

    ``partition`` numbers the partitions from 0; ``row`` is the row within it (None when the partition
    cannot be read at all); ``detail`` says what is wrong. A caller that knows where the partitions come
    from words the message with :meth:`explain` (``tvoronoi batch --dask`` names the file and line).
    """

    def __init__(self, partition: int | None, row: int | None, detail: str, index=None):
        self.partition, self.row, self.detail, self.index = partition, row, detail, index
        where = "a partition" if partition is None else f"partition {partition}"
        if row is not None:
            where += f", row {row}" + ("" if index is None else f" (index {index!r})")
        super().__init__(f"{where}: {detail}")

    def __reduce__(self):
        return (PartitionError, (self.partition, self.row, self.detail, self.index))

    def explain(self, where: str) -> str:
        """The message with ``where`` naming the place ("points.csv, line 7")."""
        return f"{where}: {self.detail}"


@dataclass(frozen=True)
class Job:
    """What every task of one build shares: the columns, the plan, the box, the clip region and the output."""

    x: str
    y: str
    properties: tuple[str, ...]
    renames: dict
    plan: Plan
    engine: str
    clip: object = None
    to: str | None = None
    format: str = "parquet"
    crs: object = None
    delaunay: bool = False
    delaunay_to: str | None = None
    hull: Hull | None = None


@dataclass(frozen=True)
class Result:
    """What ``voronoi`` did: the cells (a Dask DataFrame, or None when written), rounds, parts written;
    with ``delaunay``, the triangles likewise."""

    cells: object
    rounds: int
    pending_after: tuple[int, ...]
    n_tiles: int
    parts: tuple[str, ...] = ()
    triangles: object = None
    triangles_pending_after: tuple[int, ...] = ()
    triangle_parts: tuple[str, ...] = ()


# ---------------------------------------------------------------------------------------------
# the points: a Dask DataFrame or array


def _as_frame(points, x: str | None, y: str | None):
    """(frame, x, y): a Dask DataFrame and the names of its coordinate columns."""
    import dask.array as da
    import dask.dataframe as dd

    from tvoronoi.coordinate_names import named_column

    if isinstance(points, da.Array):
        if points.ndim != 2 or points.shape[1] != 2:
            raise TvoronoiError(f"a Dask array of points must have shape (n, 2), got {points.shape}")
        return dd.from_dask_array(points.astype(np.float64), columns=["x", "y"]), "x", "y"
    if not isinstance(points, dd.DataFrame):
        raise TvoronoiError(
            f"points must be a Dask DataFrame or a Dask array of shape (n, 2), got {type(points).__name__}; "
            f"for points in memory call tvoronoi.voronoi"
        )
    names = [str(c) for c in points.columns]
    chosen = []
    for role, given in (("x", x), ("y", y)):
        if given is not None:
            if given not in names:
                raise TvoronoiError(f"no column {given!r} for {role}: the columns are {', '.join(names)}")
            chosen.append(given)
            continue
        j = named_column(names, role)
        if j is None:
            raise TvoronoiError(f"no column names the {role} coordinate among {', '.join(names)}; pass {role}=NAME")
        chosen.append(names[j])
    return points, chosen[0], chosen[1]


def coordinate_columns(frame, x: str | None = None, y: str | None = None) -> tuple[str, str]:
    """The names of a Dask DataFrame's x and y columns, as ``voronoi`` finds them."""
    _, xname, yname = _as_frame(frame, x, y)
    return xname, yname


def _coordinates(part, column: str) -> np.ndarray:
    """A coordinate column as float64, NaN where a value is not a number."""
    import pandas as pd

    return pd.to_numeric(part[column], errors="coerce").to_numpy(np.float64, na_value=np.nan)


def _summary(part, x: str, y: str, n_sample: int, seed: int, clip, number: int, hull: bool = False) -> dict:
    """One partition's row count, the extent of its sites (inside the clip region) and a sample of them;
    with ``hull``, the rows and places of the sites on their convex hull's boundary."""
    xs, ys = _coordinates(part, x), _coordinates(part, y)
    bad = ~(np.isfinite(xs) & np.isfinite(ys))
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        column = x if not np.isfinite(xs[row]) else y
        value = part[column].iloc[row]
        value = float(value) if isinstance(value, (float, np.floating)) else value
        raise PartitionError(
            number,
            row,
            f"{column} is {value!r}, not a finite number ({int(bad.sum())} such "
            f"row(s) in this partition); drop or fix those rows",
            part.index[row],
        )
    out: dict = {"n": len(part), "extent_all": _extent(xs, ys)}
    if clip is not None:
        from tvoronoi.region import sites_inside

        keep = sites_inside(np.column_stack([xs, ys]), clip)
        rows = np.flatnonzero(keep)
        xs, ys = xs[keep], ys[keep]
    else:
        rows = np.arange(len(xs))
    out.update(m=len(xs), extent=None, sample=np.empty((0, 2)))
    if hull:
        from tvoronoi.hull import boundary_hull

        on = boundary_hull(np.column_stack([xs, ys]), np.arange(len(xs)))
        out["hull"] = (rows[on].astype(np.int64), np.column_stack([xs[on], ys[on]]))
    if len(xs):
        out["extent"] = _extent(xs, ys)
        rng = np.random.default_rng([seed, number])
        take = rng.choice(len(xs), min(len(xs), n_sample), replace=False) if len(xs) > n_sample else slice(None)
        out["sample"] = np.column_stack([xs[take], ys[take]])
    return out


def _extent(xs: np.ndarray, ys: np.ndarray) -> Region | None:
    if len(xs) == 0:
        return None
    return (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))


def _meets(extent: Region | None, region: Region) -> bool:
    """Whether a partition's sites (their extent) can lie in the closed region."""
    return extent is not None and not (
        extent[2] < region[0] or extent[0] > region[2] or extent[3] < region[1] or extent[1] > region[3]
    )


def _select(part, first_row: int, x: str, y: str, regions: list, keep: list[str], clip) -> tuple:
    """For each closed region, the rows of one partition whose site lies in it, with their input rows
    (one pass over the partition serves every unit of a round)."""
    import pandas as pd

    xs, ys = _coordinates(part, x), _coordinates(part, y)
    bins = _Bins(xs, ys) if len(regions) > FEW_REGIONS and len(xs) else None
    out = []
    for region in regions:
        rows = np.flatnonzero(in_region(xs, ys, region)) if bins is None else bins.rows_in(region)
        frame = pd.DataFrame({ID: np.int64(first_row) + rows, X: xs[rows], Y: ys[rows]})
        inside = np.ones(len(rows), bool)
        if clip is not None and len(rows):
            from tvoronoi.region import sites_inside

            inside = sites_inside(np.column_stack([xs[rows], ys[rows]]), clip)
        frame["__tvoronoi_inside"] = inside
        for name in keep:
            frame[name] = part[name].to_numpy()[rows]
        out.append(frame)
    return tuple(out)


class _Bins:
    """A partition's sites in the bins of a GRID x GRID grid over their extent, for many regions.

    A site's bin and a region's range of bins come from the same rounded arithmetic, which is monotone
    (a larger coordinate never lands in a lower bin), so the bins a region meets hold each of its sites;
    ``rows_in`` then tests those sites exactly.
    """

    def __init__(self, xs: np.ndarray, ys: np.ndarray):
        self.xs, self.ys = xs, ys
        self.x0, self.y0 = float(xs.min()), float(ys.min())
        width, height = float(xs.max()) - self.x0, float(ys.max()) - self.y0
        self.sx = GRID / width if width > 0 else 0.0
        self.sy = GRID / height if height > 0 else 0.0
        cell = (self._bins(xs, self.x0, self.sx) * GRID + self._bins(ys, self.y0, self.sy)).astype(np.int16)
        self.order = np.argsort(cell, kind="stable")  # a radix sort: rows ascending within a bin
        self.starts = np.zeros(GRID * GRID + 1, np.int64)
        np.cumsum(np.bincount(cell, minlength=GRID * GRID), out=self.starts[1:])

    @staticmethod
    def _bins(values, origin: float, scale: float) -> np.ndarray:
        if scale == 0:  # every site at one coordinate: one bin (a region's side may be infinite)
            return np.zeros(np.shape(values), np.int16)
        return np.clip(np.floor((np.asarray(values, np.float64) - origin) * scale), 0, GRID - 1).astype(np.int16)

    def rows_in(self, region: Region) -> np.ndarray:
        """The rows of the sites in the closed region, ascending."""
        x0, y0, x1, y1 = region
        gx0, gx1 = (int(v) for v in self._bins([x0, x1], self.x0, self.sx))
        gy0, gy1 = (int(v) for v in self._bins([y0, y1], self.y0, self.sy))
        columns = [
            self.order[self.starts[gx * GRID + gy0] : self.starts[gx * GRID + gy1 + 1]] for gx in range(gx0, gx1 + 1)
        ]
        near = np.concatenate(columns) if columns else np.empty(0, np.int64)
        return np.sort(near[in_region(self.xs[near], self.ys[near], region)])


# ---------------------------------------------------------------------------------------------
# one tile, one round (runs on a worker)


# what a unit of work emits: a tile's cells and triangles (the first round), or a group of its pending
# cells, or of its sites with pending triangles (later rounds)
BOTH, CELLS, TRIANGLES = "both", "cells", "triangles"


def _run_tile(pieces: list, t: int, region: Region, group, kind: str, job: Job, round_: int, name: str):
    """Build a region of tile t for its own sites (``group``: those of a group of pending ones only);
    return (cells frame or part name, triangles frame or part name, (pending cells, their reaches),
    (sites with pending triangles, their reaches)); None for what ``kind`` does not ask."""
    import pandas as pd

    from tvoronoi.api import voronoi as build

    sites = pd.concat(pieces, ignore_index=True) if pieces else pd.DataFrame()
    plan = job.plan
    xs, ys = sites[X].to_numpy(), sites[Y].to_numpy()
    ids = sites[ID].to_numpy(np.int64)
    own = tile_of(xs, ys, plan.rects[t : t + 1]) == 0 if len(sites) else np.zeros(0, bool)
    if group is not None:
        own &= np.isin(ids, group)
    inside = sites["__tvoronoi_inside"].to_numpy(bool)
    built = np.flatnonzero(inside)
    pts = np.column_stack([xs[built], ys[built]])
    everything = plan.sees_everything(region)
    want = own[built]
    diagram = build(pts, bbox=plan.box, engine=job.engine, threads=1) if want.any() else None
    cells_out = tris_out = left_cells = left_tris = None
    if kind in (BOTH, CELLS) and job.to is not None and job.format == "parquet" and job.clip is None:
        # written: the certified cells go from the diagram to the part a row group at a time
        cells_out, left_cells = _write_cells(sites, ids, built, pts, want, region, everything, diagram, job, name)
    elif kind in (BOTH, CELLS):
        cells = build_tile(
            pts, ids[built], want, region, plan.box, everything=everything, engine=job.engine, diagram=diagram
        )
        # the tile's own sites outside the clip region get no cell: written once, in the first round
        outside = np.flatnonzero(own & ~inside) if round_ == 1 else np.empty(0, np.int64)
        left_cells = (cells.pending, cells.reaches)
        if job.to is None:
            cells_out = _cells_frame(sites, ids, cells, outside, job)
        else:
            from tvoronoi.writers.parts import write_part

            frame, geoms = _cells_frame(sites, ids, cells, outside, job)
            cells_out = write_part(frame, geoms, job.to, name, job.format, job.crs)
    if job.delaunay and kind in (BOTH, TRIANGLES):
        if diagram is None:
            tri = np.empty((0, 3), np.int64)
            left_tris = (np.empty(0, np.int64), np.empty((0, 4)))
        else:
            assert job.hull is not None
            got = tile_triangles(
                pts, ids[built], want, region, diagram, hull=job.hull, extent=plan.extent, everything=everything
            )
            tri, left_tris = got.triangles, (got.pending, got.reaches)
        tris_out = _triangles_out(tri, ids[built], pts, job, name)
    return cells_out, tris_out, left_cells, left_tris


def _write_cells(sites, ids, built, pts, want, region, everything: bool, diagram, job: Job, name: str):
    """A task's certified cells written as a GeoParquet part: (the part's name, (pending cells, their
    reaches)). ``built`` are the rows of ``sites`` the diagram holds (at ``pts``), ``want`` (over them)
    those it emits."""
    import pandas as pd

    from tvoronoi.tiles import certify_cells
    from tvoronoi.writers.parts import write_cells_part

    if diagram is None:
        return "", (np.empty(0, np.int64), np.empty((0, 4)))
    verdict = certify_cells(diagram, pts, want, region, everything=everything)
    rows = built[verdict.kept]
    out = {SITE: ids[rows]}
    for column in job.properties:
        out[job.renames.get(column, column)] = sites[column].to_numpy()[rows]
    part = write_cells_part(pd.DataFrame(out), diagram, verdict.kept, job.to, name, job.crs)
    return part, (ids[built[verdict.failed]], verdict.reaches)


def _triangles_out(tri: np.ndarray, ids: np.ndarray, pts: np.ndarray, job: Job, name: str):
    """A task's triangles: a frame (a, b, c: input rows, counter-clockwise, lowest first; geometry) or,
    written, the part's name."""
    import pandas as pd
    import shapely

    xy = pts[np.searchsorted(ids, tri)] if len(tri) else np.empty((0, 3, 2))
    if job.delaunay_to is not None:
        from tvoronoi.writers.parts import write_triangles_part

        return write_triangles_part(tri, xy, job.delaunay_to, name, job.format, job.crs)
    rings = shapely.polygons(np.concatenate([xy, xy[:, :1]], axis=1)) if len(tri) else np.empty(0, object)
    wkb = shapely.to_wkb(rings) if len(tri) else np.empty(0, object)
    return pd.DataFrame(
        {"a": tri[:, 0], "b": tri[:, 1], "c": tri[:, 2], GEOMETRY: pd.array(wkb, dtype=_binary_dtype())}
    )


def _cells_frame(sites, ids: np.ndarray, cells, outside: np.ndarray, job: Job):
    """The emitted rows in site order: ``site``, the properties, ``geometry`` (WKB; None without a cell).

    When the cells are written (``job.to``), the frame has no geometry column and the shapely cells come
    beside it: (frame, geometries); the writer takes them as they are.
    """
    import pandas as pd
    import shapely

    lengths = np.diff(cells.offsets)
    has = lengths >= 3  # fewer points: no area (a cell touching the box)
    geoms = np.full(len(cells.ids), None, object)
    if has.any():
        keep = np.repeat(has, lengths)
        xy = cells.ring_xy[keep]
        index = np.repeat(np.arange(int(has.sum())), lengths[has])
        geoms[has] = shapely.polygons(shapely.linearrings(xy, indices=index))
    if job.clip is not None and has.any():
        from tvoronoi.region import cut_polygons

        geoms, _ = cut_polygons(geoms, job.clip)
    site = np.concatenate([cells.ids, ids[outside]])
    geoms = np.concatenate([geoms, np.full(len(outside), None, object)])
    order = np.argsort(site, kind="stable")
    position = np.searchsorted(ids, site[order])
    out = {SITE: site[order]}
    for name in job.properties:
        out[job.renames.get(name, name)] = sites[name].to_numpy()[position]
    if job.to is not None:
        return pd.DataFrame(out), geoms[order]
    wkb = shapely.to_wkb(geoms[order]) if len(order) else np.empty(0, object)
    out[GEOMETRY] = pd.array(wkb, dtype=_binary_dtype())
    return pd.DataFrame(out)


def _binary_dtype():
    """WKB as Arrow binary: Dask would take a column of Python bytes for text and decode it."""
    import pandas as pd
    import pyarrow as pa

    return pd.ArrowDtype(pa.binary())


def _meta(frame_meta, job: Job):
    import pandas as pd

    cols = {SITE: pd.Series(dtype="int64")}
    for name in job.properties:
        cols[job.renames.get(name, name)] = frame_meta[name]
    cols[GEOMETRY] = pd.Series(dtype=_binary_dtype())
    return pd.DataFrame(cols)


# ---------------------------------------------------------------------------------------------
# the public entry


def voronoi(
    points,
    *,
    client=None,
    bbox=None,
    tiles: int | None = None,
    to=None,
    format: str = "parquet",
    clip=None,
    engine: str = "incremental",
    x: str | None = None,
    y: str | None = None,
    crs=None,
    seed: int = 0,
    halo_scale: float = 1.0,
    delaunay=False,
) -> Result:
    """The clipped Voronoi cells of a Dask DataFrame or array of points, built tile by tile on a cluster.

    Every cell equals, bit for bit, the cell ``tvoronoi.voronoi`` gives the same row (see tvoronoi.tiles).
    With ``delaunay``, also the Delaunay triangles, each from the task of its lowest-numbered site (see
    tvoronoi.tile_delaunay): those of ``tvoronoi.voronoi``, with every polygon of four or more
    cocircular sites cut into a fan from its lowest-numbered site (``canonical_triangles``).

    Parameters
    ----------
    points : dask.dataframe.DataFrame or dask.array.Array of shape (n, 2)
        A DataFrame's x/y columns are found by name (x/y, lon/lat, easting/northing...) unless ``x`` and
        ``y`` name them; its other columns are properties, carried with their sites.
    client : distributed.Client, optional
        The cluster; by default the current client.
    bbox : (xmin, ymin, xmax, ymax), optional
        The box of the cells; by default the sites' bounding box grown by 10% (as ``tvoronoi.voronoi``).
    tiles : int, optional
        Tiles (tasks per round); by default from n and the workers.
    to : str, optional
        A directory to write the cells to, one part per task: GeoParquet parts with ``_metadata`` and
        ``_common_metadata`` (pyarrow and geopandas read the directory as one table), or GeoJSONSeq parts.
    format : {"parquet", "geojsonseq"}
        The parts' format with ``to``.
    clip : shapely Polygon or MultiPolygon, optional
        As in ``tvoronoi.voronoi``: the cells of the sites inside, cut to the region.
    engine : {"incremental", "fortune"}
    crs : optional
        The coordinates' CRS, recorded in the GeoParquet metadata.
    halo_scale : float
        Multiplies the first halos (tests use a small one to force more rounds).
    delaunay : bool or str, optional
        True: the triangles as a Dask DataFrame too; a directory: the triangles written there as parts
        (in ``format``: GeoParquet with ``sites``, three input rows, or GeoJSONSeq with ``"sites"``).

    Returns
    -------
    Result
        ``cells``: a Dask DataFrame with one row per input row, in row order within each part:
        ``site`` (the input row), the properties, ``geometry`` (WKB polygon; None for a repeated point,
        a cell that misses the box, a site outside ``clip``); None when written with ``to``. Also the
        rounds run and the cells still pending after each. ``triangles`` (with ``delaunay=True``): a Dask
        DataFrame of ``a``, ``b``, ``c`` (input rows, counter-clockwise, ``a`` the lowest) and ``geometry``;
        ``triangles_pending_after``: the sites whose triangles were still pending after each round.

    Raises
    ------
    TvoronoiError
        Dask not installed, bad points, box, engine, tiles or output.
    """
    distributed = require_dask()
    import dask

    from tvoronoi.api import as_bbox, check_engine, default_bbox

    check_engine(engine)
    if format not in FORMATS:
        raise TvoronoiError(f"unknown format {format!r}: choose one of {', '.join(FORMATS)}")
    if clip is not None:
        from tvoronoi.region import as_region

        clip = as_region(clip)
    delaunay_to = None if isinstance(delaunay, bool) or delaunay is None else delaunay
    if delaunay_to is not None and to is not None and os.path.abspath(str(delaunay_to)) == os.path.abspath(str(to)):
        raise TvoronoiError(f"the cells and the triangles would go to one directory {to}; choose two")
    client = client if client is not None else distributed.get_client()
    frame, xname, yname = _as_frame(points, x, y)
    properties = tuple(str(c) for c in frame.columns if str(c) not in (xname, yname))
    from tvoronoi.writers.geojson_diagram import property_renames

    renames = {**property_renames(list(properties)), **({GEOMETRY: GEOMETRY + "_2"} if GEOMETRY in properties else {})}
    parts = frame.to_delayed()
    workers = max(
        1, len(client.scheduler_info(n_workers=-1).get("workers", {})) if hasattr(client, "scheduler_info") else 1
    )

    # one pass: counts, extent, sample
    n_tiles_guess = tiles if tiles is not None else 4 * workers
    per_part = max(1, (SAMPLE_PER_TILE * n_tiles_guess) // max(1, len(parts)))
    futures = client.compute(
        [dask.delayed(_summary)(p, xname, yname, per_part, seed, clip, k, bool(delaunay)) for k, p in enumerate(parts)]
    )
    try:
        summaries = client.gather(futures)
    except TvoronoiError:
        raise
    except Exception as exc:  # a partition that cannot be read: name the first that failed
        failed = next((k for k, f in enumerate(futures) if f.status == "error"), None)
        raise PartitionError(failed, None, f"cannot be read ({exc.__class__.__name__}: {exc})") from None
    counts = [s["n"] for s in summaries]
    m = int(sum(s["m"] for s in summaries))
    if m == 0:
        where = "inside the clip region" if clip is not None else "in the input"
        raise TvoronoiError(f"no points {where}: nothing to build")
    if tiles is None:
        tiles = default_tiles(m, workers)
    extents = np.array([s["extent"] for s in summaries if s["extent"] is not None])
    extent = (
        float(extents[:, 0].min()),
        float(extents[:, 1].min()),
        float(extents[:, 2].max()),
        float(extents[:, 3].max()),
    )
    if bbox is not None:
        box = as_bbox(bbox)
    elif clip is not None:
        from tvoronoi.region import region_box

        box = region_box(clip)
    else:
        box = default_bbox(np.array([extent[:2], extent[2:]]))
    sample = np.concatenate([s["sample"] for s in summaries])
    plan = plan_tiles(sample, tiles, extent, box, m)
    plan = Plan(plan.rects, plan.halos * halo_scale, plan.extent, plan.box)
    firsts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    hull = None
    if delaunay:
        ids = np.concatenate([firsts[k] + s["hull"][0] for k, s in enumerate(summaries)])
        hull = Hull.of(np.concatenate([s["hull"][1] for s in summaries]), ids)
    from tvoronoi.writers.parts import finish_directory, prepare_directory, remove_directory

    written = [d for d in (to, delaunay_to) if d is not None]
    for k, directory in enumerate(written):
        try:
            prepare_directory(directory)
        except TvoronoiError:
            for done in written[:k]:
                remove_directory(done)
            raise
    job = Job(
        xname,
        yname,
        properties,
        renames,
        plan,
        engine,
        clip,
        None if to is None else str(to),
        format,
        crs,
        bool(delaunay),
        None if delaunay_to is None else str(delaunay_to),
        hull,
    )

    try:
        run = _rounds(client, plan, job, parts, summaries, firsts)
        names: tuple[str, ...] = ()
        tri_names: tuple[str, ...] = ()
        if to is not None:
            names = tuple(client.gather(run.cells))
            finish_directory(to, [name for name in names if name], format, crs)
        if delaunay_to is not None:
            tri_names = tuple(client.gather(run.triangles))
            finish_directory(delaunay_to, [name for name in tri_names if name], format, crs)
    except BaseException:
        for directory in written:  # no half-written dataset left behind
            remove_directory(directory)
        raise
    import dask.dataframe as dd

    cells = None if to is not None else dd.from_delayed(run.cells, meta=_meta(frame._meta, job), verify_meta=False)
    triangles = None
    if delaunay and delaunay_to is None:
        triangles = dd.from_delayed(run.triangles, meta=_triangles_meta(), verify_meta=False)
    return Result(
        cells,
        run.rounds,
        tuple(run.pending_after),
        plan.n_tiles,
        names,
        triangles,
        tuple(run.triangles_pending_after),
        tri_names,
    )


def _triangles_meta():
    import pandas as pd

    return pd.DataFrame(
        {
            "a": pd.Series(dtype="int64"),
            "b": pd.Series(dtype="int64"),
            "c": pd.Series(dtype="int64"),
            GEOMETRY: pd.Series(dtype=_binary_dtype()),
        }
    )


@dataclass
class _Run:
    cells: list
    triangles: list
    rounds: int
    pending_after: list
    triangles_pending_after: list
    token: str = ""


def _run_units(client, pieces: list, calls: list, token: str, run=None) -> list:
    """Run ``run(pieces[g], *calls[g])`` (``_run_tile`` by default) for every unit g of a round, each on a
    worker thread as it frees up: [(cells, triangles, pending cells, pending triangles) futures] in unit
    order.

    Given all at once, the scheduler placed a round's tiles by where their pieces lay, before it knew
    their cost: 6 of 10 equal tiles on one of two workers, the other then idle for a third of the run.
    Here each worker thread gets a unit, and the worker that finishes one gets the next (a preference:
    another worker takes it if that one is gone). The threads are counted again as units finish, so that
    workers that join during a round get units too. A unit that fails stops the round at once.
    """
    import operator
    from collections import Counter

    from distributed import as_completed

    outputs: list = [None] * len(calls)
    running = as_completed()
    busy: Counter = Counter()  # units started on each worker and not yet done
    meant: dict = {}  # the worker each running unit was given to

    def start(g: int, worker) -> None:
        where = {} if worker is None else {"workers": [worker], "allow_other_workers": True}
        whole = client.submit(
            run or _run_tile, pieces[g], *calls[g], key=f"tvoronoi-tile-{token}-{g}", pure=False, **where
        )
        outputs[g] = [
            client.submit(operator.getitem, whole, j, key=f"tvoronoi-tile-{token}-{g}-{j}", pure=False)
            for j in range(4)
        ]
        busy[worker] += 1
        meant[whole.key] = worker
        running.add(whole)
        pieces[g] = None  # the task holds them now: each is freed once the task is done

    def fill(waiting: list) -> None:
        # a unit for every free thread of the workers there are now (all to the scheduler's choice while
        # it names none)
        threads = client.nthreads() if hasattr(client, "nthreads") else {}
        if not threads:
            if not busy:
                start(waiting.pop(), None)
            return
        for worker, count in sorted(threads.items()):
            while waiting and busy[worker] < count:
                start(waiting.pop(), worker)

    waiting = list(range(len(calls)))[::-1]  # the next unit last
    if waiting and hasattr(client, "wait_for_workers"):
        client.wait_for_workers(1)
    if waiting:
        fill(waiting)
    for done in running:
        if done.status != "finished":
            done.result()  # raises the unit's error: the round stops here
        busy[meant.pop(done.key)] -= 1
        if waiting:
            fill(waiting)
    return outputs


def _rounds(client, plan: Plan, job: Job, parts: list, summaries: list, firsts: np.ndarray) -> _Run:
    """Run the rounds: the tasks' outputs as futures (cells, triangles), rounds, what was pending after each."""
    import dask

    xname, yname, properties, clip = job.x, job.y, job.properties, job.clip
    # rounds: every tile in the first; then each group of pending cells, or of sites with pending
    # triangles (group_reaches), with the box it needs, grown by the tile's halo doubled each round
    units: list[tuple[int, np.ndarray | None, Region | None, str]] = [
        (t, None, None, BOTH) for t in range(plan.n_tiles)
    ]
    import uuid

    run = _Run([], [], 0, [], [], token=uuid.uuid4().hex)
    round_ = 0
    while units:
        round_ += 1
        if round_ > MAX_ROUNDS:
            raise TvoronoiError("the tiles' regions stopped growing before every cell was certified")
        regions = [plan.region(t, round_, box_needed) for t, _, box_needed, _ in units]
        # each unit reads the partitions whose sites reach its region (all of them for shuffled input; a
        # few for input sorted in space), one piece at least so that the task knows the columns; each
        # partition is read once a round, for all the units it serves
        reach = [[k for k, s in enumerate(summaries) if _meets(s["extent_all"], region)] or [0] for region in regions]
        serves: dict[int, list[int]] = {}
        for u, ks in enumerate(reach):
            for k in ks:
                serves.setdefault(k, []).append(u)
        pieces: list[list] = [[] for _ in units]
        for k, us in serves.items():
            chosen = dask.delayed(_select, nout=len(us))(
                parts[k], int(firsts[k]), xname, yname, [regions[u] for u in us], list(properties), clip
            )
            for j, u in enumerate(us):
                pieces[u].append(chosen[j])
        calls = []
        for g, (t, group, _, kind) in enumerate(units):
            name = f"part-r{round_:02d}-t{t:05d}" + ("" if group is None else f"-g{g:05d}")
            calls.append((t, regions[g], group, kind, job, round_, name))
        flat = client.compute([piece for unit in pieces for piece in unit])
        starts = np.cumsum([0] + [len(unit) for unit in pieces])
        ready = [flat[starts[g] : starts[g + 1]] for g in range(len(pieces))]
        del flat
        outputs = _run_units(client, ready, calls, f"{run.token}-r{round_}")
        cells_f = [out[0] for out in outputs]
        tris_f = [out[1] for out in outputs]
        left_cells, left_tris = client.gather([out[2] for out in outputs]), client.gather([out[3] for out in outputs])
        next_units: list[tuple[int, np.ndarray | None, Region | None, str]] = []
        for (t, _, _, kind), cells, tris, lc, lt in zip(units, cells_f, tris_f, left_cells, left_tris):
            if kind != TRIANGLES:
                run.cells.append(cells)
                next_units += [(t, ids, b, CELLS) for ids, b in group_reaches(lc[0], lc[1], plan.margin(t, round_))]
            if job.delaunay and kind != CELLS:
                run.triangles.append(tris)
                next_units += [(t, ids, b, TRIANGLES) for ids, b in group_reaches(lt[0], lt[1], plan.margin(t, round_))]
        run.pending_after.append(sum(len(lc[0]) for lc in left_cells if lc is not None))
        if job.delaunay:
            run.triangles_pending_after.append(sum(len(lt[0]) for lt in left_tris if lt is not None))
        units = next_units
    run.rounds = round_
    return run


def local_client(workers: int | None = None, *, quiet: bool = False):
    """A LocalCluster on this machine (one single-threaded worker process per core by default) and its client.

    ``quiet`` keeps the cluster's own log lines (a task's failure, told again by the exception) off stderr.
    The workers run without the ``MALLOC_TRIM_THRESHOLD_`` Dask's nanny sets by default (see
    ``WORKER_ENVIRON_UNSET``; one set in this process's environment is kept) and without Dask's
    statistical profiler (``LOCAL_WORKER_CONFIG``): the dashboard's profile stays empty.
    """
    import logging

    import dask

    distributed = require_dask()
    if workers is None:
        try:
            workers = len(os.sched_getaffinity(0))
        except AttributeError:
            workers = os.cpu_count() or 1
    unset = {f"distributed.nanny.pre-spawn-environ.{name}": None for name in WORKER_ENVIRON_UNSET}
    # the nannies take the configuration in force as they start, and hand it to their workers
    with dask.config.set({**unset, **LOCAL_WORKER_CONFIG}):
        cluster = distributed.LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            silence_logs=logging.CRITICAL if quiet else logging.WARN,
        )
    return distributed.Client(cluster)


def connect(address: str, timeout: float = 10.0):
    """A client of the scheduler at ``address`` (tcp://HOST:PORT), or a TvoronoiError naming it."""
    distributed = require_dask()
    try:
        return distributed.Client(address, timeout=timeout)
    except (OSError, TimeoutError) as exc:
        raise TvoronoiError(
            f"cannot reach the Dask scheduler at {address} ({exc.__class__.__name__}: {exc}); start one with "
            f"`dask scheduler` and workers with `dask worker {address}`, or use --dask local"
        ) from None
