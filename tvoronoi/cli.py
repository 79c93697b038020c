"""The console script: `tvoronoi` starts the terminal UI, `tvoronoi batch` writes GeoJSON cells."""

from __future__ import annotations

import argparse
import os
import re
import signal
import sys
import warnings
from contextlib import contextmanager
from typing import TYPE_CHECKING

from tvoronoi import __version__
from tvoronoi.api import ENGINES, INSERTION_ORDERS, as_bbox, check_engine
from tvoronoi.errors import CoordinateRangeError, TvoronoiError
from tvoronoi.fileio import STDIO
from tvoronoi.readers import FORMATS

if TYPE_CHECKING:
    from rich.progress import Progress

PROG = "tvoronoi"
# inputs this large show a progress display (on a terminal, without -q)
PROGRESS_MIN_POINTS = 200_000
PROGRESS_MIN_BYTES = 4 << 20  # a CSV of about 200,000 points
EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130

BATCH_EPILOG = """\
output:
  OUTPUT (by extension or --to) is an RFC 7946 FeatureCollection (.geojson),
  an RFC 8142 GeoJSON sequence with a record separator before each feature
  (.geojsons, as GDAL writes it), one feature per line (.geojsonl, .jsonl:
  GDAL's GeoJSONSeq driver and jq read both), or GeoParquet 1.1 (.parquet,
  needs pyarrow). Each holds one Polygon per distinct site, in
  input order, with properties {"site": ROW, ...the row's other columns} and
  "duplicates": [ROWS] where later rows repeat the site. A cell that misses
  a --bbox leaving its site outside has "geometry": null.

  An existing OUTPUT or --delaunay FILE is not replaced unless --force is
  given, and then only by renaming a complete new file over it: a failed run
  leaves every existing file as it was, and no half-written file behind. A
  symbolic link keeps pointing where it pointed; the file it names is
  replaced. Character devices (/dev/null), named pipes, /dev/stdout and "-"
  are written directly, with or without --force, and never replaced.

  --clip FILE cuts the cells to the union of the Polygons and MultiPolygons
  of a GeoJSON file (in the coordinates of the points): only the sites the
  region covers get cells, which tile the region; a site outside it is
  written with "geometry": null (a warning gives their count). --lloyd N
  first moves every site N times to the centroid of its cell (within the
  box, or the clip region) and writes the cells of the moved sites; a
  centroid outside its cell (in a hole or notch of the region) gives way
  to the cell's nearest point, just inside: no site leaves the region, and
  the sites outside it stay where they are.

  --dask local[:WORKERS] or --dask tcp://HOST:PORT builds the cells tile by
  tile on a Dask cluster (pip install 'tvoronoi[dask]'), the same cells bit
  for bit: INPUT may then be a CSV/Parquet file, a directory or a glob, and
  OUTPUT is a new directory of GeoParquet parts (with _metadata) or, with
  --to geojsonseq, of GeoJSONSeq parts; --tiles N sets the tiles.

  A progress display appears on stderr for inputs of 200,000 points or more
  when stderr is a terminal and -q is not given.

exit status:
  0    success (warnings may have been printed)
  1    an output could not be written (disk full, permission denied, ...),
       or the reader of a pipe left early (| head), which is not reported
  2    bad input or options: unreadable or malformed point file, bad --bbox,
       unknown or unavailable engine, an existing output without --force
  130  interrupted
"""


# output formats: --to names, and the extensions that choose them
OUTPUT_FORMATS = ("geojson", "geojsonseq", "geojsonl", "parquet")
OUTPUT_EXTENSIONS = {
    ".geojson": "geojson",
    ".json": "geojson",
    ".geojsons": "geojsonseq",
    ".geojsonseq": "geojsonseq",
    ".geojsonl": "geojsonl",
    ".jsonl": "geojsonl",
    ".ndjson": "geojsonl",
    ".parquet": "parquet",
    ".geoparquet": "parquet",
    ".pq": "parquet",
}
GEOJSON_LAYOUT = {"geojson": "collection", "geojsonseq": "seq", "geojsonl": "lines"}
CRS84 = "OGC:CRS84"
LONLAT_BOX = (-180.0, -90.0, 180.0, 90.0)


class OutputError(Exception):
    """An output that could not be written; the message names it."""


