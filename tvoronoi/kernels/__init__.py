"""The Cython kernels: one phase of the algorithms per module (see ARCHITECTURE.md)."""

import os

# The phases that split (threads=N) run a few OpenMP loops; between them the waiting threads sleep
# instead of spinning, so that a build shares a busy machine, and the terminal UI's event loop, fairly.
# libgomp reads this once, when the first kernel loads it; a setting of the user's own wins.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

# Threads whose kernels are asked to stop (their idents): a build by halves (tvoronoi.halves) whose main
# thread is interrupted adds its other thread here, and that thread's kernels raise KeyboardInterrupt at
# their next poll (interrupt.pxd) instead of running their half to the end.
STOPPING: set[int] = set()
