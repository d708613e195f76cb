"""What a limit-surface fit to measurements gave, in numbers and words, and its report folder.

:func:`fit_summary` condenses a :class:`~fixplan.motion.Fit` of the measurements of a CSV file
(:class:`~fixplan.io.fit_data.FitData`) into plain values: the surface's ``mu`` and ``rho``, its
coefficients (or matrix), the fit's options and its errors on the fitted and the held-out pairs;
:func:`describe_fit` puts them in lines of text (the command line's output).
:func:`write_fit_report` writes into a folder

- ``report.md`` and ``report.html``: the data, the fitted surface, its errors and the figures;
- ``fit.json``: the fit as :meth:`Fit.save <fixplan.motion.Fit.save>` writes it (read it back
  with :meth:`Fit.load <fixplan.motion.Fit.load>`);
- ``sections.png`` (:func:`fixplan.io.fit_figures.fit_sections_figure`: the measurements and
  the fitted level set in the paper's Fig. 5 sections) and ``errors.png``
  (:func:`fixplan.io.fit_figures.fit_errors_figure`: histograms of the radial errors and twist
  angles).

As for plan reports, nothing depends on the time or the machine's paths, and the folder appears
whole or not at all.
"""

from __future__ import annotations

import math
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import cvxpy

import fixplan
from fixplan.io import fit_figures
from fixplan.io.fit_data import FitData
from fixplan.io.fit_figures import NEAR_PLANE_ANGLE
from fixplan.io.report_document import (
    Block,
    Code,
    Heading,
    Image,
    List,
    Paragraph,
    Table,
    Writer,
    inline,
    staged_folder,
)
from fixplan.motion import Fit, FitErrors, FittedQuartic
from fixplan.motion.fitted_quartic import MONOMIALS

_SOLVER_PACKAGES = {"CLARABEL": "clarabel", "SCS": "scs"}
_ERROR_ROWS = (
    ("level_rms", "rms(H − 1)", ""),
    ("radial_median", "median radial error |r_fit / r − 1|", "%"),
    ("angle_mean_rad", "mean twist angle", "°"),
    ("angle_median_rad", "median twist angle", "°"),
)


def _errors(errors: FitErrors | None) -> dict | None:
    if errors is None:
        return None
    return {
        "samples": errors.samples,
        "level_rms": errors.level_rms,
        "radial_median": errors.radial_median,
        "angle_mean_rad": errors.angle_mean,
        "angle_median_rad": errors.angle_median,
    }


def _normal_force_source(data: FitData) -> str:
    if data.normal_forces is None:
        return "given"
    return "column, varying" if data.varying_normal_force else "column, constant"


def fit_summary(data: FitData, fit: Fit) -> dict:
    """The fit of ``data`` as plain values (SI units; angles in radians where named so).

    ``mu`` is the surface's largest force over its normal force and ``rho_m`` its largest
    moment over its largest force (the paper's ``rho``); ``coordinates_rho_m`` is the length of
    the fit's coordinates ``x = (fx, fy, m / rho)``. A quartic gives its ``coefficients``
    [1/N⁴] of the ``monomials`` of ``x``; an ellipsoid its ``matrix`` ``A`` in ``q = (fx /
    f_max, fy / f_max, m / m_max)``, ``q^T A q = 1`` on the surface.
    """
    surface, report = fit.surface, fit.report
    quartic = isinstance(surface, FittedQuartic)
    summary = {
        "data": {
            "file": data.path.name,
            "sha256": data.sha256,
            "rows": data.rows,
            "twists": data.twists is not None,
            "normal_force": _normal_force_source(data),
        },
        "model": "quartic" if quartic else "ellipsoid",
        "mu": surface.mu,
        "rho_m": surface.max_moment / surface.max_force,
        "max_force_N": surface.max_force,
        "max_moment_Nm": surface.max_moment,
        "normal_force_N": surface.normal_force,
        "monomials": list(MONOMIALS) if quartic else None,
        "coefficients": surface.coefficients.tolist() if quartic else None,
        "matrix": None if quartic else surface.matrix.tolist(),
    }
    if report is not None:
        summary.update(
            coordinates_rho_m=report.rho,
            weight=report.weight,
            regularization=report.regularization,
            holdout=report.holdout,
            seed=report.seed,
            solver=report.solver,
            training=_errors(report.training),
            validation=_errors(report.validation),
        )
    return summary


def _value(value: float | None, unit: str) -> str:
    """An error figure as printed: percentages and degrees from fractions and radians."""
    if value is None:
        return "-"
    if unit == "%":
        return f"{100.0 * value:.3g} %"
    if unit == "°":
        return f"{math.degrees(value):.3g}°"
    return f"{value:.3g}"