def parse_bbox(text: str) -> tuple[float, float, float, float]:
    """Parse ``--bbox XMIN,YMIN,XMAX,YMAX`` with the API's box check; errors name the value given.

    >>> parse_bbox("-1,0,2.5,1e3")
    (-1.0, 0.0, 2.5, 1000.0)
    """
    return as_bbox(
        [part.strip() for part in text.split(",")],
        what=f"--bbox {text!r}",
        names=("XMIN", "YMIN", "XMAX", "YMAX"),
        sep=",",
    )


def parse_delimiter(text: str) -> str:
    """Parse ``--delimiter``: one character, or "tab" / "\\t" for a tab.

    >>> parse_delimiter("tab"), parse_delimiter(";")
    ('\\t', ';')
    """
    named = {"tab": "\t", "\\t": "\t", "comma": ",", "semicolon": ";", "pipe": "|", "space": " "}
    value = named.get(text.lower(), text)
    if len(value) != 1 or value in '\r\n"':
        raise argparse.ArgumentTypeError(f"{text!r}: give one character, e.g. ';' or 'tab'")
    return value


COMMANDS = ("batch",)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="Exact, fast 2D Voronoi diagrams. Without a command, tvoronoi starts the terminal UI "
        "(on a generated point set, or on FILE: tvoronoi FILE).",
        usage=f"{PROG} [-h] [--version] [FILE | batch ...]",
    )
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    batch = commands.add_parser(
        "batch",
        prog=f"{PROG} batch",  # (argparse would prefix the main parser's whole usage line)
        help="write the Voronoi cells of a point file as GeoJSON or GeoParquet",
        description="Read points, build their Voronoi diagram clipped to a box, and write the cells as GeoJSON, "
        "a GeoJSON sequence or GeoParquet.",
        epilog=BATCH_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    batch.add_argument(
        "input", metavar="INPUT", help='point file (CSV, TSV, text, GeoJSON, .npy, (Geo)Parquet), or "-" for stdin'
    )
    batch.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="OUTPUT",
        help='file of the cells (.geojson, .geojsons, .geojsonl, .parquet), or "-" for stdout',
    )
    batch.add_argument("--engine", choices=ENGINES, default="incremental", help="default: %(default)s")
    batch.add_argument(
        "--bbox",
        metavar="XMIN,YMIN,XMAX,YMAX",
        help="the box bounding the cells; default: the points' bounding box grown by 10%% "
        "of its larger side on every side",
    )
    batch.add_argument(
        "--clip",
        metavar="FILE",
        help="cut the cells to the (Multi)Polygons of a GeoJSON file; sites outside get no cell",
    )
    batch.add_argument(
        "--lloyd",
        type=int,
        metavar="N",
        help="Lloyd relaxation: move each site to its cell's centroid N times (kept inside the --clip region), "
        "then write the cells",
    )
    batch.add_argument(
        "--delaunay",
        metavar="FILE",
        help='also write the Delaunay triangles, in the format of its extension or --to ("-" for '
        "stdout); with --dask, a new directory of parts",
    )
    batch.add_argument("--x", metavar="COL", help="x column of a table: a name, a 0-based index or colN")
    batch.add_argument("--y", metavar="COL", help="y column of a table: a name, a 0-based index or colN")
    batch.add_argument("--format", choices=FORMATS, help="input format; default: from the extension, else the content")
    batch.add_argument(
        "--delimiter",
        metavar="CHAR",
        type=parse_delimiter,
        help='field separator of a CSV input: ",", ";", "tab", "|", ...; default: a tab for .tsv, '
        "else found from the first rows (a ;-separated file may use decimal commas)",
    )
    batch.add_argument(
        "--insertion",
        choices=INSERTION_ORDERS,
        default="brio",
        help="incremental engine: insertion order (default: %(default)s)",
    )
    batch.add_argument("--seed", type=int, default=0, help="seed of the insertion order (default: %(default)s)")
    batch.add_argument(
        "--to",
        choices=OUTPUT_FORMATS,
        help="output format of OUTPUT and --delaunay FILE; default: from the extension "
        "(.geojson, .geojsons, .geojsonl/.jsonl, .parquet), else geojson",
    )
    batch.add_argument(
        "--precision",
        type=int,
        metavar="N",
        help="GeoJSON: round coordinates to N decimal digits (default: the exact doubles, valid cells; "
        "rounding coarser than the cells' detail can make rings touch or cross)",
    )
    batch.add_argument(
        "--crs",
        metavar="AUTH:CODE",
        help="the CRS of the input coordinates, e.g. EPSG:3857, recorded in GeoParquet "
        "(default: the input's own, else OGC:CRS84 for lon/lat columns, else unknown)",
    )
    batch.add_argument(
        "--dask",
        metavar="local[:WORKERS]|tcp://HOST:PORT",
        help="build tile by tile on Dask: a LocalCluster of this machine (local, local:WORKERS) or "
        "an existing scheduler; INPUT may be a CSV/Parquet file, a directory or a glob, read "
        "in partitions, and OUTPUT a new directory of parts (needs tvoronoi[dask])",
    )
    batch.add_argument(
        "--tiles",
        type=int,
        metavar="N",
        help="with --dask: tiles, one task each per round (default: from the points and workers)",
    )
    batch.add_argument("-q", "--quiet", action="store_true", help="no progress display and no warnings")
    batch.add_argument("--force", action="store_true", help="replace an existing OUTPUT or --delaunay FILE")
    return parser


