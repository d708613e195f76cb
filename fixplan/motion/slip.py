r"""Online updates of a limit surface from slip onsets (paper §3 and §4.3; issue 11 §1).

The paper asks for the limit surface (LS) to be updated while manipulating: detect the onset of
slip, read the force and moment at that instant, and rescale the friction coefficient and the
largest force and moment. :class:`SlipEstimator` does this recursively, in constant time per
sample, and :class:`ScaledSurface` is the rescaled exact surface.

**Model.** A nominal surface ``S0`` (its shape is trusted) at normal force ``N0`` has friction
``mu0`` (largest force over ``N0``) and characteristic length ``rho0`` (largest moment about its
centre of pressure ``c`` over the largest force). In its normalised coordinates

.. math:: q = \left(\frac{f_x}{\mu N}, \frac{f_y}{\mu N}, \frac{m_c}{\mu \rho N}\right),
    \qquad m_c = m - (c_x f_y - c_y f_x),

with ``mu = mu0``, ``rho = rho0`` and ``N = N0`` it is ``{q : g0(q) <= 1}`` for a gauge ``g0``
(convex, positively homogeneous). The estimated surface at normal force ``N`` is the same set
with the estimates ``mu`` and ``rho`` in ``q``: forces scaled by ``mu / mu0`` and moments about
``c`` by ``mu rho / (mu0 rho0)``, and everything by ``N`` (the LS is linear in the normal
force). It is exactly the LS of the nominal pressure shape with friction ``mu`` and the patch
scaled by ``rho / rho0`` about ``c`` (:class:`ScaledSurface`).

**Update.** The state is ``x = (log mu, log rho)`` with covariance ``P``. At slip onset the load
lies on the true surface, ``g0(q) = 1``. As ``g0`` is homogeneous, ``∂ log g0 / ∂ log mu = -1``
and ``∂ log g0 / ∂ log rho = -s`` with ``s = q_m ∂_m g0 / g0`` the moment's share of the
friction power (0 for a translation, 1 for a rotation about ``c``), so each onset ``(L, N)`` is
the linear measurement

.. math:: y = \log g_0(q(\hat x)) = H (x - \hat x) + e, \qquad H = (1, s), \quad
    e \sim \mathcal N(0, \sigma^2),

``sigma`` the relative noise of the force sensor, and the extended Kalman filter (recursive least
squares with exponential forgetting ``lambda``) does

.. math:: P \leftarrow P / \lambda, \quad S = H P H^T + \sigma^2, \quad K = P H^T / S, \quad
    \hat x \leftarrow \hat x + K y, \quad P \leftarrow P - K H P .

Onsets with a twist ``V`` add normality: the twist about ``c`` in normalised coordinates,
``(v_c, rho w)``, is parallel to ``∇g0(q)``. Their elevations ``θ_V = atan2(rho w, |v_c|)`` and
``θ_n(q) = atan2(∂_m g0, |∂_f g0|)`` give a second scalar measurement, of ``log rho`` only (the
normal ``∇g0`` is homogeneous of degree 0, so ``mu`` drops out),

.. math:: y_t = θ_V(\hat\rho) - θ_n(q(\hat x)) = h_t (\log\rho - \log\hat\rho) + e_t, \qquad
    h_t = -\sin θ_V \cos θ_V - \frac{dθ_n}{dθ_q} \sin θ_q \cos θ_q,

``θ_q`` the elevation of ``q`` (it falls as ``rho`` grows) and ``e_t`` of standard deviation
``twist_noise``; it is processed after the load's, at the same linearisation point. The twist's
direction within the force plane carries no information on ``(mu, rho)`` and is not used.

Each update is O(1) and solves nothing: ``g0``, ``s``, ``θ_n`` and ``dθ_n/dθ_q`` come from a
table of the nominal surface over load directions (:class:`_ShapeTable`: the half sphere
``q_m >= 0``, the other half by central symmetry, on a grid of elevation and azimuth, bilinear
interpolation), built once from the nominal's ``safety_factor`` and ``motion`` at construction;
the same table serves exact surfaces and ellipsoids. One exact inverse-map query per onset would
cost 0.1-2 ms; an update costs a few microseconds of pure Python
(``benchmarks/bench_slip.py``).

The covariance accounts for the sensor noise only: a nominal shape that differs from the true
one (an ellipsoid for a rectangle) biases ``mu`` and ``rho`` by the shape error, which more
onsets do not remove.

**Forgetting, gate and rejections.** Every sample that is a measurement (finite, ``N > 0``, a
twist that does not oppose the load) first ages the estimate, ``P ← P / lambda`` (``lambda = 1``:
no forgetting), capped so that neither variance exceeds the prior's. A slip onset cannot lie
inside the surface: a sample with ``y < -GATE_SIGMAS · sqrt(S)`` is rejected as ``"inside"`` (a
false slip detection). The gate widens with the estimate's own uncertainty: at the start, so that
a nominal surface far too large still learns, and with forgetting, so that after a drop of
``mu`` the rejected onsets age the estimate until they are admitted. A gate at one ``sigma``
would reject about a sixth of genuine onsets and bias ``mu`` upwards. Other rejections:
``"not finite"`` (NaN or infinite entries), ``"normal force"`` (``N <= 0``) and ``"twist"``
(a zero twist, or one whose power ``V·L`` is not positive, against normality). Rejected samples
never change the estimate beyond that ageing and are counted by reason.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.models.base import finite_pair, fmt
from fixplan.models.ellipsoid import Ellipsoid, FittedEllipsoid, surface_axis
from fixplan.surface.limit_surface import LimitSurface

#: An onset is rejected as "inside" when its log-gauge lies more than this many standard
#: deviations of its prediction inside the current surface (3: about 0.1 % of genuine onsets).
GATE_SIGMAS = 3.0

#: Default number of elevation steps of the shape table over ``[0, π/2]`` (four times as many
#: azimuth steps over ``[-π, π]``): 16,705 directions, built in 0.15-0.5 s from an exact
#: surface. Measured radial interpolation error: 2e-5 to 6e-5 root-mean-square over directions
#: (uniform disk, 10:1 rectangle, three points), at most 6e-5 on the disk, 3e-4 at the facets
#: of the points and 1e-3 on the rounded edges of the rectangle; far below sensor noise.
DEFAULT_RESOLUTION = 64

#: Reasons a sample is rejected, the keys of :attr:`SlipEstimator.rejected`.
REASONS = ("not finite", "normal force", "twist", "inside")


@dataclass(frozen=True, slots=True, kw_only=True, repr=False, eq=False)
class ScaledSurface:
    r"""An exact limit surface with its friction and patch size scaled.

    The limit surface of the nominal's pressure shape with friction ``friction_scale`` times
    the nominal's and the patch scaled by ``length_scale`` about ``center``: forces are scaled
    by ``friction_scale`` and moments about ``center`` by ``friction_scale * length_scale``.
    With ``A`` the map of a load to the nominal load it corresponds to (about the origin),

    .. math:: A = T^{-1} D T, \quad D = \mathrm{diag}(k_f, k_f, k_f k_\rho)^{-1}, \quad
        T L = (f_x, f_y, m - c \times f),

    the safety factor is the nominal's at ``A L``, the motion is ``A^T`` times the nominal's,
    the support function is ``h(V) = h_0(A^{-T} V)`` and the forward map
    ``L(V) = A^{-1} L_0(A^{-T} V)``. It has the interface of :class:`~fixplan.LimitSurface`
    that the motion layer uses (:func:`~fixplan.motion.push_step`, :func:`~fixplan.motion.push`).

    Attributes
    ----------
    nominal : LimitSurface
        The surface that is scaled (not frictionless).
    friction_scale : float
        Factor on the friction coefficient [-], > 0.
    length_scale : float
        Factor on the patch size [-], > 0.
    center : tuple of float
        Point [m] about which the patch is scaled (its centre of pressure keeps it in place).
    """

    nominal: LimitSurface
    friction_scale: float
    length_scale: float
    center: tuple[float, float] = (0.0, 0.0)
    _to_nominal: np.ndarray = field(init=False)
    _from_nominal: np.ndarray = field(init=False)
    _units: tuple[float, float] = field(init=False)

    def __post_init__(self):
        if not isinstance(self.nominal, LimitSurface) or self.nominal.frictionless:
            raise InvalidArgumentError(
                "nominal must be a fixplan.LimitSurface with friction, got "
                f"{type(self.nominal).__name__}"
            )
        kf = validation.positive_scalar("friction_scale", self.friction_scale)
        kr = validation.positive_scalar("length_scale", self.length_scale)
        cx, cy = finite_pair("center", self.center)
        about_center = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [cy, -cx, 1.0]])
        scale = np.array([kf, kf, kf * kr])
        to_nominal = np.linalg.inv(about_center) @ (about_center / scale[:, None])
        from_nominal = np.linalg.inv(about_center) @ (about_center * scale[:, None])
        for name, value in (
            ("friction_scale", kf),
            ("length_scale", kr),
            ("center", (cx, cy)),
            ("_to_nominal", to_nominal),
            ("_from_nominal", from_nominal),
        ):
            object.__setattr__(self, name, value)
        to_nominal.setflags(write=False)
        from_nominal.setflags(write=False)
        max_moment = float(self.support(np.array([0.0, 0.0, 1.0])))
        object.__setattr__(self, "_units", (kf * self.nominal.max_force, max_moment))

    # -- description --------------------------------------------------------------------------

    @property
    def mu(self) -> float | None:
        """Friction coefficient (``None`` for a combined or position-dependent nominal)."""
        mu = self.nominal.mu
        return mu * self.friction_scale if isinstance(mu, float) else None

    @property
    def normal_force(self) -> float:
        """Total normal force [N], the nominal's."""
        return self.nominal.normal_force

    @property
    def frictionless(self) -> bool:
        """Always ``False``: the nominal has friction and the scale is positive."""
        return False

    @property
    def max_force(self) -> float:
        """Largest friction force [N] (pure translation)."""
        return self._units[0]

    @property
    def max_moment(self) -> float:
        """Largest friction moment about the origin [N m] (rotation about the origin)."""
        return self._units[1]

    @property
    def characteristic_length(self) -> float:
        """``max_moment / max_force`` [m], about the origin as for the exact surface."""
        return self._units[1] / self._units[0]

    def __repr__(self) -> str:
        return (
            f"ScaledSurface({self.nominal!r}, friction_scale={fmt(self.friction_scale)}, "
            f"length_scale={fmt(self.length_scale)}, "
            f"center=({fmt(self.center[0])}, {fmt(self.center[1])}) m)"
        )

    # -- maps ---------------------------------------------------------------------------------

    def support(self, twist) -> np.ndarray | float:
        """Support function ``h(V)`` [W per unit speed] of twists ``(3,)`` or ``(K, 3)``."""
        return self.nominal.support(np.asarray(twist, dtype=float) @ self._from_nominal)

    def load(self, twist) -> np.ndarray:
        """Load ``(fx, fy, m)`` on the surface that sustains sliding with ``twist``."""
        twists = np.asarray(twist, dtype=float) @ self._from_nominal
        return self.nominal.load(twists) @ self._from_nominal.T

    def safety_factor(self, load) -> np.ndarray | float:
        """Factor ``s`` with ``s * load`` on the surface (``inf`` for the zero load)."""
        return self.nominal.safety_factor(self._nominal_loads(load))

    def contains(self, load) -> np.ndarray | bool:
        """Whether the contact holds ``load``, as :meth:`fixplan.LimitSurface.contains`."""
        return self.nominal.contains(self._nominal_loads(load))

    def motion(self, load) -> np.ndarray:
        """Unit twist of impending sliding under ``load``, scaled as
        :meth:`fixplan.LimitSurface.motion` (``(vx, vy, rho * w)`` of unit norm)."""
        return self._unit_twists(self.nominal.motion(self._nominal_loads(load)))

    def motion_and_safety_factor(self, load) -> tuple[np.ndarray, np.ndarray | float]:
        """:meth:`motion` and :meth:`safety_factor` from one solve."""
        twists, safety = self.nominal.motion_and_safety_factor(self._nominal_loads(load))
        return self._unit_twists(twists), safety

    def _nominal_loads(self, load) -> np.ndarray:
        return np.asarray(load, dtype=float) @ self._to_nominal.T

    def _unit_twists(self, twists: np.ndarray) -> np.ndarray:
        twists = twists @ self._to_nominal
        scaled = twists * np.array([1.0, 1.0, self.characteristic_length])
        return twists / np.linalg.norm(scaled, axis=-1, keepdims=True)


