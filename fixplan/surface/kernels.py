r"""Support functions of contact patches: the engine behind :class:`~fixplan.LimitSurface`.

A kernel evaluates, for a batch of twists ``V = (vx, vy, w)`` (``(K, 3)``), the support
(dissipation) function of a patch carrying unit friction (``mu * N = 1``)

.. math:: h(V) = \int \frac{p}{N} \, |v(x)| \, dA, \qquad v(x) = (v_x - w y, v_y + w x),

its gradient, the load :math:`L(V) = \nabla h(V)` (paper eqs. 4-5), and its Hessian, which only
steers Newton's method in the inverse map. Kernels are immutable and work in the contact frame.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np

from fixplan.surface.geometry import Pose, merged_points
from fixplan.tolerances import HESSIAN_STEP


class SupportKernel(ABC):
    """Support function ``h``, load ``∇h`` and Hessian ``∇²h`` of one patch, batched."""

    @property
    @abstractmethod
    def size(self) -> float:
        """Length scale of the patch [m] (radius of a circle about the origin holding it)."""

    @property
    def facets(self) -> tuple[np.ndarray, np.ndarray]:
        """Point supports ``(P, 2)`` [m] and their friction ``(P,)``: the facets of the surface."""
        return np.empty((0, 2)), np.empty(0)

    @abstractmethod
    def evaluate(self, twists: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Support values ``(K,)`` and loads ``(K, 3)`` for nonzero twists ``(K, 3)``."""

    def support(self, twists: np.ndarray) -> np.ndarray:
        """Support values ``(K,)``."""
        return self.evaluate(twists)[0]

    def hessian(self, twists: np.ndarray) -> np.ndarray:
        """Hessians ``(K, 3, 3)`` by central differences of the exact gradient."""
        scale = np.hypot(np.hypot(twists[:, 0], twists[:, 1]), self.size * twists[:, 2])
        hess = np.empty((len(twists), 3, 3))
        for j, unit in enumerate(np.eye(3)):
            step = HESSIAN_STEP * scale / (self.size if j == 2 else 1.0)
            delta = step[:, None] * unit[None, :]
            plus = self.evaluate(twists + delta)[1]
            minus = self.evaluate(twists - delta)[1]
            hess[:, :, j] = (plus - minus) / (2.0 * step[:, None])
        return 0.5 * (hess + hess.transpose(0, 2, 1))

    def newton_terms(self, twists: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Support values, gradients and Hessians in one call."""
        h, g = self.evaluate(twists)
        return h, g, self.hessian(twists)

    def smoothed(self, smoothing: float) -> SupportKernel:
        """This kernel with the kinks of its point supports rounded off over speeds below
        ``smoothing`` (continuous fields have no kinks and return themselves)."""
        return self


def twist_to_local(pose: Pose) -> np.ndarray:
    """Matrix ``T`` (3x3) with ``V_local = T @ V`` for a patch placed by ``pose``.

    The local origin ``t`` moves with ``v + w * J t`` (``J`` the 90-degree rotation); that
    velocity in local axes is ``R^T (v + w J t)`` (``R`` the pose's :attr:`~Pose.rotation`); the
    angular rate is the same in both frames, but for a mirrored pose, whose local frame turns
    the other way: ``-w``.
    """
    rot = pose.rotation
    tx, ty = pose.offset
    transform = np.eye(3)
    transform[:2, :2] = rot.T
    transform[:2, 2] = rot.T @ np.array([-ty, tx])
    transform[2, 2] = -1.0 if pose.mirrored else 1.0
    return transform


@dataclass(frozen=True, slots=True)
class PosedKernel(SupportKernel):
    """A kernel written in a patch's local frame, evaluated in the contact frame."""

    local: SupportKernel
    pose: Pose
    _transform: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "_transform", twist_to_local(self.pose))

    @property
    def size(self) -> float:
        return self.local.size + float(np.hypot(*self.pose.offset))

    @property
    def facets(self):
        points, friction = self.local.facets
        return self.pose.apply(points), friction

    def evaluate(self, twists):
        transform = self._transform
        h, loads = self.local.evaluate(twists @ transform.T)
        return h, loads @ transform

    def hessian(self, twists):
        transform = self._transform
        return transform.T @ self.local.hessian(twists @ transform.T) @ transform

    def newton_terms(self, twists):
        transform = self._transform
        h, g, hess = self.local.newton_terms(twists @ transform.T)
        return h, g @ transform, transform.T @ hess @ transform

    def smoothed(self, smoothing):
        return PosedKernel(self.local.smoothed(smoothing), self.pose)


@dataclass(frozen=True, slots=True)
class SumKernel(SupportKernel):
    """Weighted sum of kernels: the Minkowski sum of their (scaled) limit surfaces."""

    parts: tuple[SupportKernel, ...]
    scales: tuple[float, ...]
    #: The parts' point supports, those at one place one support with their summed friction:
    #: its facet is the whole force's (each copy failed its facet test, and the inverse map
    #: did not converge on 52 of 300 loads of two point sets sharing a point).
    _facets: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        points, friction = zip(*(part.facets for part in self.parts), strict=True)
        scaled = [f * s for f, s in zip(friction, self.scales, strict=True)]
        merged = merged_points(np.concatenate(points), np.concatenate(scaled))
        object.__setattr__(self, "_facets", merged)

    @property
    def size(self) -> float:
        return max(part.size for part in self.parts)

    @property
    def facets(self):
        return self._facets

    def evaluate(self, twists):
        h = np.zeros(len(twists))
        loads = np.zeros((len(twists), 3))
        for part, scale in zip(self.parts, self.scales, strict=True):
            hp, lp = part.evaluate(twists)
            h += scale * hp
            loads += scale * lp
        return h, loads

    def hessian(self, twists):
        return sum(
            scale * part.hessian(twists)
            for part, scale in zip(self.parts, self.scales, strict=True)
        )

    def newton_terms(self, twists):
        h = np.zeros(len(twists))
        g = np.zeros((len(twists), 3))
        hess = np.zeros((len(twists), 3, 3))
        for part, scale in zip(self.parts, self.scales, strict=True):
            hp, gp, hessp = part.newton_terms(twists)
            h += scale * hp
            g += scale * gp
            hess += scale * hessp
        return h, g, hess

    def smoothed(self, smoothing):
        return SumKernel(tuple(p.smoothed(smoothing) for p in self.parts), self.scales)


@dataclass(frozen=True, slots=True)
class EllipsoidKernel(SupportKernel):
    """The support function of an ellipsoid ``L^T A L <= 1`` (a friction model's set rather than
    a patch's): ``h(V) = sqrt(V^T B V)`` with ``B = A^{-1}`` (``inverse``), its load
    ``B V / h(V)`` and Hessian ``(B - B V V^T B / h²) / h`` in closed form."""

    inverse: np.ndarray

    @property
    def size(self) -> float:
        # (The largest moment over the largest force: the lever of the surface's twists.)
        return float(np.sqrt(self.inverse[2, 2] / self.inverse[0, 0]))

    def evaluate(self, twists):
        stretched = twists @ self.inverse
        h = np.sqrt(np.einsum("kc,kc->k", twists, stretched))
        return h, stretched / h[:, None]

    def hessian(self, twists):
        return self.newton_terms(twists)[2]

    def newton_terms(self, twists):
        h, loads = self.evaluate(twists)
        hess = (self.inverse[None] - loads[:, :, None] * loads[:, None, :]) / h[:, None, None]
        return h, loads, hess
