"""`tvoronoi batch INPUT -o DIR --dask ... [--delaunay DIR]`: point files read in partitions, cells (and
triangles) written as parts by the tasks."""

from __future__ import annotations

import glob
import os
import re
import sys

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
        raise TvoronoiError('--dask reads files in partitions, not stdin: give a file, a directory or a glob')
    if os.path.isdir(spec):
        files = sorted(os.path.join(spec, name) for name in os.listdir(spec)
                       if name.lower().endswith(CSV_EXTENSIONS + PARQUET_EXTENSIONS) and not name.startswith(("_", ".")))
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
    """A Dask DataFrame over the files (row order: the files in order, each from its start)."""
    import dask.dataframe as dd

    kinds = {_kind(path, fmt) for path in files}
    if len(kinds) > 1:
        raise TvoronoiError(f"the input mixes CSV and Parquet files ({files[0]}, ...): give one kind")
    kind = kinds.pop()
    try:
        if kind == "parquet":
            frame = dd.read_parquet(files)
            if "geometry" in frame.columns:
                frame = frame.map_partitions(_geometry_to_xy, meta=_geometry_meta(frame._meta))
            return frame
        sep = delimiter or ("\t" if files[0].lower().endswith(".tsv") else ",")
        return dd.read_csv(files, sep=sep, blocksize=CSV_BLOCKSIZE)
    except (OSError, ValueError) as exc:
        raise TvoronoiError(f"{files[0]}: cannot be read in partitions ({exc})") from None


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
    from tvoronoi.distributed import require_dask, voronoi

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
    frame = read_partitions(files, args.format, args.delimiter)
    x, y = _column(frame, args.x), _column(frame, args.y)
    client = client_for(args.dask)
    try:
        result = voronoi(frame, client=client, bbox=bbox, tiles=args.tiles, to=args.output, format=output_format,
                         clip=region, engine=args.engine, x=x, y=y, crs=args.crs,
                         delaunay=False if args.delaunay is None else args.delaunay)
    except TvoronoiError as exc:
        if str(exc).startswith(("partition ", "the points cannot be read")):
            # partitions are numbered through the files in sorted order (a CSV file may hold several)
            raise TvoronoiError(f"{args.input}: {exc}") from None
        raise
    finally:
        cluster = getattr(client, "cluster", None)
        client.close()
        if cluster is not None:
            cluster.close()
    if not quiet:
        parts = sum(1 for name in result.parts if name)
        print(f"tvoronoi: {len(files)} file(s) -> {args.output}: {parts} parts from {result.n_tiles} tiles, "
              f"{result.rounds} round(s) (cells left after each: {', '.join(map(str, result.pending_after))})",
              file=sys.stderr)
        if args.delaunay is not None:
            parts = sum(1 for name in result.triangle_parts if name)
            print(f"tvoronoi: Delaunay triangles -> {args.delaunay}: {parts} parts (sites with triangles left after "
                  f"each round: {', '.join(map(str, result.triangles_pending_after))})", file=sys.stderr)
