"""The one exception family of tvoronoi: bad input, named precisely."""


class TvoronoiError(ValueError):
    """Input that tvoronoi cannot use; the message names the culprit and the fix."""


class InputFileError(TvoronoiError):
    """A point file that cannot be read: missing, empty, malformed or non-finite."""


class EngineError(TvoronoiError):
    """An engine name or option that does not exist (or is not available yet)."""
