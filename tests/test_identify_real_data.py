"""The helpers of ``examples/identify_real_data.py`` on a made-up object (synthetic pairs and
pushes of a known ellipsoid, written in the files' formats; no real data)."""

import csv
import importlib
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from fixplan.motion import Outline, ellipsoid_from_matrix, synthetic
from fixplan.motion.fitted_quartic import MONOMIALS, monomials

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))  # the scripts' mcube
identify = importlib.import_module("identify_real_data")
mcube = importlib.import_module("mcube")

#: Zhou's ``A`` of the made-up object [1/N²] in ``x = (fx, fy, m / rho)``, and its ``rho`` [m].
MATRIX = np.array([[0.40, -0.02, -0.04], [-0.02, 0.45, 0.02], [-0.04, 0.02, 1.20]])
RHO = 0.05
SQUARE = [[-0.04, -0.04], [0.04, -0.04], [0.04, 0.04], [-0.04, 0.04]]
PUSHER_MU = 0.3

#: Noise-free pairs of an ellipsoid, which both models represent exactly: the fits recover it to
#: the fit's regularisation and solver accuracy.
RECOVERED_RADIAL, RECOVERED_ANGLE = 1e-3, 1e-3  # [-], [rad]

#: A replay of the very surface that made a push ends where it did (to rounding).
SAME_POSE_MM = 1e-9

#: Our fits' replays end within this of the truth's [mm], [deg].
FITTED_POSE_MM, FITTED_POSE_DEG = 0.05, 0.05


def truth():
    return ellipsoid_from_matrix(MATRIX, rho=RHO)


def quartic_coefficients():
    """Coefficients of ``(x^T A x)^2`` in the order of ``MONOMIALS`` (least squares on points:
    exact, it is a quartic form)."""
    points = np.random.default_rng(2).standard_normal((40, 3))
    values = np.einsum("ij,jk,ik->i", points, MATRIX, points) ** 2
    return np.linalg.lstsq(monomials(points), values, rcond=None)[0]


def zhou_entry():
    return {"rho_m": RHO,
            "quadratic": {"A_normalised": MATRIX.tolist(), "mu_pusher_best": PUSHER_MU},
            "poly4": {"coeffs_normalised": quartic_coefficients().tolist(),
                      "mu_pusher_best": PUSHER_MU}}  # fmt: skip


def made_up_pushes(count=2):
    """Test-push rows whose end poses are the truth's replay (Zhou's simulator's too)."""
    rows = []
    for k in range(count):
        row = {"k": float(k), "x0_m": 0.0, "y0_m": 0.0, "th0_rad": 0.1 * k,
               "tipx0_m": -0.05, "tipy0_m": 0.01 * k - 0.005, "tipx1_m": -0.01,
               "tipy1_m": 0.012 * k - 0.004}  # fmt: skip
        x1, y1, th1 = mcube.replay(truth(), row, Outline.polygon(SQUARE), mu=PUSHER_MU,
                                   steps=identify.STEPS)  # fmt: skip
        for prefix in ("", "quad_", "poly4_"):
            row.update({f"{prefix}x1_m": x1, f"{prefix}y1_m": y1, f"{prefix}th1_rad": th1})
        rows.append(row)
    return rows


def write_data(folder: Path, group: str, pushes: list[dict]):
    """The made-up object's files, in ``folder`` (``holdout/`` for plywood) as the real ones."""
    surface, name = group.split("/")
    folder.mkdir(exist_ok=True)
    (folder / "mcube_shapes.json").write_text(
        json.dumps({"shapes": {name: {"vertices_m": SQUARE, "rho_m": RHO}}})
    )
    files = mcube.folder(folder, surface)
    files.mkdir(exist_ok=True)
    (files / "mcube_zhou_fits.json").write_text(
        json.dumps({"poly4_monomials": list(MONOMIALS), "fits": {group: zhou_entry()}})
    )
    loads, twists = synthetic(truth(), 120, seed=3)
    with (files / "mcube_ls_pairs.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["surface", "shape", "fx_N", "fy_N", "m_Nm", "vx_mps", "vy_mps", "w_radps"])
        writer.writerows([surface, name, *row] for row in np.hstack([loads, twists]))
    with (files / "mcube_test_pushes.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, ["surface", "shape", *pushes[0]])
        writer.writeheader()
        writer.writerows({"surface": surface, "shape": name, **row} for row in pushes)


def test_the_split_is_deterministic_disjoint_and_holds_out_the_stated_fraction():
    training, held_out = identify.split(506)
    again = identify.split(506)
    np.testing.assert_array_equal(training, again[0])
    np.testing.assert_array_equal(held_out, again[1])
    assert len(held_out) == round(identify.HELD_OUT * 506)
    assert set(training).isdisjoint(held_out)
    assert sorted([*training, *held_out]) == list(range(506))
    assert not np.array_equal(identify.split(506, seed=1)[1], held_out)


@pytest.fixture(scope="module")
def group():
    """The made-up object with our fits of its noise-free pairs and Zhou's (the truth)."""
    loads, twists = synthetic(truth(), 120, seed=3)
    return identify.build_group("abs/made-up", loads, twists, zhou_entry())


def test_fits_of_noise_free_pairs_recover_the_surface_and_zhous_fits_are_read_as_given(group):
    assert set(group.surfaces) == set(identify.LABELS)
    assert group.pusher_mu == dict.fromkeys(identify.LABELS, PUSHER_MU)
    figures = identify.held_out_errors(group)
    for label in ("Zhou ellipsoid", "Zhou quartic"):  # the truth, exactly
        radial, level, angle = figures[label]
        assert radial < 1e-10 and level < 1e-10 and angle < 1e-6
    for label in ("ours ellipsoid", "ours quartic"):
        radial, level, angle = figures[label]
        assert radial < 100 * RECOVERED_RADIAL and angle < np.degrees(RECOVERED_ANGLE)


def test_replayed_pushes_of_the_true_surface_end_where_the_rows_say(group):
    errors = identify.push_errors(group, made_up_pushes(), Outline.polygon(SQUARE))
    for label in ("Zhou ellipsoid", *identify.SIMULATORS):
        assert errors[label][0] < SAME_POSE_MM
    for label in ("Zhou quartic", "ours ellipsoid", "ours quartic"):
        assert errors[label][0] < FITTED_POSE_MM and errors[label][1] < FITTED_POSE_DEG


def test_the_script_reads_a_group_prints_its_table_and_keeps_plywood_for_holdout(tmp_path, capsys):
    write_data(tmp_path, "abs/made-up", made_up_pushes(1))
    identify.main(["--data", str(tmp_path), "--pushes"])
    printed = capsys.readouterr().out
    assert "abs/made-up: 120 pairs, 90 fitted, 30 held out; rho = 50.0 mm; 1 test pushes" in printed
    assert "trained on ALL the pairs" in printed
    for label in identify.LABELS:
        marker = " *" if label.startswith("Zhou") else ""
        assert printed.count(f"  {label}{marker} ") == 2  # the group's table and the mean
    with pytest.raises(SystemExit):
        identify.main(["--data", str(tmp_path), "--group", "plywood/made-up"])
    write_data(tmp_path, "plywood/made-up", made_up_pushes(1))
    identify.main(["--data", str(tmp_path), "--holdout"])
    assert "plywood/made-up: 120 pairs" in capsys.readouterr().out
