r"""Mirror symmetries of a layout problem, so that equivalent layouts are solved once.

The transforms tried are the eight sign flips ``x -> c + S (x - c)``, ``S = diag(±1, ±1, ±1)``,
about the centre of mass ``c``. Forces map by ``S``; moments (pseudovectors) by ``det(S) S``, so
a wrench about ``c`` maps as ``(f, m) -> (S f, det(S) S m)``. A transform is a symmetry of the
problem when it keeps gravity, maps the set of task wrenches (about ``c``) onto itself, and maps
every contact onto one of the same kind (fixed or candidate), role, friction coefficient, given
forces and friction model, at the mapped position, normal and centre of pressure, with the
friction set mapped onto that contact's: in contact coordinates ``(ft1, ft2, mn)`` the map is

.. math:: M = \begin{pmatrix} t_1'^T S t_1 & t_1'^T S t_2 & 0 \\
                              t_2'^T S t_1 & t_2'^T S t_2 & 0 \\ 0 & 0 & \det S \end{pmatrix}

and the model must give every load ``ℓ`` and ``M ℓ`` the same safety factor (checked on a fixed
set of random loads; an improper ``S`` mirrors the patch, which a disk or a centred rectangle
allows and a general polygon does not). The objective values of the planner (sums and maxima
over contacts and load cases) are then the same for a layout and its image.
"""

from __future__ import annotations

import itertools

import numpy as np

from fixplan.models.base import FrictionModel
from fixplan.planner.problem import Problem

#: Relative tolerance of the matches (positions against the problem's size, directions,
#: wrenches against the largest, safety factors).
SYMMETRY_RTOL = 1e-9
#: Random loads on which a friction model's invariance under a map is checked.
PROBE_LOADS = 32
#: Relative tolerance of the safety factors of a probe load and its image (quadrature noise of
#: the exact model stays far below it).
PROBE_RTOL = 1e-6


def symmetries(
    problem: Problem, models: list[FrictionModel], candidates: set[int], length_scale: float
) -> list[np.ndarray]:
    """The contact permutations ``(C,)`` of the problem's symmetries (identity included)."""
    center = problem.body.center_of_mass
    found = []
    for signs in itertools.product((1.0, -1.0), repeat=3):
        flip = np.array(signs)
        permutation = _permutation(problem, models, candidates, center, flip, length_scale)
        if permutation is not None:
            found.append(permutation)
    return found


def canonical(layout: tuple[int, ...], permutations: list[np.ndarray]) -> tuple[int, ...]:
    """The representative of ``layout``'s orbit: the smallest of its sorted images."""
    return min(tuple(sorted(int(p[i]) for i in layout)) for p in permutations)


def _permutation(problem, models, candidates, center, flip, length_scale):
    gravity = problem.body.gravity
    if np.abs(flip * gravity - gravity).max() > SYMMETRY_RTOL * max(np.abs(gravity).max(), 1.0):
        return None
    if not _maps_loads(problem, center, flip, length_scale):
        return None
    contacts = problem.contacts
    permutation = np.full(len(contacts), -1)
    for i, contact in enumerate(contacts):
        for j, other in enumerate(contacts):
            # (Each image once: coincident contacts, alike, take their images in turn.)
            if j not in permutation and (
                _maps_contact(contact, other, models[i], models[j], center, flip, length_scale)
                and (i in candidates) == (j in candidates)
            ):
                permutation[i] = j
                break
        else:
            return None
    return permutation


def _maps_loads(problem, center, flip, length_scale) -> bool:
    wrenches = problem.task_wrenches()
    about_center = wrenches.copy()
    about_center[3:] -= np.cross(center, wrenches[:3].T).T
    about_center[3:] /= length_scale
    mapped = about_center * np.concatenate([flip, np.prod(flip) * flip])[:, None]
    tolerance = SYMMETRY_RTOL * max(np.abs(about_center).max(), 1.0)
    unused = set(range(wrenches.shape[1]))
    for column in mapped.T:
        match = next(
            (j for j in unused if np.abs(about_center[:, j] - column).max() <= tolerance), None
        )
        if match is None:
            return False
        unused.discard(match)
    return True


def _maps_contact(contact, other, model, other_model, center, flip, length_scale) -> bool:
    if (contact.role, contact.mu, contact.force, contact.max_force) != (
        other.role,
        other.mu,
        other.force,
        other.max_force,
    ):
        return False
    distance = SYMMETRY_RTOL * length_scale
    for point, image in (
        (contact.position, other.position),
        (contact.center_of_pressure, other.center_of_pressure),
    ):
        if np.abs(center + flip * (point - center) - image).max() > distance:
            return False
    if np.abs(flip * contact.normal - other.normal).max() > SYMMETRY_RTOL:
        return False
    if not _same_form(model, other_model):
        return False
    frame, image = contact.frame, other.frame
    mapped = np.zeros((3, 3))
    mapped[:2, :2] = image[:2] @ (flip[:, None] * frame[:2].T)
    mapped[2, 2] = np.prod(flip)
    return _invariant(model, mapped[: model.load_dimension, : model.load_dimension])


def _same_form(model, other) -> bool:
    if model is other:
        return True
    a, b = model.conic_form(), other.conic_form()
    pairs = ((a.normal, b.normal), (a.load, b.load), (a.aux, b.aux))
    return a.cones == b.cones and all(np.array_equal(x, y) for x, y in pairs)


def _invariant(model, mapped: np.ndarray) -> bool:
    """Whether ``model`` gives every probe load and its image under ``mapped`` the same safety
    factor."""
    if model.frictionless or np.allclose(mapped, np.eye(len(mapped)), rtol=0, atol=SYMMETRY_RTOL):
        return True
    rng = np.random.default_rng(0)
    units = np.array([model.mu, model.mu, model.mu * max(model.rho, 1e-3)])[: len(mapped)]
    loads = rng.standard_normal((PROBE_LOADS, len(mapped))) * units
    before = model.safety_factor(loads)
    after = model.safety_factor(loads @ mapped.T)
    return bool(np.allclose(before, after, rtol=PROBE_RTOL, atol=0.0))
