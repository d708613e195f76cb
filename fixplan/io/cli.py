"""The ``fixplan`` command line.

Results go to stdout; logs, warnings and progress to stderr (a progress bar only on a terminal).
Exit codes: 0 success, 1 unexpected error, 2 invalid input, 3 cannot be held (infeasible, or a
load case whose safety factor is below 1), 4 solver failure or inaccurate result.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import dataclasses
import functools
import importlib
import json
import logging
import math
import os
import sys
import time
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path

from fixplan import __version__
from fixplan.errors import ConvergenceError, FixplanError, GeometryError, InvalidArgumentError

# Only the standard library is imported up to here: ``fixplan --help`` and ``--version`` stay
# fast (numpy, cvxpy and the planner are imported by the subcommands that use them).

EXIT_OK = 0
EXIT_UNEXPECTED = 1
EXIT_INVALID_INPUT = 2
EXIT_NOT_HELD = 3
EXIT_SOLVER = 4

EXIT_CODES = f"""\
exit codes:
  {EXIT_OK}  success
  {EXIT_UNEXPECTED}  unexpected error
  {EXIT_INVALID_INPUT}  invalid input (bad file, option or value)
  {EXIT_NOT_HELD}  cannot be held (infeasible, or a load case not held)
  {EXIT_SOLVER}  solver failure or inaccurate result
"""

_DESCRIPTION = f"""\
example:
  fixplan plan problems/vise-milling.toml

Grasp and fixture planning with friction limit surfaces (after Howe & Cutkosky, "Practical
Force-Motion Models for Sliding Manipulation"): the smallest clamp or grip forces that hold a
part under every task load, the safety margin of a given setup, and how it would start to slide.

{EXIT_CODES}"""

log = logging.getLogger("fixplan")


class _Names(Sequence):
    """A tuple of names defined in a fixplan module, imported when argparse first reads it (to
    check a value or show a subcommand's help), so that building the parser imports nothing."""

    def __init__(self, module: str, attribute: str):
        self.module = module
        self.attribute = attribute

    @functools.cached_property
    def names(self) -> tuple[str, ...]:
        return tuple(getattr(importlib.import_module(self.module), self.attribute))

    def __getitem__(self, index):
        return self.names[index]

    def __len__(self) -> int:
        return len(self.names)


_MODEL_NAMES = _Names("fixplan.planner.problem", "MODEL_NAMES")
_OBJECTIVES = _Names("fixplan.planner.problem", "OBJECTIVES")
_DISK_PROFILES = _Names("fixplan.surface.pressure", "DISK_PROFILES")
_FIT_MODELS = _Names("fixplan.motion.identify", "MODELS")


class _Parser(argparse.ArgumentParser):
    """An argument parser that exits with EXIT_INVALID_INPUT on usage errors."""

    def error(self, message: str):
        self.print_usage(sys.stderr)
        self.exit(EXIT_INVALID_INPUT, f"{self.prog}: error: {message}\n")


def _subcommand(commands, name: str, help_text: str, example: str, run):
    """A subcommand that runs ``run(args)``, with the options every subcommand has: ``--json``
    and the verbosity."""
    parser = commands.add_parser(
        name,
        help=help_text,
        description=f"example:\n  {example}\n\n{help_text}\n\n{EXIT_CODES}",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--json", action="store_true", help="print one JSON document")
    group = parser.add_mutually_exclusive_group()
    group.add_argument("-q", "--quiet", action="store_true", help="errors only on stderr")
    group.add_argument("-v", "--verbose", action="store_true", help="more detail on stderr")
    parser.set_defaults(run=run)
    return parser


def _objective_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--objective",
        choices=_OBJECTIVES,
        metavar="OBJECTIVE",
        help="replace the file's objective (check-compliant: the check followed by the "
        "compliant analysis): %(choices)s",
    )


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="fixplan",
        description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"fixplan {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    plan = _subcommand(
        commands, "plan", "solve a problem file and summarise the plan",
        "fixplan plan problems/vise-milling.toml --report out/",
        _run_plan,
    )  # fmt: skip
    plan.add_argument("file", type=Path, help="problem file (TOML)")
    plan.add_argument("--report", type=Path, metavar="DIR", help="write a report folder")
    plan.add_argument(
        "--model",
        choices=_MODEL_NAMES,
        metavar="MODEL",
        help="override every contact's model (contacts without a patch get its point version): "
        "%(choices)s",
    )
    plan.add_argument("--solver", choices=("CLARABEL", "OSQP", "SCS"), help="conic/QP solver")
    _objective_option(plan)

    check = _subcommand(
        commands, "check", "validate a problem file and report every problem in it",
        "fixplan check problems/fixture-321.toml",
        _run_check,
    )  # fmt: skip
    check.add_argument("file", type=Path, help="problem file (TOML)")
    _objective_option(check)

    surface = _subcommand(
        commands, "surface", "the limit surface of one contact patch and every model's error",
        "fixplan surface --shape disk --radius 0.01 --pressure hertz --mu 0.8 --normal-force 20",
        _run_surface,
    )  # fmt: skip
    surface.add_argument("--shape", choices=("disk", "rectangle"), required=True)
    surface.add_argument("--radius", type=float, help="disk radius [m]")
    surface.add_argument("--inner-radius", type=float, help="annulus inner radius [m]")
    surface.add_argument("--length", type=float, help="rectangle length along x [m]")
    surface.add_argument("--width", type=float, help="rectangle width along y [m]")
    surface.add_argument(
        "--pressure",
        default="uniform",
        choices=_DISK_PROFILES,
        metavar="PROFILE",
        help="disk profile: %(choices)s (default %(default)s)",
    )
    surface.add_argument("--mu", type=float, required=True, help="friction coefficient")
    surface.add_argument("--normal-force", type=float, default=1.0, help="normal force [N]")
    surface.add_argument("--plot", type=Path, metavar="PNG", help="save the cross sections")

    compare = _subcommand(
        commands, "compare", "solve a problem with every applicable model, side by side",
        "fixplan compare problems/hertz-pinch.toml",
        _run_compare,
    )  # fmt: skip
    compare.add_argument("file", type=Path, help="problem file (TOML)")
    compare.add_argument("--solver", choices=("CLARABEL", "OSQP", "SCS"), help="solver")

    push = _subcommand(
        commands, "push", "simulate a part pushed across its support (a push file)",
        "fixplan push problems/push-box-finger.toml --report out/",
        _run_push,
    )  # fmt: skip
    push.add_argument("file", type=Path, help='push file (TOML, kind = "push")')
    push.add_argument("--report", type=Path, metavar="DIR", help="write a report folder")

    fit = _subcommand(
        commands, "fit", "fit a limit surface to measured loads (and twists) in a CSV file",
        "fixplan fit measurements.csv --model quartic --report out/",
        _run_fit,
    )  # fmt: skip
    fit.add_argument(
        "file", type=Path, help="CSV file: columns fx, fy, m [N, N, N m], optionally vx, vy, w "
        "[m/s, m/s, rad/s] and normal_force [N]",
    )  # fmt: skip
    fit.add_argument(
        "--model", default="ellipsoid", choices=_FIT_MODELS, metavar="MODEL",
        help="%(choices)s (default %(default)s)",
    )  # fmt: skip
    fit.add_argument(
        "--weight", type=float, metavar="W",
        help="weight of the twists against the loads, >= 0 (default 1)",
    )  # fmt: skip
    fit.add_argument(
        "--holdout", type=float, metavar="F",
        help="fraction of the rows held out of the fit to measure it, in [0, 1) (default 0.2)",
    )  # fmt: skip
    fit.add_argument(
        "--normal-force", type=float, metavar="N",
        help="normal force of the measurements [N] when the file has no normal_force column "
        "(default 1)",
    )  # fmt: skip
    fit.add_argument("--save", type=Path, metavar="FIT.json", help="write the fit as JSON")
    fit.add_argument("--report", type=Path, metavar="DIR", help="write a report folder")

    layout = _subcommand(
        commands, "layout", "choose the best contacts among candidates (a layout file)",
        "fixplan layout problems/layouts/layout-plate.toml --top 3 --report out/",
        _run_layout,
    )  # fmt: skip
    layout.add_argument(
        "file", type=Path, help="layout file: a problem file with [[candidates]] and [choose]"
    )
    layout.add_argument("--top", type=int, default=5, help="layouts printed (default 5)")
    layout.add_argument("--mode", choices=("auto", "exact", "large"), default="auto",
                        help="exact enumeration, large-problem heuristic, or auto (default)")  # fmt: skip
    layout.add_argument("--report", type=Path, metavar="DIR", help="write a report folder")
    _objective_option(layout)

    export = _subcommand(
        commands, "export", "write a problem and its plan as a simulator scene (MuJoCo MJCF)",
        "fixplan export problems/hertz-pinch.toml --mujoco pinch.xml --load lift-accelerating",
        _run_export,
    )  # fmt: skip
    export.add_argument("file", type=Path, help="problem file (TOML)")
    export.add_argument("--mujoco", type=Path, required=True, metavar="SCENE.xml",
                        help="the MJCF scene to write")  # fmt: skip
    export.add_argument("--load", help="the load case whose task load is ramped (default first)")
    export.add_argument("--scale", type=float, default=1.0,
                        help="multiply the planned forces by this (default 1)")  # fmt: skip

    validate = _subcommand(
        commands, "validate",
        "simulate a plan in MuJoCo or Drake: held at +margin, slips at -margin?",
        "fixplan validate problems/hertz-pinch.toml --margin 0.1 --report out/",
        _run_validate,
    )  # fmt: skip
    validate.add_argument("file", type=Path, help="problem file (TOML)")
    validate.add_argument("--engine", choices=("mujoco", "drake"), default="mujoco",
                          help="the physics engine (default mujoco; drake: hydroelastic "
                               "fingertips, their pressure fields and fixplan's exact limit "
                               "surface of them)")  # fmt: skip
    validate.add_argument("--load", action="append", metavar="NAME",
                          help="validate this load case only (repeatable; default all)")  # fmt: skip
    validate.add_argument("--margin", type=float, default=0.1,
                          help="scale the forces by 1 ± this (default 0.1)")  # fmt: skip
    validate.add_argument("--report", type=Path, metavar="DIR", help="write a report folder")
    _sweep_parser(commands)
    return parser


def _sweep_parser(commands) -> None:
    sweep = _subcommand(
        commands, "sweep", "solve a problem file for many values of its inputs, in parallel (Dask)",
        "fixplan sweep problems/fixture-321.toml --vary contacts[7].position[0]=-0.05:0.05:11 "
        "--vary defaults.mu=0.15:0.35:5 --out sweep/",
        _run_sweep,
    )  # fmt: skip
    sweep.add_argument("file", type=Path, help="problem file (TOML)")
    sweep.add_argument(
        "--vary", action="append", required=True, metavar="KEY=START:STOP:COUNT",
        help="a number of the file at a key path (contacts[1].mu, body.mass, loads[0].force[2]) "
        "from START to STOP; COUNT values on a grid (leave :COUNT out with --method lhs); repeat "
        "for more keys",
    )  # fmt: skip
    sweep.add_argument("--out", type=Path, required=True, metavar="DIR",
                       help="folder of sweep.csv, sweep.parquet and figures/")  # fmt: skip
    sweep.add_argument("--method", choices=("grid", "lhs"), default="grid",
                       help="Cartesian grid or Latin hypercube (default %(default)s)")  # fmt: skip
    sweep.add_argument("--samples", type=int, metavar="N", help="cases of a Latin hypercube")
    sweep.add_argument("--seed", type=int, default=0, help="seed of a Latin hypercube")
    where = sweep.add_mutually_exclusive_group()
    where.add_argument(
        "--workers", type=int, metavar="N",
        help="worker processes of a local Dask cluster (default: one per core; 0: solve in this "
        "process without Dask)",
    )  # fmt: skip
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="an existing Dask cluster's scheduler, e.g. tcp://host:8786")  # fmt: skip
    sweep.add_argument("--resume", type=Path, metavar="TABLE",
                       help="keep the cases of this earlier table of the sweep (CSV or Parquet) "
                       "and solve only the others")  # fmt: skip
    sweep.add_argument("--chunk-size", type=int, metavar="N",
                       help="cases per Dask task (default 16; keep it when resuming)")  # fmt: skip
    _objective_option(sweep)


