"""The tactile-grid kernel holds each corner of the cell lattice once, weighted by the mixed
second difference of the pressures of the four cells around it, and equals the kernel of every
loaded cell's own four edges.

Reference: :func:`four_edges_per_cell` builds that kernel here, from the field's cell centres
and values, with the edge sums of :mod:`~fixplan.surface.polygon_kernel` (a different closed
form: signed triangles over each edge, where the grid kernel sums an antiderivative over the
corners). Values, loads and Hessians agree to rounding (:data:`KERNEL_RTOL`). The far rule of a
large grid (blocks of cells, :func:`~fixplan.surface.grid_kernel.block_rule`) is checked against
a Gauss rule of 6 x 6 points per cell, and integrates polynomials as it should.
"""

from __future__ import annotations

import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.surface import limit_surface
from fixplan.surface.closed_form import EdgeSumKernel, GridKernel
from fixplan.surface.grid_kernel import BLOCK_NODES, block_rule
from fixplan.surface.kernels import PosedKernel
from fixplan.surface.point_kernel import PARALLEL_MIN_WORK, PointSetKernel
from fixplan.tolerances import FAR_FIELD_RADII, INVERSE_RTOL

#: Node against edge kernel, per twist: support value relative to itself, load and Hessian
#: (moments divided by the patch size) relative to their largest component. Both sum terms of
#: size ``R³`` (distance ``R`` to the centre of rotation) to a total of size ``R`` times the
#: patch area, so rounding grows with ``R`` over the cell size: on the 120 x 150 grid, with the
#: centre at 3.1 sizes, the edge sums' Hessian is 1.8e-12 off the node formula evaluated in
#: 80-bit long double, the node sums' 2.0e-13.
KERNEL_RTOL = 5e-12
#: Safety factors through the inverse map: Newton stops when the twist is within about
#: INVERSE_RTOL, which leaves the safety factor within its square; rounding dominates.
SAFETY_RTOL = 1e-12
#: Unit motions through the inverse map: the twist is within about INVERSE_RTOL of the solution,
#: amplified by the conditioning of the normal map (up to 2e-11 measured on these grids).
MOTION_ATOL = 1e3 * INVERSE_RTOL
DX, DY = 0.002, 0.003  # cell size [m]; unequal to catch swapped axes


def random_values(ny: int, nx: int, seed: int) -> np.ndarray:
    """Random pressures with about a fifth of the cells zero, a plateau of 2 x 3 equal cells and
    a pair of equal neighbours."""
    rng = np.random.default_rng(seed)
    values = rng.uniform(0.2, 2.0, size=(ny, nx))
    values[rng.random((ny, nx)) < 0.2] = 0.0
    values[1:3, 2:5] = 1.25
    values[ny - 1, nx - 2 :] = 0.75
    return values


def hertz_values(ny: int, nx: int) -> np.ndarray:
    """A Hertz-like map over an ellipse inside the grid, zero outside it."""
    y, x = np.meshgrid(np.linspace(-1, 1, ny), np.linspace(-1, 1, nx), indexing="ij")
    return np.sqrt(np.clip(1.0 - (x * x + y * y) / 0.85**2, 0.0, None))


def lone(ny: int, nx: int, rows: slice, columns: slice, seed: int) -> np.ndarray:
    """Zeros except distinct random pressures on ``values[rows, columns]``."""
    values = np.zeros((ny, nx))
    block = values[rows, columns]
    block[...] = np.random.default_rng(seed).uniform(0.5, 1.5, size=block.shape)
    return values


def make_grid(values: np.ndarray) -> pressure.GridField:
    ny, nx = values.shape
    return pressure.grid(DX * np.arange(nx), DY * np.arange(ny), values)


GRIDS = {
    "random with zeros and equal neighbours": lambda: make_grid(random_values(7, 9, 1)),
    "uniform plateau": lambda: make_grid(np.ones((5, 6))),
    "one loaded cell": lambda: make_grid(lone(3, 3, slice(1, 2), slice(1, 2), 2)),
    "one row of 7 cells": lambda: make_grid(lone(3, 7, slice(1, 2), slice(0, 7), 3)),
    "one column of 5 cells": lambda: make_grid(lone(5, 2, slice(0, 5), slice(1, 2), 4)),
    "Hertz map of 30 x 40 cells": lambda: make_grid(hertz_values(30, 40)),
    "Hertz map of 120 x 150 cells": lambda: make_grid(hertz_values(120, 150)),
    "posed random grid": lambda: (
        make_grid(random_values(6, 8, 5)).rotated(0.7, about=(0.003, -0.002)).shifted(0.01, -0.02)
    ),
}


