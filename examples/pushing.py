"""Pushing a box across a table: a round finger off-centre, then a flat pusher at an angle.

A 90 × 60 mm box of 0.5 kg rests on a table with uniform pressure under it (friction 0.3). First a
round finger (radius 5 mm, friction 0.25) pushes it 15 mm off its centre line: by Mason's voting
theorem the box turns clockwise, away from the finger, while the finger slides along its face.
Then a flat pusher (150 mm face, friction 0.25) meets the same box turned by 20°: the box turns
until it lies flush against the face and then rides on it (stable pushing, Lynch & Mason 1996).

Run: ``python examples/pushing.py [--figures DIR]`` (figures and an animated GIF into DIR).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from fixplan import LimitSurface, pressure
from fixplan.motion import LinePusher, Outline, PointPusher, push

LENGTH, WIDTH, MASS, TABLE_MU, PUSHER_MU = 0.09, 0.06, 0.5, 0.3, 0.25
SPEED = 0.02  # m/s


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--figures", type=Path, metavar="DIR", help="write figures and GIFs")
    args = parser.parse_args(argv)
    box = Outline.rectangle(LENGTH, WIDTH)
    table = LimitSurface(pressure.rectangle(LENGTH, WIDTH), mu=TABLE_MU, normal_force=MASS * 9.81)
    finger = PointPusher(([-0.06, 0.015], [SPEED, 0.0]), mu=PUSHER_MU, radius=0.005)
    flat = LinePusher(([-0.07, 0.0], [SPEED, 0.0]), mu=PUSHER_MU, width=0.15)
    runs = {
        "finger": push(table, finger, shape=box, duration=4.0, steps=400),
        "flat": push(
            table, flat, shape=box, pose=(0.0, 0.0, math.radians(20)), duration=4.0, steps=400
        ),
    }
    for name, trajectory in runs.items():
        x, y, theta = trajectory.poses[-1]
        modes = {mode: trajectory.modes.count(mode) for mode in sorted(set(trajectory.modes))}
        print(f"{name:6s}: final pose x = {1e3 * x:6.1f} mm, y = {1e3 * y:6.1f} mm, "
              f"theta = {math.degrees(theta):6.1f} deg; steps per mode {modes}")  # fmt: skip
    travel = runs["flat"].line_contact_travel()
    print(f"flat  : flush against the face after {1e3 * travel:.1f} mm of pusher travel")
    if args.figures is not None:
        from fixplan.io.figures import save_gif, save_png, trajectory_figure

        args.figures.mkdir(parents=True, exist_ok=True)
        for name, trajectory in runs.items():
            save_png(trajectory_figure(trajectory), args.figures / f"push-{name}.png")
            save_gif(trajectory, args.figures / f"push-{name}.gif")
        print(f"figures in {args.figures}")


if __name__ == "__main__":
    main()
