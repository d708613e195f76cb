"""Bodies from meshes (mass properties against closed forms) and inertial loads (d'Alembert)."""

import numpy as np
import pytest
import trimesh

from fixplan import Body, Contact, Load, Problem, solve
from fixplan.planner.mesh_body import MeshError, read_mesh, surface_contact
from fixplan.planner.problem import ProblemError, box_inertia

STEEL = 7850.0


def test_a_box_mesh_has_the_mass_centre_and_inertia_of_a_box():
    extents = np.array([0.15, 0.1, 0.03])
    body = Body.from_mesh(trimesh.creation.box(extents=extents), density=STEEL)
    mass = STEEL * extents.prod()
    assert body.mass == pytest.approx(mass, rel=1e-12)
    np.testing.assert_allclose(body.center_of_mass, 0.0, atol=1e-15)
    a, b, c = extents**2
    expected = mass / 12.0 * np.diag([b + c, a + c, a + b])
    np.testing.assert_allclose(body.inertia, expected, rtol=1e-12, atol=1e-15 * mass)
    np.testing.assert_allclose(box_inertia(mass, extents), expected, rtol=1e-15)


def test_a_moved_and_turned_box_carries_its_inertia_along():
    extents = np.array([0.2, 0.05, 0.1])
    angle = 0.7
    turn = trimesh.transformations.rotation_matrix(angle, [1.0, 2.0, 0.5])
    turn[:3, 3] = [0.3, -0.1, 0.25]
    mesh = trimesh.creation.box(extents=extents, transform=turn)
    body = Body.from_mesh(mesh, mass=2.0)
    rotation = turn[:3, :3]
    np.testing.assert_allclose(body.center_of_mass, turn[:3, 3], atol=1e-14)
    expected = rotation @ box_inertia(2.0, extents) @ rotation.T
    np.testing.assert_allclose(body.inertia, expected, rtol=1e-11, atol=1e-15)
    assert body.mass == 2.0


@pytest.mark.parametrize("sections", [6, 16, 64])
def test_a_cylinder_mesh_is_the_regular_prism_it_is_made_of(sections):
    """A trimesh cylinder is a regular ``n``-gon prism: its polar moment of area is
    ``A R² (2 + cos 2π/n) / 6`` (``A R² / 2`` as ``n`` grows)."""
    radius, height = 0.02, 0.05
    mesh = trimesh.creation.cylinder(radius=radius, height=height, sections=sections)
    body = Body.from_mesh(mesh, density=2700.0)
    area = 0.5 * sections * radius**2 * np.sin(2 * np.pi / sections)
    mass = 2700.0 * area * height
    polar = radius**2 * (2.0 + np.cos(2 * np.pi / sections)) / 6.0
    expected = mass * np.diag([polar / 2 + height**2 / 12, polar / 2 + height**2 / 12, polar])
    assert body.mass == pytest.approx(mass, rel=1e-12)
    np.testing.assert_allclose(body.inertia, expected, rtol=1e-11, atol=1e-16)


def test_a_sphere_mesh_tends_to_the_solid_sphere():
    radius = 0.03
    body = Body.from_mesh(trimesh.creation.icosphere(subdivisions=5, radius=radius), mass=1.0)
    # A fine icosphere: isotropic to 1e-6, 2/5 m r² within the 0.1 % its facets cut off.
    moments = np.linalg.eigvalsh(body.inertia)
    assert moments.max() - moments.min() < 1e-6 * moments.max()
    assert moments.mean() == pytest.approx(0.4 * radius**2, rel=1e-3)


def test_a_mesh_file_in_millimetres_reads_with_a_scale(tmp_path):
    path = tmp_path / "part.stl"
    trimesh.creation.box(extents=[150.0, 100.0, 30.0]).export(path)
    body = Body.from_mesh(path, density=STEEL, scale=0.001)
    assert body.mass == pytest.approx(STEEL * 0.15 * 0.1 * 0.03, rel=1e-9)


@pytest.mark.parametrize(
    ("spoil", "message"),
    [
        (lambda m: m.update_faces(np.arange(len(m.faces)) > 0), "not watertight"),
        (lambda m: m.faces.__setitem__(0, m.faces[0][::-1]), "inconsistently wound"),
        (lambda m: m.invert(), "inverted normals"),
    ],
)
def test_a_mesh_that_is_not_a_solid_is_refused_with_the_reason(spoil, message):
    mesh = trimesh.creation.box(extents=[1.0, 2.0, 3.0])
    spoil(mesh)
    with pytest.raises(MeshError, match=message):
        Body.from_mesh(mesh, density=1.0)