def _error_lines(summary: dict) -> list[tuple[str, str, str]]:
    """``(figure, fitted, held out)`` of each error figure."""
    training, validation = summary["training"], summary["validation"]
    rows = [("pairs", str(training["samples"]), "-" if validation is None else
             str(validation["samples"]))]  # fmt: skip
    for key, label, unit in _ERROR_ROWS:
        if unit == "°" and not summary["data"]["twists"]:
            continue
        held = "-" if validation is None else _value(validation[key], unit)
        rows.append((label, _value(training[key], unit), held))
    return rows


def _coefficients(summary: dict):
    """``(monomial, coefficient)`` pairs of a quartic's summary."""
    return zip(summary["monomials"], summary["coefficients"], strict=True)


def _coefficient_lines(summary: dict) -> list[str]:
    if summary["coefficients"] is not None:
        return [
            "coefficients of H(x) = sum c_k x^a_k, x = (fx, fy, m / rho) [1/N^4]",
            *(f"  {name:10s} {value: .6g}" for name, value in _coefficients(summary)),
        ]
    return [
        "matrix A of q^T A q = 1, q = (fx / f_max, fy / f_max, m / m_max)",
        *("  " + " ".join(f"{v: 11.6g}" for v in row) for row in summary["matrix"]),
    ]


def _weight_text(summary: dict) -> str:
    if not summary["data"]["twists"]:
        return "no twists (the level set only)"
    return f"twists weighted {summary['weight']:g} against the loads"


def describe_fit(summary: dict) -> list[str]:
    """The summary in lines of text (the command line's output)."""
    data = summary["data"]
    twists = "with twists" if data["twists"] else "without twists (level set only)"
    lines = [
        f"data       {data['file']}: {data['rows']} measurements {twists}; normal force "
        f"{summary['normal_force_N']:.6g} N ({data['normal_force']})",
        f"model      {summary['model']}",
        f"mu         {summary['mu']:.6g}",
        f"rho        {summary['rho_m']:.6g} m (max moment / max force)",
        f"max force  {summary['max_force_N']:.6g} N, max moment {summary['max_moment_Nm']:.6g} N m",
    ]
    if "solver" in summary:
        lines += [
            f"fit        x = (fx, fy, m / rho), rho {summary['coordinates_rho_m']:.6g} m; "
            f"{_weight_text(summary)}; regularization "
            f"{summary['regularization']:g}; solver {summary['solver']}",
            f"held out   {summary['holdout']:g} of the pairs (seed {summary['seed']})",
        ]
    lines += _coefficient_lines(summary)
    if "training" in summary:
        lines.append(f"errors     {'':34s} {'fitted':>10s} {'held out':>10s}")
        lines += [f"  {a:42s} {b:>10s} {c:>10s}" for a, b, c in _error_lines(summary)]
    return lines


def write_fit_report(directory, data: FitData, fit: Fit) -> list[Path]:
    """Write the report folder of a fit (see the module docstring); returns the files written.

    Raises
    ------
    ReportError
        The folder cannot be created or a file cannot be written.
    """
    summary = fit_summary(data, fit)
    directory = Path(directory)
    loads, twists = data.fit_loads, data.twists
    with staged_folder(directory) as staging:
        writer = Writer(staging)
        writer.save("fit.json", fit.save)
        writer.figure("sections.png", lambda: fit_figures.fit_sections_figure(fit, loads))
        writer.figure("errors.png", lambda: fit_figures.fit_errors_figure(fit, loads, twists))
        known = fit_figures.fit_split(fit, loads).known
        blocks = _document(data, summary, known)
        writer.document(blocks, f"fixplan fit: {data.path.name}")
    return [directory / path.name for path in writer.written]


def _package_version(package: str) -> str:
    try:
        return version(package)
    except PackageNotFoundError:
        return "not installed"


