r"""Drake's hydroelastic contact as an independent check of the exact limit surface.

A compliant hydroelastic sphere (the fingertip) is pressed with a normal force onto a rigid plate.
Drake integrates Coulomb friction over the pressure field of the contact patch, one point per
polygon of the contact surface (at its centroid, carrying area times pressure): fixplan reads
that field from the engine (:func:`fixplan.surface.pressure.points`) and builds its exact limit
surface. A load ramped along a direction ``(fx, fy, m)`` (force along the plate and moment about
its normal, applied to the fingertip) must start the fingertip sliding where the ray meets that
surface; the Table 2 ellipsoid of the same field predicts a different load, which shows its error.

The fingertip slides and spins on the plate but neither tilts nor rolls (joints: height, then
planar ``x, y, θ``); gravity is off. Drake's ``lagged`` discrete contact approximation bounds each
point's friction by its normal force of the previous step, so a fingertip at rest obeys Coulomb's
law point by point. SAP (Drake's default) adds normal force where points slide fast ("gliding"
of its convex relaxation), which raises the friction moment during spin above that law.

A hydroelastic sphere's pressure at the plane is :math:`p = E\,(R - \sqrt{(R-\delta)^2+r^2})/R`,
close to the paraboloid :math:`E\,(\delta - r^2/2R)/R`, not Hertzian: the field is compared with
the least-squares paraboloid and Hertz profile.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models import Ellipsoid
from fixplan.surface import pressure
from fixplan.surface.limit_surface import LimitSurface

#: Discrete time step [s], fingertip mass [kg] and mass of the carriage of its height joint [kg].
TIME_STEP = 1e-3
TIP_MASS, CARRIAGE_MASS = 0.05, 0.01
#: Friction regularisation of the ``lagged`` approximation [m/s]: creep below slip is ~10x this.
STICTION_TOLERANCE = 1e-6
#: Hunt-Crossley dissipation of the fingertip [s/m].
DISSIPATION = 5.0
#: Seconds simulated with the normal force alone before the field is read.
SETTLE = 0.1
#: The fingertip slides once a point of its patch moves faster than this [m/s].
SLIP_SPEED = 1e-4
#: The ramp of the load over the exact limit surface's load: start, rate [1/s] and end multiple.
RAMP_START, RAMP_RATE, RAMP_END = 0.95, 0.5, 1.2
#: Steps on the penetration that makes the field's resultant the normal force, and their
#: relative tolerance on that resultant.
PRESS_STEPS, PRESS_RTOL = 30, 1e-9


def hydroelastic_plant(builder):
    """A multibody plant and scene graph in ``builder`` (a Drake ``DiagramBuilder``) with
    the contact of these checks: hydroelastic polygons, ``TIME_STEP``, the ``lagged``
    approximation and ``STICTION_TOLERANCE``."""
    from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig

    config = MultibodyPlantConfig(
        time_step=TIME_STEP,
        contact_model="hydroelastic",
        contact_surface_representation="polygon",
        discrete_contact_approximation="lagged",
        stiction_tolerance=STICTION_TOLERANCE,
    )
    return AddMultibodyPlant(config, builder)


@dataclass(frozen=True, slots=True, kw_only=True)
class DirectionResult:
    """Slip onset along one load direction.

    Attributes
    ----------
    direction : numpy.ndarray
        The load direction ``(fx, fy, m)`` as given [N, N, N m].
    exact_load : numpy.ndarray
        Where the direction meets the exact limit surface of the engine's field [N, N, N m].
    onset : float or None
        Drake's load at slip onset over ``exact_load`` [-]; ``None`` if the fingertip held up to
        ``RAMP_END``.
    ellipsoid : float
        The ellipsoid's limit along the direction over ``exact_load`` [-].
    """

    direction: np.ndarray
    exact_load: np.ndarray
    onset: float | None
    ellipsoid: float

    @property
    def ellipsoid_error(self) -> float:
        """The ellipsoid's limit against Drake's onset, relative [-] (NaN if it never slid)."""
        return np.nan if self.onset is None else self.ellipsoid / self.onset - 1.0


@dataclass(frozen=True, slots=True, kw_only=True)
class HydroelasticCheck:
    """The engine's pressure field, its exact limit surface and the slip onsets.

    Attributes
    ----------
    field : PointsField
        The engine's field at rest: polygon centroids, relative to the fingertip's axis [m],
        weighted by area times pressure.
    limit_surface : LimitSurface
        Exact limit surface of ``field`` at the friction and normal force of the scene.
    resultant : float
        Integral of the engine's pressure over the patch [N] (the normal force at rest).
    penetration : float
        Depth of the fingertip's undeformed sphere below the plate [m].
    radii : numpy.ndarray
        Distance of each polygon centroid from the fingertip's axis [m].
    pressures : numpy.ndarray
        The engine's pressure at each polygon centroid [Pa].
    parabolic_radius : float
        Patch radius of the least-squares paraboloid ``p0 (1 - r²/a²)`` [m].
    parabolic_deviation, hertz_deviation : float
        Largest deviation of the field from the least-squares paraboloid and Hertz profile
        ``p0 sqrt(1 - r²/a²)``, over the peak pressure [-].
    directions : tuple of DirectionResult
        Slip onset per load direction.
    """

    field: pressure.PointsField
    limit_surface: LimitSurface
    resultant: float
    penetration: float
    radii: np.ndarray
    pressures: np.ndarray
    parabolic_radius: float
    parabolic_deviation: float
    hertz_deviation: float
    directions: tuple[DirectionResult, ...]


def hydroelastic_check(
    *,
    radius: float,
    modulus: float,
    mu: float,
    normal_force: float,
    directions: Sequence[Sequence[float]],
    resolution: float | None = None,
) -> HydroelasticCheck:
    """Press a compliant sphere on a plate in Drake and ramp loads until it slides.

    Parameters
    ----------
    radius : float
        Fingertip sphere radius ``R`` [m].
    modulus : float
        Hydroelastic modulus ``E`` [Pa] of the fingertip.
    mu : float
        Coulomb friction of fingertip and plate, static and dynamic [-].
    normal_force : float
        Force pressing the fingertip on the plate [N].
    directions : sequence of (fx, fy, m)
        Load directions [N, N, N m], forces along the plate and moment about its normal on the
        fingertip's axis; only the direction counts.
    resolution : float, optional
        Resolution hint of the fingertip's tetrahedral mesh [m]; default ``R / 8``.
    """
    radius = validation.positive_scalar("radius", radius)
    modulus = validation.positive_scalar("modulus", modulus)
    mu = validation.positive_scalar("mu", mu)
    normal_force = validation.positive_scalar("normal_force", normal_force)
    loads = validation.finite_array("directions", directions, shape=(None, 3))
    if np.any(np.linalg.norm(loads, axis=1) == 0.0):
        raise InvalidArgumentError("directions must be nonzero load directions (fx, fy, m)")
    hint = (
        radius / 8.0 if resolution is None else validation.positive_scalar("resolution", resolution)
    )
    scene = _Scene(radius, modulus, mu, hint)
    scene.press(normal_force)
    at_rest = scene.context.Clone()
    xy, areas, pressures = scene.patch()
    force = areas * pressures
    field = pressure.points(xy, pressure.measurable(force), centered=False)
    surface = LimitSurface(field, mu=mu, normal_force=normal_force)
    ellipsoid = Ellipsoid.from_limit_surface(surface)
    results = []
    for direction in loads:
        exact_load = direction * surface.safety_factor(direction)
        scene.context.SetTimeStateAndParametersFrom(at_rest)
        results.append(
            DirectionResult(
                direction=direction,
                exact_load=exact_load,
                onset=scene.ramp(exact_load, xy),
                ellipsoid=float(ellipsoid.safety_factor(exact_load)),
            )
        )
    radii = np.hypot(xy[:, 0], xy[:, 1])
    parabola, parabolic_deviation = _profile_fit(radii, pressures, power=1)
    _, hertz_deviation = _profile_fit(radii, pressures, power=2)
    return HydroelasticCheck(
        field=field,
        limit_surface=surface,
        resultant=float(force.sum()),
        penetration=scene.penetration,
        radii=radii,
        pressures=pressures,
        parabolic_radius=parabola,
        parabolic_deviation=parabolic_deviation,
        hertz_deviation=hertz_deviation,
        directions=tuple(results),
    )


def _profile_fit(radii: np.ndarray, pressures: np.ndarray, *, power: int) -> tuple[float, float]:
    """Least-squares fit of ``p**power = c0 + c1 r²``: the patch radius [m] and the largest
    deviation over the peak pressure [-] (power 1: paraboloid, 2: Hertz)."""
    basis = np.column_stack([np.ones_like(radii), radii**2])
    (c0, c1), *_ = np.linalg.lstsq(basis, pressures**power, rcond=None)
    fitted = np.clip(c0 + c1 * radii**2, 0.0, None) ** (1.0 / power)
    return float(np.sqrt(-c0 / c1)), float(np.max(np.abs(fitted - pressures)) / pressures.max())


class _Scene:
    """The fingertip on its joints over the plate, in a Drake diagram with a simulator."""

    def __init__(self, radius: float, modulus: float, mu: float, resolution: float):
        from pydrake.geometry import (
            AddCompliantHydroelasticProperties,
            AddContactMaterial,
            AddRigidHydroelasticProperties,
            Box,
            ProximityProperties,
            Sphere,
        )
        from pydrake.math import RigidTransform
        from pydrake.multibody.plant import CoulombFriction
        from pydrake.multibody.tree import PlanarJoint, PrismaticJoint, SpatialInertia
        from pydrake.systems.analysis import Simulator
        from pydrake.systems.framework import DiagramBuilder

        builder = DiagramBuilder()
        plant, scene_graph = hydroelastic_plant(builder)
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
        friction = CoulombFriction(mu, mu)
        plate = ProximityProperties()
        AddRigidHydroelasticProperties(10.0 * radius, plate)
        AddContactMaterial(friction=friction, properties=plate)
        thickness = radius
        plant.RegisterCollisionGeometry(
            plant.world_body(),
            RigidTransform([0.0, 0.0, -thickness / 2.0]),
            Box(20.0 * radius, 20.0 * radius, thickness),
            "plate",
            plate,
        )
        tip_properties = ProximityProperties()
        AddCompliantHydroelasticProperties(resolution, modulus, tip_properties)
        AddContactMaterial(dissipation=DISSIPATION, friction=friction, properties=tip_properties)
        carriage = plant.AddRigidBody(
            "carriage", SpatialInertia.SolidSphereWithMass(CARRIAGE_MASS, radius)
        )
        tip = plant.AddRigidBody("tip", SpatialInertia.SolidSphereWithMass(TIP_MASS, radius))
        plant.RegisterCollisionGeometry(
            tip, RigidTransform(), Sphere(radius), "tip", tip_properties
        )
        self.height = plant.AddJoint(
            PrismaticJoint("height", plant.world_frame(), carriage.body_frame(), [0.0, 0.0, 1.0])
        )
        self.planar = plant.AddJoint(PlanarJoint("planar", carriage.body_frame(), tip.body_frame()))
        plant.Finalize()
        self.diagram = builder.Build()
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant, self.scene_graph, self.radius = plant, scene_graph, radius
        self.modulus, self.normal_force = modulus, 0.0

    @property
    def plant_context(self):
        return self.plant.GetMyMutableContextFromRoot(self.context)

    @property
    def penetration(self) -> float:
        return self.radius - self.height.get_translation(self.plant_context)

    def press(self, normal_force: float) -> None:
        """Put the fingertip where its field carries ``normal_force`` [N], then settle."""
        self.normal_force = normal_force
        depth = np.sqrt(normal_force / (np.pi * self.modulus))  # paraboloid: N = π E δ²
        for _ in range(PRESS_STEPS):
            self.height.set_translation(self.plant_context, self.radius - depth)
            resultant = self._geometric_resultant()
            if resultant == 0.0:
                raise InvalidArgumentError(
                    f"the fingertip's mesh makes no contact at {depth!r} m: give a finer "
                    "resolution or a larger normal_force"
                )
            depth *= np.sqrt(normal_force / resultant)
            if abs(resultant / normal_force - 1.0) < PRESS_RTOL:
                break
        self.height.set_translation(self.plant_context, self.radius - depth)
        self._apply(np.zeros(3))
        self.simulator.Initialize()
        self.simulator.AdvanceTo(self.context.get_time() + SETTLE)

    def _geometric_resultant(self) -> float:
        """The pressure field's integral at the current pose [N], from the geometry alone."""
        from pydrake.geometry import HydroelasticContactRepresentation

        query = self.scene_graph.get_query_output_port().Eval(
            self.scene_graph.GetMyContextFromRoot(self.context)
        )
        surfaces = query.ComputeContactSurfaces(HydroelasticContactRepresentation.kPolygon)
        return sum(
            float(np.prod(surface_polygons(surface)[1:], axis=0).sum()) for surface in surfaces
        )

    def patch(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Polygon centroids relative to the fingertip's axis [m], their areas [m²] and the
        pressure there [Pa], from the engine's contact results."""
        results = self.plant.get_contact_results_output_port().Eval(self.plant_context)
        if results.num_hydroelastic_contacts() != 1:
            raise InvalidArgumentError(
                f"expected one hydroelastic contact, got {results.num_hydroelastic_contacts()}: "
                "raise normal_force or lower modulus"
            )
        surface = results.hydroelastic_contact_info(0).contact_surface()
        centroids, areas, pressures = surface_polygons(surface)
        start = self.planar.position_start()
        axis = self.plant.GetPositions(self.plant_context)[start : start + 2]
        return centroids[:, :2] - axis, areas, pressures

    def _apply(self, load: np.ndarray) -> None:
        """Press with the normal force and apply ``load`` ``(fx, fy, m)`` [N, N, N m]."""
        tau = np.zeros(self.plant.num_velocities())
        tau[self.height.velocity_start()] = -self.normal_force
        start = self.planar.velocity_start()
        tau[start : start + 3] = load
        port = self.plant.get_applied_generalized_force_input_port()
        port.FixValue(self.plant_context, tau)

    def ramp(self, load: np.ndarray, xy: np.ndarray) -> float | None:
        """The multiple of ``load`` at which a point of the patch ``xy`` [m] (about the axis)
        first slides faster than ``SLIP_SPEED``; ``None`` if none does by ``RAMP_END``."""
        self.simulator.Initialize()
        multiple = RAMP_START
        while multiple <= RAMP_END:
            self._apply(multiple * load)
            self.simulator.AdvanceTo(self.context.get_time() + TIME_STEP)
            v = self.plant.GetVelocities(self.plant_context)
            vx, vy, w = v[self.planar.velocity_start() : self.planar.velocity_start() + 3]
            if np.max(np.hypot(vx - w * xy[:, 1], vy + w * xy[:, 0])) > SLIP_SPEED:
                return multiple
            multiple += RAMP_RATE * TIME_STEP
        return None


def surface_polygons(surface) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centroids [m], areas [m²] and the pressure at the centroids [Pa] of the polygons of a
    Drake contact surface."""
    mesh, field = surface.poly_mesh_W(), surface.poly_e_MN()
    n = mesh.num_elements()
    centroids = np.array([mesh.element_centroid(i) for i in range(n)])
    areas = np.array([mesh.area(i) for i in range(n)])
    pressures = np.array([field.EvaluateCartesian(i, centroids[i]) for i in range(n)])
    return centroids, areas, pressures
