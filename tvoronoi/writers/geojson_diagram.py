"""GeoJSON out: Voronoi cells and Delaunay triangles, streamed in chunks and written atomically."""

from __future__ import annotations

from typing import Callable

import numpy as np
import orjson

from tvoronoi.errors import TvoronoiError
from tvoronoi.fileio import gc_paused
from tvoronoi.readers.text_column import TextColumn
from tvoronoi.writers import forked
from tvoronoi.writers.background import background
from tvoronoi.writers.targets import open_output

__all__ = ["write_cells", "write_delaunay", "missing_cells"]

# features serialized per orjson call: large enough to amortise numpy and orjson
# calls, small enough that a chunk of text stays a few megabytes
CHUNK_FEATURES = 10_000
# a ring with fewer distinct points has no area; such a cell is written as null
MIN_RING_POINTS = 3
# property names tvoronoi writes itself; a site property of the same name is renamed
RESERVED = ("site", "duplicates")

ProgressCallback = Callable[[int, int], None]

_OPT_NUMPY = orjson.OPT_SERIALIZE_NUMPY
_CLOSE_BRACKET = ord("]")
# one feature per line; %b are the ring's positions "[x,y],...,[x,y]" and the properties object
_POLYGON = b'{"type":"Feature","geometry":{"type":"Polygon","coordinates":[[%b]]},"properties":%b}'
_NULL = b'{"type":"Feature","geometry":null,"properties":%b}'
_GEOMETRY = b'{"type":"Feature","geometry":%b,"properties":%b}'
_TRIANGLE = b'{"type":"Feature","geometry":{"type":"Polygon","coordinates":[[%b]]},"properties":{"sites":[%d,%d,%d]}}'
_SEPARATOR = b",\n"
# a Polygon feature up to its ring, and from its ring to the value of "site"
_FEATURE_OPEN = b'{"type":"Feature","geometry":{"type":"Polygon","coordinates":[['
_RING_CLOSE = b']]},"properties":{"site":'

# the text of a NaN row between two rings (see ring_chunk)
_RING_BREAK = b",[null,null],"
# GeoJSON text sequences (RFC 8142): each feature opens with a record separator and ends a line
RS = b"\x1e"
# how features are framed: a FeatureCollection, an RFC 8142 sequence, or one feature per line
LAYOUTS = ("collection", "seq", "lines")


class _Framing:
    """Writes features in chunks as a FeatureCollection or as a GeoJSON sequence."""

    def __init__(self, stream, layout: str, bbox: bytes, *, opened: bool = False):
        """``opened``: the features go on after others (a later part of an output): no header."""
        if layout not in LAYOUTS:
            raise TvoronoiError(f"unknown GeoJSON layout {layout!r}; choose one of {', '.join(LAYOUTS)}")
        self.stream, self.layout, self.first = stream, layout, not opened
        if layout == "collection" and not opened:
            stream.write(b'{"type":"FeatureCollection",%b"features":[\n' % bbox)

    def write(self, features: list[bytes]) -> None:
        if not features:
            return
        if self.layout == "collection":
            if not self.first:
                self.stream.write(_SEPARATOR)
            self.stream.write(_SEPARATOR.join(features))
        else:
            prefix = RS if self.layout == "seq" else b""
            self.stream.write(b"".join(b"%b%b\n" % (prefix, feature) for feature in features))
        self.first = False

    def joined(self, pieces: list[bytes], feature_start: bytes, feature_end: bytes) -> None:
        """Write a chunk of features given as one list of pieces: each feature's own pieces, the
        last of which (``feature_end`` + the break + ``feature_start``) closes it and opens the next.
        ``feature_start`` opens the first feature and ``feature_end`` closes the last."""
        if not pieces:
            return
        if self.layout == "collection":
            lead, tail = (b"" if self.first else _SEPARATOR), b""
        else:
            lead, tail = (RS if self.layout == "seq" else b""), b"\n"
        pieces[-1] = feature_end + tail
        pieces.insert(0, lead + feature_start)
        self.stream.write(b"".join(pieces))
        self.first = False

    def between(self) -> bytes:
        """The bytes between two features."""
        return _SEPARATOR if self.layout == "collection" else (b"\n" + RS if self.layout == "seq" else b"\n")

    def close(self) -> None:
        if self.layout == "collection":
            self.stream.write(b"\n]}\n")


