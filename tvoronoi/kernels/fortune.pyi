"""Type stub of fortune.pyx: Fortune's sweep (the whole run, or its state after some events)."""

from typing import Any

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
I32 = npt.NDArray[np.int32]

STATUS_OK: int
STATUS_BROKEN: int
STATUS_NO_MEMORY: int
STATUS_NO_REPAIR: int
STATUS_MESSAGES: dict[int, str]

# The result dict: status, tv, opp, dup, steps, flips, near_ties, exact_tests, located, queue; with stop_after
# the sweep's state (beach, beach_edges, events, records, triangles, sweep_y, last): see sweep's docstring.
def sweep(
    xs: F64, ys: F64, stop_after: int = -1, hints: bool = True, guard: bool = True, buckets: bool = True
) -> dict[str, Any]: ...
def legalize(xs: F64, ys: F64, tv: I32, opp: I32, bounded: bool = False) -> int: ...
def circle_event_top(ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> tuple[Any, ...]: ...
def circle_event_top_fine(
    ax: float, ay: float, bx: float, by: float, cx: float, cy: float
) -> tuple[float, float, float] | None: ...
def site_before_event(y: float, ax: float, ay: float, bx: float, by: float, cx: float, cy: float) -> bool: ...
def event_top_order(t1: tuple[float, ...], t2: tuple[float, ...]) -> int: ...