class _Stopwatch:
    """Wall-clock time of the stages of a command [s], for ``-v``."""

    def __init__(self):
        self._last = time.perf_counter()
        self._start = self._last
        self.laps: list[tuple[str, float]] = []

    def lap(self, stage: str) -> None:
        """End ``stage`` now."""
        now = time.perf_counter()
        self.laps.append((stage, now - self._last))
        self._last = now

    def __str__(self) -> str:
        stages = ", ".join(f"{stage} {seconds:.3f} s" for stage, seconds in self.laps)
        return f"{stages}; total {self._last - self._start:.3f} s"


class _Progress:
    """A progress bar on stderr, drawn only when stderr is a terminal."""

    def __init__(self, label: str, enabled: bool):
        self.label = label
        self.enabled = enabled and sys.stderr.isatty()
        self.start = time.perf_counter()

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled or time.perf_counter() - self.start < 0.5:
            return
        width = 30
        filled = int(width * done / max(total, 1))
        bar = "#" * filled + "-" * (width - filled)
        sys.stderr.write(f"\r{self.label} [{bar}] {done}/{total}")
        if done >= total:
            sys.stderr.write("\n")
        sys.stderr.flush()


# -- plan ----------------------------------------------------------------------------------------


def _run_layout(args: argparse.Namespace) -> tuple[int, str]:
    from fixplan.design.layout import LayoutSearch
    from fixplan.io.problem_file import load_problem

    if args.top < 1:
        raise InvalidArgumentError(f"--top must be a positive integer, got {args.top}")
    problem_file = load_problem(args.file, objective=args.objective, layout=True)
    if args.report is not None:
        _check_output_folder(args.report, "--report")
    try:
        search = LayoutSearch(
            problem_file.problem, problem_file.candidates, choose=problem_file.choose
        )
    except InvalidArgumentError as exc:
        raise InvalidArgumentError(f"{args.file}: {exc}") from None
    layouts = search.run(top=args.top, mode=args.mode)
    stats = search.stats
    if args.report is not None:
        from fixplan.io.layout_report import write_layout_report

        written = write_layout_report(args.report, problem_file, layouts, stats)
        log.info("wrote %d report files to %s", len(written), args.report)
    code = EXIT_OK if layouts else EXIT_NOT_HELD
    if args.json:
        document = {
            "problem": {"name": problem_file.name, "file": str(problem_file.path),
                        "sha256": problem_file.sha256},
            "search": dataclasses.asdict(stats),
            "layouts": [
                {"contacts": list(layout.contacts), "objective_value": layout.objective_value,
                 "equivalents": [list(e) for e in layout.equivalents],
                 "plan": layout.plan.as_dict()}
                for layout in layouts
            ],
        }  # fmt: skip
        return code, _json(document)
    fixed = len(problem_file.problem.contacts) - len(problem_file.candidates)
    lines = [
        f"layouts    {problem_file.name} ({problem_file.kind}), {len(problem_file.candidates)} "
        f"candidates, {fixed} fixed contacts, {len(problem_file.problem.loads)} load cases",
        f"objective  {problem_file.problem.objective}",
        f"search     {stats.mode}: {stats.layouts} layouts, {stats.invalid} invalid, "
        f"{stats.pruned} pruned, {stats.merged} merged by {stats.symmetries - 1} symmetries, "
        f"{stats.solved} solved ({stats.feasible} held), {stats.seconds:.2f} s",
    ]
    if not layouts:
        lines.append("no layout of the candidates holds every load case")
    for rank, layout in enumerate(layouts, start=1):
        twins = f"  (+{len(layout.equivalents)} symmetric)" if layout.equivalents else ""
        lines.append(
            f"  {rank:2d}  {_number(layout.objective_value):>12s}  {', '.join(layout.contacts)}"
            f"{twins}"
        )
    return code, "\n".join(lines)