def _join_bbox(argv: list[str]) -> list[str]:
    """Turn "--bbox VALUE" into "--bbox=VALUE", so that a negative XMIN is not taken for an option."""
    out: list[str] = []
    tokens = iter(argv)
    for token in tokens:
        if token == "--":
            out.append(token)
            out.extend(tokens)
            break
        if token == "--bbox":
            value = next(tokens, None)
            out.append(token if value is None else f"--bbox={value}")
        else:
            out.append(token)
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the console script with ``argv`` (default: ``sys.argv[1:]``) and return the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if len(argv) == 1 and argv[0] not in COMMANDS and not argv[0].startswith("-"):
        # tvoronoi FILE: the terminal UI on a point file
        path = argv[0]
        if not os.path.isfile(path):
            print(
                f"{PROG}: error: {path}: no such file (to compute cells without the UI: {PROG} batch INPUT -o OUTPUT)",
                file=sys.stderr,
            )
            return EXIT_USAGE
        return run_tui(path)
    try:
        args = build_parser().parse_args(_join_bbox(argv))
    except SystemExit as e:  # --help, --version, usage errors
        return e.code if isinstance(e.code, int) else EXIT_USAGE
    if args.command is None:
        return run_tui()
    return run_batch(args)


def run_tui(path: str | None = None) -> int:
    """The terminal UI, on the point file ``path`` if given."""
    try:
        from tvoronoi.tui.app import main as tui_main
    except ImportError as e:
        print(f"{PROG}: error: the terminal UI cannot start: {e}", file=sys.stderr)
        return EXIT_FAILURE
    status = tui_main(path)
    return status if isinstance(status, int) else EXIT_OK


def run_batch(args) -> int:
    """Read, build and write; map every expected failure to a one-line message and an exit status."""
    phases = Phases(enabled=not args.quiet and sys.stderr.isatty())
    try:
        with _terminate_as_exit(), phases:
            return _batch(args, phases)
    except TvoronoiError as e:
        _error(str(e))
        return EXIT_USAGE
    except OutputError as e:
        if str(e):
            _error(str(e))
        return EXIT_FAILURE
    except MemoryError:
        _error("out of memory; try fewer points or a machine with more memory")
        return EXIT_FAILURE
    except KeyboardInterrupt:
        _error("interrupted")
        return EXIT_INTERRUPTED


def _batch(args, phases: Phases) -> int:
    import numpy as np

    # a value at the edge of the double range overflows in the box arithmetic; the checks
    # that follow report it in words, so numpy's own warnings are not printed
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return _batch_run(args, phases)


