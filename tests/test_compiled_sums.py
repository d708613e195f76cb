"""The compiled inverse map of summed surfaces (``LimitSurface.combine``, a contact set's exact
form) and of ellipsoids: the same answers as the NumPy path, which evaluates each part's own
kernel and sums them, and the parts' supports, loads and Hessians summed."""

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.surface.geometry import Pose
from fixplan.surface.inverse import solve
from fixplan.surface.kernels import PosedKernel
from fixplan.surface.point_kernel import PARALLEL_MIN_WORK, PointSetKernel

RNG = np.random.default_rng(23)

PINS = pressure.points([[0.0, 0.04], [0.05, -0.02]], [1.0, 2.0])
ANNULUS = pressure.disk(0.02, "annulus", inner_radius=0.01)


def pad():
    return LimitSurface(pressure.rectangle(0.03, 0.01), mu=0.4, normal_force=3.0).placed(
        Pose(angle=0.3, offset=(0.02, 0.01))
    )


def disk_from_above():
    return LimitSurface(pressure.disk(0.01, "hertz"), mu=0.5, normal_force=2.0).placed(
        Pose(angle=0.7, offset=(-0.03, 0.0), mirrored=True)
    )


def ellipsoid():
    matrix = np.array([[4.0, 0.5, 10.0], [0.5, 3.0, -20.0], [10.0, -20.0, 9000.0]])
    return LimitSurface.ellipsoid(matrix, normal_force=2.0).placed(
        Pose(angle=0.2, offset=(0.0, -0.03))
    )


def pins():
    return LimitSurface(PINS, mu=0.3, normal_force=4.0)


def nested_pad_and_pins():
    turned = Pose(angle=-1.0, offset=(0.01, 0.0), mirrored=True)
    return LimitSurface.combine([pad(), pins()]).placed(turned)


def annulus_and_ellipsoid():
    return LimitSurface.combine([LimitSurface(ANNULUS, mu=0.2), ellipsoid()])


SUMS = {
    "pad and disk from above": lambda: LimitSurface.combine([pad(), disk_from_above()]),
    "pads and pins": lambda: LimitSurface.combine([pad(), disk_from_above(), pins()]),
    "pad, ellipsoid and pins": lambda: LimitSurface.combine([pad(), ellipsoid(), pins()]),
    "sums of sums, placed": lambda: LimitSurface.combine(
        [nested_pad_and_pins(), annulus_and_ellipsoid()]
    ),
    "ellipsoid": ellipsoid,
}


def loads_of(surface, count):
    """Random loads, and where the surface has point supports, loads on and next to their
    facets (rotations about a point, scaled in or out)."""
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    loads = RNG.normal(size=(count, 3)) * units
    points = surface.point_supports[0]
    if len(points):
        at = points[RNG.integers(len(points), size=count)]
        near = at + RNG.normal(size=(count, 2)) * 1e-9
        on_facets = surface.load_at_cor(near) * RNG.uniform(0.5, 2.0, size=(count, 1))
        off_facets = surface.load_at_cor(at) * 0.9 + RNG.normal(size=(count, 3)) * 1e-3 * units
        loads = np.vstack([loads, on_facets, off_facets])
    return loads


def unit_motions(surface, twists):
    normalised = twists * np.array([surface.max_force, surface.max_force, surface.max_moment])
    return normalised / np.linalg.norm(normalised, axis=1, keepdims=True)


@pytest.mark.parametrize("name", SUMS)
def test_a_compiled_sum_answers_as_the_numpy_path_of_its_parts(name):
    """Safety factors to 1e-13 and motions to 1e-10 (unit twists in normalised coordinates:
    the inverse map's accuracy) on random loads and loads on and next to facets (seen: 1.4e-15
    and 5.1e-13), one load at a time and batched."""
    surface = SUMS[name]()
    assert surface._compiled is not None
    loads = loads_of(surface, 100)
    motions, safety = surface.motion_and_safety_factor(loads)
    size = np.max(np.abs(loads / surface._units), axis=1)
    numpy = solve(surface._kernel, surface._scale, loads / size[:, None], surface._units)
    np.testing.assert_allclose(safety, numpy.safety_factor / size, rtol=1e-13)
    np.testing.assert_allclose(unit_motions(surface, motions),
                               unit_motions(surface, numpy.twist), rtol=0, atol=1e-10)  # fmt: skip
    for k in range(0, len(loads), 37):
        motion, alone = surface.motion_and_safety_factor(loads[k])
        assert alone == safety[k]
        np.testing.assert_array_equal(motion, motions[k])


def summed_parts(surface, method, twists):
    """``method`` of each part of a combined surface at ``twists``, summed (parts of parts
    too)."""
    if not surface.parts:
        return getattr(surface, method)(twists)
    return sum(summed_parts(part, method, twists) for part in surface.parts)