def _rounded(xy: np.ndarray, precision: int | None) -> np.ndarray:
    """Coordinates rounded to ``precision`` decimal digits (None: as computed)."""
    return xy if precision is None else np.round(xy, precision)


# ---------------------------------------------------------------------------
# rings to JSON text


def _ring_texts(xy: np.ndarray, first: np.ndarray, last: np.ndarray) -> tuple[memoryview, list, list]:
    """Serialize closed rings in one orjson call and locate each ring in the text.

    Parameters
    ----------
    xy : (p, 2) float64
        The positions of all rings, one after the other, each ring closed.
    first, last : (k,) int64
        Ring k is ``xy[first[k]:last[k] + 1]``.

    Returns
    -------
    text, starts, stops
        ``text[starts[k]:stops[k]]`` is ring k as ``[x,y],...,[x,y]``; numbers are
        orjson's shortest representation that reads back to the same float64.
    """
    text = orjson.dumps(np.ascontiguousarray(xy, dtype=np.float64), option=_OPT_NUMPY)
    # "[[x,y],[x,y],...]": position j ends at the j-th "]" (numbers hold none); the last
    # "]" closes the array
    close = np.flatnonzero(np.frombuffer(text, np.uint8) == _CLOSE_BRACKET)[:-1]
    open_ = np.empty(len(close), np.int64)
    if len(close):
        open_[0] = 1
        open_[1:] = close[:-1] + 2  # after "],"
    return memoryview(text), open_[first].tolist(), (close[last] + 1).tolist()