def _batch_run(args, phases: Phases) -> int:
    import numpy as np

    from tvoronoi.api import voronoi
    from tvoronoi.readers import read_points
    from tvoronoi.writers.geojson_diagram import missing_cells, write_cells, write_delaunay
    from tvoronoi.writers.geoparquet import crs_name, projjson
    from tvoronoi.writers.targets import descriptor_of, is_direct, output_file

    bbox = None if args.bbox is None else parse_bbox(args.bbox)
    names = [name for name in (args.output, args.delaunay) if name is not None]
    if names.count(STDIO) > 1:
        raise TvoronoiError('-o and --delaunay cannot both be "-": stdout takes one of them')
    if (
        len(names) == 2
        and STDIO not in names
        and os.path.abspath(names[0]) == os.path.abspath(names[1])
        and not (is_direct(names[0]) and descriptor_of(names[0]) is None)
    ):  # /dev/null takes both
        raise TvoronoiError(f"-o and --delaunay name the same file {names[0]}; choose two names")
    if args.precision is not None and not 0 <= args.precision <= 17:
        raise TvoronoiError(f"--precision {args.precision}: give a number of decimal digits from 0 to 17")
    if args.crs is not None and not _CRS_CODE.fullmatch(args.crs):
        raise TvoronoiError(f"--crs {args.crs!r}: give an authority and a code, e.g. EPSG:3857 or OGC:CRS84")
    formats = {name: _output_format(name, args.to) for name in names}
    if "parquet" in formats.values():
        from tvoronoi.writers.geoparquet import require_pyarrow

        require_pyarrow()
    if args.lloyd is not None and args.lloyd < 0:
        raise TvoronoiError(f"--lloyd {args.lloyd}: give a number of iterations, 0 or more")
    # the engine and its options pass the API's own checks before a large file is read (the box's
    # range against the sites' scale waits for the sites)
    check_engine(args.engine, args.insertion)
    options = dict(engine=args.engine, bbox=bbox, insertion=args.insertion, seed=args.seed)
    region = None
    if args.clip is not None:
        from tvoronoi.readers.clip_region import read_region
        from tvoronoi.region import as_region

        region = as_region(read_region(args.clip), what=f"--clip {args.clip}")
        options["clip"] = region
    if args.dask is not None:
        from tvoronoi import cli_distributed

        if args.output == STDIO:
            raise TvoronoiError('with --dask, OUTPUT is a new directory of parts, not "-"')
        fmt = args.to or OUTPUT_EXTENSIONS.get(os.path.splitext(args.output)[1].lower(), "parquet")
        cli_distributed.run(args, fmt, bbox, region, args.quiet)
        return EXIT_OK
    if args.tiles is not None:
        raise TvoronoiError("--tiles goes with --dask (tiles on a cluster); without it the build is one diagram")

    outputs = {}
    try:
        # creating the temporary files now shows that they can be written, before any work
        for name in names:
            with _writing(name):
                outputs[name] = output_file(name, overwrite=args.force)
        if args.input != STDIO and _size(args.input) >= PROGRESS_MIN_BYTES:
            phases.show()
        with phases.phase("read") as done:
            points = read_points(args.input, x=args.x, y=args.y, fmt=args.format, delimiter=args.delimiter)
            done(f"{len(points):,} points")
        if points.choice is not None and not args.quiet:
            phases.note(f"{points.source}: {points.choice}")
        crs = args.crs or points.crs or (CRS84 if points.lonlat else None)
        if args.crs and points.crs and crs_name(points.crs) != crs_name(args.crs) and not args.quiet:
            phases.warn(
                f"--crs {args.crs} replaces {points.source}'s own CRS {crs_name(points.crs)}; the coordinates "
                "are labelled, not transformed (drop --crs to keep the file's)"
            )
        lonlat = crs is not None and crs_name(crs) in ("OGC:CRS84", "EPSG:4326")
        if "parquet" in formats.values():
            projjson(crs)  # a CRS pyproj does not know fails here, before the build
        geojson_out = [name for name, fmt in formats.items() if fmt != "parquet"]
        if crs is not None and not lonlat and geojson_out and not args.quiet:
            phases.warn(
                f"{', '.join(geojson_out)}: RFC 7946 GeoJSON has no CRS and is read as lon/lat, but the "
                f"coordinates are {crs_name(crs)}; write GeoParquet (.parquet) to keep the CRS"
            )
        if lonlat and not args.quiet:
            beyond = _beyond_lonlat(points.xy)
            if beyond is not None:
                row, what, count = beyond
                others = "" if count == 1 else f" (and {count - 1:,} more sites)"
                phases.warn(
                    f"{points.locate(row)}: {what} lies beyond [-180, 180] x [-90, 90], the range of "
                    f"{crs_name(crs)}{others}; the cells are built in the plane as given: check the "
                    "columns (--x/--y) or give the CRS with --crs"
                )
        if bbox is None and lonlat and region is None:
            # lon/lat: the default box stops at the antimeridian and the poles
            options["bbox"] = _lonlat_box(points.xy)
        if len(points) >= PROGRESS_MIN_POINTS:
            phases.show()
        xy = points.xy
        if args.lloyd:
            from tvoronoi.relax import lloyd

            with phases.phase(f"lloyd x{args.lloyd}"):
                try:
                    xy = lloyd(xy, args.lloyd, **options)
                except CoordinateRangeError as e:
                    raise TvoronoiError(f"{points.source}, {e.explain(points.place)}") from None
        with phases.phase("build") as done:
            try:
                diagram = voronoi(xy, **options)
            except CoordinateRangeError as e:
                raise TvoronoiError(f"{points.source}, {e.explain(points.place)}") from None
            done(f"{len(diagram.triangles):,} triangles")

        repeats = diagram.n_sites - int(np.count_nonzero(diagram.site_of == np.arange(diagram.n_sites)))
        if repeats and not args.quiet:
            phases.warn(
                f"{repeats} repeated point{'s share' if repeats > 1 else ' shares'} the cell of an earlier "
                f'point (see "duplicates" in the output)'
            )
        outside = 0
        if region is not None:
            from tvoronoi.region import ClippedDiagram

            assert isinstance(diagram, ClippedDiagram), "voronoi(clip=...) returns a ClippedDiagram"
            outside = diagram.n_outside
        if outside and not args.quiet:
            which = "sites lie" if outside > 1 else "site lies"
            phases.warn(f'{outside} {which} outside the --clip region {args.clip}: written with "geometry": null')
        missing = len(missing_cells(diagram)) - outside
        if missing and not args.quiet:
            which = "cells miss the box (their sites lie" if missing > 1 else "cell misses the box (its site lies"
            phases.warn(f'{missing} {which} outside --bbox): written with "geometry": null')

        with phases.counter("write cells") as progress, _writing(args.output):
            stream = outputs[args.output].file
            if formats[args.output] == "parquet":
                from tvoronoi.writers.geoparquet import write_cells_parquet

                write_cells_parquet(diagram, points, stream, crs=crs)
            else:
                write_cells(
                    diagram,
                    points,
                    stream,
                    progress=progress,
                    precision=args.precision,
                    layout=GEOJSON_LAYOUT[formats[args.output]],
                )
        if args.delaunay is not None:
            with phases.counter("write triangles") as progress, _writing(args.delaunay):
                stream = outputs[args.delaunay].file
                if formats[args.delaunay] == "parquet":
                    from tvoronoi.writers.geoparquet import write_delaunay_parquet

                    write_delaunay_parquet(diagram, stream, crs=crs)
                else:
                    write_delaunay(
                        diagram,
                        stream,
                        progress=progress,
                        precision=args.precision,
                        layout=GEOJSON_LAYOUT[formats[args.delaunay]],
                    )
        for name, output in outputs.items():
            with _writing(name):
                output.commit()
    except BaseException:
        for output in outputs.values():
            output.discard()
        raise
    return EXIT_OK


