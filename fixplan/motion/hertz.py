r"""Linearised elastic contact stiffness of simple shapes pressed on a flat, for the springs of
:mod:`fixplan.motion.compliance`.

Each function returns the :class:`~fixplan.motion.compliance.Stiffness` of one contact at a
given normal preload: the slope of the force–approach law there (normal) and the sticking
(no-slip) stiffness of the contact patch against a tangential force and a twist about the normal,
at zero tangential load. Both bodies are linear elastic and, near the contact, half-spaces; the
interaction of normal and tangential tractions between dissimilar materials is neglected (it
vanishes for like materials), as in the Mindlin stiffness quoted by J85. Per body, with Young's
modulus ``E``, Poisson ratio ``ν`` and shear modulus ``G = E / (2 (1 + ν))``, the contact
modulus is ``1/E* = Σ (1 - ν²)/E`` and the compliances of the two bodies add.

References: K. L. Johnson, *Contact Mechanics*, CUP 1985 (J85); R. D. Mindlin, J. Appl. Mech.
16 (1949) 259–268; J. L. Lubkin, J. Appl. Mech. 18 (1951) 183–187; E. Reissner and
H. F. Sagoci, J. Appl. Phys. 15 (1944) 652–654; G. Lundberg, Forsch. Ing.-Wes. 10 (1939)
201–211. Section and equation numbers of J85 are cited as recalled: the book's text was not at
hand to check them. Every closed form here is re-derived in ``tests/test_hertz.py``.
"""

from __future__ import annotations

import math

from fixplan import validation
from fixplan.errors import InvalidArgumentError
from fixplan.motion.compliance import ComplianceError, Stiffness

#: A line contact's half-width may be at most this fraction of its length: the cylinder's
#: formulas are leading order in ``b / L`` (their error is of that order).
MAX_WIDTH_TO_LENGTH = 0.1


def hertz_sphere(
    *,
    radius: float,
    preload: float,
    young: float,
    poisson: float,
    young_flat: float,
    poisson_flat: float,
) -> Stiffness:
    r"""Stiffness of a sphere pressed on a flat, linearised at its preload.

    Hertz (J85 §4.2, eqs 4.22–4.23): ``F = (4/3) E* √R d^{3/2}`` between the normal force and
    the approach ``d``, with contact radius ``a = √(R d) = (3 F R / (4 E*))^{1/3}``. Its slope
    is the normal stiffness. Sticking against a tangential force, the contact circle of each
    body translates as a rigid disc by ``Q (2 - ν) / (8 G a)`` (Mindlin 1949; J85 §7.2), and
    against a twist it turns as a rigid disc by ``3 M / (16 G a³)`` (Lubkin 1951, from the
    bonded punch of Reissner and Sagoci 1944; J85 §7.3). Adding the two bodies' compliances,

    .. math:: k_n = 2 E^* a, \qquad k_t = 8 G^* a, \qquad k_r = \tfrac{16}{3} G_r a^3,
        \qquad \frac{1}{G^*} = \sum \frac{2 - ν}{G}, \quad \frac{1}{G_r} = \sum \frac1G.

    ``k_t`` and ``k_r`` are the initial (zero tangential load) stick stiffnesses; partial slip
    softens both as the load nears the friction limit.

    Parameters
    ----------
    radius : float
        Sphere radius [m], > 0.
    preload : float
        Normal force at which the law is linearised [N], > 0.
    young, poisson : float
        Young's modulus [Pa], > 0, and Poisson ratio [-], in (-1, 0.5), of the sphere (finger
        tip, locator pin).
    young_flat, poisson_flat : float
        Those of the flat (the part).

    Returns
    -------
    Stiffness
        ``normal`` and ``tangential`` [N/m], ``torsional`` [N m/rad].

    Raises
    ------
    ComplianceError
        An argument is out of range (the message names it).
    """
    try:
        R = validation.positive_scalar("radius", radius)
        F = validation.positive_scalar("preload", preload)
    except InvalidArgumentError as exc:
        raise ComplianceError(str(exc)) from None
    materials = _materials(young, poisson, young_flat, poisson_flat)
    e_star = 1.0 / sum((1.0 - nu**2) / e for e, nu, _ in materials)
    g_star = 1.0 / sum((2.0 - nu) / g for _, nu, g in materials)
    g_twist = 1.0 / sum(1.0 / g for _, _, g in materials)
    a = (3.0 * F * R / (4.0 * e_star)) ** (1.0 / 3.0)
    return Stiffness(
        normal=2.0 * e_star * a, tangential=8.0 * g_star * a, torsional=16.0 / 3.0 * g_twist * a**3
    )


