"""Simulators: fixplan's contact models as the parameters of physics engines (MuJoCo)."""

from fixplan.sim.mujoco_contact import MujocoContact, mujoco_contact

__all__ = ["MujocoContact", "mujoco_contact"]
