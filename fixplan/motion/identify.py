r"""Limit surfaces fitted to measured (load, twist) pairs (paper §3, §4.3; Zhou et al. 2016).

:func:`fit` fits, in the coordinates ``x = (fx, fy, m / rho)`` [N], either an ellipsoid
``H(x) = x^T A x`` (``A ⪰ 0``) or an SOS-convex homogeneous quartic ``H(x)``
(:class:`~fixplan.motion.fitted_quartic.FittedQuartic`) whose level set ``H = 1`` is the limit
surface and whose normal ``∇H`` is the sliding twist. As Zhou, Paolini, Bagnell & Mason
(ICRA 2016; ``FitEllipsoidForceVelocityCVX.m``, ``Fit4thOrderPolyCVX.m``) it solves the convex
program

.. math::

    \min_{H, s \ge 0} \; \lambda \|c\| + \frac{1}{n} \sum_i |H(x_i) - 1|
        + \frac{w}{n} \sum_i \Big\| \frac{\nabla H(x_i)}{d} - s_i \hat v_i \Big\|,

with ``c`` the coefficients (``‖A‖_F`` for the ellipsoid), ``d`` the degree (so that
``x · ∇H / d = H``), ``v̂_i`` the measured twist ``(vx, vy, rho w)`` made unit and ``w`` the
weight of the twists against the loads (0 without twists: the level set only). The data are
scaled to unit median radius first, so ``λ`` is dimensionless. The ellipsoid becomes a
:class:`~fixplan.models.FittedEllipsoid`, usable by the planner. SOS-convexity of the quartic is
the semidefinite constraint ``y^T ∇²H(x) y = z^T Q z``, ``z = (x_i y_j)``, ``Q ⪰ ε I``.

Two departures from Zhou's program. (1) The twist term uses ``∇H / d`` (Zhou's quartic uses
``∇H``, four times the weight of his ellipsoid's ``A x``). The twist term alone is smallest for
``H → 0``: with noisy twists it shrinks ``H`` on the data (inflates the surface), the more the
heavier its weight (Zhou's published quartics have median ``H`` of 0.4–0.9 on their own
training loads); keep ``w`` near 1. (2) A residual ``|H(x_i) - 1|``
weighs its pair by ``|x_i|^d`` (its gradient in the coefficients), which biases the surface
outward by about ``d σ²`` under radial noise ``σ`` (1 % for the quartic at 5 % noise); the program
is solved once more with the level residuals divided by ``H(x_i)`` of the first fit and the twist
residuals by ``H(x_i)^{1 - 1/d}``, which removes that weighting.

:func:`synthetic` makes pairs from a known surface for tests and demos. What a fit returns, its
report, its JSON and :func:`~fixplan.motion.fit_report.assess` are in
:mod:`fixplan.motion.fit_report`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models.ellipsoid import FittedEllipsoid
from fixplan.models.sdp import solve_sdp
from fixplan.motion.fit_report import MODELS, Fit, FitReport, assess, measured_pairs
from fixplan.motion.fitted_quartic import (
    EXPONENTS,
    FittedQuartic,
    gradient_matrices,
    monomials,
    sos_convexity_maps,
)
from fixplan.motion.forward_map import forward_map
from fixplan.surface.limit_surface import LimitSurface
from fixplan.tolerances import MAX_FIT_WEIGHT

#: Default weight ``λ`` of the coefficient norm, with the data scaled to unit median radius. It
#: only keeps the problem bounded when the data leave a direction free; at 0.1 (Zhou's value,
#: in newtons) it would shrink every fit by a few per cent.
REGULARIZATION = 1e-4

#: Smallest curvature ``ε`` of a fit with the data scaled to unit median radius: ``A ⪰ ε I`` and
#: ``Q ⪰ ε I``, which keeps the surface bounded and strictly convex (its normals unique).
MIN_CURVATURE = 1e-6

#: Default fraction of the pairs held out of the fit to measure it.
HOLDOUT = 0.2

_DEGREE = {"ellipsoid": 2, "quartic": 4}
_COEFFICIENTS = {"ellipsoid": 6, "quartic": 15}

#: Loads whose normalised rank is below 3 at this relative singular value do not span all
#: three directions (fx, fy, m).
_RANK_RTOL = 1e-9


def fit(
    loads,
    twists=None,
    *,
    model: str = "ellipsoid",
    normal_force: float = 1.0,
    weight: float = 1.0,
    rho: float | None = None,
    regularization: float = REGULARIZATION,
    holdout: float = HOLDOUT,
    seed: int = 0,
) -> Fit:
    """Fit a limit surface to measured loads (and twists) (see the module docstring).

    Parameters
    ----------
    loads : array_like
        ``(n, 3)`` loads ``(fx, fy, m)`` [N, N, N m] about the frame origin at which the part
        slid, all at ``normal_force``; none zero.
    twists : array_like, optional
        ``(n, 3)`` twists ``(vx, vy, w)`` [m/s, m/s, rad/s] measured with them (only their
        directions matter); none zero. Without them only the level set is fitted.
    model : str
        ``"ellipsoid"`` (a :class:`~fixplan.models.FittedEllipsoid`) or ``"quartic"`` (a
        :class:`~fixplan.motion.fitted_quartic.FittedQuartic`).
    normal_force : float
        Normal force [N] of the measurements; the surface holds at it.
    weight : float
        Weight ``w`` >= 0 of the twists against the loads (Zhou et al.: 1).
    rho : float, optional
        Length [m] of the moment coordinate ``m / rho`` and of the twists' ``rho w``; default
        the largest moment over the largest force of the loads.
    regularization : float
        Weight ``λ`` >= 0 of the coefficient norm.
    holdout : float
        Fraction in [0, 1) of the pairs left out of the fit and measured in
        ``report.validation``; drawn with ``seed``.
    seed : int
        Seed of the held-out split.

    Raises
    ------
    InvalidArgumentError
        For arrays of the wrong shape, non-finite or zero rows, loads that do not span
        ``(fx, fy, m)``, fewer fitted pairs than coefficients (6 for the ellipsoid, 15 for the
        quartic) or options out of range.
    ConvergenceError
        When neither Clarabel nor SCS solves the fit to optimality.
    """
    model = validation.choice("model", model, MODELS)
    loads, twists = measured_pairs(loads, twists)
    normal_force = validation.positive_scalar("normal_force", normal_force)
    weight = validation.nonnegative_scalar("weight", weight)
    if weight > MAX_FIT_WEIGHT:
        raise InvalidArgumentError(
            f"weight must be at most {MAX_FIT_WEIGHT:g} (the twists against the loads; keep it "
            f"near 1), got {weight!r}"
        )
    regularization = validation.nonnegative_scalar("regularization", regularization)
    holdout = validation.nonnegative_scalar("holdout", holdout)
    if holdout >= 1.0:
        raise InvalidArgumentError(f"holdout must be a fraction in [0, 1), got {holdout!r}")
    rho = _default_rho(loads) if rho is None else validation.positive_scalar("rho", rho)
    order = _rng(seed).permutation(len(loads))
    held = max(round(holdout * len(loads)), 1) if holdout > 0.0 else 0
    train, test = order[held:], order[:held]
    if len(train) < _COEFFICIENTS[model]:
        raise InvalidArgumentError(
            f"the {model} fit needs at least {_COEFFICIENTS[model]} fitted pairs (its coefficients)"
            f", got {len(train)} of {len(loads)} after holding out {held}"
        )
    x = loads[train] * np.array([1.0, 1.0, 1.0 / rho])
    scale = float(np.median(np.linalg.norm(x, axis=1)))
    x = x / scale
    singular = np.linalg.svd(x, compute_uv=False)
    if singular[-1] <= _RANK_RTOL * singular[0]:
        raise InvalidArgumentError(
            "loads must span all three directions (fx, fy, m): they lie in a plane"
        )
    directions = None
    if twists is not None:
        directions = twists[train] * np.array([1.0, 1.0, rho])
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    coefficients, solver = _solve_fit(model, x, directions, weight, regularization)
    if model == "ellipsoid":
        surface = ellipsoid_from_matrix(coefficients / scale**2, rho=rho, normal_force=normal_force)
        gap = np.asarray(surface.safety_factor(loads[train])) ** -1.0 - 1.0
        surface = dataclasses.replace(surface, fit_error=float(np.sqrt(np.mean(gap * gap))))
    else:
        surface = FittedQuartic(coefficients=coefficients / scale**4, rho=rho,
                                normal_force=normal_force)  # fmt: skip

    def errors(rows):
        return assess(surface, loads[rows], None if twists is None else twists[rows], rho=rho)

    report = FitReport(
        model=model,
        twists=twists is not None,
        weight=weight if twists is not None else 0.0,
        regularization=regularization,
        rho=rho,
        holdout=holdout,
        seed=int(seed),
        solver=solver,
        training=errors(train),
        validation=errors(test) if held else None,
    )
    return Fit(surface=surface, report=report)


def ellipsoid_from_matrix(matrix, *, rho: float, normal_force: float = 1.0) -> FittedEllipsoid:
    """The ellipsoid ``x^T A x = 1``, ``x = (fx, fy, m / rho)`` [N], as a ``FittedEllipsoid``.

    ``matrix`` is ``A`` (3x3, symmetric positive definite) [1/N²] at ``normal_force`` [N], e.g.
    a published fit (Zhou's ``A_normalised`` with his ``rho``). The model's ``mu`` is its
    largest force (pure translation) over ``normal_force``, its root mean square over the force
    directions (as :meth:`~fixplan.models.FittedEllipsoid.from_loads`: isotropic friction makes
    it the same in every direction), and its ``rho`` its largest moment over that force.
    """
    matrix = validation.finite_array("matrix", matrix, shape=(3, 3))
    rho = validation.positive_scalar("rho", rho)
    normal_force = validation.positive_scalar("normal_force", normal_force)
    if not np.allclose(matrix, matrix.T, rtol=1e-12, atol=0.0):
        raise InvalidArgumentError(f"matrix must be symmetric, got {matrix.tolist()}")
    if np.linalg.eigvalsh(matrix)[0] <= 0.0:
        raise InvalidArgumentError(
            f"matrix must be positive definite (a bounded ellipsoid), got {matrix.tolist()}"
        )
    to_x = np.diag([1.0, 1.0, 1.0 / rho])
    physical = to_x @ matrix @ to_x
    inverse = np.linalg.inv(physical)  # support function h(V) = sqrt(V^T A^-1 V)
    max_force = math.sqrt(0.5 * (inverse[0, 0] + inverse[1, 1]))
    max_moment = math.sqrt(inverse[2, 2])
    units = np.diag([max_force, max_force, max_moment])
    normalised = units @ physical @ units
    return FittedEllipsoid(
        matrix=0.5 * (normalised + normalised.T),
        mu=max_force / normal_force,
        rho=max_moment / max_force,
        normal_force=normal_force,
    )


def synthetic(
    surface, n: int, *, noise_force: float = 0.0, noise_angle: float = 0.0, seed: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """``n`` (load, twist) pairs of ``surface`` with measurement noise, for tests and demos.

    Twists are drawn uniformly over the directions of ``(vx, vy, rho w)`` (``rho`` the
    surface's characteristic length) and mapped to loads by the surface's forward map
    (:class:`~fixplan.LimitSurface`, :class:`~fixplan.motion.fitted_quartic.FittedQuartic`, or
    any surface of :func:`~fixplan.motion.forward_map.forward_map`). Then each component of
    ``(fx, fy, m / rho)`` gets Gaussian noise of standard deviation ``noise_force`` times the
    load's norm, and each twist is turned by an angle ``noise_angle`` × ``|N(0, 1)|`` [rad]
    (root mean square ``noise_angle``) in a uniformly random direction.

    Returns
    -------
    loads : numpy.ndarray
        ``(n, 3)`` ``(fx, fy, m)`` [N, N, N m].
    twists : numpy.ndarray
        ``(n, 3)`` ``(vx, vy, w)``, with ``(vx, vy, rho w)`` of unit norm.
    """
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise InvalidArgumentError(f"n must be a positive integer, got {n!r}")
    noise_force = validation.nonnegative_scalar("noise_force", noise_force)
    noise_angle = validation.nonnegative_scalar("noise_angle", noise_angle)
    rng = _rng(seed)
    if isinstance(surface, LimitSurface):
        rho = surface.characteristic_length
    else:
        rho = surface.characteristic_length if isinstance(surface, FittedQuartic) else surface.rho
    scale = np.array([1.0, 1.0, rho])
    directions = _unit(rng.standard_normal((int(n), 3)))
    if isinstance(surface, LimitSurface | FittedQuartic):
        loads = np.asarray(surface.load(directions / scale))
    else:
        load = forward_map(surface).load
        loads = np.array([load(twist) for twist in directions / scale])
    x = loads / scale
    x = x + noise_force * np.linalg.norm(x, axis=1, keepdims=True) * rng.standard_normal(x.shape)
    across = rng.standard_normal(directions.shape)
    across = _unit(across - np.einsum("ij,ij->i", across, directions)[:, None] * directions)
    turn = noise_angle * np.abs(rng.standard_normal(len(directions)))[:, None]
    directions = np.cos(turn) * directions + np.sin(turn) * across
    return x * scale, directions / scale


# -- the convex programs --------------------------------------------------------------------------


def _solve_fit(model, x, directions, weight, regularization) -> tuple[np.ndarray, str]:
    """Coefficients (``A`` or ``c``) of the fit to unit-scaled ``x``, and the solver.

    Solved twice: with unit weights, then reweighted by the first fit (module docstring). The
    weights are constants, not cvxpy Parameters: with one per pair the parametrised problem
    takes longer to compile than to solve twice.
    """
    import cvxpy as cp

    degree = _DEGREE[model]
    level_weights = twist_weights = np.ones(len(x))
    for _ in range(2):
        problem, variable, level = _program(cp, model, x, directions, weight, regularization,
                                            level_weights, twist_weights)  # fmt: skip
        solver = solve_sdp(
            problem, what=f"the {model} fit",
            advice="check that the loads surround the origin and are not dominated by outliers",
        )  # fmt: skip
        # H of the fit (> 0: it is strictly convex) sets the weights of the next solve.
        fitted = np.maximum(np.asarray(level.value), MIN_CURVATURE)
        level_weights, twist_weights = 1.0 / fitted, fitted ** (1.0 / degree - 1.0)
    value = np.asarray(variable.value)
    return (0.5 * (value + value.T) if model == "ellipsoid" else value), solver


def _program(cp, model, x, directions, weight, regularization, level_weights, twist_weights):
    """The fit as a cvxpy problem, its coefficient variable and ``H`` at the pairs."""
    if model == "ellipsoid":
        variable = cp.Variable((3, 3), PSD=True)
        level = cp.sum(cp.multiply(x @ variable, x), axis=1)
        normals = [x @ variable[:, k] for k in range(3)]
        constraints = [variable >> MIN_CURVATURE * np.eye(3)]
        size = cp.norm(variable, "fro")
    else:
        variable = cp.Variable(len(EXPONENTS))
        gram = cp.Variable((9, 9), PSD=True)
        coefficient_map, gram_map = sos_convexity_maps()
        level = monomials(x) @ variable
        normals = [matrix @ variable / _DEGREE[model] for matrix in gradient_matrices(x)]
        constraints = [
            coefficient_map @ variable == gram_map @ cp.vec(gram, order="F"),
            gram >> MIN_CURVATURE * np.eye(9),
        ]
        size = cp.norm(variable)
    count = len(x)
    objective = cp.sum(cp.multiply(level_weights, cp.abs(level - 1.0))) / count
    objective += regularization * size
    if directions is not None and weight > 0.0:
        stretch = cp.Variable(count, nonneg=True)
        gaps = cp.vstack([normals[k] - cp.multiply(stretch, directions[:, k]) for k in range(3)])
        objective += weight * cp.sum(cp.multiply(twist_weights, cp.norm(gaps, 2, axis=0))) / count
    return cp.Problem(cp.Minimize(objective), constraints), variable, level


# -- helpers ----------------------------------------------------------------------------------------


def _rng(seed) -> np.random.Generator:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise InvalidArgumentError(f"seed must be an integer >= 0, got {seed!r}")
    return np.random.default_rng(int(seed))


def _default_rho(loads: np.ndarray) -> float:
    """The largest moment over the largest force of ``loads`` [m]."""
    force = float(np.max(np.hypot(loads[:, 0], loads[:, 1])))
    moment = float(np.max(np.abs(loads[:, 2])))
    if force == 0.0 or moment == 0.0:
        raise InvalidArgumentError(
            "loads must span all three directions (fx, fy, m): "
            + ("every force is zero" if force == 0.0 else "every moment is zero")
        )
    return moment / force


def _unit(vectors: np.ndarray) -> np.ndarray:
    return vectors / np.linalg.norm(vectors, axis=1, keepdims=True)
