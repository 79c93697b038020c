"""A slow, obvious reference: each cell as the box cut by the half-planes of every other site."""

import numpy as np
import shapely


def clip_half_plane(poly, a, b, c):
    """Keep the part of polygon (k, 2) where a*x + b*y <= c (Sutherland-Hodgman)."""
    if len(poly) == 0:
        return poly
    out = []
    vals = poly @ np.array([a, b]) - c
    for k in range(len(poly)):
        p, q = poly[k], poly[(k + 1) % len(poly)]
        vp, vq = vals[k], vals[(k + 1) % len(poly)]
        if vp <= 0:
            out.append(p)
        if (vp < 0 < vq) or (vq < 0 < vp):
            t = vp / (vp - vq)
            out.append(p + t * (q - p))
    return np.array(out).reshape(-1, 2)


def oracle_cells(points, bbox):
    """Cell of each distinct point (first copy); None for later copies."""
    xmin, ymin, xmax, ymax = bbox
    box = np.array([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]], float)
    cells = []
    seen = {}
    for i, s in enumerate(points):
        key = (float(s[0]), float(s[1]))
        if key in seen:
            cells.append(None)
            continue
        seen[key] = i
        poly = box
        for t in points:
            if t[0] == s[0] and t[1] == s[1]:
                continue
            # |x - s|^2 <= |x - t|^2  <=>  2 (t - s) . x <= |t|^2 - |s|^2
            poly = clip_half_plane(poly, 2 * (t[0] - s[0]), 2 * (t[1] - s[1]), t @ t - s @ s)
        cells.append(shapely.Polygon(poly) if len(poly) >= 3 else shapely.Polygon())
    return cells


def assert_matches_oracle(d, *, rtol=1e-7):
    """Every cell of d equals the oracle's, up to rounding."""
    xmin, ymin, xmax, ymax = d.bbox
    size = max(xmax - xmin, ymax - ymin)
    # the oracle works in coordinates relative to the box corner, which keeps
    # its half-plane constants well conditioned at large offsets
    origin = np.array([xmin, ymin])
    ref = oracle_cells(d.sites - origin, (0.0, 0.0, xmax - xmin, ymax - ymin))
    for i, want in enumerate(ref):
        ring = d.cell_polygon(i)
        if want is None or want.area == 0:
            assert len(ring) == 0 or shapely.Polygon(ring).area <= (rtol * size) ** 2
            continue
        got = shapely.Polygon(ring - origin)
        # areas and vertex distances, not an overlay: GEOS can mis-node two rings that
        # differ only in the last bits of their vertices
        assert abs(got.area - want.area) <= rtol * size * (got.length + want.length), (
            f"cell {i}: area {got.area}, the oracle's {want.area}"
        )
        assert got.hausdorff_distance(want) <= rtol * size, f"cell {i}: a vertex is off"
