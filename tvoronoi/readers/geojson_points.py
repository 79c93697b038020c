"""GeoJSON point files: Point and MultiPoint features, with their properties."""

from __future__ import annotations

import itertools
import math
import re

import numpy as np

from tvoronoi.fileio import gc_paused

from ..errors import InputFileError, TvoronoiError
from .pointset import PointSet

GEOMETRY_TYPES = (
    "Point",
    "MultiPoint",
    "LineString",
    "MultiLineString",
    "Polygon",
    "MultiPolygon",
    "GeometryCollection",
)


def _describe(value) -> str:
    if isinstance(value, dict):
        return f'an object of type "{value["type"]}"' if "type" in value else "an object without a type"
    return {list: "a list", str: "a string", bool: "a boolean", type(None): "null"}.get(type(value), "a number")


def _geojson_sites(doc, source: str):
    """Yield (where, part, position, properties) for each site of a GeoJSON document.

    ``where`` names the feature ("features[3]"), ``part`` is the index within a MultiPoint
    (None for a Point); the position is checked to be a list of at least two numbers.
    """
    kind = doc.get("type") if isinstance(doc, dict) else None
    if kind == "FeatureCollection":
        features = doc.get("features")
        if not isinstance(features, list):
            raise InputFileError(f'{source}: the FeatureCollection has no "features" list')
        labelled = ((f"features[{k}]", feature) for k, feature in enumerate(features))
    elif kind == "Feature":
        labelled = iter([("the feature", doc)])
    elif kind in ("Point", "MultiPoint"):
        labelled = iter([("the geometry", {"type": "Feature", "geometry": doc, "properties": None})])
    elif kind in GEOMETRY_TYPES:
        raise InputFileError(
            f"{source}: the file is a single {kind} geometry; tvoronoi reads Point and MultiPoint geometries"
        )
    else:
        raise InputFileError(
            f"{source}: not GeoJSON: expected a FeatureCollection, a Feature or a Point/MultiPoint "
            f"geometry, found {_describe(doc)}"
        )
    for where, feature in labelled:
        if not isinstance(feature, dict):
            raise InputFileError(f"{source}, {where}: not a Feature object but {_describe(feature)}")
        properties = feature.get("properties")
        if properties is None:
            properties = {}
        elif not isinstance(properties, dict):
            raise InputFileError(
                f'{source}, {where}: "properties" is {_describe(properties)}; it must be an object or null'
            )
        geometry = feature.get("geometry")
        if geometry is None:
            raise InputFileError(
                f"{source}, {where}: the geometry is null; tvoronoi reads Point and MultiPoint "
                f"features: give the feature a point or remove it"
            )
        kind = geometry.get("type") if isinstance(geometry, dict) else _describe(geometry)
        coordinates = geometry.get("coordinates") if isinstance(geometry, dict) else None
        if kind == "Point":
            yield where, None, _position(coordinates, source, where), properties
        elif kind == "MultiPoint":
            if not isinstance(coordinates, list):
                raise InputFileError(
                    f"{source}, {where}: MultiPoint coordinates are {_describe(coordinates)}, not a list of positions"
                )
            for part, position in enumerate(coordinates):
                yield where, part, _position(position, source, f"{where}, point {part}"), properties
        else:
            raise InputFileError(
                f'{source}, {where}: geometry type "{kind}" is not a point; tvoronoi reads Point and '
                f"MultiPoint features: convert it (e.g. to its centroid) or remove it"
            )


_NUMBER_TYPES = (int, float)
CRS84 = "OGC:CRS84"
# "urn:ogc:def:crs:EPSG::3857", "urn:ogc:def:crs:OGC:1.3:CRS84", "EPSG:3857"
_CRS_NAME = re.compile(r"(?:urn:ogc:def:crs:)?(?P<authority>[A-Za-z]+):(?:[0-9.]*:)?(?P<code>[A-Za-z0-9]+)")


def _position(position, source: str, where: str):
    if (
        type(position) is list
        and len(position) >= 2
        and type(position[0]) in _NUMBER_TYPES
        and type(position[1]) in _NUMBER_TYPES
    ):
        return position
    raise InputFileError(
        f"{source}, {where}: coordinates {position!r} are not a position; a point needs [x, y] numbers"
    )


