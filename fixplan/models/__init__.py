"""Friction models of a contact: the exact limit surface and the paper's approximations.

Every model is built from an exact :class:`~fixplan.LimitSurface` by
``Model.from_limit_surface(ls, ...)`` and offers one interface (:class:`FrictionModel`):
``contains``, ``safety_factor``, ``motion`` (where the model has a motion map), ``conservative``
and ``constraints(load, normal_force)`` for cvxpy, and
``conic_form()``: the same set as cones on affine rows, which the planner stacks over every
contact and load case. Models are immutable values that store their
geometry per unit normal force.

============================  ==========  ======  ============  ===========================
model                         torsion     motion  conservative  cvxpy form
============================  ==========  ======  ============  ===========================
:class:`Ellipsoid`            yes         yes     no            one second-order cone
:class:`FittedEllipsoid`      yes         yes     no            one second-order cone
:class:`FacetedEllipsoid`     yes         yes     no            cone + 2 inequalities/point
:class:`Cone`                 yes         no      yes           two second-order cones
:class:`Pyramid`              yes         no      if inscribed  ``2k`` linear inequalities
:class:`PointCone`            no          yes     yes           one second-order cone
:class:`PointPyramid`         no          no      if inscribed  ``k`` linear inequalities
:class:`Exact`                yes         yes     yes (exact)   tangent planes; cuts in planner
:class:`Polytope`             yes         yes     if inscribed  ``2k`` linear inequalities
============================  ==========  ======  ============  ===========================

A :class:`Polytope` is any set of linear inequalities; built from tangent planes it reports its
largest radial gap to the surface cut (``from_limit_surface``; a fitted quartic's
``planner_model``).

Every model accepts ``mu = 0``, a frictionless contact: its set is the load 0 and its
constraints ``load == 0`` (see :mod:`fixplan.models.base`). Accuracy against the exact surface is
measured by :func:`fixplan.models.compare.compare`.
"""

from fixplan.models.base import FrictionModel
from fixplan.models.conic import ConicForm
from fixplan.models.ellipsoid import Ellipsoid, FacetedEllipsoid, FittedEllipsoid, fit_ellipsoid
from fixplan.models.exact import Exact
from fixplan.models.polyhedral import Cone, PointCone, PointPyramid, Pyramid
from fixplan.models.polytope import Polytope

#: Every model class, in the order of the table above.
MODEL_CLASSES = (
    Ellipsoid,
    FittedEllipsoid,
    FacetedEllipsoid,
    Cone,
    Pyramid,
    PointCone,
    PointPyramid,
    Exact,
    Polytope,
)

__all__ = [
    "MODEL_CLASSES",
    "Cone",
    "ConicForm",
    "Ellipsoid",
    "Exact",
    "FacetedEllipsoid",
    "FittedEllipsoid",
    "FrictionModel",
    "PointCone",
    "PointPyramid",
    "Polytope",
    "Pyramid",
    "fit_ellipsoid",
]
