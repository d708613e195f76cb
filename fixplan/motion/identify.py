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

:func:`assess` measures any surface against pairs (the figures of a :class:`FitReport`), and
:func:`synthetic` makes pairs from a known surface for tests and demos.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fixplan import validation
from fixplan.errors import ConvergenceError, InvalidArgumentError
from fixplan.models.ellipsoid import Ellipsoid, FittedEllipsoid
from fixplan.motion.fitted_quartic import (
    EXPONENTS,
    MONOMIALS,
    FittedQuartic,
    gradient_matrices,
    monomials,
    sos_convexity_maps,
)
from fixplan.motion.forward_map import forward_map
from fixplan.surface.limit_surface import LimitSurface

MODELS = ("ellipsoid", "quartic")

#: Default weight ``λ`` of the coefficient norm, with the data scaled to unit median radius. It
#: only keeps the problem bounded when the data leave a direction free; at 0.1 (Zhou's value,
#: in newtons) it would shrink every fit by a few per cent.
REGULARIZATION = 1e-4

#: Smallest curvature ``ε`` of a fit with the data scaled to unit median radius: ``A ⪰ ε I`` and
#: ``Q ⪰ ε I``, which keeps the surface bounded and strictly convex (its normals unique).
MIN_CURVATURE = 1e-6

#: Default fraction of the pairs held out of the fit to measure it.
HOLDOUT = 0.2

#: The schema of the JSON files of :meth:`Fit.save`.
FORMAT, VERSION = "fixplan.fit", 1

_DEGREE = {"ellipsoid": 2, "quartic": 4}
_COEFFICIENTS = {"ellipsoid": 6, "quartic": 15}

#: Loads whose normalised rank is below 3 at this relative singular value do not span all
#: three directions (fx, fy, m).
_RANK_RTOL = 1e-9


@dataclass(frozen=True, slots=True, kw_only=True)
class FitErrors:
    """How well a surface matches (load, twist) pairs.

    Attributes
    ----------
    samples : int
        Number of pairs.
    level_rms : float
        Root mean square of ``H(L) - 1`` [-], ``H`` the model's level function (``x^T A x`` of
        an ellipsoid, the quartic, ``1 / safety_factor`` of other surfaces).
    radial_median : float
        Median of ``|r_fit / r - 1|`` [-]: the surface's radius along each load over the
        load's (the safety factor minus 1).
    angle_mean, angle_median : float or None
        Mean and median angle [rad] between the surface's normal at each load and the measured
        twist, both as ``(vx, vy, rho w)``; ``None`` without twists.
    """

    samples: int
    level_rms: float
    radial_median: float
    angle_mean: float | None = None
    angle_median: float | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class FitReport:
    """What :func:`fit` fitted and how well, on the fitted pairs and on held-out ones.

    Attributes
    ----------
    model : str
        ``"ellipsoid"`` or ``"quartic"``.
    twists : bool
        Whether twists were fitted (else the level set only).
    weight, regularization : float
        Weight ``w`` of the twists and ``λ`` of the coefficient norm (module docstring).
    rho : float
        Length [m] of ``x = (fx, fy, m / rho)`` and of the twists' ``(vx, vy, rho w)``.
    holdout : float
        Fraction of the pairs held out; ``seed`` drew them.
    seed : int
        Seed of the random split.
    solver : str
        The cvxpy solver that solved the fit.
    training : FitErrors
        On the fitted pairs.
    validation : FitErrors or None
        On the held-out pairs (``None`` when ``holdout`` is 0).
    """

    model: str
    twists: bool
    weight: float
    regularization: float
    rho: float
    holdout: float
    seed: int
    solver: str
    training: FitErrors
    validation: FitErrors | None


