"""tvoronoi: exact, fast 2D Voronoi diagrams, with a terminal UI and a batch mode."""

__version__ = "0.1.0"

__all__ = [
    "voronoi",
    "lloyd",
    "Diagram",
    "DynamicVoronoi",
    "TvoronoiError",
    "generate",
    "steps",
    "fortune_steps",
    "incremental_steps",
]

from tvoronoi.errors import TvoronoiError


def __getattr__(name):
    # The engines are loaded on first use, so `tvoronoi --help` and the
    # readers start without importing the compiled kernels.
    if name == "voronoi":
        from tvoronoi.api import voronoi

        return voronoi
    if name == "lloyd":
        from tvoronoi.relax import lloyd

        return lloyd
    if name == "Diagram":
        from tvoronoi.diagram import Diagram

        return Diagram
    if name == "DynamicVoronoi":
        from tvoronoi.dynamic import DynamicVoronoi

        return DynamicVoronoi
    if name in ("steps", "fortune_steps", "incremental_steps"):
        from tvoronoi import trace

        return getattr(trace, name)
    if name == "generate":
        from tvoronoi.generators import generate

        return generate
    raise AttributeError(f"module 'tvoronoi' has no attribute {name!r}")