def _exit_code(plan) -> int:
    if plan.status == "infeasible":
        return EXIT_NOT_HELD
    if plan.status != "optimal":
        return EXIT_SOLVER
    if plan.held and not all(plan.held.values()):
        return EXIT_NOT_HELD
    return EXIT_OK


def _number(value: float, unit: str = "") -> str:
    if value is None:
        return "-"
    if not math.isfinite(value):
        return "inf" if value > 0 else str(value)
    return f"{value:.4g}{(' ' + unit) if unit else ''}"


def _summary(problem_file, plan) -> str:
    from fixplan.planner.problem import FIXED_FORCE_OBJECTIVES

    problem = problem_file.problem
    lines = [
        f"problem    {problem_file.name} ({problem_file.kind}), {len(problem.contacts)} contacts, "
        f"{len(problem.loads)} load cases",
        f"objective  {plan.objective}",
        f"status     {plan.status}",
    ]
    if plan.objective_value is not None:
        unit = "" if plan.objective in FIXED_FORCE_OBJECTIVES else "N"
        if plan.objective == "min-squared-normal-force":
            unit = "N^2"
        lines.append(f"value      {_number(plan.objective_value, unit)}")
    if plan.forces:
        lines.append("active forces")
        for name, force in plan.forces.items():
            if isinstance(force, float):
                lines.append(f"  {name:24s} {_number(force, 'N'):>12s}  (clamp)")
            else:
                lines.append(
                    f"  {name:24s} {_number(float(max(force)), 'N'):>12s}  (finger, largest "
                    "over the load cases)"
                )
    if plan.safety_factors:
        lines.append("safety factors (largest multiple of each task load held)")
        for name, value in plan.safety_factors.items():
            words = plan.describe_held(name)
            words = words if plan.held.get(name) else words.replace("not held", "NOT HELD", 1)
            critical = "  <- critical" if name == plan.critical_load else ""
            lines.append(f"  {name:24s} {_number(value):>12s}  {words}{critical}")
    if plan.critical_load is not None:
        lines.append(f"critical   load {plan.critical_load!r}, contact {plan.critical_contact!r}")
        motion = plan.motions.get(plan.critical_load)
        if motion is not None:
            lines.append(f"motion     if it slips, the part {motion.describe()}")
    if plan.certificate:
        lines.append(f"cannot be held: {plan.certificate}")
    for note in plan.warnings:
        lines.append(f"warning    {note}")
    return "\n".join(lines)


def _load(file: Path, model: str | None = None, objective: str | None = None):
    from fixplan.io.problem_file import load_problem

    return load_problem(file, model=model, objective=objective)


def _compliant(problem_file, plan):
    """The compliant analysis that objective check-compliant runs after the rigid check
    (``None`` when the rigid check found no contact forces)."""
    if plan.contact_wrenches is None:
        return None
    from fixplan.io.compliant_report import compliant_analysis

    log.info("compliant analysis of %s", problem_file.path)
    return compliant_analysis(problem_file, plan)


def _compliant_outputs(plan, result) -> tuple[dict | None, list[str]]:
    """The ``compliant`` object of ``--json`` and the compliant lines of the text output."""
    if result is None:
        return None, [f"compliant  not analysed: the rigid check ended {plan.status!r}"]
    from fixplan.io.compliant_report import compliant_summary, describe_compliant

    summary = compliant_summary(plan, result)
    return summary, describe_compliant(summary)


def _json(document: dict) -> str:
    """``document`` as strict JSON: infinities and NaN become the strings ``"inf"``, ``"-inf"``
    and ``"nan"`` (as in :meth:`Plan.as_dict`)."""

    def strict(value):
        if isinstance(value, float) and not math.isfinite(value):
            return "nan" if math.isnan(value) else "inf" if value > 0 else "-inf"
        if isinstance(value, dict):
            return {key: strict(item) for key, item in value.items()}
        if isinstance(value, list | tuple):
            return [strict(item) for item in value]
        return value

    return json.dumps(strict(document), indent=2, sort_keys=True, allow_nan=False)


def _output_path(path: Path, option: str) -> str:
    """How messages name the output ``path`` of ``option``; rejects a path holding a NUL."""
    text = str(path)
    if "\x00" in text:
        raise InvalidArgumentError(f"{option} {text!r}: not a valid path (it holds a NUL)")
    return f"{option} {text}"


