"""Layer 3: problems, the stacked convex planner, verified plans, motions and certificates.

Imports only from :mod:`fixplan.models`, :mod:`fixplan.surface` and the top-level modules.
"""

from fixplan.planner.contact_surface import ContactSetSurface
from fixplan.planner.plan import Plan
from fixplan.planner.planner import Planner, solve
from fixplan.planner.problem import Body, Contact, Load, Problem, ProblemError
from fixplan.planner.screw import Screw

__all__ = [
    "Body",
    "Contact",
    "ContactSetSurface",
    "Load",
    "Plan",
    "Planner",
    "Problem",
    "ProblemError",
    "Screw",
    "solve",
]
