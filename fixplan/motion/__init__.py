"""Layer 4: how a part moves (paper §4.3) — pushing, and in time pivoting and free sliding.

Built on the limit surfaces and models of the layers below, without changing their conventions;
imports only from :mod:`fixplan.planner`, :mod:`fixplan.models`, :mod:`fixplan.surface` and the
top-level modules.
"""

from fixplan.motion.pushing import MotionCone, PushStep, motion_cone, push_step

__all__ = ["MotionCone", "PushStep", "motion_cone", "push_step"]