def test_a_flat_or_unreadable_mesh_and_a_wrong_mass_are_refused(tmp_path):
    with pytest.raises(MeshError, match="zero volume"):
        read_mesh(trimesh.creation.box(extents=[1.0, 1.0, 0.0]))
    (tmp_path / "bad.stl").write_text("not a mesh")
    with pytest.raises(MeshError, match=r"bad\.stl"):
        read_mesh(tmp_path / "bad.stl")
    (tmp_path / "part.txt").write_text("0 0 0")
    with pytest.raises(MeshError, match=r"part\.txt.*file_type 'txt'.*formats .* \.stl"):
        read_mesh(tmp_path / "part.txt")
    box = trimesh.creation.box(extents=[1.0, 1.0, 1.0])
    with pytest.raises(MeshError, match="exactly one of density"):
        Body.from_mesh(box, density=1.0, mass=1.0)
    with pytest.raises(MeshError, match="density must be"):
        Body.from_mesh(box, density=-1.0)


def test_a_contact_on_the_surface_is_the_closest_point_with_the_inward_normal():
    mesh = trimesh.creation.box(extents=[0.2, 0.1, 0.04])
    point, normal, distance = surface_contact(mesh, [0.03, 0.06, 0.01])
    np.testing.assert_allclose(point, [0.03, 0.05, 0.01], atol=1e-15)
    np.testing.assert_allclose(normal, [0.0, -1.0, 0.0], atol=1e-15)
    assert distance == pytest.approx(0.01, abs=1e-15)


def test_inertia_by_hand_is_validated():
    with pytest.raises(ProblemError, match="symmetric"):
        Body(mass=1.0, center_of_mass=[0, 0, 0], inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(ProblemError, match="not the inertia of a body"):
        Body(mass=1.0, center_of_mass=[0, 0, 0], inertia=np.diag([1.0, 1.0, 3.0]))
    body = Body(mass=6.0, center_of_mass=[0, 0, 0], size=[1.0, 2.0, 3.0])
    np.testing.assert_allclose(np.diag(body.inertia), [6.5, 5.0, 2.5])


def test_the_dalembert_wrench_of_a_moving_body_by_hand():
    inertia = np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 4.0]])
    body = Body(mass=1.5, center_of_mass=[0.1, -0.2, 0.3], inertia=inertia)
    load = Load(name="swing", acceleration=[1.0, 2.0, -3.0], angular_velocity=[0.5, -1.0, 2.0],
                angular_acceleration=[3.0, 0.0, -1.0])  # fmt: skip
    # Written out component by component, independently of numpy's cross product.
    f = [-1.5, -3.0, 4.5]
    c = [0.1, -0.2, 0.3]
    c_cross_f = [c[1] * f[2] - c[2] * f[1], c[2] * f[0] - c[0] * f[2], c[0] * f[1] - c[1] * f[0]]
    w = [0.5, -1.0, 2.0]
    iw = [2.0 * 0.5 + 0.1 * -1.0, 0.1 * 0.5 + 3.0 * -1.0 + 0.2 * 2.0, 0.2 * -1.0 + 4.0 * 2.0]
    w_cross_iw = [w[1] * iw[2] - w[2] * iw[1], w[2] * iw[0] - w[0] * iw[2],
                  w[0] * iw[1] - w[1] * iw[0]]  # fmt: skip
    ia = [2.0 * 3.0, 0.1 * 3.0 + 0.2 * -1.0, 4.0 * -1.0]
    moment = [c_cross_f[k] - ia[k] - w_cross_iw[k] for k in range(3)]
    np.testing.assert_allclose(body.inertial_wrench(load), f + moment, rtol=1e-15, atol=1e-15)


def _pinch(load: Load, mass: float, mu: float) -> Problem:
    fingers = [
        Contact(name=name, role="finger", position=[0, s * 0.05, 0], normal=[0, -s, 0], mu=mu,
                model="point-cone")
        for name, s in (("left", -1), ("right", 1))
    ]  # fmt: skip
    body = Body(mass=mass, center_of_mass=[0, 0, 0], size=[0.1, 0.1, 0.1])
    return Problem(body=body, contacts=fingers, loads=[load], objective="min-max-normal-force")


@pytest.mark.parametrize("lift", [0.0, 2.5, 9.0])
def test_a_box_lifted_with_acceleration_needs_m_g_plus_a_over_two_mu_per_finger(lift):
    mass, mu = 1.2, 0.4
    plan = solve(_pinch(Load(name="lift", acceleration=[0, 0, lift]), mass, mu))
    assert plan.status == "optimal"
    expected = mass * (9.81 + lift) / (2 * mu)
    np.testing.assert_allclose(plan.forces["left"], expected, rtol=1e-7)
    np.testing.assert_allclose(plan.forces["right"], expected, rtol=1e-7)


def test_a_turning_load_needs_the_bodys_inertia():
    body = Body(mass=1.0, center_of_mass=[0, 0, 0])
    contact = Contact(name="c", role="finger", position=[0, 0, 0], normal=[0, 0, 1], mu=0.5,
                      model="point-cone")  # fmt: skip
    with pytest.raises(ProblemError, match="needs an inertia tensor"):
        Problem(body=body, contacts=[contact], loads=[Load(name="spin", angular_velocity=[0, 0, 1])],
                objective="min-max-normal-force")  # fmt: skip
