"""What a push did, in numbers and words, and its report folder.

:func:`push_summary` condenses a :class:`~fixplan.motion.Trajectory` of a push file into plain
values (the final pose and how far the part moved and turned, the time in each contact mode, the
largest pusher force, the pusher travel until a line pusher has the part flush against its face).
:func:`write_push_report` writes into a folder

- ``report.md`` and ``report.html``: the push's inputs, the summary and the figures;
- ``push.json``: the summary with sorted keys;
- ``trajectory.csv``: one row per step (time, pose, twist, mode, force, contact point);
- ``trajectory.png`` (:func:`fixplan.io.figures.trajectory_figure`) and ``trajectory.gif``
  (:func:`fixplan.io.figures.save_gif`).

As for plan reports, nothing depends on the time or the machine's paths, and the folder appears
whole or not at all.
"""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

import numpy as np

from fixplan.io import figures
from fixplan.io.push_file import PushFile
from fixplan.io.report_document import (
    Heading,
    Image,
    List,
    Paragraph,
    Table,
    Writer,
    inline,
    staged_folder,
)
from fixplan.motion import Trajectory
from fixplan.motion.pushing import MODES

_CSV_HEADER = ("t_s,x_m,y_m,theta_rad,vx_mps,vy_mps,w_radps,mode,force_x_N,force_y_N,"
               "contact_x_m,contact_y_m")  # fmt: skip


def push_summary(push_file: PushFile, trajectory: Trajectory) -> dict:
    """The outcome of a push as plain values (SI units; angles in degrees where named so)."""
    poses = trajectory.poses
    steps = len(trajectory.modes)
    moved = poses[-1] - poses[0]
    forces = np.linalg.norm(trajectory.forces, axis=1) if steps else np.zeros(0)
    travel = trajectory.line_contact_travel() if hasattr(trajectory.pusher, "width") else None
    return {
        "name": push_file.name,
        "model": push_file.model,
        "duration_s": float(trajectory.t[-1]),
        "steps": steps,
        "start_pose": [float(v) for v in poses[0]],
        "final_pose": [float(v) for v in poses[-1]],
        "moved_m": float(math.hypot(moved[0], moved[1])),
        "turned_deg": math.degrees(float(moved[2])),
        "mode_fractions": {mode: trajectory.modes.count(mode) / max(steps, 1) for mode in MODES},
        "max_force_N": float(forces.max()) if forces.size else 0.0,
        "line_contact_travel_m": travel,
        "pusher": type(push_file.pusher).__name__,
    }


def describe_push(summary: dict) -> list[str]:
    """The summary in lines of text (the command line's output)."""
    x, y, theta = summary["final_pose"]
    modes = ", ".join(f"{mode} {100 * share:.0f} %" for mode, share in
                      summary["mode_fractions"].items() if share > 0)  # fmt: skip
    lines = [
        f"push       {summary['name']}: {summary['pusher']}, {summary['model']} support, "
        f"{summary['steps']} steps over {summary['duration_s']:.4g} s",
        f"final pose x = {1e3 * x:.4g} mm, y = {1e3 * y:.4g} mm, theta = "
        f"{math.degrees(theta):.4g} deg",
        f"moved      {1e3 * summary['moved_m']:.4g} mm, turned {summary['turned_deg']:.4g} deg",
        f"modes      {modes}",
        f"max force  {summary['max_force_N']:.4g} N (pusher on part)",
    ]
    if summary["pusher"] == "LinePusher":
        travel = summary["line_contact_travel_m"]
        lines.append(
            "flush      never: the part did not turn flush against the pusher's face"
            if travel is None
            else f"flush      after {1e3 * travel:.4g} mm of pusher travel the part lies flush "
            "against the pusher's face"
        )
    return lines


def trajectory_csv(trajectory: Trajectory) -> str:
    """One CSV row per step: the time and pose at its end, its twist, mode, force and contact."""
    out = io.StringIO()
    out.write(_CSV_HEADER + "\n")
    for k, mode in enumerate(trajectory.modes):
        numbers = [trajectory.t[k + 1], *trajectory.poses[k + 1], *trajectory.twists[k]]
        tail = [*trajectory.forces[k], *trajectory.contact_points[k]]
        out.write(",".join(f"{v:.9g}" for v in numbers) + f",{mode},")
        out.write(",".join("" if math.isnan(v) else f"{v:.9g}" for v in tail) + "\n")
    return out.getvalue()


def write_push_report(directory, push_file: PushFile, trajectory: Trajectory) -> list[Path]:
    """Write the report folder of a push (see the module docstring); returns the files written.

    Raises
    ------
    ReportError
        The folder cannot be created or a file cannot be written.
    """
    summary = push_summary(push_file, trajectory)
    directory = Path(directory)
    with staged_folder(directory) as staging:
        writer = Writer(staging)
        writer.write("push.json", (json.dumps(summary, indent=2, sort_keys=True) + "\n").encode())
        writer.write("trajectory.csv", trajectory_csv(trajectory).encode())
        writer.figure("trajectory.png", lambda: figures.trajectory_figure(trajectory))
        writer.save("trajectory.gif", lambda path: figures.save_gif(trajectory, path))
        blocks = [
            Heading(1, inline(f"fixplan push report: {push_file.name}")),
            Paragraph(inline(f"Input file SHA-256 {push_file.sha256}.")),
            Table(("item", "value"), tuple((inline(k), inline(v)) for k, v in _inputs(push_file))),
            Heading(2, inline("Outcome")),
            List(tuple(inline(line) for line in describe_push(summary))),
            Heading(2, inline("Figures")),
            Image(
                "trajectory.png",
                "trajectory",
                inline("The part, the pusher and the contact modes over the push."),
            ),
            Image("trajectory.gif", "animation", inline("The push, animated.")),
        ]
        writer.document(blocks, f"fixplan push: {push_file.name}")
    return [directory / path.name for path in writer.written]


def _inputs(push_file: PushFile) -> list[tuple[str, str]]:
    pusher = push_file.pusher
    size = (
        f"width {pusher.width:g} m" if hasattr(pusher, "width") else f"radius {pusher.radius:g} m"
    )
    return [
        ("support", f"{push_file.model} limit surface, mu {push_file.support_mu:g}, normal force "
                    f"{push_file.normal_force:.4g} N"),
        ("pusher", f"{type(pusher).__name__}, {size}, mu {pusher.mu:g}"),
        ("start pose", ", ".join(f"{v:g}" for v in push_file.pose)),
        ("simulation", f"{push_file.duration:g} s in {push_file.steps} steps"),
    ]  # fmt: skip
