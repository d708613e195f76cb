"""fixplan: grasp and fixture planning with friction limit surfaces and convex optimisation.

The science follows Howe & Cutkosky, "Practical Force-Motion Models for Sliding Manipulation":
exact limit surfaces of planar contacts for any pressure distribution (:class:`LimitSurface`,
:mod:`fixplan.pressure`), their approximations, and a convex planner built on them.
"""

from importlib.metadata import PackageNotFoundError, version

from fixplan import compare, models, pressure
from fixplan.errors import (
    ConvergenceError,
    FixplanError,
    GeometryError,
    InvalidArgumentError,
    ModelError,
)
from fixplan.limit_surface import LimitSurface

try:
    __version__ = version("fixplan")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = [
    "ConvergenceError",
    "FixplanError",
    "GeometryError",
    "InvalidArgumentError",
    "LimitSurface",
    "ModelError",
    "__version__",
    "compare",
    "models",
    "pressure",
]