def far_rule(field: pressure.GridField) -> PointSetKernel:
    """The Gauss rule of the cells for far centres of rotation (order as the grid kernel's)."""
    cells = np.count_nonzero(field.values > 0.0)
    order = 8 if cells <= 16 else 4 if cells <= 256 else 3
    return PointSetKernel(*field._local_quadrature(order))


def four_edges_per_cell(field: pressure.GridField) -> tuple[EdgeSumKernel, np.ndarray]:
    """The unmerged grid kernel: each loaded cell's counter-clockwise boundary with its pressure
    [1/m²], in the grid's local frame (whose origin it keeps: the second value)."""
    dx, dy = field.cell_size
    rows, columns = np.nonzero(field.values > 0.0)
    loads = field.values[rows, columns]
    centres = np.column_stack([field.x[columns], field.y[rows]])
    corners = np.array([[-dx, -dy], [dx, -dy], [dx, dy], [-dx, dy]]) / 2.0
    squares = centres[:, None, :] + corners[None, :, :]
    starts = squares.reshape(-1, 2)
    ends = np.roll(squares, -1, axis=1).reshape(-1, 2)
    weights = np.repeat(loads / loads.sum() / (dx * dy), 4)
    return EdgeSumKernel(starts, ends, weights, far_rule(field)), np.zeros(2)


def node_and_edge_kernels(field, monkeypatch) -> tuple[GridKernel, EdgeSumKernel]:
    """The library's kernel of ``field`` and the same with :func:`four_edges_per_cell`."""
    nodes = limit_surface._field_kernel(field)
    with monkeypatch.context() as patch:
        patch.setattr(limit_surface, "_grid_kernel", four_edges_per_cell)
        edges = limit_surface._field_kernel(field)
    return nodes, edges


def lattice_nodes(field: pressure.GridField) -> dict:
    """Mixed differences [1/m²] by lattice corner ``(i, k)`` (``i`` along x, ``k`` along y),
    summed cell by cell in plain Python: a cell's pressure counts positive at its lower-left and
    upper-right corners and negative at the other two."""
    dx, dy = field.cell_size
    _, fractions = field.cells()
    rows, columns = np.nonzero(field.values > 0.0)
    nodes = {}
    for k, i, fraction in zip(rows.tolist(), columns.tolist(), fractions.tolist(), strict=True):
        p = fraction / (dx * dy)
        for corner, sign in (((i, k), 1), ((i + 1, k), -1), ((i + 1, k + 1), 1), ((i, k + 1), -1)):
            nodes[corner] = nodes.get(corner, 0.0) + sign * p
    return {corner: kappa for corner, kappa in nodes.items() if abs(kappa) > 1e-12 * abs(p)}


def table_nodes(kernel: GridKernel, field: pressure.GridField) -> dict:
    """The kernel's node table as in :func:`lattice_nodes` (corners rounded to the lattice)."""
    dx, dy = field.cell_size
    x, y, kappa = kernel.table
    origin = np.array([field.x[0] - dx / 2, field.y[0] - dy / 2])
    corners = np.rint((np.column_stack([x, y]) - origin) / (dx, dy)).astype(int)
    nodes = {}
    for corner, value in zip(map(tuple, corners), kappa, strict=True):
        assert corner not in nodes, f"node {corner} appears twice"
        nodes[corner] = value
    return nodes


def twists(field, seed: int) -> np.ndarray:
    """Rotations about points inside the grid (random, at and next to cell corners, on cell
    sides), about centres out to past the far-field radius, nearly pure and pure translations;
    contact frame."""
    rng = np.random.default_rng(seed)
    points, _ = field.quadrature(2)
    low, high = points.min(axis=0), points.max(axis=0)
    size = float(np.max(np.linalg.norm(points - field.center, axis=1)))
    dx, dy = field.cell_size
    centres = field.cells()[0][:4]
    corners = field.pose.apply(np.vstack([centres + [dx / 2, -dy / 2], centres - [0, dy / 2]]))
    next_to_corners = corners + 1e-9 * size * rng.normal(size=corners.shape)
    inside = np.vstack([rng.uniform(low, high, size=(20, 2)), corners, next_to_corners])
    outside = field.center + rng.normal(size=(20, 2)) * size * rng.uniform(0.5, 6.0, (20, 1))
    cors = np.vstack([inside, outside])
    rates = rng.choice([-1.0, 1.0], size=len(cors)) * rng.uniform(0.5, 20.0, size=len(cors))
    rotations = rates[:, None] * np.column_stack([cors[:, 1], -cors[:, 0], np.ones(len(cors))])
    velocities = rng.normal(size=(10, 2))
    translations = np.hstack([velocities, 1e-7 / size * rng.normal(size=(10, 1))])
    return np.vstack([rotations, translations, [[1.0, -0.5, 0.0]]])