class _ShapeTable:
    """The nominal gauge ``g0``, power share ``s`` and normal elevation ``θ_n`` over directions.

    Nodes at elevations ``θ_q`` in ``[0, π/2]`` (``n`` steps) and azimuths in ``[-π, π]``
    (``4 n`` steps) of unit normalised loads. Each cell keeps the coefficients
    ``(a, b, c, d)`` of ``a + b u + c v + d u v`` (``u``, ``v`` in ``[0, 1]`` across the cell)
    of the three quantities in one list: the update is pure Python arithmetic, where a list read
    costs a tenth of a NumPy scalar read.
    """

    __slots__ = ("_azimuth_step", "_cells", "_elevation_step", "_steps", "_width")

    def __init__(self, nominal, *, units: np.ndarray, center: tuple[float, float], steps: int):
        azimuths = np.linspace(-np.pi, np.pi, 4 * steps + 1)
        elevations = np.linspace(0.0, 0.5 * np.pi, steps + 1)
        elevation, azimuth = np.meshgrid(elevations, azimuths, indexing="ij")
        q = np.stack([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth),
                      np.sin(elevation)], axis=-1).reshape(-1, 3)  # fmt: skip
        cx, cy = center
        loads = q * units
        loads[:, 2] += cx * loads[:, 1] - cy * loads[:, 0]  # moments about the origin
        if isinstance(nominal, LimitSurface):
            twists, safety = nominal.motion_and_safety_factor(loads)
        else:
            twists, safety = nominal.motion(loads), nominal.safety_factor(loads)
        # The normal in q: the twist about the centre, (v_c, rho w), up to a positive factor.
        normal = np.column_stack([twists[:, 0] - cy * twists[:, 2],
                                  twists[:, 1] + cx * twists[:, 2],
                                  units[2] / units[0] * twists[:, 2]])  # fmt: skip
        nodes = np.column_stack([
            1.0 / safety,
            normal[:, 2] * q[:, 2] / np.einsum("ij,ij->i", normal, q),
            np.arctan2(normal[:, 2], np.hypot(normal[:, 0], normal[:, 1])),
        ]).reshape(steps + 1, 4 * steps + 1, 3)  # fmt: skip
        f00, f10 = nodes[:-1, :-1], nodes[:-1, 1:]
        f01, f11 = nodes[1:, :-1], nodes[1:, 1:]
        cells = np.stack([f00, f10 - f00, f01 - f00, f11 - f10 - f01 + f00], axis=-1)
        self._cells = cells.reshape(-1, 12).tolist()
        self._steps = steps
        self._width = 4 * steps
        self._azimuth_step = 4 * steps / (2.0 * math.pi)
        self._elevation_step = steps / (0.5 * math.pi)

    def at(self, qx: float, qy: float, qm: float) -> tuple[float, float, float, float, float]:
        """``(g0, s, θ_n, dθ_n/dθ_q, θ_q)`` at ``q`` with ``qm >= 0``, interpolated."""
        radius = math.hypot(qx, qy)
        elevation = math.atan2(qm, radius)
        x = (math.atan2(qy, qx) + math.pi) * self._azimuth_step
        y = elevation * self._elevation_step
        i = min(int(x), self._width - 1)
        j = min(int(y), self._steps - 1)
        u = x - i
        v = y - j
        g, gu, gv, guv, s, su, sv, suv, t, tu, tv, tuv = self._cells[j * self._width + i]
        tv += tuv * u
        gauge = (g + gu * u + (gv + guv * u) * v) * math.sqrt(radius * radius + qm * qm)
        share = s + su * u + (sv + suv * u) * v
        return gauge, share, t + tu * u + tv * v, tv * self._elevation_step, elevation