def _document(data: FitData, summary: dict, known: bool) -> list[Block]:
    solver = summary.get("solver")
    header = [
        ("fixplan", inline(fixplan.__version__)),
        ("cvxpy", inline(cvxpy.__version__)),
        ("solver", inline("none" if solver is None else
                          f"{solver} {_package_version(_SOLVER_PACKAGES.get(solver, solver))}")),
        ("data file", inline(Code(data.path.name))),
        ("data file SHA-256", inline(Code(data.sha256))),
        ("columns", inline(*_joined(Code(c) for c in data.columns))),
        ("measurements", inline(f"{data.rows}, " + ("with twists" if data.twists is not None
                                                    else "without twists (level set only)"))),
        ("normal force", inline(_normal_force_text(data, summary))),
    ]  # fmt: skip
    blocks: list[Block] = [
        Heading(1, inline(f"fixplan fit report: {data.path.name}")),
        Table(("item", "value"), tuple((inline(k), v) for k, v in header)),
    ]
    if data.comments:
        blocks += [
            Paragraph(inline("Comments of the data file:")),
            List(tuple(inline(c) for c in data.comments)),
        ]
    blocks += [Heading(2, inline("Fitted surface")), *_surface_blocks(summary)]
    if "training" in summary:
        blocks += [
            Heading(2, inline("Errors")),
            Paragraph(inline(
                "On the fitted pairs and on the pairs held out of the fit. H is the fitted "
                "level function (1 on the surface); the radial error is the surface's radius "
                "along a measured load over the load's, minus 1; the twist angle is between the "
                "surface's normal at the load and the measured twist, as (vx, vy, rho w).")),
            Table(("figure", "fitted", "held out"),
                  tuple(tuple(inline(c) for c in row) for row in _error_lines(summary))),
        ]  # fmt: skip
    note = "" if known else " The fit's split is unknown: every pair is drawn as measured."
    degrees = math.degrees(NEAR_PLANE_ANGLE)
    blocks += [
        Heading(2, inline("Figures")),
        Image("sections.png", "sections", inline(
            "The fitted level set in the (fx, fy), (fx, m) and (fy, m) sections (the last two "
            f"are the paper's Fig. 5) and the measured loads within {degrees:.0f}° of each "
            "plane, projected on it, in the surface's normalised coordinates." + note)),
        Image("errors.png", "error histograms", inline(
            "Histograms of the radial errors and of the twist angles, fitted and held-out "
            "pairs apart." + note)),
        Heading(2, inline("Reuse")),
        Paragraph(inline(
            Code("fit.json"), " holds the fit; ",
            Code('fixplan.motion.Fit.load("fit.json").surface'), " is the surface, for ",
            Code("push"), ", ", Code("push_step"), " and (an ellipsoid) the planner.")),
    ]  # fmt: skip
    return blocks


def _joined(parts) -> list:
    """``parts`` with ``", "`` between them."""
    out = []
    for part in parts:
        out += [", ", part] if out else [part]
    return out


def _normal_force_text(data: FitData, summary: dict) -> str:
    force = f"{summary['normal_force_N']:.6g} N"
    if data.normal_forces is None:
        return f"{force} (given: the file has no normal_force column)"
    if not data.varying_normal_force:
        return f"{force} (the normal_force column, the same in every row)"
    low, high = float(data.normal_forces.min()), float(data.normal_forces.max())
    return (f"{force}, the mean of the normal_force column ({low:.6g} to {high:.6g} N); each "
            "load was scaled to it")  # fmt: skip


def _surface_blocks(summary: dict) -> list[Block]:
    rows = [
        ("model", summary["model"]),
        ("mu (max force / normal force)", f"{summary['mu']:.6g}"),
        ("rho (max moment / max force)", f"{summary['rho_m']:.6g} m"),
        ("max force", f"{summary['max_force_N']:.6g} N"),
        ("max moment", f"{summary['max_moment_Nm']:.6g} N m"),
        ("normal force", f"{summary['normal_force_N']:.6g} N"),
    ]
    if "solver" in summary:
        rows += [
            ("coordinates", f"x = (fx, fy, m / rho), rho = {summary['coordinates_rho_m']:.6g} m"),
            ("twist weight", _weight_text(summary)),
            ("regularization", f"{summary['regularization']:g}"),
            ("held out", f"{summary['holdout']:g} of the pairs (seed {summary['seed']})"),
        ]
    blocks: list[Block] = [Table(("item", "value"), tuple((inline(k), inline(v)) for k, v in rows))]
    if summary["coefficients"] is not None:
        blocks += [
            Paragraph(inline("Coefficients of H(x) = Σ c_k x^a_k in x = (fx, fy, m / rho) "
                             "[1/N⁴]; the surface is H = 1.")),
            Table(("monomial", "c_k"), tuple((inline(Code(name)), inline(f"{value:.9g}"))
                                             for name, value in _coefficients(summary))),
        ]  # fmt: skip
    else:
        blocks += [
            Paragraph(inline("Matrix A of the ellipsoid q^T A q = 1 in q = (fx / f_max, "
                             "fy / f_max, m / m_max).")),
            Table(("", "q1", "q2", "q3"), tuple(
                (inline(f"q{i + 1}"), *(inline(f"{v:.9g}") for v in row))
                for i, row in enumerate(summary["matrix"]))),
        ]  # fmt: skip
    return blocks