@dataclass(frozen=True, slots=True, kw_only=True)
class Fit:
    """A fitted surface and its report (``None`` for a surface of given coefficients).

    ``surface`` is a :class:`~fixplan.models.FittedEllipsoid` or a
    :class:`~fixplan.motion.fitted_quartic.FittedQuartic`; :meth:`save` and :meth:`load` keep
    both in JSON.
    """

    surface: FittedEllipsoid | FittedQuartic
    report: FitReport | None = None

    def __post_init__(self):
        if not isinstance(self.surface, FittedEllipsoid | FittedQuartic):
            raise InvalidArgumentError(
                f"surface must be a FittedEllipsoid or a FittedQuartic, got "
                f"{type(self.surface).__name__}"
            )
        if self.report is not None and not isinstance(self.report, FitReport):
            raise InvalidArgumentError(f"report must be a FitReport or None, got {self.report!r}")

    def save(self, path) -> None:
        """Write the fit to ``path`` as JSON (schema ``fixplan.fit``, version 1)."""
        Path(path).write_text(json.dumps(_to_json(self), indent=2) + "\n", encoding="utf-8")

    @classmethod
    def load(cls, path) -> Fit:
        """Read a fit written by :meth:`save`; errors name the file and the bad key."""
        try:
            document = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            raise InvalidArgumentError(f"{path}: cannot read a fit as JSON: {exc}") from exc
        return _from_json(document, str(path))


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
    loads, twists = _pairs(loads, twists)
    normal_force = validation.positive_scalar("normal_force", normal_force)
    weight = validation.nonnegative_scalar("weight", weight)
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
            f"a {model} fit needs at least {_COEFFICIENTS[model]} fitted pairs (its coefficients)"
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


def assess(surface, loads, twists=None, *, rho: float | None = None) -> FitErrors:
    """How well ``surface`` matches measured pairs (the figures of :class:`FitErrors`).

    ``surface`` has ``safety_factor`` and ``motion`` (any limit surface or model with a motion
    map, e.g. a published fit, so that fits are compared by the same code); ``loads`` and
    ``twists`` as for :func:`fit`. ``rho`` [m] weighs the twists' rotation in the angles
    (``(vx, vy, rho w)``); default the surface's ``rho`` (``characteristic_length`` of a
    :class:`~fixplan.LimitSurface`).
    """
    loads, twists = _pairs(loads, twists)
    if rho is None:
        rho = surface.characteristic_length if isinstance(surface, LimitSurface) else surface.rho
    rho = validation.positive_scalar("rho", rho)
    safety = np.atleast_1d(surface.safety_factor(loads))
    degree = 4 if isinstance(surface, FittedQuartic) else (
        2 if isinstance(surface, FittedEllipsoid | Ellipsoid) else 1)  # fmt: skip
    level = safety**-degree - 1.0
    errors = {
        "samples": len(loads),
        "level_rms": float(np.sqrt(np.mean(level * level))),
        "radial_median": float(np.median(np.abs(safety - 1.0))),
    }
    if twists is not None:
        weights = np.array([1.0, 1.0, rho])
        angles = _angles(np.atleast_2d(surface.motion(loads)) * weights, twists * weights)
        errors["angle_mean"] = float(np.mean(angles))
        errors["angle_median"] = float(np.median(angles))
    return FitErrors(**errors)


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
        solver = _solve(cp, problem, model)
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


def _solve(cp, problem, model: str) -> str:
    """Solve with Clarabel, once more with SCS if Clarabel fails; the solver's name."""
    for solver in (cp.CLARABEL, cp.SCS):
        try:
            problem.solve(solver=solver)
        except cp.error.SolverError:
            continue
        if problem.status == cp.OPTIMAL:
            return solver
    raise ConvergenceError(
        f"the {model} fit did not solve to optimality (status {problem.status!r} with Clarabel "
        "and SCS); check that the loads surround the origin and are not dominated by outliers"
    )


# -- helpers ----------------------------------------------------------------------------------------


def _rows(name: str, value) -> np.ndarray:
    """``value`` as an ``(n, 3)`` finite array with no zero row."""
    array = validation.finite_array(name, value, shape=(None, 3))
    zero = np.flatnonzero(~np.any(array != 0.0, axis=1))
    if len(array) == 0 or zero.size:
        what = "is empty" if len(array) == 0 else f"row {int(zero[0])} is zero"
        raise InvalidArgumentError(
            f"{name} {what}: every measured pair needs a nonzero {name[:-1]}"
        )
    return array


