"""The MIT push data (MCube) as Zhou et al. prepared them: reading the files, replaying a push.

Data (read at run time, never copied into the project): the MIT push dataset (Yu, Bauza,
Fazeli, Rodriguez, IROS 2016) as prepared by Jiaji Zhou for "A convex polynomial force-motion
model for planar sliding" (Zhou, Paolini, Bagnell, Mason, ICRA 2016; PlanarManipulationToolBox,
GPL-2.0): 11 steel objects on an ABS sheet (and, held out, on plywood) pushed by a steel cylinder
of radius 4.75 mm, with Zhou's (load, twist) pairs, fitted limit surfaces, pusher friction and
simulated final poses. See ``shared/real_data/README.md`` for sources, licences and units.

A group is ``"surface/shape"`` (e.g. ``"abs/rect1"``). The plywood groups live in ``holdout/``,
for the final validation only. Shared by ``pushing_real_data.py`` and ``identify_real_data.py``.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

from fixplan.motion import Outline, PointPusher, push

HOLDOUT_SURFACE = "plywood"
PUSHER_RADIUS = 0.00475  # m, the steel cylinder of the MIT push dataset
DEFAULT_DATA = Path(__file__).resolve().parents[2] / "shared" / "real_data"

#: Duration [s] of a replayed push: the pusher covers the measured tip displacement in it (the
#: motion is quasi-static, so only the path matters).
PUSH_DURATION = 1.0

_NAMES = ("surface", "shape")


def folder(data: Path, surface: str) -> Path:
    """The folder of ``surface``'s files: ``holdout/`` for the held-out plywood half."""
    return data / "holdout" if surface == HOLDOUT_SURFACE else data


def groups(data: Path, surface: str) -> list[str]:
    """The groups ``"surface/shape"`` of ``surface`` that Zhou fitted, in file order."""
    fits = json.loads((folder(data, surface) / "mcube_zhou_fits.json").read_text())["fits"]
    return [group for group in fits if group.split("/")[0] == surface]


def shape(data: Path, group: str) -> dict:
    """The object of ``group`` (``vertices_m``, ``rho_m``, ...; ``mcube_shapes.json``)."""
    return json.loads((data / "mcube_shapes.json").read_text())["shapes"][group.split("/")[1]]


def zhou_fits(data: Path, group: str) -> dict:
    """Zhou's fits of ``group`` (``quadratic``, ``poly4``, ``rho_m``; ``mcube_zhou_fits.json``)."""
    surface = group.split("/")[0]
    return json.loads((folder(data, surface) / "mcube_zhou_fits.json").read_text())["fits"][group]


def _rows(path: Path, group: str) -> list[dict[str, float]]:
    """The rows of ``group`` in the CSV ``path``, their numbers as floats."""
    key = tuple(group.split("/"))
    with path.open(newline="") as handle:
        return [{k: float(v) for k, v in row.items() if k not in _NAMES}
                for row in csv.DictReader(handle) if (row["surface"], row["shape"]) == key]  # fmt: skip


def pairs(data: Path, group: str) -> tuple[np.ndarray, np.ndarray]:
    """Zhou's training pairs of ``group``: loads ``(fx, fy, m)`` [N, N, N m] and twists
    ``(vx, vy, w)`` [m/s, m/s, rad/s], ``(n, 3)`` each (``mcube_ls_pairs.csv``)."""
    rows = _rows(folder(data, group.split("/")[0]) / "mcube_ls_pairs.csv", group)
    loads = np.array([[r["fx_N"], r["fy_N"], r["m_Nm"]] for r in rows])
    twists = np.array([[r["vx_mps"], r["vy_mps"], r["w_radps"]] for r in rows])
    return loads, twists


def measured_pushes(data: Path, group: str, limit: int | None = None) -> list[dict[str, float]]:
    """The first ``limit`` (default all) test pushes of ``group`` (``mcube_test_pushes.csv``)."""
    return _rows(folder(data, group.split("/")[0]) / "mcube_test_pushes.csv", group)[:limit]


def replay(surface, row: dict[str, float], outline: Outline, *, mu: float, steps: int):
    """Final pose ``(x, y, θ)`` [m, m, rad] of the part on ``surface`` pushed as in ``row``:
    from its measured start pose, the pusher's centre moving on the measured straight line, with
    pusher friction ``mu``, in ``steps`` integration steps. Half the measured starts have the
    cylinder up to 3.4 mm into the part (tracking errors): any overlap below its radius is
    allowed, the pusher touching the part from the start."""
    start = np.array([row["tipx0_m"], row["tipy0_m"]])
    velocity = (np.array([row["tipx1_m"], row["tipy1_m"]]) - start) / PUSH_DURATION
    pusher = PointPusher((start, velocity), mu=mu, radius=PUSHER_RADIUS)
    trajectory = push(surface, pusher, shape=outline, pose=tuple(pose(row, at="0")),
                      duration=PUSH_DURATION, steps=steps, start_overlap=PUSHER_RADIUS)  # fmt: skip
    return trajectory.poses[-1]


def pose(row: dict[str, float], *, at: str = "1", simulator: str = "") -> np.ndarray:
    """The pose ``(x, y, θ)`` [m, m, rad] of a push ``row`` measured at its start (``at="0"``)
    or end (``"1"``), or simulated by Zhou (``simulator="quad_"`` or ``"poly4_"``, the end)."""
    return np.array([row[f"{simulator}{name}{at}_{unit}"]
                     for name, unit in (("x", "m"), ("y", "m"), ("th", "rad"))])  # fmt: skip


def angle_difference(a: float, b: float) -> float:
    """|a - b| modulo 2π [rad]."""
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def pose_error(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Distance [mm] and angle [deg] between poses ``(x, y, θ)`` [m, m, rad]."""
    return 1000 * float(np.linalg.norm(a[:2] - b[:2])), math.degrees(angle_difference(a[2], b[2]))