class SlipEstimator:
    """Recursive estimate of ``mu`` and ``rho`` of a contact from slip onsets (module docstring).

    Parameters
    ----------
    surface : LimitSurface, Ellipsoid or FittedEllipsoid
        The nominal surface: its shape is kept, its ``mu`` and ``rho`` are the starting estimate.
    forgetting : float
        Exponential forgetting factor ``lambda`` in ``(0, 1]`` per sample; 1 keeps every sample
        at equal weight, below 1 the estimate tracks changes with a memory of about
        ``1 / (1 - lambda)`` samples.
    noise : float
        Relative noise of the measured loads [-] (standard deviation of the log-gauge), > 0.
    twist_noise : float
        Standard deviation of the elevation of measured twists [rad], > 0.
    prior_std : float
        Standard deviation of ``log mu`` and ``log rho`` before any sample [-], > 0 (1: the
        nominal may be off by a factor of about e).
    resolution : int
        Elevation steps of the shape table (:data:`DEFAULT_RESOLUTION`), at least 8.
    """

    __slots__ = ("_accepted", "_center", "_estimate", "_nominal", "_prior", "_rejected",
                 "_table", "forgetting", "noise", "twist_noise")  # fmt: skip

    def __init__(
        self,
        surface: LimitSurface | Ellipsoid | FittedEllipsoid,
        *,
        forgetting: float = 1.0,
        noise: float = 0.03,
        twist_noise: float = 0.1,
        prior_std: float = 1.0,
        resolution: int = DEFAULT_RESOLUTION,
    ):
        mu, rho, center, normal_force = _nominal_units(surface)
        forgetting = validation.positive_scalar("forgetting", forgetting)
        if forgetting > 1.0:
            raise InvalidArgumentError(f"forgetting must be in (0, 1], got {forgetting!r}")
        if isinstance(resolution, bool) or not isinstance(resolution, int) or resolution < 8:
            raise InvalidArgumentError(f"resolution must be an integer >= 8, got {resolution!r}")
        self.forgetting = forgetting
        self.noise = validation.positive_scalar("noise", noise)
        self.twist_noise = validation.positive_scalar("twist_noise", twist_noise)
        self._prior = validation.positive_scalar("prior_std", prior_std) ** 2
        self._nominal = (surface, mu, rho)
        self._center = center
        units = np.array([mu, mu, mu * rho]) * normal_force
        self._table = _ShapeTable(surface, units=units, center=center, steps=resolution)
        # log mu, log rho, P00, P01, P11.
        self._estimate = [math.log(mu), math.log(rho), self._prior, 0.0, self._prior]
        self._accepted = 0
        self._rejected = dict.fromkeys(REASONS, 0)

    # -- estimates ----------------------------------------------------------------------------

    @property
    def mu(self) -> float:
        """Estimated friction coefficient [-]."""
        return math.exp(self._estimate[0])

    @property
    def rho(self) -> float:
        """Estimated characteristic length [m]: largest moment about the centre of pressure
        over the largest force."""
        return math.exp(self._estimate[1])

    @property
    def mu_std(self) -> float:
        """Standard deviation of :attr:`mu` [-] (to first order: ``mu`` times that of
        ``log mu``)."""
        return self.mu * math.sqrt(self._estimate[2])

    @property
    def rho_std(self) -> float:
        """Standard deviation of :attr:`rho` [m] (to first order)."""
        return self.rho * math.sqrt(self._estimate[4])

    @property
    def covariance(self) -> np.ndarray:
        """Covariance ``(2, 2)`` of ``(log mu, log rho)`` [-]."""
        _, _, p00, p01, p11 = self._estimate
        return np.array([[p00, p01], [p01, p11]])

    @property
    def accepted(self) -> int:
        """Number of samples that updated the estimate."""
        return self._accepted

    @property
    def rejected(self) -> dict[str, int]:
        """Number of rejected samples by reason (:data:`REASONS`)."""
        return dict(self._rejected)

    @property
    def nominal(self) -> LimitSurface | Ellipsoid | FittedEllipsoid:
        """The nominal surface the estimator was built with."""
        return self._nominal[0]

    @property
    def surface(self) -> ScaledSurface | Ellipsoid | FittedEllipsoid:
        """The estimated surface at the nominal's normal force: an ellipsoid nominal with the
        estimated ``mu`` and ``rho``, or the exact nominal as a :class:`ScaledSurface`."""
        nominal, mu, rho = self._nominal
        if isinstance(nominal, LimitSurface):
            return ScaledSurface(nominal=nominal, friction_scale=self.mu / mu,
                                 length_scale=self.rho / rho, center=self._center)  # fmt: skip
        return dataclasses.replace(nominal, mu=self.mu, rho=self.rho)

    def __repr__(self) -> str:
        return (
            f"SlipEstimator(mu={fmt(self.mu)} ± {self.mu_std:.2g}, "
            f"rho={fmt(self.rho)} ± {self.rho_std:.2g} m, accepted={self._accepted}, "
            f"rejected={sum(self._rejected.values())})"
        )

    # -- update -------------------------------------------------------------------------------

    def update(self, load, normal_force: float, *, twist=None) -> str:
        """Update the estimate from one slip onset; O(1).

        Parameters
        ----------
        load : array_like
            ``(fx, fy, m)`` [N, N, N m] about the frame origin at the onset of slip.
        normal_force : float
            Normal force [N] at that instant.
        twist : array_like, optional
            ``(vx, vy, w)`` [m/s, m/s, rad/s] of the slip that followed (any scale).

        Returns
        -------
        str
            ``"accepted"``, or the reason the sample was rejected (one of :data:`REASONS`).
        """
        try:
            fx, fy, m = load.tolist() if isinstance(load, np.ndarray) else load
            fx, fy, m, n = float(fx), float(fy), float(m), float(normal_force)
            if twist is not None:
                vx, vy, w = twist.tolist() if isinstance(twist, np.ndarray) else twist
                vx, vy, w = float(vx), float(vy), float(w)
        except (TypeError, ValueError) as exc:
            raise InvalidArgumentError(
                "load and twist must be 3 real numbers each and normal_force a real number, got "
                f"load={load!r}, normal_force={normal_force!r}, twist={twist!r}"
            ) from exc
        finite = math.isfinite
        if not (finite(fx) and finite(fy) and finite(m) and finite(n)) or (
            twist is not None and not (finite(vx) and finite(vy) and finite(w))
        ):
            return self._reject("not finite")
        if n <= 0.0:
            return self._reject("normal force")
        if twist is not None and vx * fx + vy * fy + w * m <= 0.0:
            return self._reject("twist")
        estimate = self._estimate
        log_mu, log_rho, p00, p01, p11 = estimate
        if self.forgetting < 1.0:
            # Ageing P / lambda, then D P D with D = diag(d0, d1) <= 1 so that neither
            # variance exceeds the prior (a congruence: P stays positive definite).
            age = 1.0 / self.forgetting
            d0 = min(1.0, math.sqrt(self._prior / (p00 * age)))
            d1 = min(1.0, math.sqrt(self._prior / (p11 * age)))
            p00, p01, p11 = p00 * age * d0 * d0, p01 * age * d0 * d1, p11 * age * d1 * d1
            estimate[2:] = p00, p01, p11
        cx, cy = self._center
        force_unit = 1.0 / (n * math.exp(log_mu))
        qx, qy = fx * force_unit, fy * force_unit
        qm = (m + cy * fx - cx * fy) * force_unit * math.exp(-log_rho)
        if qm < 0.0:  # central symmetry: the table holds the half q_m >= 0
            qx, qy, qm = -qx, -qy, -qm
            if twist is not None:
                vx, vy, w = -vx, -vy, -w
        gauge, share, normal, slope, elevation = self._table.at(qx, qy, qm)
        # Load: y = log g0 = H (x - x_hat), H = (1, share).
        ph0, ph1 = p00 + p01 * share, p01 + p11 * share
        spread = ph0 + share * ph1 + self.noise * self.noise
        if gauge <= math.exp(-GATE_SIGMAS * math.sqrt(spread)):
            return self._reject("inside")
        innovation = math.log(gauge)
        k0, k1 = ph0 / spread, ph1 / spread
        shift = k1 * innovation
        log_mu += k0 * innovation
        log_rho += shift
        p00, p01, p11 = p00 - k0 * ph0, p01 - k0 * ph1, p11 - k1 * ph1
        if twist is not None:
            # Twist: y_t = theta_V - theta_n = h_t (log rho - log rho_hat), linearised at the
            # same point as the load (its innovation less the load's shift of log rho).
            rate = w * math.exp(estimate[1])
            speed = math.hypot(vx - cy * w, vy + cx * w)
            observed = math.atan2(rate, speed)
            lever = 1.0 / (rate * rate + speed * speed)
            h = -rate * speed * lever - slope * math.sin(elevation) * math.cos(elevation)
            innovation = observed - normal - h * shift
            spread = h * h * p11 + self.twist_noise * self.twist_noise
            k0, k1 = h * p01 / spread, h * p11 / spread
            log_mu += k0 * innovation
            log_rho += k1 * innovation
            p00, p01, p11 = p00 - k0 * h * p01, p01 - k0 * h * p11, p11 - k1 * h * p11
        estimate[:] = log_mu, log_rho, p00, p01, p11
        self._accepted += 1
        return "accepted"

    def _reject(self, reason: str) -> str:
        self._rejected[reason] += 1
        return reason


def _nominal_units(surface) -> tuple[float, float, tuple[float, float], float]:
    """``(mu, rho, center, normal_force)`` of a nominal surface; see :class:`SlipEstimator`."""
    if isinstance(surface, LimitSurface):
        if surface.frictionless:
            raise InvalidArgumentError(
                "the nominal surface is frictionless: give it a friction coefficient (a guess "
                "will do; the estimator corrects it)"
            )
        center, rho, _ = surface_axis(surface)
        return surface.max_force / surface.normal_force, rho, center, surface.normal_force
    if isinstance(surface, Ellipsoid | FittedEllipsoid):
        if surface.frictionless:
            raise InvalidArgumentError(
                f"the nominal {type(surface).__name__} is frictionless: give it a friction "
                "coefficient (a guess will do; the estimator corrects it)"
            )
        return surface.mu, surface.rho, surface.center, surface.normal_force
    raise InvalidArgumentError(
        "surface must be a fixplan.LimitSurface, an Ellipsoid or a FittedEllipsoid, got "
        f"{type(surface).__name__} (for an Exact model pass the LimitSurface it was built from)"
    )