def _check_output_folder(path: Path, option: str) -> None:
    """Fail before any work is done if ``path`` cannot become a folder of results."""
    where = _output_path(path, option)
    if path.exists() and not path.is_dir():
        raise InvalidArgumentError(f"{where}: a file of that name exists; name a folder")
    ancestor = next(p for p in (path.absolute(), *path.absolute().parents) if p.exists())
    if not ancestor.is_dir():
        raise InvalidArgumentError(f"{where}: {ancestor} is a file, not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise InvalidArgumentError(f"{where}: cannot write in {ancestor} (permission denied)")


def _check_output_file(
    path: Path, option: str, *, not_over: tuple[Path, str] | None = None
) -> None:
    """Fail before any work is done if the file ``path`` cannot be written, or is the input
    file ``not_over`` names (its path, and what it is in words)."""
    where = _output_path(path, option)
    folder = path.absolute().parent
    if path.is_dir():
        raise InvalidArgumentError(f"{where}: a folder of that name exists; name a file")
    if not_over is not None and path.exists() and path.samefile(not_over[0]):
        raise InvalidArgumentError(f"{where}: that is {not_over[1]}; name another file")
    if not folder.is_dir():
        raise InvalidArgumentError(f"{where}: the folder {folder} does not exist; create it first")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InvalidArgumentError(f"{where}: cannot write in {folder} (permission denied)")


def _run_plan(args: argparse.Namespace) -> tuple[int, str]:
    clock = _Stopwatch()
    from fixplan.planner.planner import Planner
    from fixplan.planner.problem import COMPLIANT_OBJECTIVE

    clock.lap("imports")
    problem_file = _load(args.file, args.model, args.objective)
    if args.report is not None:
        _check_output_folder(args.report, "--report")
    clock.lap("read")
    try:
        planner = Planner(problem_file.problem, solver=args.solver)
    except InvalidArgumentError:
        from fixplan.io.problem_file import check_problem

        # Names the file and the contact at fault.
        check_problem(args.file, model=args.model, objective=args.objective)
        raise
    clock.lap("build")
    log.info("solving %s (%d load cases)", args.file, len(problem_file.problem.loads))
    plan = planner.solve(progress=_Progress("solving", not args.quiet))
    clock.lap("solve")
    compliant = plan.objective == COMPLIANT_OBJECTIVE
    result = _compliant(problem_file, plan) if compliant else None
    if compliant:
        clock.lap("compliant analysis")
    if args.report is not None:
        from fixplan.io.report import write_report

        written = write_report(args.report, problem_file, plan, planner, compliant=result)
        log.info("wrote %d report files to %s", len(written), args.report)
    summary, lines = _compliant_outputs(plan, result) if compliant else (None, [])
    if args.json:
        document = plan.as_dict()
        document["problem"] = {"name": problem_file.name, "file": str(problem_file.path),
                               "sha256": problem_file.sha256}  # fmt: skip
        if problem_file.surface_contacts:
            document["problem"]["surface_contacts"] = {
                name: dataclasses.asdict(placed)
                for name, placed in problem_file.surface_contacts.items()
            }
        if compliant:
            document["compliant"] = summary
        output = _json(document)
    else:
        output = "\n".join([_summary(problem_file, plan), *_surface_lines(problem_file), *lines])
    clock.lap("output")
    log.info("time: %s", clock)
    return _exit_code(plan), output


def _surface_lines(problem_file) -> list[str]:
    """Where the contacts given by ``on_surface`` were placed on the body's mesh."""
    return [
        f"contact {name!r} on the mesh surface at ({', '.join(f'{x:.6g}' for x in p.position)}) m, "
        f"normal ({', '.join(f'{x:.4g}' for x in p.normal)}), {p.distance * 1e3:.3g} mm from "
        "the point given"
        for name, p in problem_file.surface_contacts.items()
    ]


# -- simulators -----------------------------------------------------------------------------------


def _planned(args):
    """The problem file of ``args.file``, its plan and, if the plan is not optimal, the exit
    code and message to return (there are no forces to simulate)."""
    from fixplan.planner.planner import Planner

    problem_file = _load(args.file, None, None)
    plan = Planner(problem_file.problem).solve()
    if plan.status == "optimal":
        return problem_file, plan, None
    code = EXIT_NOT_HELD if plan.status == "infeasible" else EXIT_SOLVER
    message = f"{args.file}: the plan is {plan.status}: no forces to simulate"
    document = {"file": str(args.file), "status": plan.status, "message": message}
    return problem_file, plan, (code, _json(document) if args.json else message)


def _run_export(args: argparse.Namespace) -> tuple[int, str]:
    from fixplan.sim.mjcf import to_mjcf

    _check_output_file(args.mujoco, "--mujoco", not_over=(args.file, "the problem file"))
    problem_file, plan, failed = _planned(args)
    if failed:
        return failed
    scene = to_mjcf(problem_file.problem, plan, load=args.load, scale=args.scale)
    try:
        args.mujoco.write_text(scene.xml, encoding="utf-8")
    except OSError as exc:
        raise InvalidArgumentError(
            f"--mujoco {args.mujoco}: cannot write: {exc.strerror}"
        ) from None
    forces = ", ".join(f"{name} {force:.6g} N" for name, force in scene.forces.items())
    summary = {"scene": str(args.mujoco), "load": scene.load, "forces": scene.forces}
    text = f"wrote {args.mujoco}: load case {scene.load!r} ramped, forces {forces or 'none'}"
    return EXIT_OK, _json(summary) if args.json else text


def _run_validate(args: argparse.Namespace) -> tuple[int, str]:
    if args.engine == "drake":
        from fixplan.sim import drake_validate as judge
        from fixplan.sim.drake_scene import require_drake

        require_drake()
    else:
        from fixplan.sim import validate as judge

    problem_file, plan, failed = _planned(args)
    if failed:
        return failed
    if args.report is not None:
        _check_output_folder(args.report, "--report")
    cases = judge.validate(problem_file.problem, plan, margin=args.margin, loads=args.load,
                           progress=_Progress("simulating", not args.quiet))  # fmt: skip
    if args.report is not None:
        from fixplan.io.validation_report import write_validation_report

        written = write_validation_report(args.report, problem_file, plan, cases, args.margin,
                                          engine=args.engine)  # fmt: skip
        log.info("wrote %d report files to %s", len(written), args.report)
    code = EXIT_NOT_HELD if any(case.contradicts for case in cases) else EXIT_OK
    if args.json:
        return code, _json({"engine": args.engine, "margin": args.margin,
                            "thresholds": _thresholds(args.engine),
                            "cases": [_case_document(case) for case in cases]})  # fmt: skip
    return code, "\n".join(_validation_lines(problem_file, cases, args.margin, args.engine))


def _thresholds(engine: str) -> dict:
    """What the verdicts of a simulation check mean, in numbers."""
    from fixplan.sim.validate import HELD_DISPLACEMENT, SLIP_SPEED

    if engine == "drake":
        from fixplan.sim import drake_scene

        step = drake_scene.TIME_STEP
    else:
        from fixplan.sim.mjcf import OPTIONS

        step = float(OPTIONS["timestep"])
    return {"held_slip_m": HELD_DISPLACEMENT, "onset_speed_m_per_s": SLIP_SPEED,
            "time_step_s": step}  # fmt: skip


def _case_document(case) -> dict:
    def run(r):
        return None if r is None else {"held": r.held, "slip_m": r.displacement,
                                       "rotation_rad": r.rotation,
                                       "onset_multiple": r.onset_multiple}  # fmt: skip

    document = {"load": case.load, "planned_held": case.planned_held,
                "safety_factor": case.safety_factor, "above": run(case.above),
                "below": run(case.below), "onset": run(case.onset),
                "onset_ratio": case.onset_ratio, "motion_angle_rad": case.motion_angle,
                "contradicts": case.contradicts}  # fmt: skip
    if hasattr(case, "fields"):
        document["exact_safety_factor"] = case.exact_safety_factor
        document["exact_onset_ratio"] = case.exact_onset_ratio
        document["fields"] = [
            {"contact": item.contact, "normal_force_N": item.normal_force,
             "polygons": item.polygons, "peak_pressure_Pa": item.peak_pressure,
             "pressure_deviation": item.pressure_deviation, "torsion_ratio": item.torsion_ratio,
             "onset_use": item.onset_use}
            for item in case.fields
        ]  # fmt: skip
    return document


def _validation_lines(problem_file, cases, margin: float, engine: str) -> list[str]:
    thresholds = _thresholds(engine)
    up, down = f"+{margin:.0%}", f"-{margin:.0%}"
    drake = engine == "drake"
    lines = [
        f"problem    {problem_file.name}: {len(cases)} load cases simulated in "
        f"{'Drake (hydroelastic)' if drake else 'MuJoCo'}, "
        f"{thresholds['time_step_s'] * 1e3:g} ms steps",
        f"held       no contact slips more than {thresholds['held_slip_m'] * 1e3:g} mm (its tip "
        "against the part; area contacts: plus their turn times their radius) while the task "
        "load ramps to 1x",
        f"onset      a contact slips faster than {thresholds['onset_speed_m_per_s'] * 1e3:g} mm/s"
        + ("; s exact: fixplan's exact limit surface of the engine's pressure fields (none: "
           "they do not hold the part at any multiple)" if drake else ""),
        f"{'load case':28s} {'plan':>8s} {up:>8s} {down:>8s} {'onset/s':>8s} {'motion':>8s}"
        + (f" {'s exact':>8s} {'onset/s exact':>13s}" if drake else ""),
    ]  # fmt: skip
    for case in cases:
        ratio = "-" if case.onset_ratio is None else f"{case.onset_ratio:.3f}"
        angle = "-" if case.motion_angle is None else f"{math.degrees(case.motion_angle):.1f} deg"
        verdict = lambda run: "held" if run.held else "slips"  # noqa: E731
        note = "  <- the plan calls it held" if case.contradicts else ""
        exact = ""
        if drake:
            exact_ratio = "-" if case.exact_onset_ratio is None else f"{case.exact_onset_ratio:.3f}"
            held = "none" if case.exact_safety_factor is None else f"{case.exact_safety_factor:.4g}"
            exact = f" {held:>8s} {exact_ratio:>13s}"
        lines.append(
            f"{case.load:28s} {'held' if case.planned_held else 'slips':>8s} "
            f"{verdict(case.above):>8s} {verdict(case.below):>8s} {ratio:>8s} {angle:>8s}"
            f"{exact}{note}"
        )
        for item in case.fields if drake else ():
            deviation = "-" if item.pressure_deviation is None else f"{item.pressure_deviation:.1%}"
            use = (
                "" if item.onset_use is None else f", at onset {item.onset_use:.3f} of its exact LS"
            )
            lines.append(
                f"  field {item.contact}: {item.normal_force:.4g} N on {item.polygons} polygons, "
                f"pressure off the assumed profile by {deviation} of its peak "
                f"{item.peak_pressure / 1e6:.3g} MPa, torsion {item.torsion_ratio:.3f}x assumed{use}"
            )
    return lines


# -- push ----------------------------------------------------------------------------------------


def _run_push(args: argparse.Namespace) -> tuple[int, str]:
    from fixplan.io.push_file import load_push
    from fixplan.io.push_report import describe_push, push_summary, write_push_report
    from fixplan.motion import push

    push_file = load_push(args.file)
    if args.report is not None:
        _check_output_folder(args.report, "--report")
    log.info("pushing %s (%d steps)", args.file, push_file.steps)
    try:
        trajectory = push(
            push_file.surface, push_file.pusher, shape=push_file.shape, pose=push_file.pose,
            duration=push_file.duration, steps=push_file.steps,
            start_overlap=push_file.start_overlap, progress=_Progress("pushing", not args.quiet),
        )  # fmt: skip
    except GeometryError as exc:  # (a start, or a path, the file's values allow one by one)
        raise InvalidArgumentError(f"{args.file}: pusher: {exc}") from None
    if args.report is not None:
        written = write_push_report(args.report, push_file, trajectory)
        log.info("wrote %d report files to %s", len(written), args.report)
    summary = push_summary(push_file, trajectory)
    if args.json:
        summary["problem"] = {"file": str(push_file.path), "sha256": push_file.sha256}
        return EXIT_OK, _json(summary)
    return EXIT_OK, "\n".join(describe_push(summary))


# -- fit -----------------------------------------------------------------------------------------


def _fit_options(args: argparse.Namespace) -> dict:
    """The keyword arguments of :func:`fixplan.motion.fit` given on the command line."""
    from fixplan.tolerances import MAX_FIT_WEIGHT, MAX_FORCE

    options = {"model": args.model}
    if args.weight is not None:
        if not 0.0 <= args.weight <= MAX_FIT_WEIGHT:
            raise InvalidArgumentError(
                f"--weight must be a number from 0 to {MAX_FIT_WEIGHT:g} (keep it near 1), got "
                f"{args.weight:g}"
            )
        options["weight"] = args.weight
    if args.holdout is not None:
        if not 0.0 <= args.holdout < 1.0:
            raise InvalidArgumentError(
                f"--holdout must be a fraction in [0, 1), got {args.holdout:g}"
            )
        options["holdout"] = args.holdout
    if args.normal_force is not None and not 0.0 < args.normal_force <= MAX_FORCE:
        raise InvalidArgumentError(
            f"--normal-force must be a number > 0 and at most {MAX_FORCE:g} N, got "
            f"{args.normal_force:g}"
        )
    return options


def _run_fit(args: argparse.Namespace) -> tuple[int, str]:
    from fixplan.io.fit_data import read_fit_data
    from fixplan.io.fit_report import describe_fit, fit_summary, write_fit_report
    from fixplan.io.toml_schema import Issue, ProblemFileError
    from fixplan.motion import fit

    options = _fit_options(args)
    data = read_fit_data(args.file)
    if data.normal_forces is not None and args.normal_force is not None:
        raise InvalidArgumentError(
            f"--normal-force: {args.file} has a normal_force column already; drop one of them"
        )
    if data.twists is None and args.weight is not None:
        log.warning("--weight is ignored: %s has no twist columns (vx, vy, w)", args.file)
    normal_force = data.normal_force if data.normal_force is not None else args.normal_force
    if args.report is not None:
        _check_output_folder(args.report, "--report")
    if args.save is not None:
        _check_output_file(args.save, "--save", not_over=(args.file, "the measurements' file"))
    log.info("fitting a %s to %d measurements of %s", args.model, data.rows, args.file)
    try:
        result = fit(data.fit_loads, data.twists, normal_force=normal_force or 1.0, **options)
    except InvalidArgumentError as exc:
        # The data cannot be fitted (too few rows for the model, loads in a plane): name the file.
        raise ProblemFileError(args.file, [Issue(key_path="", message=str(exc))]) from exc
    if args.save is not None:
        try:
            result.save(args.save)
        except OSError as exc:
            raise InvalidArgumentError(f"--save {args.save}: cannot write it: {exc}") from exc
        log.info("wrote %s", args.save)
    if args.report is not None:
        written = write_fit_report(args.report, data, result)
        log.info("wrote %d report files to %s", len(written), args.report)
    summary = fit_summary(data, result)
    summary["data"]["file"] = str(args.file)
    if args.json:
        return EXIT_OK, _json(summary)
    return EXIT_OK, "\n".join(describe_fit(summary))


# -- sweep ---------------------------------------------------------------------------------------


def _sweep_client(args: argparse.Namespace):
    """The Dask client of ``--scheduler`` or ``--workers`` (``None``: a local cluster)."""
    from fixplan.design import SERIAL

    if args.scheduler is not None:
        from distributed import Client

        try:
            return Client(args.scheduler, timeout=30)
        except (OSError, ValueError, TypeError) as exc:
            raise InvalidArgumentError(
                f"--scheduler {args.scheduler}: cannot connect to a Dask scheduler there: {exc}"
            ) from None
    return SERIAL if args.workers == 0 else None


def _sweep_table(args: argparse.Namespace) -> Path:
    """Where the rows stream to; refuses to overwrite an earlier sweep not being resumed."""
    _check_output_folder(args.out, "--out")
    table = args.out / "sweep.csv"
    if table.exists() and args.resume is None:
        raise InvalidArgumentError(
            f"--out {args.out}: holds a sweep already; continue it with --resume {table}, or "
            "choose another folder"
        )
    if args.resume is not None and not args.resume.is_file():
        raise InvalidArgumentError(f"--resume {args.resume}: no such file")
    return table


def _run_sweep(args: argparse.Namespace) -> tuple[int, str]:
    from fixplan.design import CHUNK_SIZE, SERIAL
    from fixplan.design.sweep import WORKERS_PER_CORE, most_workers
    from fixplan.io.key_path import KeyPathError
    from fixplan.io.sweep import FileCases, cases_of, run
    from fixplan.io.sweep_figures import write_sweep_figures
    from fixplan.io.sweep_table import write_tables

    if not args.verbose:
        import distributed  # noqa: F401 - sets its loggers' levels when first imported

        logging.getLogger("distributed").setLevel(logging.ERROR)  # no cluster chatter
    most = most_workers()
    if args.workers is not None and not 0 <= args.workers <= most:
        raise InvalidArgumentError(
            f"--workers must be from 0 to {most} ({WORKERS_PER_CORE} per core of this machine: "
            f"a local cluster's workers are its processes; for more, start a Dask cluster and "
            f"give --scheduler), got {args.workers}"
        )
    cases = cases_of(args.vary, method=args.method, samples=args.samples, seed=args.seed)
    try:
        FileCases.read(args.file, list(cases.columns), objective=args.objective)
    except KeyPathError as exc:
        raise InvalidArgumentError(f"--vary {exc} (in {args.file})") from None
    table_path = _sweep_table(args)
    try:
        args.out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InvalidArgumentError(f"--out {args.out}: cannot make it: {exc.strerror}") from None
    client = _sweep_client(args)
    where = (
        "in this process" if client == SERIAL
        else f"on {args.scheduler}" if args.scheduler is not None
        else f"on a local Dask cluster of {args.workers or os.cpu_count()} workers"
    )  # fmt: skip
    log.info("sweeping %s: %d cases %s", args.file, len(cases), where)
    try:
        table = run(
            args.file, cases, client=client, workers=args.workers if client is None else None,
            table=table_path, resume=args.resume,
            chunk_size=CHUNK_SIZE if args.chunk_size is None else args.chunk_size,
            progress=_Progress("sweeping", not args.quiet),
        )  # fmt: skip
    finally:
        if client not in (None, SERIAL):
            client.close()
    written = write_tables(args.out, table)
    problem_file = _load(args.file, objective=args.objective)
    figures = write_sweep_figures(args.out / "figures", table, list(cases.columns),
                                  problem_file.problem.objective)  # fmt: skip
    summary = _sweep_summary(args, table, len(cases.columns), where)
    summary["written"] = [str(path) for path in (*written, *figures)]
    if args.json:
        return EXIT_OK, _json(summary)
    return EXIT_OK, "\n".join(_describe_sweep(summary))


def _sweep_summary(args: argparse.Namespace, table, keys: int, where: str) -> dict:
    """The ``--json`` document of a sweep: counts by status, the extreme cases, the files."""
    solved = table[table["status"] == "optimal"]
    summary = {
        "file": str(args.file),
        "cases": len(table),
        "keys": list(table.columns[1 : 1 + keys]),
        "method": args.method,
        "where": where,
        "statuses": {str(k): int(v) for k, v in sorted(table["status"].value_counts().items())},
    }
    if len(solved):
        lowest = solved.loc[solved["objective_value"].idxmin()]
        weakest = solved.loc[solved["safety_factor"].idxmin()]
        summary["objective_range"] = [float(solved["objective_value"].min()),
                                      float(solved["objective_value"].max())]  # fmt: skip
        summary["lowest_objective_case"] = int(lowest["case"])
        summary["smallest_safety_factor"] = float(weakest["safety_factor"])
        summary["smallest_safety_factor_case"] = int(weakest["case"])
    return summary


def _describe_sweep(summary: dict) -> list[str]:
    statuses = ", ".join(f"{status} {count}" for status, count in summary["statuses"].items())
    lines = [
        f"sweep      {summary['file']}: {summary['cases']} cases ({summary['method']} over "
        f"{', '.join(summary['keys'])}), {summary['where']}",
        f"status     {statuses}",
    ]
    if "objective_range" in summary:
        low, high = summary["objective_range"]
        lines += [
            f"objective  {_number(low)} to {_number(high)} (lowest: case "
            f"{summary['lowest_objective_case']})",
            f"safety     smallest factor {_number(summary['smallest_safety_factor'])} (case "
            f"{summary['smallest_safety_factor_case']})",
        ]
    lines += [f"wrote      {path}" for path in summary["written"]]
    return lines


# -- check ---------------------------------------------------------------------------------------


def _run_check(args: argparse.Namespace) -> tuple[int, str]:
    from fixplan.io.problem_file import ProblemFileError, check_problem
    from fixplan.io.push_file import KIND as PUSH_KIND
    from fixplan.io.push_file import file_kind, load_push

    try:
        if file_kind(args.file) == PUSH_KIND:
            if args.objective is not None:
                raise InvalidArgumentError(
                    f"--objective: {args.file} is a push file (no objective)"
                )
            push_file = load_push(args.file)
            return EXIT_OK, _checked_push(args, push_file)
        problem_file = check_problem(args.file, objective=args.objective)
        plan, result = _checked_compliant(args, problem_file)
    except ProblemFileError as exc:
        if not args.json:
            raise
        print(f"fixplan: error: {exc}", file=sys.stderr)
        issues = [{"key_path": i.key_path, "message": i.message} for i in exc.issues]
        document = {"file": str(args.file), "valid": False, "issues": issues}
        return EXIT_INVALID_INPUT, _json(document)
    problem = problem_file.problem
    code = EXIT_OK if plan is None else _exit_code(plan)
    summary, lines = (None, []) if plan is None else _compliant_outputs(plan, result)
    if args.json:
        document = {
            "file": str(args.file),
            "valid": True,
            "issues": [],
            "name": problem_file.name,
            "kind": problem_file.kind,
            "objective": problem.objective,
            "contacts": [contact.name for contact in problem.contacts],
            "loads": [load.name for load in problem.loads],
            "sha256": problem_file.sha256,
        }
        if plan is not None:
            document.update(status=plan.status, compliant=summary)
        return code, _json(document)
    valid = (
        f"{args.file}: valid — {problem_file.name} ({problem_file.kind}), objective "
        f"{problem.objective}, {len(problem.contacts)} contacts, {len(problem.loads)} load cases"
    )
    if plan is not None:
        valid += f"; rigid check {plan.status}, safety factor {_number(plan.safety_factor)}"
    return code, "\n".join([valid, *lines])


def _checked_compliant(args: argparse.Namespace, problem_file) -> tuple:
    """``(plan, result)`` of the rigid check and the compliant analysis that objective
    check-compliant asks ``check`` for; ``(None, None)`` for the other objectives."""
    from fixplan.planner.problem import COMPLIANT_OBJECTIVE

    if problem_file.problem.objective != COMPLIANT_OBJECTIVE:
        return None, None
    from fixplan.planner.planner import Planner

    log.info("checking %s rigidly", args.file)
    plan = Planner(problem_file.problem).solve(progress=_Progress("solving", not args.quiet))
    return plan, _compliant(problem_file, plan)


def _checked_push(args: argparse.Namespace, push_file) -> str:
    """What ``check`` says of a valid push file."""
    if args.json:
        document = {"file": str(args.file), "valid": True, "issues": [], "name": push_file.name,
                    "kind": "push", "sha256": push_file.sha256}  # fmt: skip
        return _json(document)
    return (
        f"{args.file}: valid — {push_file.name} (push), {type(push_file.pusher).__name__}, "
        f"{push_file.model} support, {push_file.steps} steps over {push_file.duration:g} s"
    )


# -- surface -------------------------------------------------------------------------------------


def _bounded(option: str, value: float | None, limit: float, unit: str) -> None:
    """Reject an option value above ``limit`` (the range the library accepts is checked by it)."""
    if value is not None and math.isfinite(value) and abs(value) > limit:
        raise InvalidArgumentError(f"{option} must be at most {f'{limit:g} {unit}'.strip()}, "
                                   f"got {value:g}")  # fmt: skip


def _patch(args: argparse.Namespace):
    from fixplan.surface import pressure
    from fixplan.tolerances import (
        MAX_ASPECT_RATIO,
        MAX_FORCE,
        MAX_LENGTH,
        MAX_MU,
        MIN_MU,
        MIN_PATCH_LENGTH,
    )

    for option in ("radius", "inner_radius", "length", "width"):
        value = getattr(args, option)
        _bounded(f"--{option.replace('_', '-')}", value, MAX_LENGTH, "m")
        if value is not None and 0.0 < value < MIN_PATCH_LENGTH:
            raise InvalidArgumentError(
                f"--{option.replace('_', '-')} must be at least {MIN_PATCH_LENGTH:g} m, got "
                f"{value:g}"
            )
    if args.shape == "rectangle" and (args.length or 0.0) > 0.0 and (args.width or 0.0) > 0.0:
        ratio = max(args.length, args.width) / min(args.length, args.width)
        if ratio > MAX_ASPECT_RATIO:
            raise InvalidArgumentError(
                f"--length and --width: the sides' ratio {ratio:.3g} exceeds the "
                f"{MAX_ASPECT_RATIO:g} accepted"
            )
    _bounded("--normal-force", args.normal_force, MAX_FORCE, "N")
    _bounded("--mu", args.mu, MAX_MU, "")
    if 0.0 < args.mu < MIN_MU:
        raise InvalidArgumentError(
            f"--mu must be at least {MIN_MU:g} (friction that small is rounding noise), got "
            f"{args.mu:g}"
        )
    # Options of the other shape (or profile) are refused, as a problem file's keys are.
    unused = {"disk": ("length", "width"), "rectangle": ("radius", "inner_radius")}[args.shape]
    if args.shape == "disk" and args.pressure != "annulus":
        unused += ("inner_radius",)
    for option in unused:
        if getattr(args, option) is not None:
            of = "--pressure annulus" if option == "inner_radius" and args.shape == "disk" else ""
            raise InvalidArgumentError(
                f"--{option.replace('_', '-')} is not an option of --shape {args.shape}"
                + (f" --pressure {args.pressure} (only of {of})" if of else "")
            )
    if args.shape == "disk":
        if args.radius is None:
            raise InvalidArgumentError("--shape disk needs --radius [m]")
        return pressure.disk(args.radius, args.pressure, inner_radius=args.inner_radius)
    if args.length is None or args.width is None:
        raise InvalidArgumentError("--shape rectangle needs --length and --width [m]")
    if args.pressure != "uniform":
        raise InvalidArgumentError("--shape rectangle supports only --pressure uniform")
    return pressure.rectangle(args.length, args.width)


def _surface_models(surface):
    from fixplan.models import Cone, Ellipsoid, Exact, FittedEllipsoid, PointCone, Pyramid

    return {
        "ellipsoid": Ellipsoid.from_limit_surface(surface),
        "fitted-ellipsoid": FittedEllipsoid.from_limit_surface(surface),
        "cone": Cone.from_limit_surface(surface),
        "pyramid (4, inscribed)": Pyramid.from_limit_surface(surface),
        "pyramid (8, inscribed)": Pyramid.from_limit_surface(surface, facets=8),
        "exact": Exact.from_limit_surface(surface),
        "point-cone": PointCone.from_limit_surface(surface),
    }


def _percent(fraction: float) -> float:
    """``fraction`` in percent rounded to 0.01, without a negative zero."""
    return round(100.0 * fraction, 2) + 0.0


def _run_surface(args: argparse.Namespace) -> tuple[int, str]:
    from fixplan.models.compare import compare
    from fixplan.surface.limit_surface import LimitSurface

    patch = _patch(args)
    if args.plot is not None:
        _check_output_file(args.plot, "--plot")
    surface = LimitSurface(patch, mu=args.mu, normal_force=args.normal_force)
    models = _surface_models(surface)
    accuracy = {name: compare(model, surface, n=1000) for name, model in models.items()}
    if args.plot is not None:
        from fixplan.io.figures import save_png, surface_figure

        try:
            save_png(surface_figure(surface, models), args.plot)
        except OSError as exc:
            raise InvalidArgumentError(f"--plot {args.plot}: cannot write it: {exc}") from exc
        log.info("wrote %s", args.plot)
    summary = {
        "shape": args.shape,
        "pressure": args.pressure,
        "mu": args.mu,
        "normal_force_N": args.normal_force,
        "max_force_N": surface.max_force,
        "max_moment_Nm": surface.max_moment,
        "characteristic_length_m": surface.characteristic_length,
        "frictionless": surface.frictionless,
        "models": {
            name: {
                "max_overestimate": acc.max_overestimate,
                "max_underestimate": acc.max_underestimate,
                "unsafe_fraction": acc.unsafe_fraction,
                "max_motion_angle_rad": acc.max_motion_angle,
            }
            for name, acc in accuracy.items()
        },
    }
    if args.json:
        return EXIT_OK, _json(summary)
    lines = [
        f"limit surface of a {args.shape} patch ({args.pressure} pressure)",
        f"  mu = {args.mu:g}, normal force = {args.normal_force:g} N",
        f"  max friction force     {surface.max_force:12.6g} N",
        f"  max friction moment    {surface.max_moment:12.6g} N m",
        f"  characteristic length  {surface.characteristic_length:12.6g} m",
        *(
            [
                "  frictionless: the limit surface is the load 0; the errors below are those of",
                "  the shapes (mu = 1), the same at any mu > 0",
            ]
            if surface.frictionless
            else []
        ),
        "model errors against the exact surface (radial, over 1000 load directions;",
        "  over = model holds more than the contact: unsafe)",
        f"  {'model':24s} {'max over':>9s} {'max under':>10s} {'unsafe':>7s} {'motion':>9s}",
    ]
    for name, acc in accuracy.items():
        angle = (
            "-" if acc.max_motion_angle is None else f"{math.degrees(acc.max_motion_angle):.2f}°"
        )
        over, under = (_percent(acc.max_overestimate), _percent(acc.max_underestimate))
        lines.append(
            f"  {name:24s} {over:8.2f}% {under:9.2f}% {100 * acc.unsafe_fraction:6.1f}% {angle:>9s}"
        )
    return EXIT_OK, "\n".join(lines)


# -- compare -------------------------------------------------------------------------------------


def _compare_models(problem) -> list[str]:
    """Models to compare: the area models where some contact has a patch (the others then
    take the point version), and the point models."""
    point_models = ["point-cone", "point-pyramid"]
    if any(contact.patch is not None for contact in problem.contacts):
        return ["exact", "ellipsoid", "cone", "pyramid", *point_models]
    return point_models


def _run_compare(args: argparse.Namespace) -> tuple[int, str]:
    from fixplan.planner.planner import Planner

    base = _load(args.file)
    models = _compare_models(base.problem)
    problem_files = {model: _load(args.file, model) for model in models}
    progress = _Progress("models", not args.quiet)
    rows = []
    for index, (model, problem_file) in enumerate(problem_files.items()):
        start = time.perf_counter()
        plan = Planner(problem_file.problem, solver=args.solver).solve()
        elapsed = time.perf_counter() - start
        rows.append((model, plan, elapsed))
        progress(index + 1, len(models))
    code = max(_exit_code(plan) for _, plan, _ in rows)
    if args.json:
        document = {
            model: {
                "status": plan.status,
                "objective_value": plan.as_dict()["objective_value"],
                "safety_factor": plan.as_dict()["safety_factor"],
                "safety_factors": plan.as_dict()["safety_factors"],
                "solve_time_s": elapsed,
            }
            for model, plan, elapsed in rows
        }
        return code, _json(document)
    lines = [
        f"{base.name}: objective {base.problem.objective}, every contact with one model "
        "(contacts without a patch with its point version)",
        f"  {'model':14s} {'status':11s} {'value':>12s} {'min safety':>11s} {'time':>8s}",
    ]
    for model, plan, elapsed in rows:
        lines.append(
            f"  {model:14s} {plan.status:11s} {_number(plan.objective_value):>12s} "
            f"{_number(plan.safety_factor):>11s} {elapsed:7.2f}s"
        )
    return code, "\n".join(lines)


@contextlib.contextmanager
def _stdout_to_stderr() -> Iterator[None]:
    """Send everything written to file descriptor 1 to stderr meanwhile.

    Solvers print from compiled code straight to the process's stdout (SCS prints ``ERROR:
    ...`` even when told to be quiet); stdout must carry only the results. Where file
    descriptors cannot be duplicated (an embedding without a real stdout), nothing changes.
    """
    sys.stdout.flush()
    try:
        saved = os.dup(1)
        os.dup2(2, 1)
    except (OSError, ValueError):
        yield
        return
    try:
        yield
    finally:
        sys.stdout.flush()
        _flush_c_streams()
        os.dup2(saved, 1)
        os.close(saved)


def _flush_c_streams() -> None:
    """Flush the C library's output buffers (text a solver printed but did not flush yet)."""
    with contextlib.suppress(OSError, AttributeError, TypeError):  # no C library found
        ctypes.CDLL(None).fflush(None)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    level = logging.ERROR if args.quiet else logging.DEBUG if args.verbose else logging.WARNING
    logging.basicConfig(level=level, format="fixplan: %(message)s", stream=sys.stderr)
    try:
        with warnings.catch_warnings(), _stdout_to_stderr():
            warnings.simplefilter("ignore" if args.quiet else "default")
            import numpy as np

            with np.errstate(all="ignore"):
                code, output = args.run(args)
    except ConvergenceError as exc:
        return _failed(args, "numerical failure", str(exc), EXIT_SOLVER)
    except FixplanError as exc:
        # Errors about the input, the outputs asked for (a folder that cannot be written) or an
        # extra they need derive from ValueError, OSError or ImportError; any other is fixplan's
        # own failure.
        invalid = isinstance(exc, ValueError | OSError | ImportError)
        return _failed(args, "error", str(exc), EXIT_INVALID_INPUT if invalid else EXIT_UNEXPECTED)
    except KeyboardInterrupt:  # pragma: no cover
        return EXIT_UNEXPECTED
    except Exception as exc:
        log.debug("unexpected error", exc_info=True)
        message = f"{type(exc).__name__}: {exc} (run with -v for details)"
        return _failed(args, "unexpected error", message, EXIT_UNEXPECTED)
    try:
        print(output, flush=True)
    except BrokenPipeError:
        # The reader of stdout left early (``fixplan plan FILE | head``): drop the rest quietly.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return code


def _failed(args: argparse.Namespace, kind: str, message: str, code: int) -> int:
    """Say why a command failed (on stderr; with ``--json`` also as a document on stdout, for
    the scripts that read it) and return its exit ``code``."""
    print(f"fixplan: {kind}: {message}", file=sys.stderr)
    if getattr(args, "json", False):
        what = {EXIT_INVALID_INPUT: "invalid input", EXIT_SOLVER: "numerical failure"}
        document = {"error": what.get(code, "unexpected error"), "message": message,
                    "exit_code": code}  # fmt: skip
        print(_json(document), flush=True)
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
