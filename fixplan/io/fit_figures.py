r"""Figures of a limit surface fitted to measurements (:func:`fixplan.motion.fit`).

:func:`fit_sections_figure` draws the measured loads and the fitted level set in the sections of
the paper's Fig. 5 (and the force plane), :func:`fit_errors_figure` the histograms of the radial
errors and of the twist angles, on the fitted pairs and on the held-out ones. As in
:mod:`fixplan.io.figures`, the data are computed first (plain numpy) and drawn second on a
:class:`matplotlib.figure.Figure` with the Agg canvas; both accept ``axes=`` and return the
figure; :func:`fixplan.io.figures.save_png` writes them with deterministic bytes.

Axes are the fitted surface's normalised loads

.. math:: \left(\frac{f_x}{f_{max}}, \frac{f_y}{f_{max}}, \frac{m}{m_{max}}\right),

with ``f_max`` and ``m_max`` its largest force [N] and moment [N m] (``max_force`` and
``max_moment`` at its normal force).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from fixplan.errors import InvalidArgumentError
from fixplan.io.figures import SECTION_POINTS, _closed, _fmt, _new_figure
from fixplan.motion import Fit, FittedQuartic

if TYPE_CHECKING:  # pragma: no cover - typing only; matplotlib is imported when drawing
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: Measurements within this angle [rad] of a section's plane are drawn in that section,
#: projected on it (uniformly spread loads: about a quarter of them in each section).
NEAR_PLANE_ANGLE = math.radians(15.0)
#: Bins of each histogram (shared by the fitted and held-out pairs).
HISTOGRAM_BINS = 30
#: Relative tolerance within which the split redrawn by :func:`fit_split` must reproduce the
#: median radial error of the fit's report (the same numbers, summed in the same order).
SPLIT_RTOL = 1e-9

_PLANES = (("fx-fy", 0, 1), ("fx-m", 0, 2), ("fy-m", 1, 2))
_LABELS = (r"$f_x/f_{max}$", r"$f_y/f_{max}$", r"$m/m_{max}$")
_TRAINING = ("fitted", "black")
_HELD_OUT = ("held out", "tab:orange")
_ALL = ("measured", "black")


@dataclass(frozen=True, slots=True)
class Split:
    """Which measurements a fit used.

    Attributes
    ----------
    training, held_out : numpy.ndarray
        Row indices of the fitted and of the held-out pairs (the held-out ones are empty when
        nothing was held out or the split is unknown).
    known : bool
        Whether the split is the fit's (else every row is in ``training``: a fit without a
        report, or data other than the fitted).
    """

    training: np.ndarray
    held_out: np.ndarray
    known: bool


def fit_split(fit: Fit, loads) -> Split:
    """The rows of ``loads`` that :func:`fixplan.motion.fit` fitted and held out.

    The fit draws the held-out rows as ``numpy.random.default_rng(seed).permutation(n)[:k]``,
    ``k = max(round(holdout n), 1)`` (0 without holdout), with ``seed`` and ``holdout`` of its
    report; the split is redrawn so and accepted when it reproduces the report's sample counts
    and median radial error on the fitted rows (else, as for a fit without a report, every row
    counts as measured, ``known`` is ``False``).
    """
    loads = np.asarray(loads, dtype=float)
    rows = len(loads)
    unknown = Split(np.arange(rows), np.arange(0), known=False)
    report = fit.report
    if report is None or rows == 0:
        return unknown
    order = np.random.default_rng(report.seed).permutation(rows)
    held = max(round(report.holdout * rows), 1) if report.holdout > 0.0 else 0
    training, held_out = order[held:], order[:held]
    expected = report.validation.samples if report.validation is not None else 0
    if len(training) != report.training.samples or len(held_out) != expected:
        return unknown
    radial = float(np.median(np.abs(_safety(fit, loads[training]) - 1.0)))
    if not math.isclose(radial, report.training.radial_median, rel_tol=SPLIT_RTOL):
        return unknown
    return Split(training, held_out, known=True)


def _safety(fit: Fit, loads: np.ndarray) -> np.ndarray:
    return np.atleast_1d(np.asarray(fit.surface.safety_factor(loads), dtype=float))


def _units(fit: Fit) -> np.ndarray:
    surface = fit.surface
    return np.array([surface.max_force, surface.max_force, surface.max_moment])


def _rho(fit: Fit) -> float:
    """Length [m] weighing rotation in twist angles: the fit's (as its report's angles)."""
    surface = fit.surface
    if fit.report is not None:
        return fit.report.rho
    return surface.max_moment / surface.max_force


def _title(fit: Fit) -> str:
    surface = fit.surface
    model = "quartic" if isinstance(surface, FittedQuartic) else "ellipsoid"
    rho = surface.max_moment / surface.max_force
    return (
        f"{model} fit: $\\mu$ = {_fmt(surface.mu)}, $\\rho$ = {_fmt(rho * 1e3)} mm at "
        f"N = {_fmt(surface.normal_force)} N"
    )


def _groups(split: Split) -> list[tuple[np.ndarray, tuple[str, str]]]:
    """The row sets drawn, each with its label and colour."""
    if not split.known:
        return [(split.training, _ALL)]
    groups = [(split.training, _TRAINING)]
    if len(split.held_out):
        groups.append((split.held_out, _HELD_OUT))
    return groups


def _check_pairs(loads, twists) -> tuple[np.ndarray, np.ndarray | None]:
    loads = np.asarray(loads, dtype=float)
    if loads.ndim != 2 or loads.shape[1] != 3 or not len(loads):
        raise InvalidArgumentError(f"loads must have shape (n, 3), n >= 1, got {loads.shape}")
    if twists is not None:
        twists = np.asarray(twists, dtype=float)
        if twists.shape != loads.shape:
            raise InvalidArgumentError(
                f"twists must have the shape of loads {loads.shape}, got {twists.shape}"
            )
    return loads, twists


# -- sections ---------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Sections:
    curves: tuple[np.ndarray, ...]  # (n, 2) normalised section per plane
    points: tuple[tuple[tuple[np.ndarray, tuple[str, str]], ...], ...]  # per plane, per group
    counts: tuple[int, ...]  # measurements drawn per plane
    rows: int
    title: str


def _sections_data(fit: Fit, loads) -> _Sections:
    loads, _ = _check_pairs(loads, None)
    split = fit_split(fit, loads)
    q = loads / _units(fit)
    size = np.linalg.norm(q, axis=1)
    curves, points, counts = [], [], []
    for plane, a, b in _PLANES:
        curves.append(fit.surface.curve(plane, SECTION_POINTS, normalized=True)[:, [a, b]])
        off = 3 - a - b
        near = np.abs(q[:, off]) <= math.sin(NEAR_PLANE_ANGLE) * size
        drawn = []
        for rows, style in _groups(split):
            chosen = rows[near[rows]]
            drawn.append((q[np.sort(chosen)][:, [a, b]], style))
        points.append(tuple(drawn))
        counts.append(int(np.count_nonzero(near)))
    return _Sections(tuple(curves), tuple(points), tuple(counts), len(loads), _title(fit))


def fit_sections_figure(fit: Fit, loads, *, axes: Sequence[Axes] | None = None) -> Figure:
    """The measured loads and the fitted level set in three coordinate sections.

    Panels ``(fx, fy)``, ``(fx, m)`` and ``(fy, m)`` (the last two are the paper's Fig. 5) in
    the fitted surface's normalised coordinates (module docstring): the central section of the
    fitted surface (the level set ``H = 1`` with the third coordinate 0) and the measurements
    within :data:`NEAR_PLANE_ANGLE` of the plane, projected on it, the fitted and the held-out
    ones apart (:func:`fit_split`). A measured load off the plane meets a smaller slice of the
    surface than the one drawn, so points of an exact fit lie on or just inside the curve.

    Parameters
    ----------
    fit : Fit
        The fit (:func:`fixplan.motion.fit` or :meth:`Fit.load`).
    loads : array_like
        ``(n, 3)`` measured loads ``(fx, fy, m)`` [N, N, N m] at the fit's normal force, as
        fitted.
    axes : sequence of 3 Axes, optional
        Where to draw the panels; default a new figure.

    Returns
    -------
    Figure
    """
    data = _sections_data(fit, loads)
    if axes is None:
        axes = _new_figure((13.0, 4.8)).subplots(1, 3)
    if len(axes) != 3:
        raise InvalidArgumentError(f"axes must hold 3 Axes, got {len(axes)}")
    degrees = math.degrees(NEAR_PLANE_ANGLE)
    for ax, curve, groups, count, (_, a, b) in zip(
        axes, data.curves, data.points, data.counts, _PLANES, strict=True
    ):
        closed = _closed(curve)
        ax.fill(*closed.T, color="tab:blue", alpha=0.10)
        ax.plot(*closed.T, color="tab:blue", linewidth=1.8, label="fitted surface")
        for points, (label, color) in groups:
            marker = "x" if label == _HELD_OUT[0] else "o"
            ax.plot(*points.T, linestyle="none", marker=marker, markersize=3.5, color=color,
                    alpha=0.7, label=f"{label} ({len(points)})")  # fmt: skip
        ax.axhline(0.0, color="0.8", linewidth=0.6)
        ax.axvline(0.0, color="0.8", linewidth=0.6)
        ax.set_xlabel(_LABELS[a])
        ax.set_ylabel(_LABELS[b])
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, linewidth=0.3)
        ax.set_title(f"{count} of {data.rows} measurements within {degrees:.0f}°", fontsize=10)
        ax.legend(loc="lower left", fontsize=7)
    fig = axes[0].figure
    fig.suptitle(data.title + "; measurements near each plane, projected on it", fontsize=11)
    return fig


# -- error histograms -------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Errors:
    radial: tuple[tuple[np.ndarray, tuple[str, str]], ...]  # percent, per group
    angles: tuple[tuple[np.ndarray, tuple[str, str]], ...] | None  # degrees, per group
    title: str


def pair_errors(fit: Fit, loads, twists=None) -> tuple[np.ndarray, np.ndarray | None]:
    """Each pair's signed radial error and twist angle.

    Returns
    -------
    radial : numpy.ndarray
        ``(n,)`` ``r_fit / r - 1`` [-]: the surface's radius along each load over the load's
        (the safety factor minus 1; positive where the surface lies outside the measured load).
    angles : numpy.ndarray or None
        ``(n,)`` angle [rad] between the surface's normal at each load and the measured twist,
        both as ``(vx, vy, rho w)`` with the fit's ``rho``; ``None`` without twists.
    """
    loads, twists = _check_pairs(loads, twists)
    radial = _safety(fit, loads) - 1.0
    if twists is None:
        return radial, None
    weights = np.array([1.0, 1.0, _rho(fit)])
    normals = np.atleast_2d(fit.surface.motion(loads)) * weights
    measured = twists * weights
    cross = np.linalg.norm(np.cross(normals, measured), axis=1)
    return radial, np.arctan2(cross, np.einsum("ij,ij->i", normals, measured))


def _errors_data(fit: Fit, loads, twists) -> _Errors:
    loads, twists = _check_pairs(loads, twists)
    radial, angles = pair_errors(fit, loads, twists)
    groups = _groups(fit_split(fit, loads))
    degrees = None
    if angles is not None:
        degrees = tuple((np.degrees(angles[rows]), style) for rows, style in groups)
    return _Errors(
        radial=tuple((100.0 * radial[rows], style) for rows, style in groups),
        angles=degrees,
        title=_title(fit),
    )


def _histogram(ax, groups, unit: str) -> None:
    """Step histograms of ``groups`` on shared bins, each normalised to fractions of its pairs,
    with each median marked."""
    values = np.concatenate([v for v, _ in groups])
    edges = np.histogram_bin_edges(values, bins=HISTOGRAM_BINS)
    for v, (label, color) in groups:
        if not len(v):
            continue
        median = float(np.median(np.abs(v)))
        ax.hist(v, bins=edges, weights=np.full(len(v), 1.0 / len(v)), histtype="step",
                linewidth=1.6, color=color,
                label=f"{label} ({len(v)}): median |error| {_fmt(median)}{unit}")  # fmt: skip
    ax.set_ylabel("fraction of pairs")
    ax.grid(True, linewidth=0.3)
    ax.legend(loc="upper right", fontsize=7)


def fit_errors_figure(
    fit: Fit, loads, twists=None, *, axes: Sequence[Axes] | None = None
) -> Figure:
    """Histograms of each measured pair's errors against the fitted surface.

    Left, the radial error ``r_fit / r - 1`` [%] (:func:`pair_errors`: positive where the
    surface lies outside the measured load, i.e. the fit overestimates friction there); right,
    the angle [°] between the surface's normal and the measured twist (a note without twists).
    The fitted and the held-out pairs (:func:`fit_split`) are drawn apart, each as fractions
    of its pairs on shared bins.

    Parameters
    ----------
    fit : Fit
        The fit.
    loads, twists : array_like
        ``(n, 3)`` measured loads [N, N, N m] at the fit's normal force and twists ``(vx, vy,
        w)`` [m/s, m/s, rad/s] (optional), as fitted.
    axes : sequence of 2 Axes, optional
        Where to draw the panels; default a new figure.

    Returns
    -------
    Figure
    """
    data = _errors_data(fit, loads, twists)
    if axes is None:
        axes = _new_figure((11.0, 4.2)).subplots(1, 2)
    if len(axes) != 2:
        raise InvalidArgumentError(f"axes must hold 2 Axes, got {len(axes)}")
    left, right = axes
    _histogram(left, data.radial, " %")
    left.axvline(0.0, color="0.5", linewidth=0.8, linestyle="--")
    left.set_xlabel(r"radial error $r_{fit}/r - 1$ [%] (> 0: fit outside the load)")
    left.set_title("radial error of each measured load", fontsize=10)
    if data.angles is None:
        right.text(0.5, 0.5, "no twists in the data:\nonly the level set was fitted",
                   ha="center", va="center", transform=right.transAxes)  # fmt: skip
        right.set_axis_off()
    else:
        _histogram(right, data.angles, "°")
        right.set_xlabel("angle between the fitted normal and the measured twist [°]")
        right.set_title(r"twist angle, as $(v_x, v_y, \rho\,\omega)$", fontsize=10)
    fig = left.figure
    fig.suptitle(data.title, fontsize=11)
    return fig