def _point_features(features: list):
    """(xs, ys, properties) of a list of well-formed Point features, or None at the first
    feature that is anything else (the checked walk then reads or names it)."""
    xs: list = []
    ys: list = []
    records: list[dict] = []
    try:
        for feature in features:
            geometry = feature["geometry"]
            properties = feature["properties"]
            if geometry["type"] != "Point":
                return None
            position = geometry["coordinates"]
            x, y = position[0], position[1]
            if type(position) is not list or type(x) not in _NUMBER_TYPES or type(y) not in _NUMBER_TYPES:
                return None
            if properties is None:
                properties = {}
            elif type(properties) is not dict:
                return None
            xs.append(x)
            ys.append(y)
            records.append(properties)
    except (KeyError, TypeError, IndexError):
        return None
    return xs, ys, records


def _checked_sites(doc, source: str):
    """(xs, ys, properties, where) of any GeoJSON document, each feature checked; ``where`` names
    the feature (and MultiPoint part) of each site."""
    xs: list = []
    ys: list = []
    records: list[dict] = []
    wheres: list[str] = []
    for where, part, position, properties in _geojson_sites(doc, source):
        xs.append(position[0])
        ys.append(position[1])
        records.append(properties if part is None else {**properties, "part": part})
        wheres.append(where if part is None else f"{where}, point {part}")
    return xs, ys, records, wheres.__getitem__


def read_geojson(data: bytes, source: str, x, y, loads) -> PointSet:
    """The sites of a GeoJSON file; ``loads(data, source)`` parses it (the package's JSON decoder)."""
    if x is not None or y is not None:
        raise TvoronoiError(
            f"{source}: --x/--y choose table columns; a GeoJSON file keeps its coordinates "
            f"in its geometries: drop --x/--y"
        )
    if not data.strip():
        raise InputFileError(f"{source}: no points found (the file is empty)")
    # a million features are a million dicts: the collector would walk them again and again
    with gc_paused():
        doc = loads(data, source)
        sites = None
        if type(doc) is dict and doc.get("type") == "FeatureCollection" and type(doc.get("features")) is list:
            sites = _point_features(doc["features"])
        if sites is None:
            sites = _checked_sites(doc, source)
        else:  # Point features only: site i is feature i
            sites = (*sites, "features[{}]".format)
    xs, ys, records, where = sites
    if not xs:
        raise InputFileError(f"{source}: no points found (no Point or MultiPoint features)")
    xy = np.empty((len(xs), 2), dtype=np.float64)
    try:
        xy[:, 0] = xs
        xy[:, 1] = ys
    except OverflowError:  # an integer beyond float range
        xy[:, 0] = [float(v) if abs(v) < 1e308 else math.inf for v in xs]
        xy[:, 1] = [float(v) if abs(v) < 1e308 else math.inf for v in ys]
    bad = np.flatnonzero(~np.isfinite(xy).all(axis=1))
    if len(bad):
        # the first bad site, found again with where it came from
        where, part, position, _ = next(itertools.islice(_geojson_sites(doc, source), int(bad[0]), None))
        if part is not None:
            where = f"{where}, point {part}"
        role = "x" if not math.isfinite(xy[bad[0], 0]) else "y"
        raise InputFileError(
            f"{source}, {where}: {role} is {position[0 if role == 'x' else 1]}; tvoronoi needs finite coordinates"
        )
    crs = _crs_member(doc, source)
    # the document is not kept: ``where`` holds one label per site at most
    return PointSet(
        xy, source, {}, records if any(records) else None, crs=crs, lonlat=crs is None or crs == CRS84, where=where
    )


def _crs_member(doc, source: str) -> str | None:
    """The CRS a pre-RFC 7946 ``crs`` member names ("EPSG:3857"), None without one (RFC 7946: lon/lat).

    ``{"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::3857"}}``, as GDAL writes
    it, gives "EPSG:3857"; OGC CRS84 and EPSG:4326 give "OGC:CRS84".
    """
    member = doc.get("crs") if isinstance(doc, dict) else None
    if member is None:
        return None
    name = member.get("properties", {}).get("name") if isinstance(member, dict) else None
    if not isinstance(name, str):
        raise InputFileError(
            f'{source}: the "crs" member names no CRS; expected {{"type": "name", "properties": '
            f'{{"name": "urn:ogc:def:crs:EPSG::3857"}}}}, or drop it (RFC 7946 GeoJSON is lon/lat)'
        )
    match = _CRS_NAME.fullmatch(name.strip())
    if match is None:
        return name.strip()
    authority, code = match["authority"].upper(), match["code"]
    if (authority, code) in (("OGC", "CRS84"), ("EPSG", "4326")):
        return CRS84
    return f"{authority}:{code}"
