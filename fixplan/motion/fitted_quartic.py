r"""A limit surface that is the level set of a convex homogeneous quartic (Zhou et al. 2016).

In the coordinates ``x = (fx, fy, m / rho)`` [N] of loads about the frame origin, the surface
is the level set ``H(x) = 1`` of

.. math:: H(x) = \sum_{k=1}^{15} c_k \, x^{\alpha_k}, \qquad |\alpha_k| = 4,

with the 15 monomials of :data:`MONOMIALS` (the order of Zhou's PlanarManipulationToolBox, so
published coefficients load directly). ``H`` is homogeneous of degree 4, so the factor that puts
a load on the surface is ``H(x)^{-1/4}``, and the sliding twist is the normal ``∇H`` (maximum
power): ``(vx, vy, rho w) ∝ ∇H(x)``. ``H`` is SOS-convex: ``y^T ∇²H(x) y`` is a sum of squares
of the nine products ``x_i y_j`` (:func:`sos_convexity_maps`), which makes the set convex and
lets a semidefinite program fit it (:func:`fixplan.motion.identify.fit`).

The support function ``h(V) = max {V · L : H(x) <= 1}`` and its gradient, the forward map
``L(V)``, are solved by Newton's method on ``∇H(x) = u``, ``u = (vx, vy, rho w)``, a convex
problem (``H(x) - u · x`` has a unique minimiser).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from fixplan import validation
from fixplan.errors import ConvergenceError, InvalidArgumentError
from fixplan.models.polytope import DEFAULT_CUTS, Polytope, symmetric_directions
from fixplan.surface.sphere import circle, fibonacci_sphere
from fixplan.tolerances import CONTAINMENT_RTOL

#: The 15 monomials of degree 4 in ``(x, y, z) = (fx, fy, m / rho)``, in the order of the
#: coefficients (Zhou's ``Fit4thOrderPolyCVX.m`` and ``mcube_zhou_fits.json``).
MONOMIALS = ("x^4", "y^4", "z^4", "x^3*y", "x^3*z", "y^3*x", "y^3*z", "z^3*x", "z^3*y",
             "x^2*y^2", "x^2*z^2", "y^2*z^2", "x^2*y*z", "y^2*x*z", "z^2*x*y")  # fmt: skip

#: Exponents ``(15, 3)`` of :data:`MONOMIALS`.
EXPONENTS = np.array([[4, 0, 0], [0, 4, 0], [0, 0, 4], [3, 1, 0], [3, 0, 1], [1, 3, 0],
                      [0, 3, 1], [1, 0, 3], [0, 1, 3], [2, 2, 0], [2, 0, 2], [0, 2, 2],
                      [2, 1, 1], [1, 2, 1], [1, 1, 2]])  # fmt: skip

#: Newton's method on ``∇H(x) = u`` stops when the residual is below this fraction of ``|u|``:
#: the normal is then within about this angle [rad] of ``u`` and the support function accurate
#: to about its square (the residual's rounding floor is about 1e-12).
NEWTON_RTOL = 1e-10

#: Most Newton iterations of the forward map.
NEWTON_MAX_ITERATIONS = 100

#: Sufficient decrease of the damped Newton step (Armijo constant) and most step halvings.
_ARMIJO, _MAX_HALVINGS = 1e-4, 60

#: A quartic counts as convex when the smallest eigenvalue of its Hessian on the unit sphere is
#: at least ``-CONVEXITY_RTOL`` times the largest (rounding of a solver's SOS certificate).
CONVEXITY_RTOL = 1e-6

#: Directions on the unit sphere where given coefficients are checked for a bounded, convex set.
_CHECK_DIRECTIONS = 2000

#: Force directions over which the largest force is averaged.
_FORCE_ANGLES = 360

_PLANES = {"fx-m": (0, 2), "fy-m": (1, 2), "fx-fy": (0, 1)}

#: Every exponent of degree <= 4 in three variables: the monomials of ``H`` and its derivatives.
_ALL = np.array([e for e in itertools.product(range(5), repeat=3) if sum(e) <= 4])
_INDEX = {tuple(e): i for i, e in enumerate(_ALL.tolist())}
_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def _derivative_map(orders: tuple[int, ...]) -> np.ndarray:
    """Matrix ``(35, 15)`` taking coefficients to those of a derivative of ``H`` (``orders``
    lists the variables differentiated by) in the monomials of degree <= 4."""
    result = np.zeros((len(_ALL), len(EXPONENTS)))
    for k, exponent in enumerate(EXPONENTS):
        power, factor = list(exponent), 1.0
        for axis in orders:
            factor *= power[axis]
            power[axis] -= 1
        if factor:
            result[_INDEX[tuple(power)], k] = factor
    return result


_VALUE = _derivative_map(())
_GRADIENT = np.stack([_derivative_map((k,)) for k in range(3)], axis=2)
_HESSIAN = np.stack([_derivative_map(pair) for pair in _PAIRS], axis=2)


def monomials(x: np.ndarray, exponents: np.ndarray = EXPONENTS) -> np.ndarray:
    """Monomials ``(K, E)`` of points ``x`` ``(K, 3)`` for ``exponents`` ``(E, 3)``."""
    powers = x[:, :, None] ** np.arange(5)
    return (
        powers[:, 0, exponents[:, 0]]
        * powers[:, 1, exponents[:, 1]]
        * powers[:, 2, exponents[:, 2]]
    )


def gradient_matrices(x: np.ndarray) -> np.ndarray:
    """Matrices ``(3, K, 15)``: ``gradient_matrices(x)[k] @ c`` is ``∂H/∂x_k`` at ``x``."""
    return np.einsum("ka,acd->dkc", monomials(x, _ALL), _GRADIENT)


def sos_convexity_maps() -> tuple[np.ndarray, np.ndarray]:
    r"""Linear maps ``(M_c, M_Q)`` with ``M_c c = M_Q vec(Q)`` iff ``y^T ∇²H(x) y = z^T Q z``.

    ``z = (x_i y_j)`` (``i, j`` = 0..2, index ``3 i + j``) and ``vec`` stacks columns; rows are
    the 36 monomials ``x^β y^γ`` with ``|β| = |γ| = 2``. ``H`` is SOS-convex when this holds
    for some ``Q ⪰ 0``.
    """
    rows: dict[tuple, int] = {}

    def row(beta, gamma) -> int:
        return rows.setdefault((tuple(beta), tuple(gamma)), len(rows))

    from_coefficients, from_gram = {}, {}
    for k, exponent in enumerate(EXPONENTS):
        for i, j in itertools.product(range(3), repeat=2):
            factor = exponent[i] * (exponent[j] - (i == j))
            if factor:
                beta = exponent - np.eye(3, dtype=int)[i] - np.eye(3, dtype=int)[j]
                gamma = np.eye(3, dtype=int)[i] + np.eye(3, dtype=int)[j]
                key = (row(beta, gamma), k)
                from_coefficients[key] = from_coefficients.get(key, 0.0) + factor
    for a, b in itertools.product(range(9), repeat=2):
        (i, j), (p, q) = divmod(a, 3), divmod(b, 3)
        beta = np.eye(3, dtype=int)[i] + np.eye(3, dtype=int)[p]
        gamma = np.eye(3, dtype=int)[j] + np.eye(3, dtype=int)[q]
        key = (row(beta, gamma), a + 9 * b)
        from_gram[key] = from_gram.get(key, 0.0) + 1.0
    coefficient_map = np.zeros((len(rows), len(EXPONENTS)))
    gram_map = np.zeros((len(rows), 81))
    for (r, k), value in from_coefficients.items():
        coefficient_map[r, k] = value
    for (r, k), value in from_gram.items():
        gram_map[r, k] = value
    return coefficient_map, gram_map


@dataclass(frozen=True, slots=True, kw_only=True, repr=False, eq=False)
class FittedQuartic:
    r"""A limit surface ``H(x) = 1``, ``H`` an SOS-convex quartic (see the module docstring).

    It offers the interface of :class:`fixplan.LimitSurface` (``safety_factor``, ``contains``,
    ``motion``, ``motion_and_safety_factor``, ``support``, ``load``, ``curve``, ``sample``), so
    it drives :func:`fixplan.motion.push_step` and :func:`fixplan.motion.push`.

    Attributes
    ----------
    coefficients : numpy.ndarray
        ``c`` ``(15,)`` of :data:`MONOMIALS` in ``x = (fx, fy, m / rho)`` [1/N⁴].
    rho : float
        Length [m] that scales moments in ``x`` (any positive value; Zhou's fits use the mean
        distance of the outline's vertices from their mean).
    normal_force : float
        Normal force [N] at which the surface holds (at which the loads were measured).
    """

    #: The inverse map (:meth:`motion`) is closed form and the forward map (:meth:`load`) a
    #: Newton solve: :func:`fixplan.motion.push_step` takes the route through the motion cone.
    closed_form_motion: ClassVar[bool] = True

    coefficients: np.ndarray
    rho: float
    normal_force: float = 1.0
    _value: np.ndarray = field(init=False)
    _gradient: np.ndarray = field(init=False)
    _hessian: np.ndarray = field(init=False)
    _units: np.ndarray = field(init=False)

    def __post_init__(self):
        coefficients = validation.finite_array("coefficients", self.coefficients, shape=(15,))
        object.__setattr__(self, "coefficients", coefficients)
        object.__setattr__(self, "rho", validation.positive_scalar("rho", self.rho))
        object.__setattr__(
            self, "normal_force", validation.positive_scalar("normal_force", self.normal_force)
        )
        object.__setattr__(self, "_value", _VALUE @ coefficients)
        object.__setattr__(self, "_gradient", np.einsum("ack,c->ak", _GRADIENT, coefficients))
        object.__setattr__(self, "_hessian", np.einsum("ack,c->ak", _HESSIAN, coefficients))
        self._check_shape()
        max_force = self._largest_force()
        max_moment = self.support(np.array([0.0, 0.0, 1.0]))
        object.__setattr__(self, "_units", np.array([max_force, max_force, max_moment]))

    @classmethod
    def from_coefficients(
        cls, coefficients, *, rho: float, normal_force: float = 1.0
    ) -> FittedQuartic:
        """From published coefficients: 15 numbers in the order of :data:`MONOMIALS`, or a
        mapping from the names of :data:`MONOMIALS` (``"x^4"``, ..., ``"z^2*x*y"``) to numbers;
        ``x = (fx, fy, m / rho)`` [N] at ``normal_force`` [N]."""
        if isinstance(coefficients, Mapping):
            unknown = sorted(set(coefficients) - set(MONOMIALS))
            missing = [name for name in MONOMIALS if name not in coefficients]
            if unknown or missing:
                raise InvalidArgumentError(
                    f"coefficients must name each of {', '.join(MONOMIALS)} once; unknown "
                    f"{unknown}, missing {missing}"
                )
            coefficients = [coefficients[name] for name in MONOMIALS]
        return cls(coefficients=coefficients, rho=rho, normal_force=normal_force)

    def _check_shape(self) -> None:
        """Raise unless ``H`` is positive and convex on the unit sphere (a bounded convex set)."""
        directions = fibonacci_sphere(_CHECK_DIRECTIONS)
        values, _, hessians = self._evaluate(directions, hessian=True)
        if np.min(values) <= 0.0:
            worst = directions[int(np.argmin(values))]
            raise InvalidArgumentError(
                f"coefficients give H <= 0 in the direction x = {np.round(worst, 3).tolist()}: "
                "the level set H = 1 is unbounded; give the coefficients of a positive quartic"
            )
        eigenvalues = np.linalg.eigvalsh(hessians)
        if np.any(eigenvalues[:, 0] < -CONVEXITY_RTOL * eigenvalues[:, -1]):
            worst = directions[int(np.argmin(eigenvalues[:, 0] / eigenvalues[:, -1]))]
            raise InvalidArgumentError(
                f"coefficients give a quartic that is not convex at x = "
                f"{np.round(worst, 3).tolist()}: its level set is no limit surface; fit it with "
                "fixplan.motion.fit(..., model='quartic'), which keeps it SOS-convex"
            )

    # -- description ------------------------------------------------------------------------

    @property
    def frictionless(self) -> bool:
        """Always ``False``: a fitted surface has friction."""
        return False

    @property
    def max_force(self) -> float:
        """Largest friction force [N] (pure translation), root mean square over the force
        directions: isotropic friction makes it the same in every direction, and the
        translation section of a fit is nearly a circle."""
        return float(self._units[0])

    @property
    def max_moment(self) -> float:
        """Largest friction moment about the frame origin [N m] (rotation about the origin)."""
        return float(self._units[2])

    @property
    def mu(self) -> float:
        """Largest friction force per unit normal force [-] (``max_force / normal_force``)."""
        return self.max_force / self.normal_force

    @property
    def characteristic_length(self) -> float:
        """``max_moment / max_force`` [m]."""
        return self.max_moment / self.max_force

    def __repr__(self) -> str:
        return (
            f"FittedQuartic(mu={self.mu:.6g}, rho={self.rho:.6g} m, "
            f"normal_force={self.normal_force:.6g} N)"
        )

    # -- the quartic ----------------------------------------------------------------------------

    def _coordinates(self, load) -> tuple[np.ndarray, bool]:
        loads, single = validation.vector_batch("load", load, width=3)
        return loads / np.array([1.0, 1.0, self.rho]), single

    def _evaluate(self, x: np.ndarray, *, hessian: bool = False):
        """``H`` ``(K,)``, ``∇H`` ``(K, 3)`` and, if asked, ``∇²H`` ``(K, 3, 3)`` at ``x``."""
        basis = monomials(x, _ALL)
        values, gradients = basis @ self._value, basis @ self._gradient
        if not hessian:
            return values, gradients, None
        pairs = basis @ self._hessian
        matrices = pairs[:, [[0, 3, 4], [3, 1, 5], [4, 5, 2]]]
        return values, gradients, matrices

    def level(self, load) -> np.ndarray | float:
        """``H(x)`` [-] of loads ``(3,)`` or ``(K, 3)`` [N, N, N m]: 1 on the surface."""
        x, single = self._coordinates(load)
        values = self._evaluate(x)[0]
        return float(values[0]) if single else values

    # -- inverse map ------------------------------------------------------------------------

    def safety_factor(self, load) -> np.ndarray | float:
        """Factor ``s = H(x)^{-1/4}`` with ``s * load`` on the surface (``inf`` for 0)."""
        x, single = self._coordinates(load)
        with np.errstate(divide="ignore"):
            safety = self._evaluate(x)[0] ** -0.25
        return float(safety[0]) if single else safety

    def contains(self, load) -> np.ndarray | bool:
        """Whether ``load`` is held (safety factor >= ``1 - CONTAINMENT_RTOL``)."""
        held = np.asarray(self.safety_factor(load)) >= 1.0 - CONTAINMENT_RTOL
        return bool(held) if held.ndim == 0 else held

    def motion(self, load) -> np.ndarray:
        """Unit twist of impending sliding under ``load`` (normality; NaN for the zero load),
        scaled so that ``(vx, vy, rho w)`` has unit norm."""
        return self.motion_and_safety_factor(load)[0]

    def motion_and_safety_factor(self, load) -> tuple[np.ndarray, np.ndarray | float]:
        """:meth:`motion` and :meth:`safety_factor` from one evaluation."""
        x, single = self._coordinates(load)
        values, gradients, _ = self._evaluate(x)
        with np.errstate(divide="ignore", invalid="ignore"):
            safety = values**-0.25
            twists = gradients / np.linalg.norm(gradients, axis=1, keepdims=True)
        twists[:, 2] /= self.rho
        if single:
            return twists[0], float(safety[0])
        return twists, safety

    # -- forward map ------------------------------------------------------------------------

    def support(self, twist) -> np.ndarray | float:
        """Support function ``h(V) = max {V · L : H <= 1}`` [W per unit speed] of twists
        ``(3,)`` or ``(K, 3)``."""
        twists, single = validation.vector_batch("twist", twist, width=3)
        u = twists * np.array([1.0, 1.0, self.rho])
        values = np.zeros(len(u))
        moving = np.any(u != 0.0, axis=1)
        values[moving] = np.einsum(
            "ij,ij->i", u[moving], _surface_points(self._evaluate, u[moving])
        )
        return float(values[0]) if single else values

    def load(self, twist) -> np.ndarray:
        """Load ``(fx, fy, m)`` [N, N, N m] on the surface that sustains sliding with the
        nonzero ``twist`` ``(3,)`` or ``(K, 3)``: ``∇h(V)``."""
        twists, single = validation.vector_batch("twist", twist, width=3)
        if not np.all(np.any(twists != 0.0, axis=1)):
            zero = int(np.flatnonzero(~np.any(twists != 0.0, axis=1))[0])
            raise InvalidArgumentError(f"twist[{zero}] is zero: a body at rest has no sliding load")
        points = _surface_points(self._evaluate, twists * np.array([1.0, 1.0, self.rho]))
        loads = points * np.array([1.0, 1.0, self.rho])
        return loads[0] if single else loads

    def _largest_force(self) -> float:
        """Largest force [N] (the support of pure translations ``(cos a, sin a, 0)``), root
        mean square over the force directions (the trapezoid rule on a smooth periodic
        function: exact to rounding at this many angles)."""
        angles = np.pi * np.arange(_FORCE_ANGLES) / _FORCE_ANGLES
        forces = self.support(np.column_stack([np.cos(angles), np.sin(angles), 0.0 * angles]))
        return float(np.sqrt(np.mean(forces * forces)))

    # -- as a planner model ----------------------------------------------------------------------

    def planner_model(self, *, cuts: int = DEFAULT_CUTS, inscribed: bool = True) -> Polytope:
        r"""The surface as a planner model: a polytope of ``cuts`` tangent planes.

        The planes touch the surface at the loads ``x_i`` along a centrally symmetric
        Fibonacci lattice of directions in coordinates normalised by ``max_force`` and
        ``max_moment`` (:func:`~fixplan.models.polytope.symmetric_directions`), scaled onto
        ``H = 1``: ``∇H(x_i) · x <= ∇H(x_i) · x_i``. Their intersection holds the surface;
        its largest relative radial gap to it, ``error``, is read at the polytope's vertices
        (:meth:`~fixplan.models.Polytope.from_tangent_planes`; exact, not sampled). It
        shrinks as ``1 / cuts``; 256 cuts give about 2 % on a quartic fitted to the paper's
        10:1 rectangle.

        Parameters
        ----------
        cuts : int
            Number of tangent planes (halfspaces), even, >= 6; the planner writes one linear
            inequality per plane, per contact and load case.
        inscribed : bool
            Shrink the polytope by ``1 + error`` into the surface (default), so that the
            planner is never told a contact holds a load that the fitted surface would let
            slide; it then underestimates the surface by at most ``error``. With ``False``
            the polytope holds the surface and overestimates it by at most ``error``.

        Returns
        -------
        Polytope
            Per unit normal force (as the planner's models are), with this surface's ``mu``,
            ``rho = characteristic_length``, moments about the frame origin, and ``error``.
        """
        loads = self._radial(symmetric_directions(cuts), False)
        return Polytope.from_tangent_planes(
            self.motion(loads),
            loads / self.normal_force,
            gauge=lambda unit: np.asarray(self.safety_factor(unit * self.normal_force)) ** -1.0,
            mu=self.mu,
            rho=self.characteristic_length,
            inscribed=inscribed,
        )

    # -- plotting and sampling ------------------------------------------------------------------

    def curve(self, plane: str = "fy-m", n: int = 361, *, normalized: bool = False) -> np.ndarray:
        """Cross section of the surface by a coordinate plane, as loads ``(n, 3)``.

        As :meth:`fixplan.LimitSurface.curve`: ``plane`` is ``"fx-m"``, ``"fy-m"`` or
        ``"fx-fy"``; points spread evenly in angle in coordinates normalised by ``max_force``
        and ``max_moment``, counter-clockwise from the first axis; ``normalized`` returns them
        in those coordinates.
        """
        axes = _PLANES.get(plane)
        if axes is None:
            raise InvalidArgumentError(f"plane must be one of {', '.join(_PLANES)}; got {plane!r}")
        directions = np.zeros((_count(n), 3))
        directions[:, axes] = circle(_count(n))
        return self._radial(directions, normalized)

    def sample(self, n: int = 1000, *, normalized: bool = False) -> np.ndarray:
        """``n`` loads ``(n, 3)`` spread evenly over the surface (a Fibonacci lattice of
        directions in normalised coordinates, each scaled onto the surface; deterministic)."""
        return self._radial(fibonacci_sphere(_count(n)), normalized)

    def _radial(self, directions: np.ndarray, normalized: bool) -> np.ndarray:
        loads = directions * self._units
        loads = loads * np.asarray(self.safety_factor(loads))[:, None]
        return loads / self._units if normalized else loads


def _count(n: object) -> int:
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise InvalidArgumentError(f"n must be a positive integer, got {n!r}")
    return int(n)


def _surface_points(evaluate, u: np.ndarray) -> np.ndarray:
    """Points ``x`` ``(K, 3)`` with ``H(x) = 1`` and ``∇H(x) ∝ u`` (``u`` nonzero): damped
    Newton on ``∇H(x) = t``, ``t ∝ u`` as large as ``∇H`` at the start, i.e. the minimiser of
    the convex ``H(x) - t · x``, then scaled onto the level set. ``evaluate`` is
    :meth:`FittedQuartic._evaluate`."""
    direction = u / np.linalg.norm(u, axis=1, keepdims=True)
    x = direction * evaluate(direction)[0][:, None] ** -0.25
    target = direction * np.linalg.norm(evaluate(x)[1], axis=1, keepdims=True)
    active = np.arange(len(x))
    for _ in range(NEWTON_MAX_ITERATIONS):
        values, gradients, hessians = evaluate(x[active], hessian=True)
        residual = gradients - target[active]
        size = np.linalg.norm(target[active], axis=1)
        moving = np.linalg.norm(residual, axis=1) > NEWTON_RTOL * size
        active, values, residual, hessians = (
            active[moving], values[moving], residual[moving], hessians[moving]
        )  # fmt: skip
        if active.size == 0:
            break
        step = -np.linalg.solve(hessians, residual[:, :, None])[:, :, 0]
        x[active] += _damped(evaluate, x[active], step, values, residual, target[active])
    else:
        raise ConvergenceError(
            f"Newton's method on the quartic's forward map did not converge in "
            f"{NEWTON_MAX_ITERATIONS} iterations for twists u = {u[active[:3]].tolist()}"
        )
    return x / evaluate(x)[0][:, None] ** 0.25


def _damped(evaluate, x, step, values, residual, target) -> np.ndarray:
    """``t * step`` with ``t`` halved until ``F = H - target · x`` decreases enough (Armijo)
    or, near the solution where ``F`` is flat to rounding, the residual does."""
    objective = values - np.einsum("ij,ij->i", target, x)
    slope = np.einsum("ij,ij->i", residual, step)
    size = np.linalg.norm(residual, axis=1)
    scale = np.ones(len(x))
    for _ in range(_MAX_HALVINGS):
        trial = x + scale[:, None] * step
        new, gradients, _ = evaluate(trial)
        new = new - np.einsum("ij,ij->i", target, trial)
        closer = np.linalg.norm(gradients - target, axis=1) < size
        short = (new > objective + _ARMIJO * scale * slope) & ~closer
        if not np.any(short):
            break
        scale[short] *= 0.5
    return scale[:, None] * step
