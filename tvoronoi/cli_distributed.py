"""`tvoronoi batch INPUT -o DIR --dask ... [--delaunay DIR]`: point files read in partitions, cells (and
triangles) written as parts by the tasks."""

from __future__ import annotations

import glob
import os
import re
import sys

import numpy as np

from tvoronoi.errors import TvoronoiError

# local, local:WORKERS, or a scheduler's address
_LOCAL = re.compile(r"local(?::(?P<workers>[0-9]+))?")
_ADDRESS = re.compile(r"(?:tcp|tls|ucx|inproc)://[^\s/]+(?::[0-9]+)?")
CSV_EXTENSIONS = (".csv", ".tsv", ".txt")
PARQUET_EXTENSIONS = (".parquet", ".geoparquet", ".pq")
# seconds to wait for a scheduler before saying it cannot be reached
CONNECT_TIMEOUT = 5.0
# bytes of CSV per partition: a few hundred thousand rows, a small share of a worker's memory
CSV_BLOCKSIZE = "64MB"


def parse_dask(text: str) -> tuple[str, int | None]:
    """``--dask``: ("local", workers or None) or ("address", None); errors name the value.

    >>> parse_dask("local:3"), parse_dask("tcp://10.0.0.5:8786")
    (('local', 3), ('tcp://10.0.0.5:8786', None))
    """
    local = _LOCAL.fullmatch(text)
    if local:
        workers = local.group("workers")
        if workers is not None and int(workers) < 1:
            raise TvoronoiError(f"--dask {text!r}: a local cluster needs at least one worker")
        return "local", None if workers is None else int(workers)
    if _ADDRESS.fullmatch(text):
        return text, None
    raise TvoronoiError(
        f"--dask {text!r}: give local (a cluster of this machine's cores), local:WORKERS, "
        f"or a scheduler's address such as tcp://HOST:8786"
    )


def input_files(spec: str) -> list[str]:
    """The point files of INPUT: a file, a directory (its CSV and Parquet files) or a glob, in sorted order."""
    if spec == "-":
        raise TvoronoiError("--dask reads files in partitions, not stdin: give a file, a directory or a glob")
    if os.path.isdir(spec):
        files = sorted(
            os.path.join(spec, name)
            for name in os.listdir(spec)
            if name.lower().endswith(CSV_EXTENSIONS + PARQUET_EXTENSIONS) and not name.startswith(("_", "."))
        )
        if not files:
            raise TvoronoiError(f"{spec}: the directory holds no CSV or Parquet file")
        return files
    if glob.has_magic(spec):
        files = sorted(path for path in glob.glob(spec) if os.path.isfile(path))
        if not files:
            raise TvoronoiError(f"{spec}: no file matches")
        return files
    if not os.path.isfile(spec):
        raise TvoronoiError(f"{spec}: no such file")
    return [spec]


def read_partitions(files: list[str], fmt: str | None, delimiter: str | None):
    """A Dask DataFrame over the files (row order: the files in order, each from its start), and where each
    partition comes from: [(path, kind, the file's first partition, separator)], to name the file and line of a bad row."""
    import dask.dataframe as dd

    kinds = {_kind(path, fmt) for path in files}
    if len(kinds) > 1:
        raise TvoronoiError(f"the input mixes CSV and Parquet files ({files[0]}, ...): give one kind")
    kind = kinds.pop()
    sep = delimiter or ("\t" if files[0].lower().endswith(".tsv") else ",")
    frames: list = []
    sources: list[tuple[str, str, int, str]] = []
    for path in files:
        try:
            if kind == "parquet":
                frame = dd.read_parquet(path)
                if "geometry" in frame.columns:
                    frame = frame.map_partitions(_geometry_to_xy, meta=_geometry_meta(frame._meta))
            else:
                frame = dd.read_csv(path, sep=sep, blocksize=CSV_BLOCKSIZE)
        except (OSError, ValueError) as exc:
            raise TvoronoiError(f"{path}: cannot be read in partitions ({exc})") from None
        first = len(sources)
        sources += [(path, kind, first, sep)] * frame.npartitions
        frames.append(frame)
    return (frames[0] if len(frames) == 1 else dd.concat(frames)), sources


def locate(error, frame, sources: list, client) -> str:
    """Where a PartitionError happened: the file, and the line (CSV) or 0-based row (Parquet) in it."""
    if error.partition is None or not 0 <= error.partition < len(sources):
        return "the input"
    path, kind, first, _ = sources[error.partition]
    if error.row is None:
        return path
    # the rows of the same file's earlier partitions
    before = 0
    if error.partition > first:
        lengths = frame.partitions[first : error.partition].map_partitions(len)
        before = int(sum(client.compute(lengths).result()))
    row = before + error.row
    if kind == "parquet":
        return f"{path}, row {row} (0-based)"
    line = _csv_line(path, row)
    return f"{path}, line {line}" if line is not None else f"{path}, data row {row} (0-based)"