def hertz_cylinder(
    *,
    radius: float,
    length: float,
    preload: float,
    young: float,
    poisson: float,
    young_flat: float,
    poisson_flat: float,
) -> Stiffness:
    r"""Stiffness of a cylinder lying along a flat (a line contact), linearised at its preload.

    The contact is a strip of length ``L`` and half-width ``b = √(4 F R / (π L E*))`` (J85 §4.2,
    eq 4.43, with force ``F / L`` per length). In plane strain the approach of a line contact
    depends on where it is measured from (logarithmically); here, as in Lundberg (1939), both
    bodies are half-spaces loaded over the finite strip, pressure uniform along it and
    semi-elliptic across it (end effects neglected), and the approach is that of the strip's
    middle relative to the bodies far away (3-D, so no datum is needed):

    .. math:: d = \frac{2 F}{π L E^*} \Big(\ln\frac{L}{2b} + \ln 4 + \tfrac12\Big),
        \qquad k_n = \frac{dF}{dd} = \frac{π L E^*}{2 \ln(2L/b)},

    differentiated analytically (``b ∝ √F``). Lundberg's constant, quoted as 1.8864 in the
    bearing literature, is ``ln 4 + 1/2 = 1.8863`` (re-derived from Boussinesq's point load).
    The cylinder is treated as a half-space too: for a cylinder longer than ``2R/e`` pressed
    across its diameter, J85's eq 4.45 gives it a smaller compliance
    ``(2 (1 - ν²)/(π L E)) (ln(4R/b) - 1)`` than its half-space term
    ``(2 (1 - ν²)/(π L E)) ln(2L/b)``, so there ``k_n`` is on the low side.

    No sourced formula was found for the sticking stiffnesses of a finite strip. ``k_t`` and
    ``k_r`` are therefore lower bounds, derived here, on the stiffness of the strip bonded
    (stuck) to each half-space: by minimum complementary energy, any traction with the right
    resultant gives ``k ≥ Q² / ∫ t·u`` (Cerruti's point-force displacements, J85 ch. 3). With
    the traction uniform along the strip (linear along it for the twist) and
    ``∝ (b² - x²)^{-1/2}`` across it (the bonded strip in plane strain, J85 ch. 2), to leading
    order in ``b / L`` and with ``Λ = ln(4L/b)``, each body's compliance is

    .. math:: \frac{(1 - ν)(Λ - 1) + ν}{π G L} \text{ (across the axis)}, \qquad
        \frac{Λ - 1 - ν}{π G L} \text{ (along it)}, \qquad
        \frac{12 \,[(1 - ν)(Λ - 7/3) + ν]}{π G L^3} \text{ (twist)}.

    ``k_t`` is the smaller of the two directions (along the axis for ``ν > 0``; for steel some
    20 % below the bound across it), so that it bounds both from below.

    Parameters
    ----------
    radius : float
        Cylinder radius [m], > 0.
    length : float
        Length of the line of contact [m], > 0.
    preload : float
        Normal force at which the law is linearised [N], > 0.
    young, poisson : float
        Young's modulus [Pa], > 0, and Poisson ratio [-], in (-1, 0.5), of the cylinder.
    young_flat, poisson_flat : float
        Those of the flat (the part).

    Returns
    -------
    Stiffness
        ``normal`` and ``tangential`` [N/m], ``torsional`` [N m/rad].

    Raises
    ------
    ComplianceError
        An argument is out of range (the message names it), or the preload spreads the contact
        wider than :data:`MAX_WIDTH_TO_LENGTH` of its length (not a line contact).
    """
    try:
        R = validation.positive_scalar("radius", radius)
        L = validation.positive_scalar("length", length)
        F = validation.positive_scalar("preload", preload)
    except InvalidArgumentError as exc:
        raise ComplianceError(str(exc)) from None
    materials = _materials(young, poisson, young_flat, poisson_flat)
    e_star = 1.0 / sum((1.0 - nu**2) / e for e, nu, _ in materials)
    b = math.sqrt(4.0 * F * R / (math.pi * L * e_star))
    if b > MAX_WIDTH_TO_LENGTH * L:
        raise ComplianceError(
            f"preload {F!r} N spreads the contact to a half-width {b:.3g} m, more than "
            f"{MAX_WIDTH_TO_LENGTH} of its length {L!r} m: not a line contact"
        )
    log = math.log(4.0 * L / b)
    across = sum(((1.0 - nu) * (log - 1.0) + nu) / g for _, nu, g in materials)
    along = sum((log - 1.0 - nu) / g for _, nu, g in materials)
    twist = sum(12.0 * ((1.0 - nu) * (log - 7.0 / 3.0) + nu) / g for _, nu, g in materials)
    return Stiffness(
        normal=math.pi * L * e_star / (2.0 * math.log(2.0 * L / b)),
        tangential=math.pi * L / max(across, along),
        torsional=math.pi * L**3 / twist,
    )


def _materials(young, poisson, young_flat, poisson_flat) -> list[tuple[float, float, float]]:
    """``(E, ν, G)`` of the shape and of the flat, checked."""
    materials = []
    for suffix, e, nu in (("", young, poisson), ("_flat", young_flat, poisson_flat)):
        try:
            e = validation.positive_scalar(f"young{suffix}", e)
            nu = validation.finite_scalar(f"poisson{suffix}", nu)
        except InvalidArgumentError as exc:
            raise ComplianceError(str(exc)) from None
        if not -1.0 < nu < 0.5:
            raise ComplianceError(f"poisson{suffix} must lie in (-1, 0.5), got {nu!r}")
        materials.append((e, nu, e / (2.0 * (1.0 + nu))))
    return materials
