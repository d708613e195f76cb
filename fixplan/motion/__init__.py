"""Layer 4: how a part moves (paper §4.3) — pushing, pivoting and sliding — and limit surfaces
updated from slip onsets.

Built on the limit surfaces and models of the layers below, without changing their conventions;
imports only from :mod:`fixplan.planner`, :mod:`fixplan.models`, :mod:`fixplan.surface` and the
top-level modules. Compliant contacts (paper §4.4) in :mod:`fixplan.motion.compliance`; the
stiffness of Hertzian contacts for them in :mod:`fixplan.motion.hertz`.
"""

from fixplan.motion.compliance import (
    ComplianceError,
    ComplianceResult,
    Stiffness,
    analyse,
)
from fixplan.motion.fit_report import Fit, FitErrors, FitReport, assess
from fixplan.motion.fitted_quartic import FittedQuartic
from fixplan.motion.hertz import hertz_cylinder, hertz_sphere
from fixplan.motion.identify import ellipsoid_from_matrix, fit, synthetic
from fixplan.motion.line_contact import line_push_step
from fixplan.motion.outline import FacePoints, Outline
from fixplan.motion.pivoting import Settling, settle
from fixplan.motion.pushers import LinePusher, PointPusher
from fixplan.motion.pushing import MotionCone, PushStep, motion_cone, push_step
from fixplan.motion.sliding import Sliding, slide, start_acceleration
from fixplan.motion.slip import ScaledSurface, SlipEstimator
from fixplan.motion.trajectory import Trajectory, push

__all__ = [
    "ComplianceError",
    "ComplianceResult",
    "FacePoints",
    "Fit",
    "FitErrors",
    "FitReport",
    "FittedQuartic",
    "LinePusher",
    "MotionCone",
    "Outline",
    "PointPusher",
    "PushStep",
    "ScaledSurface",
    "Settling",
    "Sliding",
    "SlipEstimator",
    "Stiffness",
    "Trajectory",
    "analyse",
    "assess",
    "ellipsoid_from_matrix",
    "fit",
    "hertz_cylinder",
    "hertz_sphere",
    "line_push_step",
    "motion_cone",
    "push",
    "push_step",
    "settle",
    "slide",
    "start_acceleration",
    "synthetic",
]
