"""Pressure and friction functions the limit surface's quadrature does not resolve are refused.

A function field is integrated by two kinds of rules: polar rules about a centre of rotation
near the patch and a fixed rule far from it (:mod:`fixplan.surface.function_kernel`). Where
both apply they agree to about 1e-14 for smooth fields; where ``p`` or ``mu`` jumps, has a kink
or a peak too narrow for them, they disagree by about the error of the answers. Such a field is
refused at construction (``QUADRATURE_RTOL``) instead of answering off by percents, or failing
to converge query after query (a step in ``p`` did on 12 of 12 random loads, 1.5 s each).
"""

import itertools

import numpy as np
import pytest
from conftest import disk_bump

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError
from fixplan.surface.function_kernel import FunctionKernel
from fixplan.tolerances import QUADRATURE_RTOL

R = 0.01
DISK = pressure.disk(R)
RECTANGLE = pressure.rectangle(0.02, 0.01)

#: Smooth fields: the two rules agree to this (measured: at most 7e-15).
SMOOTH_RTOL = 1e-13


def _peak(sigma: float):
    """A Gaussian peak of width ``sigma`` [m] off the centre of the patch, on a floor."""
    return lambda x, y: np.exp(-((x - 0.002) ** 2 + y**2) / (2.0 * sigma**2)) + 1e-3


def _cells(nx: int, ny: int) -> tuple:
    """The rectangle as ``nx x ny`` polygon regions of the function kernel."""
    xs, ys = np.linspace(-0.01, 0.01, nx + 1), np.linspace(-0.005, 0.005, ny + 1)
    return tuple(
        ("polygon", np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]]), 1.0)
        for x0, x1 in itertools.pairwise(xs)
        for y0, y1 in itertools.pairwise(ys)
    )


UNRESOLVED_PRESSURES = {
    "a step": (DISK, lambda x, y: (x > 0.003) + 1e-3),
    "a kink": (DISK, lambda x, y: 1.0 + np.abs(x) / R),
    "a ring of zero pressure": (DISK, lambda x, y: (x * x + y * y > 0.008**2) * 1.0),
    "a half loaded rectangle": (RECTANGLE, lambda x, y: (y > 0.0) * 1.0),
    "a narrow peak": (DISK, _peak(2e-4)),
}


@pytest.mark.parametrize("name", UNRESOLVED_PRESSURES)
def test_a_pressure_function_the_rules_do_not_resolve_is_refused_with_the_way_out(name):
    shape, p = UNRESOLVED_PRESSURES[name]
    field = pressure.from_function(shape, p)
    with pytest.raises(InvalidArgumentError, match=r"p\(x, y\) is not smooth enough") as error:
        LimitSurface(field, mu=0.5, normal_force=10.0)
    assert "LimitSurface.combine" in str(error.value) and "pressure.grid" in str(error.value)


@pytest.mark.parametrize("field", [DISK, RECTANGLE, pressure.disk(R, "hertz")], ids=str)
def test_a_friction_function_with_a_step_is_refused(field):
    with pytest.raises(InvalidArgumentError, match=r"mu\(x, y\) is not smooth enough"):
        LimitSurface(field, mu=lambda x, y: np.where(x > 0.001, 0.6, 0.3), normal_force=1.0)
    both = pressure.from_function(DISK, disk_bump)
    with pytest.raises(InvalidArgumentError, match=r"mu\(x, y\) times p\(x, y\) is not smooth"):
        LimitSurface(both, mu=lambda x, y: np.where(x > 0.001, 0.6, 0.3), normal_force=1.0)


SMOOTH_KERNELS = {
    "linear p on a disk": dict(regions=(("disk", R, 1.0),), pressure=lambda x, y: 1 + x / R),
    "bump on a disk": dict(regions=(("disk", R, 1.0),), pressure=disk_bump),
    "Hertz-like p on a disk": dict(
        regions=(("disk", R, 1.0),),
        pressure=lambda x, y: np.sqrt(np.clip(1.0 - (x * x + y * y) / R**2, 0.0, None)),
    ),
    "linear p on a rectangle": dict(regions=_cells(1, 1), pressure=lambda x, y: 1 + 50 * x),
    "annulus (a negative disk)": dict(
        regions=(("disk", R, 1.0), ("disk", 0.008, -1.0)), pressure=lambda x, y: 1 + x / R
    ),
    "friction on a circle": dict(regions=(("circle", R, 1.0),), friction=lambda x, y: 1 + x / R),
    "wide peak": dict(regions=(("disk", R, 1.0),), pressure=_peak(3e-3)),
}


@pytest.mark.parametrize("name", SMOOTH_KERNELS)
def test_the_rules_agree_to_rounding_on_smooth_fields(name):
    kernel = FunctionKernel(**SMOOTH_KERNELS[name])
    bound = 1e-9 if name == "wide peak" else SMOOTH_RTOL  # (its tails: 1.5e-10)
    assert kernel.rule_disagreement() < bound


@pytest.mark.parametrize("sigma", [2e-3, 1.5e-3])
def test_the_disagreement_is_of_the_order_of_the_error_of_the_support_function(sigma, rng):
    # Reference: the same peak on 40 x 20 cells (each resolved by its rules), itself within
    # 1e-13 of 80 x 40 cells.
    coarse = FunctionKernel(regions=_cells(1, 1), pressure=_peak(sigma))
    fine = FunctionKernel(regions=_cells(40, 20), pressure=_peak(sigma))
    finer = FunctionKernel(regions=_cells(80, 40), pressure=_peak(sigma))
    twists = rng.normal(size=(100, 3)) * [1.0, 1.0, 100.0]
    reference = fine.evaluate(twists)[0]
    np.testing.assert_allclose(finer.evaluate(twists)[0], reference, rtol=1e-13)
    error = np.max(np.abs(coarse.evaluate(twists)[0] - reference) / reference)
    disagreement = coarse.rule_disagreement()
    assert disagreement > QUADRATURE_RTOL
    assert disagreement / 3.0 < error < 3.0 * disagreement


def test_a_friction_function_out_of_range_around_a_polygon_is_refused_saying_where():
    # Positive on the rectangle, negative 3 patch radii to its left, where the rules about a
    # centre of rotation near the polygon evaluate it (on triangles that leave the polygon).
    with pytest.raises(InvalidArgumentError, match="up to 4 patch radii around it"):
        LimitSurface(RECTANGLE, mu=lambda x, y: 0.5 + 0.2 * x / R, normal_force=1.0)
