"""The ``fixplan`` command line.

Results go to stdout, messages to stderr. Exit codes: 0 success, 1 unexpected error,
2 invalid input.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

import numpy as np

from fixplan import __version__, pressure
from fixplan.errors import FixplanError
from fixplan.limit_surface import LimitSurface

EXIT_OK = 0
EXIT_UNEXPECTED = 1
EXIT_INVALID_INPUT = 2

_DESCRIPTION = """\
example:
  fixplan surface --shape rectangle --length 0.08 --width 0.008 --mu 0.3 --normal-force 500

Grasp and fixture planning with friction limit surfaces (Howe & Cutkosky).

exit codes: 0 success, 1 unexpected error, 2 invalid input
"""


class _Parser(argparse.ArgumentParser):
    """An argument parser that exits with EXIT_INVALID_INPUT on usage errors."""

    def error(self, message: str):
        self.print_usage(sys.stderr)
        self.exit(EXIT_INVALID_INPUT, f"{self.prog}: error: {message}\n")


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="fixplan",
        description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"fixplan {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    surface = commands.add_parser(
        "surface",
        help="the limit surface of one contact patch",
        description="Summarise the exact limit surface of one contact patch.\n\nexample:\n"
        "  fixplan surface --shape disk --radius 0.01 --pressure hertz --mu 0.8 --normal-force 20",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    surface.add_argument("--shape", choices=("disk", "rectangle"), required=True)
    surface.add_argument("--radius", type=float, help="disk radius [m]")
    surface.add_argument("--inner-radius", type=float, help="annulus inner radius [m]")
    surface.add_argument("--length", type=float, help="rectangle length along x [m]")
    surface.add_argument("--width", type=float, help="rectangle width along y [m]")
    surface.add_argument(
        "--pressure", default="uniform", choices=pressure.DISK_PROFILES, help="disk profile"
    )
    surface.add_argument("--mu", type=float, required=True, help="friction coefficient")
    surface.add_argument("--normal-force", type=float, default=1.0, help="normal force [N]")
    surface.add_argument("--json", action="store_true", help="print one JSON document")
    surface.set_defaults(run=_run_surface)
    return parser


def _patch(args: argparse.Namespace) -> pressure.PressureField:
    if args.shape == "disk":
        if args.radius is None:
            raise FixplanError("--shape disk needs --radius (m)")
        inner = args.inner_radius if args.pressure == "annulus" else None
        return pressure.disk(args.radius, args.pressure, inner_radius=inner)
    if args.length is None or args.width is None:
        raise FixplanError("--shape rectangle needs --length and --width (m)")
    if args.pressure != "uniform":
        raise FixplanError("--shape rectangle supports only --pressure uniform")
    return pressure.rectangle(args.length, args.width)


def _run_surface(args: argparse.Namespace) -> int:
    surface = LimitSurface(_patch(args), mu=args.mu, normal_force=args.normal_force)
    section = surface.curve("fy-m", 9)
    summary = {
        "shape": args.shape,
        "pressure": args.pressure,
        "mu": args.mu,
        "normal_force_N": args.normal_force,
        "max_force_N": surface.max_force,
        "max_moment_Nm": surface.max_moment,
        "characteristic_length_m": surface.characteristic_length,
        "limit_curve_fy_m": [[float(f), float(m)] for _, f, m in section[:3]],
    }
    if args.json:
        print(json.dumps(summary, indent=2))
        return EXIT_OK
    print(f"limit surface of a {args.shape} patch ({args.pressure} pressure)")
    print(f"  mu = {args.mu:g}, normal force = {args.normal_force:g} N")
    print(f"  max friction force   {surface.max_force:12.6g} N")
    print(f"  max friction moment  {surface.max_moment:12.6g} N m")
    print(f"  characteristic length {surface.characteristic_length:11.6g} m")
    print("  limit curve (fy, m) from pure force to pure moment:")
    for _, f, m in section[:3]:
        print(f"    fy = {f:12.6g} N    m = {m:12.6g} N m")
    return EXIT_OK


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    parser = _build_parser()
    args = parser.parse_args(argv)
    try:
        with np.errstate(all="ignore"):
            return args.run(args)
    except FixplanError as exc:
        print(f"fixplan: error: {exc}", file=sys.stderr)
        return EXIT_INVALID_INPUT


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
