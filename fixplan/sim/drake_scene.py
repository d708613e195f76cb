r"""A planning problem, a plan's forces and a ramped task load as a Drake hydroelastic scene.

- The part is a free body with the problem's mass, centre of mass and inertia (a massless part
  gets ``MASSLESS`` kg and no gravity, as in the MuJoCo scene); its body frame sits at the centre
  of mass with the world's axes at the start.
- Each contact is a rigid hydroelastic pad fixed to the part (a box whose outer face holds the
  contact point, normal along the contact normal) pressed by a compliant hydroelastic sphere:
  fixed to the world for locators and supports, on a prismatic joint along the normal for clamps
  and fingers, pushed by a constant generalised force (the normal force, with the sphere's
  weight along the joint compensated). Each sphere touches only its own pad; friction is the contact's ``mu``.
- The sphere of an area contact is sized so that its patch under the normal force ``N`` the plan
  gives it is the contact's patch (:func:`fingertip`); a point contact gets a small stiff sphere
  of patch radius ``POINT_PATCH`` [m]. Spheres start at the depth that carries ``N``.
- The task wrench of the load case is applied at the centre of mass, ramped ``k(t) W`` from a
  starting multiple; gravity acts throughout.

Drake's ``lagged`` discrete approximation (as in :mod:`fixplan.sim.drake_check`) bounds each
point's friction by its normal force of the previous step, so a patch at rest obeys Coulomb's
law point by point and its friction follows the exact limit surface of the engine's field.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError, MissingExtraError
from fixplan.planner.problem import Contact, Problem

# The fingertip check's time step [s], friction regularisation [m/s] and dissipation [s/m].
from fixplan.sim.drake_check import DISSIPATION, TIME_STEP, hydroelastic_plant
from fixplan.surface import pressure

#: Sphere radius over the radius of the patch it makes [-], and the sphere's mesh resolution
#: hint over its radius [-].
SPHERE_OVER_PATCH, RESOLUTION = 3.0, 1.0 / 8.0
#: Patch radius [m] of the small stiff sphere of a point contact.
POINT_PATCH = 5e-4
#: Half side of a pad over the sphere's patch radius [-] (the pad's thickness is its half side).
PAD_OVER_PATCH = 3.0
#: Mass [kg] of a clamp's or finger's sphere.
TIP_MASS = 0.05
#: Mass [kg] given to a massless part; gravity is then off.
MASSLESS = 1e-3
#: A contact whose planned normal force is below this fraction of the case's largest one gets a
#: sphere sized for that fraction (an unloaded locator still needs a finite modulus) [-].
FORCE_FLOOR = 0.1


@dataclass(frozen=True, slots=True, kw_only=True)
class Fingertip:
    r"""The compliant sphere of a contact.

    Drake's pressure in a hydroelastic sphere of radius ``R`` and modulus ``E`` grows linearly
    with depth below its surface; pressed ``δ`` into a flat, the patch has radius
    ``a = sqrt(R² - d²)`` (``d = R - δ``) and carries

    .. math:: N = \frac{2 \pi E}{R} \left( \frac{R a^2}{2} - \frac{R^3 - d^3}{3} \right),

    nearly the paraboloid ``p = E (δ - r²/2R) / R`` with ``N = π E δ²``.

    Attributes
    ----------
    radius, modulus : float
        ``R`` [m] and ``E`` [Pa].
    depth : float
        ``δ`` at the design normal force [m].
    patch_radius : float
        ``a`` at the design normal force [m] (the mesh trims a little of its rim).
    """

    radius: float
    modulus: float
    depth: float
    patch_radius: float


@dataclass(frozen=True, slots=True, kw_only=True)
class EnginePatch:
    """One contact's surface in the engine.

    Attributes
    ----------
    xy : numpy.ndarray
        ``(n, 2)``: polygon centroids in the contact's patch coordinates, about the contact point
        along its ``t1, t2`` [m].
    pressures, areas : numpy.ndarray
        The pressure at each centroid [Pa] and the polygon's area [m²].
    wrench : numpy.ndarray
        ``(fn, ft1, ft2, mn)``: the force of the sphere on the part in the contact frame [N] and
        its moment about the contact normal through the contact point [N m].
    """

    xy: np.ndarray
    pressures: np.ndarray
    areas: np.ndarray
    wrench: np.ndarray


def fingertip(patch_radius: float, normal_force: float) -> Fingertip:
    """The sphere of radius ``SPHERE_OVER_PATCH * patch_radius`` whose patch under
    ``normal_force`` [N] has radius ``patch_radius`` [m]."""
    patch_radius = validation.positive_scalar("patch_radius", patch_radius)
    normal_force = validation.positive_scalar("normal_force", normal_force)
    radius = SPHERE_OVER_PATCH * patch_radius
    d = np.sqrt(radius**2 - patch_radius**2)
    per_modulus = 2.0 * np.pi / radius * (radius * patch_radius**2 / 2.0 - (radius**3 - d**3) / 3.0)
    return Fingertip(
        radius=float(radius),
        modulus=float(normal_force / per_modulus),
        depth=float(radius - d),
        patch_radius=float(patch_radius),
    )


def patch_size(contact: Contact) -> float:
    """The radius [m] of the round patch a sphere gives ``contact``: a disk patch's radius (the
    outer one of an annulus or ring), the radius of the disk of the same area for a polygon or
    a tactile grid, ``POINT_PATCH`` for a point contact.

    Raises :class:`~fixplan.errors.InvalidArgumentError` for discrete point supports, which no
    sphere makes.
    """
    patch = contact.patch
    if patch is None or not contact.has_torsion:
        return POINT_PATCH
    if isinstance(patch, pressure.FunctionField):
        patch = patch.shape
    if isinstance(patch, pressure.DiskField):
        return patch.radius
    if isinstance(patch, pressure.PolygonField):
        return float(np.sqrt(patch.area / np.pi))
    if isinstance(patch, pressure.GridField):
        dx, dy = patch.cell_size
        return float(np.sqrt(np.count_nonzero(patch.values > 0.0) * dx * dy / np.pi))
    raise InvalidArgumentError(
        f"contact {contact.name!r}: Drake models an area contact as a compliant sphere, whose "
        f"patch is round; a {type(patch).__name__} (discrete point supports) has no area to "
        "match; validate it with --engine mujoco"
    )


def require_drake() -> None:
    """Raise :class:`~fixplan.errors.MissingExtraError` unless Drake can be imported."""
    try:
        import pydrake.multibody.plant  # noqa: F401
    except ImportError as exc:
        raise MissingExtraError(
            f"the Drake engine needs the drake extra, which is not installed ({exc}): "
            "pip install 'fixplan[drake]' (about 400 MB), or use --engine mujoco"
        ) from exc


class DrakeScene:
    """The part, its pads and the spheres on their joints, in a Drake diagram with a simulator.

    Parameters
    ----------
    problem : Problem
        The part and its contacts.
    design_forces : numpy.ndarray
        Per contact, the normal force [N] its sphere is sized for and starts at.
    """

    def __init__(self, problem: Problem, design_forces: np.ndarray):
        from pydrake.geometry import CollisionFilterDeclaration, GeometrySet
        from pydrake.multibody.tree import RotationalInertia, SpatialInertia
        from pydrake.systems.analysis import Simulator
        from pydrake.systems.framework import DiagramBuilder

        design_forces = validation.finite_array(
            "design_forces", design_forces, shape=(len(problem.contacts),)
        )
        if np.any(design_forces <= 0.0):
            raise InvalidArgumentError(
                f"design_forces must be positive normal forces [N], got {design_forces.tolist()}"
            )
        builder = DiagramBuilder()
        plant, scene_graph = hydroelastic_plant(builder)
        body = problem.body
        massive = body.mass > 0.0
        plant.mutable_gravity_field().set_gravity_vector(body.gravity if massive else np.zeros(3))
        self.center = np.asarray(body.center_of_mass, dtype=float)
        mass = body.mass if massive else MASSLESS
        inertia = _inertia(problem, mass)
        part = plant.AddRigidBody(
            "part",
            SpatialInertia.MakeFromCentralInertia(
                mass,
                np.zeros(3),
                RotationalInertia(inertia[0, 0], inertia[1, 1], inertia[2, 2],
                                  inertia[0, 1], inertia[0, 2], inertia[1, 2]),
            ),
        )  # fmt: skip
        self.tips = [
            fingertip(patch_size(c), float(f))
            for c, f in zip(problem.contacts, design_forces, strict=True)
        ]
        pads, spheres, self.joints, self.tip_bodies = [], [], [], []
        for contact, tip in zip(problem.contacts, self.tips, strict=True):
            pad, sphere, joint, holder = _add_contact(plant, part, contact, tip, self.center)
            pads.append(pad)
            spheres.append(sphere)
            self.joints.append(joint)
            self.tip_bodies.append(holder)
        plant.Finalize()
        declaration = CollisionFilterDeclaration().ExcludeWithin(GeometrySet(spheres))
        for index, sphere in enumerate(spheres):
            others = [pad for other, pad in enumerate(pads) if other != index]
            if others:
                declaration.ExcludeBetween(GeometrySet(sphere), GeometrySet(others))
        scene_graph.collision_filter_manager().Apply(declaration)
        self.diagram = builder.Build()
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant, self.part, self.problem = plant, part, problem
        self.spheres = spheres
        self.radii = np.array(
            [patch_size(c) if c.patch is not None and c.has_torsion else 0.0
             for c in problem.contacts]
        )  # fmt: skip
        self.rails = [
            contact.position - (tip.radius - tip.depth) * contact.normal
            for contact, tip in zip(problem.contacts, self.tips, strict=True)
        ]
        self.task = np.zeros(6)

    @property
    def plant_context(self):
        return self.plant.GetMyMutableContextFromRoot(self.context)

    def start(self, forces: np.ndarray, task: np.ndarray, multiple: float) -> None:
        """Back to the design pose at rest at time 0, the active contacts pushed with ``forces``
        [N] (per contact; passive ones ignored) and the task wrench ``task`` (force [N], moment
        about the centre of mass [N m], world frame) applied at ``multiple``."""
        from pydrake.math import RigidTransform

        context = self.plant_context
        self.context.SetTime(0.0)
        self.plant.SetFreeBodyPose(context, self.part, RigidTransform(self.center))
        self.plant.SetVelocities(context, np.zeros(self.plant.num_velocities()))
        tau = np.zeros(self.plant.num_velocities())
        gravity = self.plant.gravity_field().gravity_vector()
        for contact, joint, force in zip(self.problem.contacts, self.joints, forces, strict=True):
            if joint is not None:
                joint.set_translation(context, 0.0)
                tau[joint.velocity_start()] = force - TIP_MASS * float(gravity @ contact.normal)
        self.plant.get_applied_generalized_force_input_port().FixValue(context, tau)
        self.task = np.asarray(task, dtype=float)
        self.load(multiple)
        self.simulator.Initialize()

    def load(self, multiple: float) -> None:
        """Apply ``multiple`` times the task wrench to the part, at its centre of mass."""
        from pydrake.multibody.math import SpatialForce
        from pydrake.multibody.plant import ExternallyAppliedSpatialForce

        applied = ExternallyAppliedSpatialForce()
        applied.body_index = self.part.index()
        applied.p_BoBq_B = np.zeros(3)
        applied.F_Bq_W = SpatialForce(multiple * self.task[3:], multiple * self.task[:3])
        port = self.plant.get_applied_spatial_force_input_port()
        port.FixValue(self.plant_context, [applied])

    def step(self) -> float:
        """Advance one time step; returns the time [s]."""
        self.simulator.AdvanceTo(self.context.get_time() + TIME_STEP)
        return self.context.get_time()

    def slips(self) -> np.ndarray:
        """``(contacts, 4)``: each contact's tangential offset of its sphere's centre from the
        contact point on the part, in the part's frame [m], and its turn about its normal times
        its patch radius [m] (0 for point contacts, which may spin)."""
        context = self.plant_context
        pose = self.plant.EvalBodyPoseInWorld(context, self.part)
        rotation = pose.rotation().matrix()
        turn = _rotation_vector(rotation)
        rows = []
        for contact, joint, holder, rail, radius in zip(
            self.problem.contacts, self.joints, self.tip_bodies, self.rails, self.radii,
            strict=True,
        ):  # fmt: skip
            if joint is None:
                centre = rail
            else:
                centre = self.plant.EvalBodyPoseInWorld(context, holder).translation()
            point = pose.multiply(contact.position - self.center)
            relative = rotation.T @ (centre - point)
            tangential = relative - (relative @ contact.normal) * contact.normal
            rows.append([*tangential, float(turn @ contact.normal) * radius])
        return np.array(rows)

    def rotation(self) -> float:
        """Angle [rad] the part turned since the start."""
        pose = self.plant.EvalBodyPoseInWorld(self.plant_context, self.part)
        return float(np.linalg.norm(_rotation_vector(pose.rotation().matrix())))

    def twist(self) -> np.ndarray:
        """The part's twist: velocity of the body point at the world origin [m/s] and angular
        velocity [rad/s], world frame."""
        context = self.plant_context
        velocity = self.plant.EvalBodySpatialVelocityInWorld(context, self.part)
        origin = self.plant.EvalBodyPoseInWorld(context, self.part).translation()
        omega = velocity.rotational()
        return np.r_[velocity.translational() - np.cross(omega, origin), omega]

    def patches(self) -> list[EnginePatch | None]:
        """Per contact, the engine's contact surface and contact wrench (:class:`EnginePatch`);
        ``None`` where the contact is open."""
        from fixplan.sim.drake_check import surface_polygons

        context = self.plant_context
        results = self.plant.get_contact_results_output_port().Eval(context)
        pose = self.plant.EvalBodyPoseInWorld(context, self.part)
        inverse, rotation = pose.inverse(), pose.rotation().matrix()
        found = [None] * len(self.spheres)
        for index in range(results.num_hydroelastic_contacts()):
            info = results.hydroelastic_contact_info(index)
            surface = info.contact_surface()
            ids = (surface.id_M(), surface.id_N())
            contact_index = next(i for i, sphere in enumerate(self.spheres) if sphere in ids)
            contact = self.problem.contacts[contact_index]
            centroids, areas, pressures = surface_polygons(surface)
            in_part = np.array([inverse.multiply(c) for c in centroids]) + self.center
            frame = contact.frame @ rotation.T  # t1, t2, n in the world
            # F_Ac_W acts on the body of geometry M: the part when M is the pad.
            sign = -1.0 if surface.id_M() == self.spheres[contact_index] else 1.0
            spatial = info.F_Ac_W()
            force, moment = sign * spatial.translational(), sign * spatial.rotational()
            point = pose.multiply(contact.position - self.center)
            moment = moment + np.cross(surface.centroid() - point, force)
            t1, t2, n = frame
            found[contact_index] = EnginePatch(
                xy=(in_part - contact.position) @ contact.frame[:2].T,
                pressures=pressures,
                areas=areas,
                wrench=np.array([force @ n, force @ t1, force @ t2, moment @ n]),
            )
        return found


def _add_contact(plant, part, contact: Contact, tip: Fingertip, center: np.ndarray) -> tuple:
    """Register ``contact``'s rigid pad on ``part`` and its compliant sphere, fixed in the
    world or on a prismatic joint along the normal; returns the pad's and the sphere's geometry
    ids, the joint (``None`` when fixed) and the body holding the sphere."""
    from pydrake.geometry import (
        AddCompliantHydroelasticProperties,
        AddContactMaterial,
        AddRigidHydroelasticProperties,
        Box,
        ProximityProperties,
        Sphere,
    )
    from pydrake.math import RigidTransform, RotationMatrix
    from pydrake.multibody.plant import CoulombFriction
    from pydrake.multibody.tree import FixedOffsetFrame, PrismaticJoint, SpatialInertia

    friction = CoulombFriction(contact.mu, contact.mu)
    half = PAD_OVER_PATCH * tip.patch_radius
    rigid = ProximityProperties()
    AddRigidHydroelasticProperties(2.0 * half, rigid)
    AddContactMaterial(friction=friction, properties=rigid)
    facing = RotationMatrix.MakeFromOneVector(contact.normal, 2)
    middle = contact.position + 0.5 * half * contact.normal - center
    pad = plant.RegisterCollisionGeometry(part, RigidTransform(facing, middle),
                                          Box(2.0 * half, 2.0 * half, half),
                                          f"pad-{contact.name}", rigid)  # fmt: skip
    soft = ProximityProperties()
    AddCompliantHydroelasticProperties(RESOLUTION * tip.radius, tip.modulus, soft)
    AddContactMaterial(dissipation=DISSIPATION, friction=friction, properties=soft)
    place = contact.position - (tip.radius - tip.depth) * contact.normal
    joint = None
    if contact.is_active:
        holder = plant.AddRigidBody(
            f"tip-{contact.name}", SpatialInertia.SolidSphereWithMass(TIP_MASS, tip.radius)
        )
        rail = plant.AddFrame(
            FixedOffsetFrame(f"rail-{contact.name}", plant.world_frame(), RigidTransform(place))
        )
        joint = plant.AddJoint(
            PrismaticJoint(f"push-{contact.name}", rail, holder.body_frame(), contact.normal)
        )
        pose = RigidTransform()
    else:
        holder, pose = plant.world_body(), RigidTransform(place)
    sphere = plant.RegisterCollisionGeometry(holder, pose, Sphere(tip.radius),
                                             f"tip-{contact.name}", soft)  # fmt: skip
    return pad, sphere, joint, holder


def _rotation_vector(rotation: np.ndarray) -> np.ndarray:
    """The rotation vector [rad] of a rotation matrix (angle times unit axis)."""
    from pydrake.common.eigen_geometry import AngleAxis

    turn = AngleAxis(rotation)
    return turn.angle() * turn.axis()


def _inertia(problem: Problem, mass: float) -> np.ndarray:
    """The part's inertia about its centre of mass [kg m²] (a sphere's reaching the farthest
    contact where none is given, as in the MuJoCo scene)."""
    body = problem.body
    if body.inertia is not None and body.mass > 0.0:
        return np.asarray(body.inertia, dtype=float)
    spread = max(
        max(float(np.linalg.norm(c.position - body.center_of_mass)) for c in problem.contacts),
        POINT_PATCH,
    )
    return 0.4 * mass * spread**2 * np.eye(3)
