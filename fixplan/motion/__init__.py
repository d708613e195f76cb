"""Layer 4: how a part moves (paper §4.3) — pushing, and in time pivoting and free sliding.

Built on the limit surfaces and models of the layers below, without changing their conventions;
imports only from :mod:`fixplan.planner`, :mod:`fixplan.models`, :mod:`fixplan.surface` and the
top-level modules.
"""

from fixplan.motion.outline import Outline
from fixplan.motion.pivoting import Settling, settle
from fixplan.motion.pushing import MotionCone, PushStep, motion_cone, push_step
from fixplan.motion.sliding import Sliding, slide, start_acceleration
from fixplan.motion.trajectory import PointPusher, Trajectory, push

__all__ = [
    "MotionCone",
    "Outline",
    "PointPusher",
    "PushStep",
    "Settling",
    "Sliding",
    "Trajectory",
    "motion_cone",
    "push",
    "push_step",
    "settle",
    "slide",
    "start_acceleration",
]