def closed_rings(diagram, a: int, b: int, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closed rings of the cells of rows a..b-1 where ``keep`` (a (b-a,) bool mask) holds.

    Returns (xy, first, last) as :func:`_ring_texts` takes them.
    """
    offsets = diagram.cell_offsets
    lengths = np.diff(offsets[a : b + 1])
    ring = diagram.cell_vertices[offsets[a] : offsets[b]]
    if not keep.all():
        ring = ring[np.repeat(keep, lengths)]
        lengths = lengths[keep]
    stops = np.cumsum(lengths)
    starts = stops - lengths
    # repeat each ring's first point after its last one
    index = np.insert(ring, stops, ring[starts])
    shift = np.arange(len(lengths), dtype=np.int64)
    # np.take is much faster than fancy indexing for gathering rows
    return np.take(diagram.cell_points, index, axis=0), starts + shift, stops + shift


def ring_chunk(diagram, a: int, b: int, precision: int | None) -> list[bytes]:
    """The closed rings of the cells of rows a..b-1 (each with a ring) as JSON texts
    ``[x,y],...,[x,y]``, one per row, in one gather and one orjson call.

    The positions are gathered with each ring's first point repeated after its last and a
    NaN row (written ``[null,null]``) after that, where the text is cut.
    """
    offsets = diagram.cell_offsets
    lengths = np.diff(offsets[a : b + 1])
    ring = diagram.cell_vertices[offsets[a] : offsets[b]]
    stops = np.cumsum(lengths)
    # after each ring: its first vertex, then -1 for the cut
    extra = np.empty((len(lengths), 2), ring.dtype)
    extra[:, 0] = ring[stops - lengths]
    extra[:, 1] = -1
    index = np.insert(ring, np.repeat(stops, 2), extra.ravel())[:-1]
    xy = np.take(diagram.cell_points, index, axis=0)
    xy[index < 0] = np.nan
    text = orjson.dumps(_rounded(xy, precision), option=_OPT_NUMPY)
    return text[1:-1].split(_RING_BREAK)


def cut_geometries(diagram, rows: np.ndarray, precision: int | None = None) -> list[bytes]:
    """GeoJSON geometries of the cells of ``rows`` that a clip region cut (see ClippedDiagram.reshaped).

    A few cells per chunk cross the region's boundary, so each is written from its shapely geometry.
    """
    import shapely

    geoms = diagram.clipped[rows]
    if precision is not None:
        geoms = shapely.transform(geoms, lambda xy: np.round(xy, precision))
    return [orjson.dumps(g.__geo_interface__) for g in geoms]


def ring_rows(diagram) -> tuple[np.ndarray, np.ndarray]:
    """(ring, cut): rows of distinct sites written from their CSR ring, and rows written from a cut geometry.

    Rows in neither are written with a null geometry.
    """
    distinct = diagram.site_of == np.arange(diagram.n_sites)
    ring = distinct & (np.diff(diagram.cell_offsets) >= MIN_RING_POINTS)
    reshaped = getattr(diagram, "reshaped", None)
    if reshaped is None:
        return ring, np.zeros(diagram.n_sites, bool)
    cut = distinct & reshaped & (diagram.clipped != None)  # noqa: E711 (elementwise)
    return ring & ~reshaped, cut


def cells_extent(diagram) -> np.ndarray:
    """(xmin, ymin, xmax, ymax) of the written cells: the box, or the bounds of the cells cut to a region."""
    clipped = getattr(diagram, "clipped", None)
    if clipped is None:
        return np.asarray(diagram.bbox, np.float64)
    import shapely

    return shapely.total_bounds(clipped)


def missing_cells(diagram) -> np.ndarray:
    """Rows of distinct sites whose cell misses the box (they are written with ``"geometry": null``).

    Only a box that leaves a site outside can do this; with the default box it is empty.
    """
    rows = np.arange(diagram.n_sites)
    lengths = np.diff(diagram.cell_offsets)
    return np.flatnonzero((diagram.site_of == rows) & (lengths < MIN_RING_POINTS))


# ---------------------------------------------------------------------------
# properties


def property_renames(names: list[str]) -> dict[str, str]:
    """New names for site properties that clash with tvoronoi's own ("site" becomes "site_2")."""
    renames = {}
    taken = set(names) | set(RESERVED)
    for name in RESERVED:
        if name in names:
            k = 2
            while f"{name}_{k}" in taken:
                k += 1
            renames[name] = f"{name}_{k}"
            taken.add(renames[name])
    return renames


def json_texts(values) -> list[bytes]:
    """The JSON text of each of a list of JSON-ready values, serialized in one orjson call.

    The list is written as one JSON array and cut at the commas between its values
    (the commas outside strings; a quote escaped as ``\\"`` does not end a string).
    Values that hold commas of their own (lists, objects) are written one by one.

    >>> json_texts([1, None, "a, \\"b\\"", 2.5])
    [b'1', b'null', b'"a, \\\\"b\\\\""', b'2.5']
    """
    if not len(values):
        return []
    text = orjson.dumps(values, option=_OPT_NUMPY)[1:-1]
    if b'"' not in text:
        parts = text.split(b",")
        if len(parts) == len(values):
            return parts
    else:
        # "\\" is an escaped backslash: blank it out, and a quote after a backslash is escaped
        raw = np.frombuffer(text.replace(b"\\\\", b"__") if b"\\" in text else text, np.uint8)
        quote = raw == ord('"')
        quote[1:] &= raw[:-1] != ord("\\")
        # a comma with an even number of quotes before it lies between two values
        outside = (np.cumsum(quote, dtype=np.int64) & 1) == 0
        cuts = np.flatnonzero((raw == ord(",")) & outside)
        if len(cuts) == len(values) - 1:
            starts = [0, *(cuts + 1).tolist()]
            stops = [*cuts.tolist(), len(text)]
            return [text[a:b] for a, b in zip(starts, stops)]
    return [orjson.dumps(v, option=_OPT_NUMPY) for v in values]


def _string_contents(values) -> list[bytes] | None:
    """The UTF-8 text of each of a list of strings that JSON writes between quotes as they are
    (no quote, backslash or control character), in one orjson call; None for other lists."""
    if not len(values) or type(values[0]) is not str:
        return None
    text = orjson.dumps(values)
    if b"\\" in text:
        return None
    parts = text[2:-2].split(b'","')
    return parts if len(parts) == len(values) else None


class _Properties:
    """The JSON text of the features' properties: row by row, or in bulk for a run of rows."""

    def __init__(self, diagram, points):
        self.duplicates = diagram.duplicates()
        self.columns: list = []
        self.records = None
        renames: dict[str, str] = {}
        if points is not None:
            if len(points) != diagram.n_sites:
                raise TvoronoiError(
                    f"the point set has {len(points)} rows but the diagram has {diagram.n_sites} sites; "
                    f"pass the points the diagram was built from"
                )
            renames = property_renames(points.property_names)
            if points.records is not None:
                self.records = points.records
            else:
                self.columns = [(renames.get(name, name), values) for name, values in points.columns.items()]
        self.row = _properties_writer(self.duplicates, self.columns, self.records, renames)
        self.repeated = np.array(sorted(self.duplicates), np.int64)
        # each column with the text that comes before its value in a feature: ,"name":
        self.columns = [(b",%b:" % orjson.dumps(name), values) for name, values in self.columns]

    def bulk(self, a: int, b: int) -> bool:
        """Whether rows a..b-1 can be written by :meth:`ring_features` (table columns, no repeats)."""
        repeats = np.searchsorted(self.repeated, [a, b])
        return self.records is None and repeats[0] == repeats[1]

    def ring_features(self, rings: list, a: int, b: int, frame: _Framing) -> None:
        """Write the features of rows a..b-1, each with its ring, as one list of pieces joined
        once: the column values serialized in bulk, no formatting per feature."""
        variables: list[list] = [
            rings,
            orjson.dumps(np.arange(a, b, dtype=np.int64), option=_OPT_NUMPY)[1:-1].split(b","),
        ]
        # constants[k] comes before variables[k] (constants[0] opens the feature); the last closes it
        constants = [_FEATURE_OPEN, _RING_CLOSE, b""]
        try:
            for key, values in self.columns:
                contents = _column_contents(values, a, b)
                if contents is None:
                    constants[-1] += key
                    variables.append(json_texts(values[a:b]))
                    constants.append(b"")
                else:
                    constants[-1] += key + b'"'
                    variables.append(contents)
                    constants.append(b'"')
        except orjson.JSONEncodeError:
            # the message names the row: written one by one
            frame.write([_POLYGON % (ring, self.row(i)) for ring, i in zip(rings, range(a, b))])
            return
        constants[-1] += b"}}"
        width = 2 * len(variables)
        pieces: list = [None] * (width * (b - a))
        for k, values in enumerate(variables):
            pieces[2 * k :: width] = values
            if k + 1 < len(variables):
                pieces[2 * k + 1 :: width] = [constants[k + 1]] * (b - a)
        pieces[width - 1 :: width] = [constants[-1] + frame.between() + constants[0]] * (b - a)
        frame.joined(pieces, constants[0], constants[-1])


def _column_contents(values, a: int, b: int) -> list[bytes] | None:
    """The text JSON writes between quotes for each value a..b-1 of a column of strings with
    nothing to escape (and no None); None for other columns."""
    if isinstance(values, TextColumn):
        if values.json_plain and (values.valid is None or values.valid[a:b].all()):
            return values.utf8(a, b)
        return None
    return _string_contents(values[a:b])


def _properties_writer(duplicates, columns, records, renames) -> Callable[[int], bytes]:
    """A function of a row giving the JSON text of its feature's properties."""

    def properties(i: int) -> bytes:
        repeats = duplicates.get(i)
        if not columns and not (records and records[i]) and repeats is None:
            return b'{"site":%d}' % i
        out = {"site": i}
        if records is not None:
            for key, value in records[i].items():
                out[renames.get(key, key)] = value
        for name, values in columns:
            out[name] = values[i]
        if repeats is not None:
            out["duplicates"] = repeats
        try:
            return orjson.dumps(out, option=_OPT_NUMPY)
        except orjson.JSONEncodeError as e:
            raise TvoronoiError(f"the properties of site {i} cannot be written as JSON: {e}") from None

    return properties


# ---------------------------------------------------------------------------
# writers


def _bbox_member(bbox) -> bytes:
    return b'"bbox":%b,' % orjson.dumps([float(v) for v in bbox])


def write_cells(
    diagram,
    points,
    out,
    *,
    progress: ProgressCallback | None = None,
    overwrite: bool = True,
    precision: int | None = None,
    layout: str = "collection",
) -> int:
    """Write the Voronoi cells as an RFC 7946 GeoJSON FeatureCollection.

    One Polygon feature per distinct site, in input order, one feature per
    line. The exterior ring is counter-clockwise and closed (its first
    position repeated at the end); coordinates are written as given (no CRS
    is implied) in the shortest form that reads back to the same float64.
    The properties are ``{"site": <0-based input row>, <the row's other
    properties>..., "duplicates": [<later rows at the same place>]}``; the
    last key only where the site repeats. A site property named "site" or
    "duplicates" is kept as "site_2" / "duplicates_2".

    A diagram clipped to a region (``voronoi(..., clip=...)``) writes its
    cells cut to the region: a Polygon (with holes) or a MultiPolygon
    where a cell crosses the region's boundary, ``"geometry": null`` for a
    site outside the region.

    A cell that misses the box (only possible with a box that leaves its
    site outside) has ``"geometry": null``, which RFC 7946 (section 3.2)
    allows for an unlocated feature; see :func:`missing_cells`.

    Parameters
    ----------
    diagram : Diagram
    points : PointSet or None
        The sites as read from a file, whose properties the features carry;
        None for sites without properties.
    out : str, os.PathLike or binary file
        A path, ``"-"`` for standard output, or an open binary stream. A path
        is written through a temporary file renamed into place on success.
    progress : callable(done, total), optional
        Called with the number of features written so far and in all.
    overwrite : bool
        Replace an existing file at ``out``.
    precision : int, optional
        Round coordinates to this many decimal digits (smaller files; a cell
        narrower than the rounding may then collapse or self-touch).
    layout : {"collection", "seq", "lines"}
        A FeatureCollection; or a GeoJSON text sequence (RFC 8142), each feature
        after a record separator (0x1E) and ending a line, as GDAL writes
        ``.geojsons``; or newline-delimited features, as GDAL writes
        ``.geojsonl`` and jq reads without options. GDAL's GeoJSONSeq driver
        reads both.

    Returns
    -------
    int
        The number of features written.

    Raises
    ------
    TvoronoiError
        If ``points`` does not match the diagram.
    OSError
        If writing fails (an existing file at ``out`` is then left untouched).
    """
    props = _Properties(diagram, points)
    properties = props.row
    n_sites = diagram.n_sites
    rows = np.arange(n_sites)
    distinct = diagram.site_of == rows
    has_ring, has_cut = ring_rows(diagram)
    total = int(distinct.sum())

    def emit(frame: _Framing, start: int, stop: int, report: Callable[[int], None] | None) -> int:
        """Write the features of rows start..stop-1; the number written."""
        done = 0
        for a in range(start, stop, CHUNK_FEATURES):
            b = min(a + CHUNK_FEATURES, stop)
            # the rings of this chunk, serialized together
            keep = has_ring[a:b]
            if keep.all() and props.bulk(a, b):
                # every row of the chunk is a distinct site with a ring: in bulk
                props.ring_features(ring_chunk(diagram, a, b, precision), a, b, frame)
                done += b - a
                if report is not None:
                    report(done)
                continue
            xy, first, last = closed_rings(diagram, a, b, keep)
            text, starts, stops = _ring_texts(_rounded(xy, precision), first, last)
            spans = zip(starts, stops)
            cut = iter(cut_geometries(diagram, rows[a:b][has_cut[a:b]], precision) if has_cut[a:b].any() else ())
            features = []
            chunk = distinct[a:b]
            for i, ring, is_cut in zip(rows[a:b][chunk].tolist(), keep[chunk].tolist(), has_cut[a:b][chunk].tolist()):
                if ring:
                    start_, stop_ = next(spans)
                    features.append(_POLYGON % (text[start_:stop_], properties(i)))
                elif is_cut:  # a cell cut by a clip region
                    features.append(_GEOMETRY % (next(cut), properties(i)))
                else:  # a cell that misses the box, or a site outside a clip region
                    features.append(_NULL % properties(i))
            if not features:
                continue
            frame.write(features)
            done += len(features)
            if report is not None:
                report(done)
        return done

    # a large output is made in two halves at once: the second by a forked process
    split = n_sites
    if total >= forked.MIN_FEATURES and forked.can_fork():
        split = (n_sites // 2 + CHUNK_FEATURES - 1) // CHUNK_FEATURES * CHUNK_FEATURES
    share = int(distinct[:split].sum())
    shown = [-1]

    def report(done: int) -> None:
        # the first part's share of the features stands for all of them; each count once
        if progress is not None and done != shown[0]:
            shown[0] = done
            progress(done, total)

    def report_share(done: int) -> None:
        report(done * total // max(share, 1))

    with open_output(out, overwrite=overwrite) as target, gc_paused():
        bbox = _bbox_member(_rounded(cells_extent(diagram), precision)) if (has_ring | has_cut).any() else b""
        second = None
        if split < n_sites:
            try:
                second = forked.ForkedPart(
                    target, lambda file: emit(_Framing(file, layout, b"", opened=True), split, n_sites, None)
                )
            except OSError:
                # no room for the temporary file, or no process to be had: one process writes it all
                split, share = n_sites, total
        try:
            report(0)
            with background(target) as stream:
                frame = _Framing(stream, layout, bbox)
                done = emit(frame, 0, split, report_share)
            if second is not None:
                done += second.append_to(target)
                second = None
        except BaseException:
            if second is not None:
                second.abandon()
            raise
        frame.stream = target
        frame.close()
        report(done)
    return done


def write_delaunay(
    diagram,
    out,
    *,
    progress: ProgressCallback | None = None,
    overwrite: bool = True,
    precision: int | None = None,
    layout: str = "collection",
) -> int:
    """Write the Delaunay triangles as a GeoJSON FeatureCollection of Polygons.

    Each triangle is a closed counter-clockwise ring of its three sites, with
    properties ``{"sites": [i, j, k]}`` (0-based input rows). Output, progress,
    precision, layout and errors as in :func:`write_cells`.

    Returns
    -------
    int
        The number of triangles written.
    """
    triangles = np.asarray(diagram.triangles, dtype=np.int64).reshape(-1, 3)
    total = len(triangles)
    with open_output(out, overwrite=overwrite) as target, gc_paused(), background(target) as stream:
        bbox = b""
        if total:
            used = np.zeros(diagram.n_sites, bool)
            used[triangles.ravel()] = True
            corners = diagram.sites[used]
            extent = [corners[:, 0].min(), corners[:, 1].min(), corners[:, 0].max(), corners[:, 1].max()]
            bbox = _bbox_member(_rounded(np.array(extent), precision))
        frame = _Framing(stream, layout, bbox)
        if progress is not None:
            progress(0, total)
        for a in range(0, total, CHUNK_FEATURES):
            chunk = triangles[a : a + CHUNK_FEATURES]
            # ring i, j, k, i
            xy = np.take(diagram.sites, chunk[:, [0, 1, 2, 0]].ravel(), axis=0)
            first = np.arange(0, 4 * len(chunk), 4, dtype=np.int64)
            text, starts, stops = _ring_texts(_rounded(xy, precision), first, first + 3)
            features = [
                _TRIANGLE % (text[start:stop], i, j, k) for start, stop, (i, j, k) in zip(starts, stops, chunk.tolist())
            ]
            frame.write(features)
            if progress is not None:
                progress(a + len(chunk), total)
        frame.close()
    return total
