"""Build the Cython kernels of tvoronoi (metadata lives in pyproject.toml)."""
from pathlib import Path

from Cython.Build import cythonize
from setuptools import Extension, setup

# -ffp-contract=off: the exact predicates rely on every product and sum being
# rounded on its own; a fused multiply-add would silently break them.
COMPILE_ARGS = ["-O3", "-ffp-contract=off", "-fno-math-errno"]

extensions = [
    Extension(
        f"tvoronoi.kernels.{path.stem}",
        [str(path)],
        extra_compile_args=COMPILE_ARGS,
    )
    for path in sorted(Path("tvoronoi/kernels").glob("*.pyx"))
]

setup(
    ext_modules=cythonize(
        extensions,
        language_level=3,
        compiler_directives={
            "boundscheck": False,
            "wraparound": False,
            "cdivision": True,
            "initializedcheck": False,
        },
    )
)
