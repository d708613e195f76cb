"""Simulators: fixplan's contact models as the parameters of physics engines (MuJoCo), Drake's
hydroelastic contact as a check of the exact limit surface, and plans judged by either engine
(:mod:`fixplan.sim.validate`, :mod:`fixplan.sim.drake_validate`)."""

from fixplan.sim.drake_check import DirectionResult, HydroelasticCheck, hydroelastic_check
from fixplan.sim.mujoco_contact import MujocoContact, mujoco_contact

__all__ = [
    "DirectionResult",
    "HydroelasticCheck",
    "MujocoContact",
    "hydroelastic_check",
    "mujoco_contact",
]