@pytest.mark.parametrize("name", [name for name in SUMS if name != "ellipsoid"])
def test_a_compiled_sum_has_its_parts_supports_loads_and_hessians_summed(name):
    """Each at 1e-13 of its largest entry, for a few twists (compiled) and a batch (the
    supports and loads of larger batches: the NumPy kernels)."""
    surface = SUMS[name]()
    for count in (3, 300):
        twists = RNG.normal(size=(count, 3)) * [1.0, 1.0, 30.0]
        for method in ("support", "load", "support_hessian"):
            found, expected = getattr(surface, method)(twists), summed_parts(surface, method,
                                                                             twists)  # fmt: skip
            scale = np.abs(expected).max(axis=tuple(range(1, expected.ndim)), keepdims=True)
            assert np.all(np.abs(found - expected) <= 1e-13 * scale), method


def test_an_ellipsoid_compiles_to_its_closed_forms():
    """The ellipsoid ``N sqrt(Vᵀ A⁻¹ V)``: support, load and Hessian (``(B - ℓ ℓᵀ) / h`` per
    unit force, ``B = A⁻¹``) to 1e-14, safety factors ``N / sqrt(Lᵀ A L)`` to 1e-14."""
    matrix = np.array([[4.0, 0.5, 10.0], [0.5, 3.0, -20.0], [10.0, -20.0, 9000.0]])
    surface = LimitSurface.ellipsoid(matrix, normal_force=2.0)
    inverse = np.linalg.inv(matrix)
    twists = RNG.normal(size=(20, 3)) * [1.0, 1.0, 30.0]
    h = np.sqrt(np.einsum("kc,cd,kd->k", twists, inverse, twists))
    unit_loads = twists @ inverse / h[:, None]
    hessians = (inverse - unit_loads[:, :, None] * unit_loads[:, None, :]) / h[:, None, None]
    np.testing.assert_allclose(surface.support(twists), 2.0 * h, rtol=1e-14)
    np.testing.assert_allclose(surface.load(twists), 2.0 * unit_loads, rtol=0,
                               atol=1e-14 * np.abs(2.0 * unit_loads).max())  # fmt: skip
    for found, expected in zip(surface.support_hessian(twists), 2.0 * hessians, strict=True):
        np.testing.assert_allclose(found, expected, rtol=0, atol=1e-14 * np.abs(expected).max())
    loads = RNG.normal(size=(50, 3)) * [1.0, 1.0, 0.02]
    expected = 2.0 / np.sqrt(np.einsum("kc,cd,kd->k", loads, matrix, loads))
    np.testing.assert_allclose(surface.safety_factor(loads), expected, rtol=1e-14)


def test_point_supports_posed_directly_compile_with_their_facets_in_the_contact_frame():
    """A discrete point set in a ``PosedKernel`` (not moved point by point): its facets are
    tested where the pose puts them, as the same points moved."""
    local = PointSetKernel(np.array([[0.0, 0.0], [0.02, 0.01], [0.01, 0.03]]),
                           np.array([0.2, 0.5, 0.3]), True)  # fmt: skip
    pose = Pose(angle=0.9, offset=(0.05, -0.01), mirrored=True)
    posed = LimitSurface.__new__(LimitSurface)
    posed.field, posed._mu, posed._normal_force, posed._parts = None, None, 2.0, ()
    posed._setup(PosedKernel(local, pose), 0.8)
    moved = LimitSurface(pressure.points(pose.apply(local.points), local.weights,
                                         centered=False), mu=0.4, normal_force=2.0)  # fmt: skip
    assert posed._compiled is not None and posed._compiled.discrete
    loads = loads_of(moved, 50)
    np.testing.assert_allclose(posed.safety_factor(loads), moved.safety_factor(loads),
                               rtol=1e-13)  # fmt: skip
    np.testing.assert_allclose(unit_motions(moved, posed.motion(loads)),
                               unit_motions(moved, moved.motion(loads)), rtol=0, atol=1e-10)  # fmt: skip


def test_batches_of_a_sum_large_enough_to_run_in_parallel_give_the_one_by_one_answers():
    """The parallel loops take the kernel's tuple as the serial ones do (numba's parallel loops
    take no nested tuples); their answers agree to rounding (in a fresh process, the twists
    differed by 3e-15: the two loops are compiled apart)."""
    cloud = RNG.normal(size=(26_000, 2)) * 0.02
    points = LimitSurface(pressure.points(cloud, np.ones(len(cloud))), mu=0.5)
    surface = LimitSurface.combine([points, pad(), ellipsoid()])
    compiled = surface._compiled
    assert 8 * compiled.work >= PARALLEL_MIN_WORK > compiled.work
    loads = RNG.normal(size=(8, 3)) * surface._units
    safety, twists = compiled.solve(loads, surface._units, surface._scale)
    hessians = compiled.hessians(twists)
    for k in range(8):
        alone = compiled.solve(loads[k : k + 1], surface._units, surface._scale)
        np.testing.assert_allclose(alone[0], safety[k : k + 1], rtol=1e-13)
        np.testing.assert_allclose(alone[1][0], twists[k], rtol=0,
                                   atol=1e-13 * np.abs(twists[k]).max())  # fmt: skip
        np.testing.assert_allclose(compiled.hessians(twists[k : k + 1])[0], hessians[k], rtol=0,
                                   atol=1e-13 * np.abs(hessians[k]).max())  # fmt: skip
