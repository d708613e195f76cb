"""fixplan: grasp and fixture planning with friction limit surfaces and convex optimisation.

The science follows Howe & Cutkosky, "Practical Force-Motion Models for Sliding Manipulation":
exact limit surfaces of planar contacts for any pressure distribution (:class:`LimitSurface`,
:mod:`fixplan.pressure`), the paper's approximations with their errors measured
(:mod:`fixplan.models`, :mod:`fixplan.compare`), and a convex planner built on them
(:class:`Problem`, :func:`solve`).
"""

from importlib.metadata import PackageNotFoundError, version

from fixplan import compare, models, pressure
from fixplan.contact_surface import ContactSetSurface
from fixplan.errors import (
    ConvergenceError,
    FixplanError,
    GeometryError,
    InvalidArgumentError,
    ModelError,
)
from fixplan.limit_surface import LimitSurface
from fixplan.plan import Plan
from fixplan.planner import Planner, solve
from fixplan.problem import Body, Contact, Load, Problem, ProblemError
from fixplan.problem_file import ProblemFileError, load_problem
from fixplan.screw import Screw

try:
    __version__ = version("fixplan")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = [
    "Body",
    "Contact",
    "ContactSetSurface",
    "ConvergenceError",
    "FixplanError",
    "GeometryError",
    "InvalidArgumentError",
    "LimitSurface",
    "Load",
    "ModelError",
    "Plan",
    "Planner",
    "Problem",
    "ProblemError",
    "ProblemFileError",
    "Screw",
    "__version__",
    "compare",
    "load_problem",
    "models",
    "pressure",
    "solve",
]
