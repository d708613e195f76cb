"""How much of its friction set each contact load uses, for all contacts and cases at once.

Verification and the safety analysis ask this of every (contact, load case) after each solve. A
model whose gauge is a sum of norms and maxima of linear maps of the load
(:meth:`~fixplan.models.FrictionModel.gauge_terms`: ellipsoids, cones, pyramids, polytopes) is
checked for all its cases in one compiled loop; the others (exact, SDP and faceted models,
frictionless contacts) are asked one by one through their ``safety_factor``.
"""

from __future__ import annotations

import numpy as np

from fixplan.models.base import FrictionModel
from fixplan.surface.point_kernel import compiled_scalar

#: Kinds of gauge terms, as the compiled loop numbers them.
_KINDS = {"norm": 0, "max": 1}


class FrictionUse:
    """The fraction of its friction set that each contact's friction load uses.

    Parameters
    ----------
    models : sequence of FrictionModel
        The friction model of each contact.
    slices : sequence of slice
        Rows of each contact's friction load in the stacked friction loads ``(D, K)``.
    """

    def __init__(self, models, slices):
        self._models = tuple(models)
        self._slices = tuple(slices)
        self._starts = np.array([part.start for part in self._slices], dtype=np.intp)
        self._stops = np.array([part.stop for part in self._slices], dtype=np.intp)
        width = int(max((self._stops - self._starts).max(initial=0), 1))
        self._asked = np.zeros(len(self._models), dtype=np.bool_)
        rows, kinds, owners, first = [], [], [], [0]
        for i, model in enumerate(self._models):
            terms = model.gauge_terms()
            if terms is None:
                self._asked[i] = True
                continue
            for kind, matrix in terms:
                padded = np.zeros((len(matrix), width))
                padded[:, : matrix.shape[1]] = matrix
                rows.append(padded)
                kinds.append(_KINDS[kind])
                owners.append(i)
                first.append(first[-1] + len(matrix))
        self._rows = np.vstack(rows) if rows else np.zeros((0, width))
        self._kinds = np.array(kinds, dtype=np.intp)
        self._owners = np.array(owners, dtype=np.intp)
        self._first = np.array(first, dtype=np.intp)
        self._any_asked = bool(self._asked.any())

    def __call__(
        self,
        friction: np.ndarray,
        normal: np.ndarray,
        *,
        noise: float,
        known: np.ndarray | None = None,
    ) -> np.ndarray:
        """Use ``(C, K)`` of loads ``friction`` ``(D, K)`` at normal forces ``normal`` ``(C, K)``
        [N]: 1 on the limit; 0 where the load and the normal force are within ``noise`` [N] of
        0 (solver noise); ``inf`` for a load on a contact without normal force or friction.

        ``known`` ``(C, K)`` holds uses already computed for these very loads (the cutting
        rounds of exact models ask the exact surfaces); where it is finite, the contacts asked
        one by one are not asked again.
        """
        friction = np.ascontiguousarray(friction, dtype=float)
        normal = np.ascontiguousarray(normal, dtype=float)
        use = np.empty(normal.shape)
        _USES(friction, normal, float(noise), self._starts, self._stops, self._asked,
              self._rows, self._kinds, self._owners, self._first, use)  # fmt: skip
        if not self._any_asked:
            return use
        ask = np.isnan(use) & self._asked[:, None]  # pressed and carrying a load
        if known is not None:
            found = ask & np.isfinite(known)
            use[found] = known[found]
            ask &= ~found
        for i in np.flatnonzero(ask.any(axis=1)):
            use[i, ask[i]] = friction_use(
                self._models[i], friction[self._slices[i]].T[ask[i]], normal[i, ask[i]]
            )
        return use


def friction_use(model: FrictionModel, load: np.ndarray, normal_force: np.ndarray) -> np.ndarray:
    """Fraction of its friction set that each load ``(K, d)`` uses at ``normal_force`` ``(K,)``
    (positive) [N], from the model's ``safety_factor``."""
    per_unit = load / normal_force[:, None]  # the model at unit normal force
    safety = np.atleast_1d(model.safety_factor(per_unit, normal_force=1.0))
    with np.errstate(divide="ignore"):
        return 1.0 / safety


def uses(
    friction, normal, noise, starts, stops, asked, rows, kinds, owners, first, out
):  # pragma: no cover - compiled
    """:class:`FrictionUse` for the contacts with gauge terms, into ``out`` ``(C, K)``; NaN
    where a contact of ``asked`` is pressed and carries a load (its model must be asked)."""
    contacts, cases = normal.shape
    gauge = np.zeros(contacts)
    for k in range(cases):
        gauge[:] = 0.0
        for t in range(kinds.shape[0]):
            owner = owners[t]
            start, width = starts[owner], stops[owner] - starts[owner]
            total = 0.0 if kinds[t] == 0 else -np.inf
            for r in range(first[t], first[t + 1]):
                value = 0.0
                for d in range(width):
                    value += rows[r, d] * friction[start + d, k]
                total = total + value * value if kinds[t] == 0 else max(total, value)
            gauge[owner] += np.sqrt(total) if kinds[t] == 0 else total
        for c in range(contacts):
            carries = False
            for d in range(starts[c], stops[c]):
                carries = carries or abs(friction[d, k]) > noise
            if not carries:
                out[c, k] = 0.0
            elif normal[c, k] <= noise:
                out[c, k] = np.inf
            elif asked[c]:
                out[c, k] = np.nan
            else:
                out[c, k] = gauge[c] / normal[c, k]


_USES = compiled_scalar(uses)
