"""The clip region of `tvoronoi batch --clip FILE`: the union of the (Multi)Polygons of a GeoJSON file."""

from __future__ import annotations

from tvoronoi.errors import TvoronoiError

POLYGONAL = ("Polygon", "MultiPolygon")


def read_region(path: str):
    """Read a GeoJSON FeatureCollection, Feature or geometry of Polygons and MultiPolygons; return their union.

    Raises
    ------
    TvoronoiError
        Naming the file: unreadable, not JSON, not GeoJSON, a feature that is not a (Multi)Polygon (naming
        it), an invalid polygon (with GEOS's reason), no area at all.
    """
    import orjson
    import shapely

    try:
        with open(path, "rb") as f:
            data = orjson.loads(f.read())
    except OSError as e:
        raise TvoronoiError(f"--clip {path}: cannot read it: {e.strerror or e}") from None
    except orjson.JSONDecodeError as e:
        raise TvoronoiError(f"--clip {path}: not JSON ({e}); give a GeoJSON file of Polygons") from None
    kind = data.get("type") if isinstance(data, dict) else None
    if kind == "FeatureCollection":
        features = data.get("features")
        if not isinstance(features, list):
            raise TvoronoiError(f'--clip {path}: the FeatureCollection has no "features" list')
        geometries = [(f"feature {k}", _geometry_of(path, k, feature)) for k, feature in enumerate(features)]
    elif kind == "Feature":
        geometries = [("the feature", _geometry_of(path, 0, data))]
    elif kind in POLYGONAL or kind == "GeometryCollection":
        geometries = [("the geometry", data)]
    else:
        raise TvoronoiError(
            f"--clip {path}: expected a GeoJSON FeatureCollection, Feature, Polygon or MultiPolygon, "
            f"got {'type ' + repr(kind) if kind else 'no GeoJSON type'}"
        )
    shapes = []
    for where, geometry in geometries:
        shapes.extend(_polygons(path, where, geometry))
    if not shapes:
        raise TvoronoiError(f"--clip {path}: it holds no Polygon or MultiPolygon to clip to")
    region = shapely.union_all(shapes) if len(shapes) > 1 else shapes[0]
    if region.is_empty or not region.area > 0:
        raise TvoronoiError(f"--clip {path}: its polygons have no area")
    return region


def _geometry_of(path: str, k: int, feature) -> dict:
    if not isinstance(feature, dict) or feature.get("type") != "Feature":
        raise TvoronoiError(f"--clip {path}: feature {k} is not a GeoJSON Feature")
    geometry = feature.get("geometry")
    if geometry is None:
        raise TvoronoiError(f"--clip {path}: feature {k} has a null geometry; remove it or give it a Polygon")
    return geometry


def _polygons(path: str, where: str, geometry) -> list:
    """The valid shapely (Multi)Polygons of a GeoJSON geometry (a GeometryCollection's members too)."""
    import orjson
    import shapely

    kind = geometry.get("type") if isinstance(geometry, dict) else None
    if kind == "GeometryCollection":
        out = []
        for k, member in enumerate(geometry.get("geometries") or []):
            out.extend(_polygons(path, f"{where}, member {k}", member))
        return out
    if kind not in POLYGONAL:
        raise TvoronoiError(
            f"--clip {path}: {where} is a {kind or 'geometry without a type'}; "
            f"--clip takes Polygons and MultiPolygons only"
        )
    try:
        shape = shapely.from_geojson(orjson.dumps(geometry))
    except shapely.errors.GEOSException as e:
        raise TvoronoiError(f"--clip {path}: {where} is not a readable {kind}: {e}") from None
    if not shape.is_valid:
        raise TvoronoiError(
            f"--clip {path}: {where} is not a valid {kind} ({shapely.is_valid_reason(shape)}); "
            f"repair it, e.g. with `ogr2ogr -makevalid` or shapely.make_valid"
        )
    return [] if shape.is_empty else [shape]