_CRS_CODE = re.compile(r"[A-Za-z]+:[A-Za-z0-9]+")


# extensions of formats tvoronoi does not write: an output named so is refused, not filled with GeoJSON
FOREIGN_OUTPUTS = {
    ".gpkg": "GeoPackage",
    ".shp": "shapefile",
    ".fgb": "FlatGeobuf",
    ".kml": "KML",
    ".gml": "GML",
    ".csv": "CSV",
    ".tsv": "TSV",
    ".xlsx": "Excel",
}
FORMAT_NAMES = {"geojson": "GeoJSON", "geojsonseq": "GeoJSONSeq", "geojsonl": "GeoJSON lines", "parquet": "GeoParquet"}


def _output_format(name: str, to: str | None) -> str:
    """The format of an output: --to, else its extension, else GeoJSON.

    Raises TvoronoiError for an extension of a format tvoronoi does not write, and for --to that
    puts text into a file named .parquet, or Parquet into one named as GeoJSON.
    """
    suffix = "" if name == STDIO else os.path.splitext(name)[1].lower()
    if suffix in FOREIGN_OUTPUTS and to is None:
        raise TvoronoiError(
            f"{name}: tvoronoi does not write {FOREIGN_OUTPUTS[suffix]}; name the output .geojson, "
            ".geojsons, .geojsonl or .parquet (ogr2ogr converts them further), or give --to"
        )
    implied = OUTPUT_EXTENSIONS.get(suffix)
    if to is not None:
        # (within the GeoJSON family a name is a convention; Parquet against text is not)
        if implied is not None and (implied == "parquet") != (to == "parquet"):
            raise TvoronoiError(
                f"{name}: --to {to} would write {FORMAT_NAMES[to]} into a file named as "
                f"{FORMAT_NAMES[implied]}; rename it or drop --to"
            )
        return to
    return implied or "geojson"