def _bad_csv_value(error, frame, sources: list, x: str | None, y: str | None) -> str | None:
    """A CSV partition that failed as a whole because a coordinate is not a number where the first rows
    were numbers (Dask took the column for numbers): the file's first such value, named by its line."""
    import pandas as pd

    from tvoronoi.distributed import coordinate_columns

    if error.row is not None or error.partition is None or not 0 <= error.partition < len(sources):
        return None
    path, kind, _, _ = sources[error.partition]
    if kind != "csv":
        return None
    names = coordinate_columns(frame, x, y)
    seen = 0
    try:
        chunks = pd.read_csv(
            path,
            sep=sources[error.partition][3],
            usecols=list(names),
            dtype=str,
            chunksize=1_000_000,
            keep_default_na=False,
        )
        for chunk in chunks:
            for name in names:
                text = chunk[name].to_numpy(object)
                values = pd.to_numeric(chunk[name], errors="coerce").to_numpy(float)
                bad = ~np.isfinite(values)
                if bad.any():
                    k = int(np.flatnonzero(bad)[0])
                    line = _csv_line(path, seen + k)
                    where = f"{path}, line {line}" if line is not None else f"{path}, data row {seen + k} (0-based)"
                    return (
                        f"{where}: {name} is {text[k]!r}, not a finite number; drop or fix that row (and any like it)"
                    )
            seen += len(chunk)
    except (OSError, ValueError):
        return None
    return None


def _csv_line(path: str, row: int) -> int | None:
    """The line of a CSV file where data row ``row`` (0-based, after the header, blank lines skipped) starts."""
    import csv

    with open(path, newline="", encoding="utf-8", errors="replace") as stream:
        reader = csv.reader(stream)
        previous = 0
        seen = -1  # the header is row -1
        for record in reader:
            if record:
                if seen == row:
                    return previous + 1
                seen += 1
            previous = reader.line_num
    return None


def _kind(path: str, fmt: str | None) -> str:
    if fmt in ("csv", "parquet"):
        return fmt
    if fmt is not None:
        raise TvoronoiError(f"--format {fmt}: with --dask the input is CSV or Parquet")
    return "parquet" if path.lower().endswith(PARQUET_EXTENSIONS) else "csv"


def _geometry_to_xy(part):
    """A GeoParquet partition's WKB points as x and y columns (the geometry column dropped)."""
    import numpy as np
    import shapely

    geoms = shapely.from_wkb(part["geometry"].to_numpy(dtype=object, na_value=None))
    xy = shapely.get_coordinates(geoms) if len(geoms) else np.empty((0, 2))
    if len(xy) != len(part):
        raise TvoronoiError("a GeoParquet input holds geometries that are not single points")
    out = part.drop(columns=["geometry"])
    out.insert(0, "x", xy[:, 0])
    out.insert(1, "y", xy[:, 1])
    return out


def _geometry_meta(meta):
    import numpy as np

    out = meta.drop(columns=["geometry"])
    out.insert(0, "x", np.empty(0))
    out.insert(1, "y", np.empty(0))
    return out


def _column(frame, sel: str | None) -> str | None:
    """--x/--y: a column name, or a 0-based index."""
    if sel is None:
        return None
    names = [str(c) for c in frame.columns]
    if sel in names:
        return sel
    if sel.isdigit() and int(sel) < len(names):
        return names[int(sel)]
    raise TvoronoiError(f"no column {sel!r}: the columns are {', '.join(names)}")


def client_for(spec: str):
    """A client of a new LocalCluster or of the scheduler named by --dask."""
    from tvoronoi.distributed import connect, local_client

    where, workers = parse_dask(spec)
    if where == "local":
        return local_client(workers, quiet=True)
    return connect(where, timeout=CONNECT_TIMEOUT)


def run(args, output_format: str, bbox, region, quiet: bool) -> None:
    """The batch command on Dask: read INPUT in partitions, build tile by tile, write OUTPUT as a directory."""
    from tvoronoi.distributed import PartitionError, require_dask, voronoi

    require_dask()
    parse_dask(args.dask)
    if args.tiles is not None and args.tiles < 1:
        raise TvoronoiError(f"--tiles {args.tiles}: give a positive number of tiles")
    for flag, value in (("--lloyd", args.lloyd), ("--precision", args.precision)):
        if value is not None:
            raise TvoronoiError(f"{flag} is not available with --dask yet; run without --dask for it")
    if output_format not in ("parquet", "geojsonseq"):
        raise TvoronoiError(
            "with --dask, OUTPUT is a directory of parts: --to parquet (GeoParquet, the default) or geojsonseq"
        )
    if args.delaunay == "-":
        raise TvoronoiError('with --dask, --delaunay names a new directory of parts, not "-"')
    files = input_files(args.input)
    frame, sources = read_partitions(files, args.format, args.delimiter)
    x, y = _column(frame, args.x), _column(frame, args.y)
    client = client_for(args.dask)
    try:
        result = voronoi(
            frame,
            client=client,
            bbox=bbox,
            tiles=args.tiles,
            to=args.output,
            format=output_format,
            clip=region,
            engine=args.engine,
            x=x,
            y=y,
            crs=args.crs,
            delaunay=False if args.delaunay is None else args.delaunay,
        )
    except PartitionError as exc:
        # partitions are numbered through the files in sorted order (a CSV file may hold several)
        found = _bad_csv_value(exc, frame, sources, x, y)
        raise TvoronoiError(found or exc.explain(locate(exc, frame, sources, client))) from None
    finally:
        cluster = getattr(client, "cluster", None)
        client.close()
        if cluster is not None:
            cluster.close()
    if not quiet:
        parts = sum(1 for name in result.parts if name)
        print(
            f"tvoronoi: {len(files)} file(s) -> {args.output}: {parts} parts from {result.n_tiles} tiles, "
            f"{result.rounds} round(s) (cells left after each: {', '.join(map(str, result.pending_after))})",
            file=sys.stderr,
        )
        if args.delaunay is not None:
            parts = sum(1 for name in result.triangle_parts if name)
            print(
                f"tvoronoi: Delaunay triangles -> {args.delaunay}: {parts} parts (sites with triangles left after "
                f"each round: {', '.join(map(str, result.triangles_pending_after))})",
                file=sys.stderr,
            )
