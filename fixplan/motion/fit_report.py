"""What a fit is and how good it is: :class:`Fit` (a fitted surface and its report, kept in JSON),
:class:`FitReport`, :class:`FitErrors` and :func:`assess`, which measures any surface against
(load, twist) pairs by the same code (fits by :func:`fixplan.motion.identify.fit`, published
fits, exact surfaces).

The JSON of :meth:`Fit.save` (schema ``fixplan.fit``, version 1)::

    {"format": "fixplan.fit", "version": 1, "model": "ellipsoid" | "quartic",
     "surface": {...the fields of FittedEllipsoid or FittedQuartic...},
     "report": {...the fields of FitReport...} | null}
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models.ellipsoid import Ellipsoid, FittedEllipsoid
from fixplan.models.polytope import DEFAULT_CUTS, Polytope
from fixplan.motion.fitted_quartic import MONOMIALS, FittedQuartic
from fixplan.surface.limit_surface import LimitSurface

MODELS = ("ellipsoid", "quartic")

#: The schema of the JSON files of :meth:`Fit.save`.
FORMAT, VERSION = "fixplan.fit", 1


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

    def planner_model(self, *, cuts: int | None = None) -> FittedEllipsoid | Polytope:
        """The fitted surface as a planner model, per unit normal force (as the planner's
        models are): the ellipsoid itself, or the quartic's inscribed polytope of ``cuts``
        tangent planes (default :data:`~fixplan.models.polytope.DEFAULT_CUTS`; see
        :meth:`~fixplan.motion.fitted_quartic.FittedQuartic.planner_model`, which reports its
        ``error``). An ellipsoid takes no ``cuts``: it enters the planner exactly."""
        if isinstance(self.surface, FittedQuartic):
            return self.surface.planner_model(cuts=DEFAULT_CUTS if cuts is None else cuts)
        if cuts is not None:
            raise InvalidArgumentError(
                f"cuts are only for a quartic fit, got cuts={cuts!r} for an ellipsoid, which "
                "enters the planner exactly; leave cuts out"
            )
        return dataclasses.replace(self.surface, normal_force=1.0)


def assess(surface, loads, twists=None, *, rho: float | None = None) -> FitErrors:
    """How well ``surface`` matches measured pairs (the figures of :class:`FitErrors`).

    ``surface`` has ``safety_factor`` and ``motion`` (any limit surface or model with a motion
    map, e.g. a published fit, so that fits are compared by the same code); ``loads`` and
    ``twists`` as for :func:`~fixplan.motion.identify.fit`. ``rho`` [m] weighs the twists' rotation in the angles
    (``(vx, vy, rho w)``); default the surface's ``rho`` (``characteristic_length`` of a
    :class:`~fixplan.LimitSurface`).
    """
    loads, twists = measured_pairs(loads, twists)
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


def measured_pairs(loads, twists) -> tuple[np.ndarray, np.ndarray | None]:
    """Loads and (optional) twists as :func:`_rows`, of the same shape; each twist divided by
    its largest absolute entry (only their directions matter, and their squares stay finite at
    any size)."""
    loads = _rows("loads", loads)
    if twists is None:
        return loads, None
    twists = _rows("twists", twists)
    if twists.shape != loads.shape:
        raise InvalidArgumentError(
            f"twists must have the shape of loads {loads.shape}, got {twists.shape}"
        )
    return loads, twists / np.abs(twists).max(axis=1, keepdims=True)


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles [rad] between the rows of ``a`` and ``b``."""
    cosine = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
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