@pytest.mark.parametrize("name", GRIDS)
def test_each_lattice_corner_is_kept_once_with_the_mixed_difference_of_its_cells(name):
    field = GRIDS[name]()
    kernel = limit_surface._field_kernel(field)
    local = kernel.local if isinstance(kernel, PosedKernel) else kernel
    expected = lattice_nodes(field)
    found = table_nodes(local, field)
    for corner, kappa in expected.items():
        assert found[corner] == pytest.approx(kappa, rel=1e-12), corner
    # Differences of equal pressures summed in another order can leave rounding, no more.
    largest = max(abs(kappa) for kappa in expected.values())
    for corner in found.keys() - expected.keys():
        assert abs(found[corner]) < 1e-13 * largest, corner


@pytest.mark.parametrize(
    ("name", "count"),
    [("uniform plateau", 4), ("one loaded cell", 4), ("one row of 7 cells", 2 * 8)],
)
def test_grids_keep_only_the_corners_with_a_nonzero_mixed_difference(name, count):
    kernel = limit_surface._field_kernel(GRIDS[name]())
    assert kernel.table.shape[1] == count


def test_a_uniform_plateau_keeps_its_four_outer_corners_at_the_cell_pressure():
    field = GRIDS["uniform plateau"]()
    x, y, kappa = limit_surface._field_kernel(field).table
    dx, dy = field.cell_size
    np.testing.assert_allclose(np.abs(kappa), 1.0 / (30 * dx * dy), rtol=1e-15)
    assert set(np.round(x / dx, 6)) == {
        round(field.x[0] / dx - 0.5, 6),
        round(field.x[-1] / dx + 0.5, 6),
    }
    assert set(np.round(y / dy, 6)) == {
        round(field.y[0] / dy - 0.5, 6),
        round(field.y[-1] / dy + 0.5, 6),
    }


def errors(size, terms, reference):
    """Per twist: relative errors of the support values, and of the loads and Hessians in the
    coordinates ``(vx, vy, size * w)`` (moments divided by ``size``) relative to their largest
    component; for ``(h, load[, hessian])`` from ``evaluate`` or ``newton_terms``."""
    d = np.array([1.0, 1.0, 1.0 / size])
    h, h_ref = terms[0], reference[0]
    result = [np.abs(h - h_ref) / np.abs(h_ref)]
    for value, value_ref, scale in zip(terms[1:], reference[1:], [d, np.outer(d, d)], strict=False):
        axes = tuple(range(1, value.ndim))
        result.append(
            np.max(np.abs((value - value_ref) * scale), axis=axes)
            / np.max(np.abs(value_ref * scale), axis=axes)
        )
    return result


@pytest.mark.parametrize("name", GRIDS)
def test_node_kernel_equals_the_four_edges_per_cell_kernel(name, monkeypatch):
    field = GRIDS[name]()
    nodes, edges = node_and_edge_kernels(field, monkeypatch)
    batch = twists(field, seed=len(name))
    near = FAR_FIELD_RADII * nodes.size * np.abs(batch[:, 2]) > np.hypot(batch[:, 0], batch[:, 1])
    assert np.count_nonzero(near) >= 40 and np.count_nonzero(~near) >= 10
    for method in ("evaluate", "newton_terms"):
        terms, reference = getattr(nodes, method)(batch), getattr(edges, method)(batch)
        names = ["value", "load", "Hessian"][: len(terms)]
        for what, error in zip(names, errors(nodes.size, terms, reference), strict=True):
            assert np.max(error) < KERNEL_RTOL, f"{method}: {what} off by {np.max(error):.1e}"


@pytest.mark.parametrize("name", ["random with zeros and equal neighbours", "posed random grid"])
def test_safety_factors_and_motions_match_the_four_edges_per_cell_surface(name, monkeypatch):
    field = GRIDS[name]()
    surface = LimitSurface(field, mu=0.5, normal_force=20.0)
    with monkeypatch.context() as patch:
        patch.setattr(limit_surface, "_grid_kernel", four_edges_per_cell)
        reference = LimitSurface(field, mu=0.5, normal_force=20.0)
    rng = np.random.default_rng(7)
    loads = rng.normal(size=(40, 3)) * rng.uniform(0.3, 2.0, size=(40, 1))
    loads *= np.array([surface.max_force, surface.max_force, surface.max_moment])
    motion, safety = surface.motion_and_safety_factor(loads)
    motion_ref, safety_ref = reference.motion_and_safety_factor(loads)
    np.testing.assert_allclose(safety, safety_ref, rtol=SAFETY_RTOL, atol=0.0)
    np.testing.assert_allclose(motion, motion_ref, rtol=0.0, atol=MOTION_ATOL)
    np.testing.assert_array_equal(surface.safety_factor(loads[:5]), safety[:5])
    np.testing.assert_array_equal(surface.motion(loads[:5]), motion[:5])


