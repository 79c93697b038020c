"""Build the Cython kernels of tvoronoi (metadata lives in pyproject.toml).

TVORONOI_CHECKED=1 builds a checked variant for the tests instead: Cython bounds and initialisation checks on
typed memoryviews, -O1 -g, the C files generated under build/checked-c/ (so the optimised build's C files are
left alone); TVORONOI_CHECKED=asan adds AddressSanitizer (-fsanitize=address), which also covers raw C pointers
and fixed-size stack buffers. The Makefile's ``checked`` target builds it with ``build_ext --build-lib
build/checked``; ``tests/hunt_worker.py --kernels build/checked`` loads it.
"""
import os
from pathlib import Path

import numpy
from Cython.Build import cythonize
from setuptools import Extension, setup

# -ffp-contract=off: the exact predicates rely on every product and sum being
# rounded on its own; a fused multiply-add would silently break them.
COMPILE_ARGS = ["-O3", "-ffp-contract=off", "-fno-math-errno"]
LINK_ARGS: list[str] = []
# OpenMP runs the independent loops of a phase (prange) on the threads a build is given
OPENMP = ["-fopenmp"]
DIRECTIVES = {
    "boundscheck": False,
    "wraparound": False,
    "cdivision": True,
    "initializedcheck": False,
}
CYTHON_BUILD_DIR = None

CHECKED = os.environ.get("TVORONOI_CHECKED", "")
if CHECKED:
    # wraparound stays off, as in the optimised build: a negative index (the -1 of "none") is then an
    # IndexError instead of silently reading the last element
    DIRECTIVES = dict(DIRECTIVES, boundscheck=True, initializedcheck=True)
    COMPILE_ARGS = ["-O1", "-g", "-fno-omit-frame-pointer", "-ffp-contract=off", "-fno-math-errno"]
    CYTHON_BUILD_DIR = "build/checked-c"
    if CHECKED == "asan":
        COMPILE_ARGS += ["-fsanitize=address"]
        LINK_ARGS += ["-fsanitize=address"]

extensions = [
    Extension(
        f"tvoronoi.kernels.{path.stem}",
        [str(path)],
        include_dirs=[numpy.get_include()],             # pages.pyx: numpy's data memory handler
        define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
        extra_compile_args=COMPILE_ARGS + OPENMP,
        extra_link_args=LINK_ARGS + OPENMP,
    )
    for path in sorted(Path("tvoronoi/kernels").glob("*.pyx"))
]

setup(
    ext_modules=cythonize(
        extensions,
        language_level=3,
        compiler_directives=DIRECTIVES,
        build_dir=CYTHON_BUILD_DIR,
    )
)
