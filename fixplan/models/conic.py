r"""Friction sets as convex cones on affine rows, in a form that stacks.

Every friction model writes its set at normal force ``N`` as a :class:`ConicForm`: cones on
rows that are linear in ``N``, the load and (for some models) auxiliary variables. The planner
stacks the rows of every contact and load case into one constraint per cone kind
(:mod:`fixplan.planner.stacking`); :meth:`ConvexForm.constraints` turns one form into cvxpy
constraints for a single contact.
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError


class ConvexForm:
    """What a friction model adds to be written as convex constraints (a mixin).

    The model supplies ``_unit_conic`` (its set in normalised coordinates ``q``) and the
    attributes ``frictionless``, ``torsion``, ``load_dimension``, ``center`` and ``_units()``
    of :class:`~fixplan.models.base.FrictionModel`.
    """

    __slots__ = ()

    @abstractmethod
    def _unit_conic(self) -> ConicForm:
        """``g(q) <= N`` as a :class:`ConicForm` in the normalised coordinates ``q``."""

    def conic_form(self) -> ConicForm:
        """The set at normal force ``N`` as cones on affine rows of ``(N, load, aux)``.

        The form stacks: the planner writes every contact and load case of a model type into
        one cone constraint. ``load`` is ``(ft1, ft2, mn)`` [N, N, N m] about the frame origin
        (area models) or ``(ft1, ft2)`` [N] (point models).
        """
        if self.frictionless:  # the load is zero
            width = self.load_dimension
            return ConicForm(
                normal=np.zeros(width), load=np.eye(width), aux=np.zeros((width, 0)),
                cones=(("zero", width),),
            )  # fmt: skip
        unit = self._unit_conic()
        to_q = self._normalising_map()
        return ConicForm(normal=unit.normal, load=unit.load @ to_q, aux=unit.aux, cones=unit.cones)

    def constraints(self, load, normal_force) -> list:
        """cvxpy constraints stating that ``load`` lies in the set at ``normal_force``.

        Parameters
        ----------
        load : cvxpy expression or array_like
            Area models: shape ``(3,)``, ``(ft1, ft2, mn)`` [N, N, N m] in the patch frame.
            Point models: shape ``(2,)`` ``(ft1, ft2)``, or ``(3,)`` whose moment is then
            constrained to 0.
        normal_force : cvxpy expression, Parameter or float
            Scalar normal force of the contact [N]. The constraints are homogeneous in it, so
            it may itself be a decision variable.

        Returns
        -------
        list of cvxpy.Constraint
            Convex and DPP (``problem.is_dcp(dpp=True)`` holds with Parameters): one per cone
            kind of :meth:`conic_form`. For a frictionless model: ``load == 0``.
        """
        import cvxpy as cp

        load = load if isinstance(load, cp.Expression) else cp.Constant(np.asarray(load, float))
        if not isinstance(normal_force, cp.Expression):
            normal_force = cp.Constant(validation.nonnegative_scalar("normal_force", normal_force))
        if normal_force.shape not in ((), (1,)):
            raise InvalidArgumentError(
                f"normal_force must be a scalar expression, got shape {normal_force.shape}"
            )
        if normal_force.shape == (1,):
            normal_force = cp.reshape(normal_force, (), order="C")
        allowed = ((3,),) if self.torsion else ((2,), (3,))
        if load.shape not in allowed:
            raise InvalidArgumentError(
                f"load must have shape {' or '.join(str(s) for s in allowed)} for "
                f"{type(self).__name__}, got {load.shape}"
            )
        extra = []
        if not self.torsion and load.shape == (3,):
            extra.append(load[2] == 0.0)
            load = load[:2]
        form = self.conic_form()
        rows = form.normal * normal_force + form.load @ load
        if form.aux.shape[1]:
            rows = rows + form.aux @ cp.Variable(form.aux.shape[1], name="aux")
        return form.cvxpy_constraints(cp.reshape(rows, (form.rows, 1), order="F")) + extra


@dataclass(frozen=True, slots=True)
class ConicForm:
    r"""A friction set at normal force ``N`` as cones on affine rows, in a form that stacks.

    .. math:: r = a N + B \ell + C z \in \mathcal K_1 \times \dots \times \mathcal K_m

    for the load ``ℓ`` and auxiliary variables ``z`` (e.g. the per-point forces of
    :class:`~fixplan.models.Exact`). ``cones`` lists ``(kind, size)`` in row order, ``kind``
    one of ``"zero"`` (rows equal 0), ``"nonneg"`` (rows >= 0) and ``"soc"`` (the first row
    bounds the norm of the others). Homogeneous in ``(N, ℓ, z)``, so it scales with ``N``.

    Attributes
    ----------
    normal : numpy.ndarray
        ``a`` ``(r,)``.
    load : numpy.ndarray
        ``B`` ``(r, d)``.
    aux : numpy.ndarray
        ``C`` ``(r, p)``, ``p >= 0``.
    cones : tuple of (str, int)
        The cones, in row order; their sizes add up to ``r``.
    """

    normal: np.ndarray
    load: np.ndarray
    aux: np.ndarray
    cones: tuple[tuple[str, int], ...]

    @property
    def rows(self) -> int:
        """Number of rows ``r``."""
        return len(self.normal)

    @property
    def bounds_normal(self) -> bool:
        """Whether the cones imply ``N >= 0`` on their own (a cone's first row is ``a N`` with
        ``a > 0``, or the first rows and inequalities add up to a positive multiple of ``N``):
        then the planner needs no separate sign constraint on the normal force."""
        first = [self.rows_of("soc", size)[::size] for size in self._soc_sizes]
        rows = np.concatenate([*first, self.rows_of("nonneg")]).astype(int)
        if rows.size == 0:
            return False
        coefficients = np.hstack([self.load[rows], self.aux[rows]])
        scale = max(float(np.abs(coefficients).max(initial=0.0)), 1e-300)
        pure = (np.abs(coefficients).max(axis=1, initial=0.0) <= 1e-12 * scale) & (
            self.normal[rows] > 0.0
        )
        total = np.abs(coefficients.sum(axis=0)).max(initial=0.0) <= 1e-12 * scale * len(rows)
        return bool(pure.any() or (total and self.normal[rows].sum() > 0.0))

    @property
    def _soc_sizes(self) -> list[int]:
        return sorted({size for kind, size in self.cones if kind == "soc"})

    def rows_of(self, kind: str, size: int | None = None) -> np.ndarray:
        """Indices of the rows in cones of ``kind`` (and ``size``), cone after cone."""
        found, start = [], 0
        for cone_kind, cone_size in self.cones:
            if cone_kind == kind and (size is None or cone_size == size):
                found.append(np.arange(start, start + cone_size))
            start += cone_size
        return np.concatenate(found) if found else np.empty(0, dtype=int)

    def cvxpy_constraints(self, rows) -> list:
        """Constraints on ``rows``, an expression ``(r, n)`` of ``n`` stacked columns: one
        constraint per cone kind and size over all columns."""

        constraints = []
        for kind in ("zero", "nonneg"):
            index = self.rows_of(kind)
            if index.size:
                part = rows[index, :]
                constraints.append(part == 0 if kind == "zero" else part >= 0)
        for size in self._soc_sizes:
            index = self.rows_of("soc", size)
            constraints.append(soc_columns(rows[index, :], size))
        return constraints


def soc_columns(rows, size: int):
    """One cvxpy SOC constraint: ``rows`` ``(m * size, n)`` holds ``m`` cones of ``size`` rows
    in each of its ``n`` columns (the first row of each cone bounds the norm of the rest)."""
    import cvxpy as cp

    count = rows.shape[0] // size * rows.shape[1]
    cones = cp.reshape(rows, (size, count), order="F")
    return cp.SOC(cones[0, :], cones[1:, :], axis=0)


def unit_conic(normal, q, aux=None, cones=()) -> ConicForm:
    """A :class:`ConicForm` in normalised coordinates (what :meth:`_unit_conic` returns)."""
    normal = np.asarray(normal, dtype=float)
    q = np.atleast_2d(np.asarray(q, dtype=float))
    aux = np.zeros((len(normal), 0)) if aux is None else np.asarray(aux, dtype=float)
    return ConicForm(normal=normal, load=q, aux=aux, cones=tuple(cones))
