"""The one exception family of tvoronoi: bad input, named precisely."""


class TvoronoiError(ValueError):
    """Input that tvoronoi cannot use; the message names the culprit and the fix."""


class InputFileError(TvoronoiError):
    """A point file that cannot be read: missing, empty, malformed or non-finite."""


class EngineError(TvoronoiError):
    """An engine name or option that does not exist, or an engine run that failed."""


class CoordinateRangeError(TvoronoiError):
    """Coordinates spread over more than exact arithmetic covers (2^170 around the largest).

    ``rows`` are the first row at fault and the row of the largest coordinate, ``values``
    their coordinates; :meth:`explain` words the message with the rows named by a caller
    that knows where they are in a file.
    """

    def __init__(
        self, *, rows: tuple[int, int], values: tuple[float, float], small: bool, locate, remedy: str | None = None
    ):
        self.rows, self.values, self.small = rows, values, small
        self.remedy = remedy or "round tiny values to 0, or remove the outlier"
        super().__init__(self.explain(locate))

    def explain(self, locate) -> str:
        """The message, with ``locate(row)`` naming a row ("point 3", "data.csv, line 5")."""
        (row, top_row), (value, top) = self.rows, self.values
        if self.small and top_row < 0:  # the scale is a diagram's, not these points' (a new site, a query)
            what = f"over 1e51 times smaller than {locate(top_row)} (about {top:.3g})"
        elif self.small:
            other = "the same point" if top_row == row else locate(top_row)
            what = f"over 1e51 times smaller than the largest coordinate, {top!r} ({other})"
        else:
            what = "over 1e51 times larger than the diagram's scale"
        around = locate(top_row) if top_row < 0 else "the largest coordinate"
        return (
            f"{locate(row)}: coordinate {value!r} is {what}: exact arithmetic covers a range of 2^170 "
            f"(about 1e51) around {around}; {self.remedy}"
        )