def _beyond_lonlat(xy) -> tuple[int, str, int] | None:
    """The first site of lon/lat input beyond [-180, 180] x [-90, 90], what is wrong with it, and how
    many such sites there are (None: all within)."""
    import numpy as np

    xs, ys = xy[:, 0], xy[:, 1]
    bad = (np.abs(xs) > 180) | (np.abs(ys) > 90)
    count = int(np.count_nonzero(bad))
    if count == 0:
        return None
    row = int(np.argmax(bad))
    x, y = float(xs[row]), float(ys[row])
    return row, (f"longitude {x:g}" if abs(x) > 180 else f"latitude {y:g}"), count


def _lonlat_box(xy) -> tuple[float, float, float, float] | None:
    """The default box of lon/lat sites, kept within [-180, 180] x [-90, 90] (None: sites outside it)."""
    from tvoronoi.api import default_bbox

    xmin, ymin, xmax, ymax = default_bbox(xy)
    # a column at a time (along axis 0 numpy reduces an (n, 2) array row by row, 30 times slower)
    xs, ys = xy[:, 0], xy[:, 1]
    if xs.min() < -180 or ys.min() < -90 or xs.max() > 180 or ys.max() > 90:
        return None
    box = (max(xmin, -180.0), max(ymin, -90.0), min(xmax, 180.0), min(ymax, 90.0))
    return box if box[0] < box[2] and box[1] < box[3] else None


def _size(path: str) -> int:
    try:
        return os.path.getsize(path)
    except OSError:
        return 0


@contextmanager
def _writing(name: str):
    """Tell an OSError while creating, writing or renaming ``name`` as an OutputError naming it."""
    try:
        yield
    except FileExistsError:
        raise TvoronoiError(f"{name} exists: add --force to replace it, or choose another name") from None
    except BrokenPipeError:
        # the reader of stdout went away (e.g. `| head`): stop quietly, and keep Python
        # from failing again when it flushes stdout at exit
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
        raise OutputError("") from None
    except OSError as e:
        where = "standard output" if name == STDIO else name
        raise OutputError(f"cannot write {where}: {e.strerror or e}") from None


@contextmanager
def _terminate_as_exit():
    """Turn SIGTERM into SystemExit while the batch runs, so that temporary files are removed."""

    def terminate(signum, frame):
        raise SystemExit(128 + signum)

    try:
        previous = signal.signal(signal.SIGTERM, terminate)
    except ValueError:  # not the main thread: leave signals alone
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _error(message: str) -> None:
    print(f"{PROG}: error: {message}", file=sys.stderr)


class Phases:
    """The phases read, build and write as a rich progress display on stderr, or nothing.

    The display starts on :meth:`show` (when the input turns out to be large)
    and only if it is enabled; until then phases run silently.
    """

    def __init__(self, *, enabled: bool):
        self.enabled = enabled
        self.progress: Progress | None = None

    def __enter__(self) -> Phases:
        return self

    def __exit__(self, *exc) -> None:
        if self.progress is not None:
            self.progress.stop()

    def show(self) -> None:
        if not self.enabled or self.progress is not None:
            return
        from rich.console import Console
        from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

        self.progress = Progress(
            SpinnerColumn(finished_text="[green]done"),
            TextColumn("{task.description:<16}"),
            BarColumn(),
            TextColumn("{task.fields[detail]}"),
            TimeElapsedColumn(),
            console=Console(stderr=True),
        )
        self.progress.start()

    @contextmanager
    def phase(self, label: str):
        """A phase of unknown length; the block calls the yielded function with a summary."""
        if self.progress is None:
            yield lambda detail: None
            return
        task = self.progress.add_task(label, total=None, detail="")
        yield lambda detail: self.progress.update(task, detail=detail)
        self.progress.update(task, total=1, completed=1)

    @contextmanager
    def counter(self, label: str):
        """A phase that counts; the block passes the yielded function as a progress(done, total) callback."""
        bar = self.progress
        if bar is None:
            yield None
            return
        task = bar.add_task(label, total=None, detail="")

        def progress(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total, detail=f"{done:,}/{total:,}")

        yield progress
        bar.update(task, total=1, completed=1)

    def note(self, message: str) -> None:
        """Tell what was chosen for the user (e.g. the x and y columns)."""
        self._print(f"{PROG}: {message}")

    def warn(self, message: str) -> None:
        self._print(f"{PROG}: warning: {message}")

    def _print(self, line: str) -> None:
        if self.progress is not None:
            self.progress.console.print(line, markup=False, highlight=False)
        else:
            print(line, file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