def test_batches_large_enough_to_run_in_parallel_give_the_one_by_one_answers():
    # A 120 x 150 Hertz map has about 10,000 loaded corners, each weighed as 3 points: a batch
    # of 8 queries or Hessians crosses PARALLEL_MIN_WORK and runs on the thread pool. Each
    # twist is computed alone either way, so the answers are the same to the bit.
    surface = LimitSurface(GRIDS["Hertz map of 120 x 150 cells"](), mu=0.5, normal_force=20.0)
    compiled = surface._compiled
    assert 8 * compiled.work >= PARALLEL_MIN_WORK > compiled.work
    rng = np.random.default_rng(9)
    units = np.array([surface.max_force, surface.max_force, surface.max_moment])
    loads = rng.normal(size=(8, 3)) * units
    safety, twists = compiled.solve(loads, units, surface._scale)
    hessians = compiled.hessians(twists)
    for k in range(8):
        alone = compiled.solve(loads[k : k + 1], units, surface._scale)
        np.testing.assert_array_equal(alone[0], safety[k : k + 1])
        np.testing.assert_array_equal(alone[1], twists[k : k + 1])
        np.testing.assert_array_equal(compiled.hessians(twists[k : k + 1])[0], hessians[k])


def test_a_grid_placed_away_from_the_origin_is_summed_about_its_middle():
    # The same random 64 x 64 map (0.5 mm cells) described two ways: cells at 0.1-0.132 m from
    # the origin of its own frame (centered=False), and centred on its centre of pressure, then
    # shifted there. The corner sums lose accuracy with the distance of the centre of rotation
    # over the cell size, so the first grid's kernel must switch to the far rule at four sizes
    # of the grid (about its middle), not of its distance from the origin (8.5 times more).
    # Summed about the origin, the Hessians at centres 0.1, 0.2 and 0.5 m from the middle were
    # 3.6e-12, 3.5e-11 and 2.1e-10 off; about the middle they are within 3e-15.
    rng = np.random.default_rng(12)
    side = 0.0005 * np.arange(64)
    values = rng.uniform(0.2, 2.0, (64, 64))
    away = pressure.grid(side + 0.1, side, values, centered=False)
    centred = pressure.grid(side, side, values)
    placed = centred.shifted(*(away.center_of_pressure() - centred.center_of_pressure()))
    kernel, reference = limit_surface._field_kernel(away), limit_surface._field_kernel(placed)
    assert isinstance(kernel, PosedKernel) and kernel.size < 2.0 * reference.size
    middle = away.cells()[0].mean(axis=0)
    angles = np.linspace(0.0, 2.0 * np.pi, 13)[:-1]
    cors = middle + np.repeat([0.1, 0.2, 0.5], 12)[:, None] * np.column_stack(
        [np.cos(np.tile(angles, 3)), np.sin(np.tile(angles, 3))]
    )
    batch = np.column_stack([cors[:, 1], -cors[:, 0], np.ones(len(cors))])
    terms, expected = kernel.newton_terms(batch), reference.newton_terms(batch)
    names = ["value", "load", "Hessian"]
    for what, error in zip(names, errors(reference.size, terms, expected), strict=True):
        assert np.max(error) < 1e-13, f"{what} off by {np.max(error):.1e}"


def random_map(ny: int, nx: int, seed: int) -> pressure.GridField:
    """A random map (a third of its cells empty) of ``ny x nx`` square cells of 0.1 mm."""
    rng = np.random.default_rng(seed)
    values = rng.uniform(0.2, 2.0, (ny, nx))
    values[rng.random((ny, nx)) < 0.3] = 0.0
    return pressure.grid(1e-4 * np.arange(nx), 1e-4 * np.arange(ny), values)


def small_patch_on_a_large_grid() -> pressure.GridField:
    """A Hertz disk of 9.5 cells' radius on a 400 x 400 grid of 0.1 mm cells: the blocks must
    be sized by the loaded cells (whose size sets the far switch), not by the grid."""
    i = np.arange(400)
    x, y = np.meshgrid(i, i)
    values = np.sqrt(np.clip(1.0 - (np.hypot(x - 205, y - 195) / 9.5) ** 2, 0.0, None))
    return pressure.grid(1e-4 * i, 1e-4 * i, values)


