r"""An exact contact on point supports in a convex program: its set exactly, one cone per point.

At normal force ``N``, point supports at ``(x_i, y_i)`` (the contact's frame) whose friction is
``c_i N`` (``c_i``: the point's friction per unit normal force, its ``mu`` times its share of the
force) hold exactly the loads

.. math:: \ell = \sum_i \left(f_i,\; x_i f_{i,y} - y_i f_{i,x}\right), \qquad |f_i| \le c_i N,

the Minkowski sum of the points' friction disks (paper §4.4): a second-order cone per point.
Where an exact contact's set has facets, no ellipsoid osculates it there
(:mod:`~fixplan.planner.osculating_contact`), and its seed polytope holds it only from outside;
on point supports alone this is the set itself, in one solve.
"""

from __future__ import annotations

import cvxpy as cp

from fixplan.models import Exact

#: The point supports' friction is the whole surface's largest force to this fraction.
WHOLE_FRICTION_RTOL = 1e-12


def on_point_supports(model) -> bool:
    """Whether ``model`` is an exact model with friction whose surface is point supports
    alone: their friction is its largest force (a pure translation moves every point alike)."""
    if not isinstance(model, Exact) or model.frictionless:
        return False
    surface = model.surface
    friction = surface.point_supports[1]
    whole = surface.max_force
    return len(friction) > 0 and abs(float(friction.sum()) - whole) <= WHOLE_FRICTION_RTOL * whole


def point_support_constraints(model: Exact, load, normal_force) -> list:
    """The constraints that hold ``load`` (a cvxpy ``(3,)`` expression: ``(fx, fy, m)`` in the
    contact's frame, the model's load) in the exact set of ``model``'s point supports
    (:func:`on_point_supports`) at ``normal_force`` [N] (a number or an affine cvxpy scalar)."""
    points, friction = model.surface.point_supports
    per_force = friction / model.surface.normal_force
    forces = cp.Variable((len(friction), 2), name="point_support_forces")
    moment = points[:, 0] @ forces[:, 1] - points[:, 1] @ forces[:, 0]
    summed = cp.hstack([cp.sum(forces[:, 0]), cp.sum(forces[:, 1]), moment])
    return [cp.SOC(per_force * normal_force, forces, axis=1), load == summed]
