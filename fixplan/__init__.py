"""fixplan: grasp and fixture planning with friction limit surfaces and convex optimisation.

The science follows Howe & Cutkosky, "Practical Force-Motion Models for Sliding Manipulation":
exact limit surfaces of planar contacts for any pressure distribution (:class:`LimitSurface`,
:mod:`fixplan.pressure`), the paper's approximations with their errors measured
(:mod:`fixplan.models`, :mod:`fixplan.compare`), a convex planner built on them
(:class:`Problem`, :func:`solve`), and how parts move and how their limit surfaces are learnt
from measurements (:mod:`fixplan.motion`).

The package is layered; each subpackage imports only from those below it::

    io/        problem, push and measurement files, reports, figures, command line
    design/    layout search over candidate contacts (``fixplan.layout``), sweeps of a
               problem's inputs solved in parallel (Dask)
    motion/    pushing, pivoting, sliding dynamics, fits and slip-onset updates of limit surfaces
    planner/   problems -> stacked convex problem -> verified plans, motions, certificates
    models/    friction models (ellipsoid family, cones, pyramids, exact) and compare
    surface/   pressure fields -> exact limit surface (support, forward and inverse maps)
    errors, tolerances, validation

Public names are loaded on first use, so that ``import fixplan`` (and ``fixplan --help``) does
not import the solver stack.
"""

from __future__ import annotations

import importlib
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("fixplan")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

#: Public name -> module that defines it (a module itself where the name is a module).
_EXPORTS = {
    "Body": "fixplan.planner.problem",
    "Contact": "fixplan.planner.problem",
    "ContactSetSurface": "fixplan.planner.contact_surface",
    "ConvergenceError": "fixplan.errors",
    "FixplanError": "fixplan.errors",
    "GeometryError": "fixplan.errors",
    "InvalidArgumentError": "fixplan.errors",
    "LimitSurface": "fixplan.surface.limit_surface",
    "Load": "fixplan.planner.problem",
    "ModelError": "fixplan.errors",
    "Plan": "fixplan.planner.plan",
    "Planner": "fixplan.planner.planner",
    "Problem": "fixplan.planner.problem",
    "ProblemError": "fixplan.planner.problem",
    "ProblemFileError": "fixplan.io.problem_file",
    "Screw": "fixplan.planner.screw",
    "load_problem": "fixplan.io.problem_file",
    "solve": "fixplan.planner.planner",
}
_MODULES = {
    "compare": "fixplan.models.compare",
    "design": "fixplan.design",
    "layout": "fixplan.design.api",
    "models": "fixplan.models",
    "motion": "fixplan.motion",
    "pressure": "fixplan.surface.pressure",
    "sweep": "fixplan.io.sweep",
}

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
    "design",
    "layout",
    "load_problem",
    "models",
    "motion",
    "pressure",
    "solve",
    "sweep",
]


def __getattr__(name: str):
    if name in _MODULES:
        value = importlib.import_module(_MODULES[name])
    elif name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), name)
    else:
        raise AttributeError(f"module 'fixplan' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