LARGE_GRIDS = {
    "small patch on a 400 x 400 grid": small_patch_on_a_large_grid,
    "Hertz map of 120 x 150 cells": GRIDS["Hertz map of 120 x 150 cells"],
    "random 61 x 61 with empty cells": lambda: random_map(61, 61, 21),
    "strip of 7 x 300 cells": lambda: random_map(7, 300, 22),
}


@pytest.mark.parametrize("name", LARGE_GRIDS)
def test_the_far_rule_of_a_large_grid_matches_a_fine_gauss_rule_of_its_cells(name):
    # At the far-field switch (four sizes), in 36 directions, and for translations: the block
    # rule (or, where it has no fewer points, 3 x 3 Gauss points per cell) against 6 x 6 Gauss
    # points per cell; 3 x 3 points per cell are within 3e-14 there (on the small patch, which
    # that rule takes: 1.4e-13 on loads and 3.1e-12 on Hessians, its cells being 1/40 of the
    # switch distance). With blocks sized by the whole 400 x 400 grid, the small patch's
    # Hessians were 6e-5 off.
    field = LARGE_GRIDS[name]()
    kernel = limit_surface._field_kernel(field)
    cells = np.count_nonzero(field.values > 0.0)
    assert len(kernel.far.weights) <= 9 * cells
    fine = PointSetKernel(*field._local_quadrature(6))
    angles = np.linspace(0.0, 2.0 * np.pi, 37)[:-1]
    reach = FAR_FIELD_RADII * kernel.size * 1.0001
    batch = np.concatenate([
        np.column_stack([-reach * np.sin(angles), reach * np.cos(angles), -np.ones(36)]),
        np.column_stack([np.cos(angles), np.sin(angles), np.zeros(36)]),
    ])  # fmt: skip
    terms, expected = kernel.newton_terms(batch), fine.newton_terms(batch)
    for what, error, tolerance in zip(["value", "load", "Hessian"],
                                      errors(fine.size, terms, expected), [2e-13, 2e-13, 5e-12],
                                      strict=True):  # fmt: skip
        assert np.max(error) < tolerance, f"{what} off by {np.max(error):.1e}"


def test_the_large_grids_far_rule_uses_blocks():
    hertz = limit_surface._field_kernel(LARGE_GRIDS["Hertz map of 120 x 150 cells"]())
    cells = np.count_nonzero(hertz_values(120, 150) > 0.0)
    assert len(hertz.far.weights) < 9 * cells / 5


def test_the_block_rule_integrates_the_pressure_times_low_degree_polynomials_exactly():
    # 45 x 61 cells in blocks of 2 x 3 (the last block row and column padded), and the same
    # with an empty margin (cut off: blocks of the loaded cells' bounding box): the moments of
    # x^a y^b, a, b < BLOCK_NODES, against the cells' exact integrals.
    rng = np.random.default_rng(5)
    dx, dy = 2e-4, 3e-4
    corner_x, corner_y = dx * np.arange(62) - 0.006, dy * np.arange(46) - 0.007
    values = rng.uniform(0.0, 1.0, (45, 61))
    values[rng.random(values.shape) < 0.3] = 0.0
    values[:, 0] = values[0] = 0.5  # (the box is the whole grid)
    pressure_density = values / (values.sum() * dx * dy)
    margin = np.pad(pressure_density, ((3, 5), (7, 2)))
    wide_x, wide_y = dx * np.arange(-7, 65) - 0.006, dy * np.arange(-3, 51) - 0.007
    scale = 0.01  # [m]: moments of (x / scale)^a (y / scale)^b, of order 1
    cx, cy = corner_x / scale, corner_y / scale
    rules = [block_rule(corner_x, corner_y, pressure_density), block_rule(wide_x, wide_y, margin)]
    np.testing.assert_array_equal(rules[1][0], rules[0][0])  # (the same blocks)
    for points, weights in rules:
        x, y = points[:, 0] / scale, points[:, 1] / scale
        for a in range(BLOCK_NODES):
            for b in range(BLOCK_NODES):
                along_x = (cx[1:] ** (a + 1) - cx[:-1] ** (a + 1)) / (a + 1)
                along_y = (cy[1:] ** (b + 1) - cy[:-1] ** (b + 1)) / (b + 1)
                exact = along_y @ pressure_density @ along_x * scale**2
                assert abs(weights @ (x**a * y**b) - exact) < 1e-14, (a, b)
