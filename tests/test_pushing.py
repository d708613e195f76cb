"""Quasi-static pushing steps against closed forms, an independent minimum-dissipation SOCP and
the laws of pushing (Mason's voting theorem, straight pushes through the centre of pressure)."""

import math

import cvxpy as cp
import numpy as np
import pytest

from fixplan import LimitSurface, pressure
from fixplan.errors import InvalidArgumentError, ModelError
from fixplan.models import Ellipsoid, Exact, FittedEllipsoid
from fixplan.motion import FittedQuartic, motion_cone, push_step
from fixplan.motion.fitted_quartic import monomials

MU, NORMAL_FORCE, RADIUS = 0.5, 10.0, 0.05
DISK = LimitSurface(pressure.disk(RADIUS), mu=MU, normal_force=NORMAL_FORCE)
THREE_POINTS = [[0.05, 0.0], [-0.025, 0.0433], [-0.025, -0.0433]]


def jacobian(contact):
    """Velocity of the part point ``contact`` per twist (vx, vy, w)."""
    cx, cy = contact
    return np.array([[1.0, 0.0, -cy], [0.0, 1.0, cx]])


def angle(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    cosine = a @ b / (np.linalg.norm(a) * np.linalg.norm(b))
    return math.acos(min(1.0, max(-1.0, cosine)))


# -- the ellipsoid's closed form -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("contact", "velocity"),
    [([-0.05, 0.0], [1.0, 0.0]), ([-0.05, 0.02], [1.0, 0.3]), ([-0.05, -0.03], [0.8, -0.1]),
     ([0.0, -0.05], [0.05, 1.0])],
)  # fmt: skip
def test_a_sticking_push_on_the_ellipsoid_is_its_closed_form(contact, velocity):
    # H(L) = fx²/f² + fy²/f² + m²/m_max² with f = mu N and m_max = (2/3) mu N R (uniform disk):
    # minimum dissipation subject to J V = v gives V = A J^T (J A J^T)^-1 v, F ∝ (J A J^T)^-1 v.
    force_limit, moment_limit = MU * NORMAL_FORCE, 2.0 / 3.0 * MU * NORMAL_FORCE * RADIUS
    a = np.diag([1 / force_limit**2, 1 / force_limit**2, 1 / moment_limit**2])
    j = jacobian(contact)
    multiplier = np.linalg.solve(j @ a @ j.T, velocity)
    twist = a @ j.T @ multiplier
    load = j.T @ multiplier
    load = load / math.sqrt(load @ a @ load)
    model = Ellipsoid.from_limits(max_force=force_limit, max_moment=moment_limit)
    step = push_step(model, contact=contact, normal=[1.0, 0.0] if contact[0] else [0.0, 1.0],
                     velocity=velocity, mu=1.0)  # fmt: skip
    assert step.mode == "sticking"
    np.testing.assert_allclose(step.twist, twist, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(step.load, load, rtol=1e-9, atol=1e-12)
    assert step.slip == 0.0


# -- the exact surface against an independent minimum-dissipation SOCP ------------------------------


def polar_rule(radius, radial=24, angular=96):
    """Points and weights (summing to 1) of a uniform disk: Gauss-Legendre in r² × midpoints."""
    nodes, weights = np.polynomial.legendre.leggauss(radial)
    r = radius * np.sqrt(0.5 * (nodes + 1.0))
    theta = (np.arange(angular) + 0.5) * 2 * np.pi / angular
    rr, tt = np.meshgrid(r, theta, indexing="ij")
    w = np.repeat(0.5 * weights[:, None], angular, axis=1) / angular
    return np.column_stack([(rr * np.cos(tt)).ravel(), (rr * np.sin(tt)).ravel()]), w.ravel()


def dissipation_socp(points, weights, friction, *, equalities):
    """min Σ friction w_k |v(x_k)| over twists V subject to ``equalities`` (A, b): A V = b."""
    twist = cp.Variable(3)
    velocities = cp.reshape(np.vstack([jacobian(x) for x in points]) @ twist, (len(points), 2),
                            order="C")  # fmt: skip
    dissipation = friction * weights @ cp.norm(velocities, axis=1)
    a, b = equalities
    problem = cp.Problem(cp.Minimize(dissipation), [a @ twist == b])
    problem.solve(solver=cp.CLARABEL, tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10)
    assert problem.status == cp.OPTIMAL
    return twist.value


def reference_step(points, weights, friction, contact, normal, velocity, mu):
    """The twist of the step by minimum dissipation: sticking (J V = v) when the multiplier lies
    in the friction cone, else normality at the edge force scaled to the normal velocity."""
    j, n = jacobian(contact), np.asarray(normal, float)
    twist = dissipation_socp(points, weights, friction, equalities=(j, velocity))
    # The force is the gradient of h at the twist: Σ f w_k v̂_k (1, x×) mapped back through J^T.
    load = np.zeros(3)
    for x, w in zip(points, weights, strict=True):
        v = jacobian(x) @ twist
        speed = np.linalg.norm(v)
        if speed > 1e-12:
            load += friction * w * jacobian(x).T @ (v / speed)
    force = np.linalg.lstsq(j.T, load, rcond=None)[0]
    t = np.array([-n[1], n[0]])
    if abs(force @ t) <= mu * (force @ n) * (1 + 1e-9):
        return "sticking", twist
    side = 1.0 if force @ t > 0 else -1.0
    edge = (n + side * mu * t) / math.hypot(1.0, mu)
    twist = dissipation_socp(points, weights, friction, equalities=(edge @ j[None, :], [1.0]))
    twist = twist * (n @ velocity) / (n @ j @ twist)
    return ("sliding-left" if side > 0 else "sliding-right"), twist


CASES = [
    ([-0.05, 0.0], [1.0, 0.0], [1.0, 0.0], 0.3),
    ([-0.05, 0.02], [1.0, 0.0], [1.0, 0.4], 0.3),
    ([-0.05, 0.02], [1.0, 0.0], [1.0, 0.0], 0.3),
    ([-0.05, -0.03], [1.0, 0.0], [1.0, 0.2], 0.1),
    ([-0.04, 0.03], [0.8, -0.6], [1.0, -0.5], 0.0),
    ([0.01, -0.05], [0.0, 1.0], [0.3, 1.0], 0.6),
]


def dissipation_gradient(points, weights, friction, twist):
    """∇h(V) = Σ friction w_k J_kᵀ v̂_k of a point set (no point may be at rest)."""
    gradient = np.zeros(3)
    for x, w in zip(points, weights, strict=True):
        v = jacobian(x) @ twist
        assert np.linalg.norm(v) > 1e-9 * np.linalg.norm(twist), "a support point is at rest"
        gradient += friction * w * jacobian(x).T @ (v / np.linalg.norm(v))
    return gradient


@pytest.mark.parametrize(("contact", "normal", "velocity", "mu"), CASES)
def test_a_step_on_three_support_points_is_the_minimum_dissipation_twist(
    contact, normal, velocity, mu
):
    # The point set's surface is exact, so the step must satisfy the optimality conditions of
    # minimum dissipation to rounding: sticking, ∇h(V) = Jᵀ F with J V = v and F in the cone;
    # sliding, ∇h(V) ∥ Jᵀ e (normality at the edge force e) with the normal speeds equal.
    surface = LimitSurface(pressure.points(THREE_POINTS), mu=MU, normal_force=NORMAL_FORCE)
    points, weights = np.array(THREE_POINTS), np.full(3, 1.0 / 3.0)
    friction = MU * NORMAL_FORCE
    mode, twist = reference_step(points, weights, friction, contact, normal, velocity, mu)
    step = push_step(surface, contact=contact, normal=normal, velocity=velocity, mu=mu)
    assert step.mode == mode
    np.testing.assert_allclose(step.twist, twist, rtol=1e-4, atol=1e-4 * np.abs(twist).max())
    j, n = jacobian(contact), np.asarray(normal, float)
    gradient = dissipation_gradient(points, weights, friction, step.twist)
    force = np.linalg.lstsq(j.T, gradient, rcond=None)[0]
    assert np.linalg.norm(j.T @ force - gradient) <= 1e-9 * np.linalg.norm(gradient)
    np.testing.assert_allclose(step.force, force, rtol=1e-8, atol=1e-12 * np.linalg.norm(force))
    if mode == "sticking":
        np.testing.assert_allclose(j @ step.twist, velocity, rtol=1e-12, atol=1e-12)
        assert abs(force[0] * n[1] - force[1] * n[0]) <= mu * (force @ n) * (1 + 1e-9)
    else:
        tangential = abs(force[0] * n[1] - force[1] * n[0])
        assert tangential == pytest.approx(mu * (force @ n), rel=1e-9, abs=1e-12)
        assert n @ j @ step.twist == pytest.approx(n @ velocity, rel=1e-12)


@pytest.mark.parametrize(("contact", "normal", "velocity", "mu"), CASES)
def test_a_step_on_a_uniform_disk_is_the_minimum_dissipation_twist_of_a_quadrature(
    contact, normal, velocity, mu
):
    points, weights = polar_rule(RADIUS)
    mode, twist = reference_step(points, weights, MU * NORMAL_FORCE, contact, normal, velocity, mu)
    step = push_step(DISK, contact=contact, normal=normal, velocity=velocity, mu=mu)
    assert step.mode == mode
    # The quadrature of 2,304 points gives the twist to about 5e-5 (measured: at most 4.8e-5 rad
    # and 1.1e-5 in size).
    scale = np.array([1.0, 1.0, RADIUS])  # the rotation as the speed of the rim
    assert angle(step.twist * scale, twist * scale) < 2e-4
    assert np.linalg.norm(step.twist * scale) == pytest.approx(
        np.linalg.norm(twist * scale), rel=1e-3
    )


# -- laws of pushing ---------------------------------------------------------------------------------

SYMMETRIC = {
    "disk": DISK,
    "rectangle": LimitSurface(pressure.rectangle(0.1, 0.04), mu=MU, normal_force=NORMAL_FORCE),
    "ellipsoid": Ellipsoid.from_limit_surface(DISK),
    "exact-model": Exact.from_limit_surface(DISK),
}
#: Models that are symmetric only to their fit (a least-squares ellipsoid through samples of the
#: disk's surface is off by about 1e-5): they obey the voting theorem, not exact straightness.
NEARLY_SYMMETRIC = {**SYMMETRIC, "fitted-ellipsoid": FittedEllipsoid.from_limit_surface(DISK)}


@pytest.mark.parametrize("name", SYMMETRIC)
@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_a_push_through_the_centre_of_pressure_translates_the_part_straight(name, mu):
    step = push_step(SYMMETRIC[name], contact=[-0.05, 0.0], normal=[1.0, 0.0], velocity=[2.0, 0.0],
                     mu=mu)  # fmt: skip
    assert step.mode == "sticking" or (mu == 0.0 and step.mode.startswith("sliding"))
    np.testing.assert_allclose(step.twist, [2.0, 0.0, 0.0], atol=1e-9)
    assert step.force[1] == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("name", NEARLY_SYMMETRIC)
@pytest.mark.parametrize(("offset", "sense"), [(0.02, -1.0), (-0.03, 1.0)])
def test_an_off_centre_push_turns_the_part_as_the_voting_theorem_says(name, offset, sense):
    # Pushing along +x at height y = offset: the push line and both edges of the friction cone
    # (mu = 0.2, edges within 11.3° of +x) pass on the same side of the centre of pressure, so
    # all three vote for the same rotation sense, -sign(offset) (Mason 1986).
    for mu in (0.0, 0.2):
        step = push_step(NEARLY_SYMMETRIC[name], contact=[-0.05, offset], normal=[1.0, 0.0],
                         velocity=[1.0, 0.0], mu=mu)  # fmt: skip
        assert np.sign(step.twist[2]) == sense


def test_a_frictionless_pusher_pushes_along_the_normal_and_slides():
    step = push_step(DISK, contact=[-0.05, 0.02], normal=[1.0, 0.0], velocity=[1.0, 0.0], mu=0.0)
    assert step.mode in ("sliding-left", "sliding-right")
    assert step.force[1] == 0.0 and step.force[0] > 0.0
    contact_velocity = jacobian([-0.05, 0.02]) @ step.twist
    assert contact_velocity[0] == pytest.approx(1.0, rel=1e-12)
    assert step.slip == pytest.approx(0.0 - contact_velocity[1], rel=1e-12)


def test_a_pusher_moving_away_separates():
    step = push_step(DISK, contact=[-0.05, 0.0], normal=[1.0, 0.0], velocity=[-1.0, 0.5], mu=0.3)
    assert step.mode == "separated"
    assert not np.any(step.twist) and not np.any(step.force)
    assert step.slip == 0.5


@pytest.mark.parametrize("surface", [DISK, SYMMETRIC["ellipsoid"]], ids=["exact", "ellipsoid"])
def test_the_motion_cone_edges_are_where_sticking_turns_into_sliding(surface):
    contact, normal, mu = [-0.05, 0.02], [1.0, 0.0], 0.3
    cone = motion_cone(surface, contact=contact, normal=normal, mu=mu)
    j = jacobian(contact)
    for side, twist in (("left", cone.left), ("right", cone.right)):
        assert (j @ twist)[0] == pytest.approx(1.0)  # unit normal speed
        edge = j @ twist
        step = push_step(surface, contact=contact, normal=normal, velocity=edge, mu=mu)
        np.testing.assert_allclose(step.twist, twist, rtol=1e-7, atol=1e-9)
        turn = np.array([[0.0, -1.0], [1.0, 0.0]]) * (0.05 if side == "left" else -0.05)
        beyond = edge + turn @ edge
        assert push_step(surface, contact=contact, normal=normal, velocity=beyond,
                         mu=mu).mode == f"sliding-{side}"  # fmt: skip


def test_a_frictionless_support_and_a_model_without_motion_are_refused():
    frictionless = LimitSurface(pressure.disk(RADIUS), mu=0.0)
    with pytest.raises(InvalidArgumentError, match="frictionless support"):
        push_step(frictionless, contact=[-0.05, 0], normal=[1, 0], velocity=[1, 0], mu=0.3)
    with pytest.raises(InvalidArgumentError, match="normal"):
        push_step(DISK, contact=[-0.05, 0], normal=[0, 0], velocity=[1, 0], mu=0.3)
    with pytest.raises(InvalidArgumentError, match="contact must lie within 1000 m"):
        push_step(DISK, contact=[1e300, 0], normal=[1, 0], velocity=[1, 0], mu=0.3)


@pytest.mark.parametrize(
    ("contact", "normal", "velocity", "pivot"),
    [
        ([-0.0356, -0.0285], [0.0295, -0.9996], [0.677, -0.496], 0),
        ([-0.0502, 0.0426], [0.9998, -0.0219], [0.375, -0.179], 2),
        ([-0.0401, -0.0267], [-0.7607, 0.6491], [0.132, 0.494], 0),
    ],
)
def test_a_part_on_support_points_can_pivot_about_one_of_them(contact, normal, velocity, pivot):
    # The twist lands on a facet of the surface: the part turns about support point `pivot`,
    # which carries any friction force up to its share mu N / 3 (the subgradient of h there);
    # the others slide and carry mu N / 3 along their sliding directions.
    surface = LimitSurface(pressure.points(THREE_POINTS), mu=MU, normal_force=NORMAL_FORCE)
    step = push_step(surface, contact=contact, normal=normal, velocity=velocity, mu=0.5)
    points, share = np.array(THREE_POINTS), MU * NORMAL_FORCE / 3.0
    centre = np.array([-step.twist[1], step.twist[0]]) / step.twist[2]
    np.testing.assert_allclose(centre, points[pivot], atol=1e-12)
    load = step.load.copy()
    for k, x in enumerate(points):
        if k != pivot:
            v = jacobian(x) @ step.twist
            load -= share * jacobian(x).T @ (v / np.linalg.norm(v))
    held = np.linalg.lstsq(jacobian(points[pivot]).T, load, rcond=None)[0]
    np.testing.assert_allclose(jacobian(points[pivot]).T @ held, load, atol=1e-9 * share)
    assert np.linalg.norm(held) <= share * (1 + 1e-9)
    n = np.asarray(normal) / np.linalg.norm(normal)
    assert n @ jacobian(contact) @ step.twist == pytest.approx(n @ velocity, rel=1e-12)


# -- the ellipsoid's closed forms and the checks of the arguments ---------------------------------

#: An asymmetric triangle (tilted ellipsoid, centre of pressure off the origin) at 3 N.
TRIANGLE = LimitSurface(pressure.polygon([[0, 0], [0.1, 0], [0.02, 0.05]], centered=False),
                        mu=0.3, normal_force=3.0)  # fmt: skip


@pytest.mark.parametrize(
    "model",
    [Ellipsoid.from_limit_surface(TRIANGLE), FittedEllipsoid.from_limit_surface(TRIANGLE)],
    ids=["ellipsoid", "fitted-ellipsoid"],
)
def test_every_step_on_an_ellipsoid_puts_its_load_on_the_model_along_its_motion(model):
    # The step's safety factor and twist come from the load matrix in closed form; the model's
    # own safety_factor and motion (from its normalised gauge) must agree with them.
    rng = np.random.default_rng(3)
    modes = set()
    for _ in range(40):
        contact = rng.uniform(-0.05, 0.1, 2)
        normal = rng.normal(size=2)
        velocity = normal + rng.normal(size=2)
        step = push_step(model, contact=contact, normal=normal, velocity=velocity,
                         mu=rng.uniform(0.0, 1.0))  # fmt: skip
        modes.add(step.mode)
        if step.mode == "separated":
            continue
        assert model.safety_factor(step.load) == pytest.approx(1.0, rel=1e-12)
        assert angle(step.twist, model.motion(step.load)) < 1e-7
        np.testing.assert_allclose(jacobian(contact).T @ step.force, step.load, rtol=1e-12)
    assert {"sticking", "sliding-left", "sliding-right"} <= modes


@pytest.mark.parametrize("surface", [DISK, SYMMETRIC["ellipsoid"]], ids=["exact", "ellipsoid"])
def test_arguments_given_as_lists_tuples_or_arrays_give_the_same_step(surface):
    reference = push_step(surface, contact=[-0.05, 0.02], normal=[1, 0], velocity=[1.0, 0.3],
                          mu=0.4)  # fmt: skip
    for convert in (tuple, np.array, lambda v: np.array(v, dtype=np.float32)):
        step = push_step(surface, contact=convert([-0.05, 0.02]), normal=convert([1, 0]),
                         velocity=convert([1.0, 0.3]), mu=0.4)  # fmt: skip
        assert step.mode == reference.mode
        np.testing.assert_allclose(step.twist, reference.twist, rtol=1e-6)


@pytest.mark.parametrize(
    ("argument", "value", "words"),
    [
        ("velocity", [math.nan, 1.0], ["velocity", "finite"]),
        ("velocity", [1.0, math.inf], ["velocity", "finite"]),
        ("velocity", [1.0, 0.0, 0.0], ["velocity", "shape"]),
        ("contact", [[0.0, 0.0], [1.0, 1.0]], ["contact", "shape"]),
        ("contact", ["a", "b"], ["contact", "real numbers"]),
        ("normal", np.array([math.nan, 1.0]), ["normal", "finite"]),
        ("normal", (0.0, 0.0), ["normal", "nonzero"]),
    ],
)
def test_bad_arguments_of_a_step_raise_an_error_naming_them(argument, value, words):
    arguments = {"contact": [-0.05, 0.0], "normal": [1.0, 0.0], "velocity": [1.0, 0.0]}
    arguments[argument] = value
    for surface in (DISK, SYMMETRIC["ellipsoid"]):
        with pytest.raises(InvalidArgumentError) as caught:
            push_step(surface, **arguments, mu=0.3)
        for word in words:
            assert word in str(caught.value)


# -- a quartic's two routes -----------------------------------------------------------------------


def skewed_quartic():
    """A strictly SOS-convex quartic in ``x = (fx, fy, m / rho)``: ``|S x|^4 + 0.3 (x^4 + y^4 +
    z^4)`` (sums and linear maps of SOS-convex forms are SOS-convex), least squares on points."""
    stretch = np.array([[1.0, 0.3, -0.2], [0.0, 0.8, 0.4], [0.1, 0.0, 1.5]])
    points = np.random.default_rng(5).standard_normal((60, 3))
    values = np.sum((points @ stretch.T) ** 2, axis=1) ** 2 + 0.3 * np.sum(points**4, axis=1)
    coefficients = np.linalg.lstsq(monomials(points), values, rcond=None)[0]
    return FittedQuartic(coefficients=coefficients, rho=0.05, normal_force=2.0)


class ForwardRoute:
    """A quartic seen without its ``closed_form_motion`` flag: pushed through its forward map."""

    def __init__(self, quartic):
        self.quartic = quartic
        self.normal_force = quartic.normal_force
        self.motion = quartic.motion
        self.safety_factor = quartic.safety_factor
        self.motion_and_safety_factor = quartic.motion_and_safety_factor
        self.load = quartic.load


#: Agreement of the two routes' steps (both solve to rounding; what differs is the root found).
ROUTES_RTOL = 1e-9


def test_a_quartic_step_through_its_inverse_map_is_the_step_through_its_forward_map(monkeypatch):
    quartic = skewed_quartic()
    rng = np.random.default_rng(11)
    cases = []
    for _ in range(30):
        normal = rng.normal(size=2)
        cases.append({"contact": rng.uniform(-0.06, 0.06, 2), "normal": normal,
                      "velocity": normal + 0.5 * rng.normal(size=2), "mu": rng.uniform(0.1, 1.0)})  # fmt: skip
    references = [push_step(ForwardRoute(quartic), **case) for case in cases]

    def no_forward_map(self, twist):
        raise AssertionError("the quartic's step went through its forward map")

    monkeypatch.setattr(FittedQuartic, "load", no_forward_map)
    modes = set()
    for case, reference in zip(cases, references, strict=True):
        step = push_step(quartic, **case)
        assert step.mode == reference.mode
        modes.add(step.mode)
        if step.mode == "separated":
            continue
        twist_size = np.linalg.norm(reference.twist * [1.0, 1.0, quartic.rho])
        np.testing.assert_allclose(step.twist, reference.twist, rtol=0.0,
                                   atol=ROUTES_RTOL * twist_size)  # fmt: skip
        np.testing.assert_allclose(step.load, reference.load, rtol=0.0,
                                   atol=ROUTES_RTOL * np.linalg.norm(reference.load))  # fmt: skip
    assert {"sticking", "sliding-left", "sliding-right"} <= modes


@pytest.mark.parametrize("contact", [[1.0, 0.0], [1000.0, 0.0], [1.0, 1e-9]])
def test_a_motion_cone_whose_edge_does_not_push_the_part_away_is_refused_and_every_push_sticks(
    contact,
):
    # On the line of a two-point support an edge force turns the part about a support point:
    # the contact moves along the tangent (or, off the line, slightly into the pusher).
    pair = LimitSurface(pressure.points([[-0.04, 0.0], [0.04, 0.0]]), mu=0.3, normal_force=4.9)
    with pytest.raises(ModelError, match="normal speed"):
        motion_cone(pair, contact=contact, normal=[1, 0], mu=0.25)
    for velocity in ([1.0, 0.0], [1.0, 5.0], [1.0, -5.0], [1e-3, 1.0]):
        step = push_step(pair, contact=contact, normal=[1, 0], velocity=velocity, mu=0.25)
        assert step.mode == "sticking"
    cone = motion_cone(pair, contact=[0.1, 0.0], normal=[1, 0], mu=0.25)
    assert cone.left[0] == pytest.approx(1.0) and cone.right[0] == pytest.approx(1.0)