def _pairs(loads, twists) -> tuple[np.ndarray, np.ndarray | None]:
    """Loads and (optional) twists as :func:`_rows`, of the same shape."""
    loads = _rows("loads", loads)
    if twists is None:
        return loads, None
    twists = _rows("twists", twists)
    if twists.shape != loads.shape:
        raise InvalidArgumentError(
            f"twists must have the shape of loads {loads.shape}, got {twists.shape}"
        )
    return loads, twists


def _rng(seed) -> np.random.Generator:
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise InvalidArgumentError(f"seed must be an integer, got {seed!r}")
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


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles [rad] between the rows of ``a`` and ``b``."""
    cosine = np.einsum("ij,ij->i", _unit(a), _unit(b))
    return np.arccos(np.clip(cosine, -1.0, 1.0))


# -- JSON -------------------------------------------------------------------------------------------


def _to_json(fit: Fit) -> dict:
    surface = fit.surface
    if isinstance(surface, FittedQuartic):
        model, fields = (
            "quartic",
            {
                "monomials": list(MONOMIALS),
                "coefficients": surface.coefficients.tolist(),
                "rho": surface.rho,
                "normal_force": surface.normal_force,
            },
        )
    else:
        model, fields = (
            "ellipsoid",
            {
                "matrix": surface.matrix.tolist(),
                "mu": surface.mu,
                "rho": surface.rho,
                "center": list(surface.center),
                "normal_force": surface.normal_force,
                "fit_error": surface.fit_error,
            },
        )
    report = None if fit.report is None else dataclasses.asdict(fit.report)
    return {"format": FORMAT, "version": VERSION, "model": model, "surface": fields,
            "report": report}  # fmt: skip


_SURFACE_KEYS = {
    "ellipsoid": ("matrix", "mu", "rho", "center", "normal_force", "fit_error"),
    "quartic": ("monomials", "coefficients", "rho", "normal_force"),
}


def _from_json(document, source: str) -> Fit:
    top = _keys(document, ("format", "version", "model", "surface", "report"), source, "")
    if top["format"] != FORMAT or top["version"] != VERSION:
        raise InvalidArgumentError(
            f"{source}: 'format' and 'version' must be {FORMAT!r} and {VERSION}, got "
            f"{top['format']!r} and {top['version']!r}"
        )
    model = top["model"]
    if model not in MODELS:
        raise InvalidArgumentError(f"{source}: 'model' must be one of {MODELS}, got {model!r}")
    fields = _keys(top["surface"], _SURFACE_KEYS[model], source, "surface.")
    try:
        if model == "quartic":
            if fields.pop("monomials") != list(MONOMIALS):
                raise InvalidArgumentError(f"monomials must be {list(MONOMIALS)}")
            surface = FittedQuartic(**fields)
        else:
            surface = FittedEllipsoid(**fields)
    except (InvalidArgumentError, TypeError) as exc:
        raise InvalidArgumentError(f"{source}: key 'surface': {exc}") from exc
    report = top["report"]
    if report is not None:
        names = tuple(f.name for f in dataclasses.fields(FitReport))
        report = _keys(report, names, source, "report.")
        for part in ("training", "validation"):
            if report[part] is not None or part == "training":
                errors = _keys(report[part], tuple(f.name for f in dataclasses.fields(FitErrors)),
                               source, f"report.{part}.")  # fmt: skip
                report[part] = FitErrors(**errors)
        report = FitReport(**report)
    return Fit(surface=surface, report=report)


def _keys(value, names: tuple[str, ...], source: str, prefix: str) -> dict:
    """``value`` as a dict with exactly the keys ``names``; errors name ``prefix + key``."""
    if not isinstance(value, dict):
        raise InvalidArgumentError(
            f"{source}: {'the document' if not prefix else repr(prefix[:-1])} must be an object, "
            f"got {type(value).__name__}"
        )
    unknown = [key for key in value if key not in names]
    missing = [key for key in names if key not in value]
    if unknown or missing:
        key = (unknown or missing)[0]
        what = "is not a key of" if unknown else "is missing from"
        raise InvalidArgumentError(
            f"{source}: key {prefix + key!r} {what} a fit file (keys: {', '.join(names)})"
        )
    return dict(value)
