"""The column names that say x or y (any case): shared by the file readers and the DataFrame input."""

from __future__ import annotations

# in order of preference; "e" and "n" only as a pair
X_NAMES = ("x", "lon", "lng", "long", "longitude", "easting", "e")
Y_NAMES = ("y", "lat", "latitude", "northing", "n")
PAIRED_ONLY = {"e": "n", "n": "e"}
# names of longitude and latitude columns: their sites are lon/lat degrees
LON_NAMES = ("lon", "lng", "long", "longitude")
LAT_NAMES = ("lat", "latitude")


def named_column(names: list[str], role: str) -> int | None:
    """The column named as the x (role "x") or y coordinate, in order of preference, or None.

    Among names equal but for case, the one spelled exactly as the candidate comes first.

    >>> named_column(["id", "Lat", "Lon"], "x"), named_column(["id", "Lat", "Lon"], "y")
    (2, 1)
    >>> named_column(["e", "height"], "x") is None  # "e" only beside an "n"
    True
    """
    lowered = [name.lower() for name in names]
    for candidate in X_NAMES if role == "x" else Y_NAMES:
        if candidate in PAIRED_ONLY and PAIRED_ONLY[candidate] not in lowered:
            continue
        exact = [j for j, name in enumerate(names) if name == candidate]
        loose = [j for j, name in enumerate(lowered) if name == candidate]
        if exact or loose:
            return (exact or loose)[0]
    return None
