"""How much of its friction set each contact load uses, for all contacts and cases at once.

Verification and the safety analysis ask this of every (contact, load case) after each solve. A
model whose gauge is a sum of norms and maxima of linear maps of the load
(:meth:`~fixplan.models.FrictionModel.gauge_terms`: ellipsoids, cones, pyramids, polytopes) is
checked for all its cases in a few stacked sparse products; the others (exact, SDP and faceted
models, frictionless contacts) are asked one by one through their ``safety_factor``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from fixplan.models.base import FrictionModel

#: Stacked term matrices up to this many entries are kept dense (a sparse product costs about
#: 10 µs of overhead, as much as a dense one of this size).
DENSE_MAX_ENTRIES = 20_000


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
        width = max((part.stop for part in self._slices), default=0)
        blocks = {"norm": [], "max": []}
        self._fallback = []
        for i, (model, part) in enumerate(zip(self._models, self._slices, strict=True)):
            terms = model.gauge_terms()
            if terms is None:
                self._fallback.append(i)
                continue
            for kind, matrix in terms:
                placed = np.zeros((len(matrix), width))
                placed[:, part] = matrix
                blocks[kind].append((placed, i))
        self._terms = {kind: _stacked(found, len(self._models)) for kind, found in blocks.items()}
        self._starts = np.array([part.start for part in self._slices], dtype=np.intp)

    def gauges(self, friction: np.ndarray) -> np.ndarray:
        """Gauges ``(C, K)`` at unit normal force of the loads ``friction`` ``(D, K)``: NaN for
        the contacts asked one by one."""
        out = np.zeros((len(self._models), friction.shape[1]))
        norm, largest = self._terms["norm"], self._terms["max"]
        if norm is not None:
            rows, starts, owners = norm
            values = rows @ friction
            out += owners @ np.sqrt(np.add.reduceat(values * values, starts, axis=0))
        if largest is not None:
            rows, starts, owners = largest
            out += owners @ np.maximum.reduceat(rows @ friction, starts, axis=0)
        out[self._fallback] = np.nan
        return out

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
        use = np.zeros(normal.shape)
        carries = np.maximum.reduceat(np.abs(friction), self._starts, axis=0) > noise
        pressed = carries & (normal > noise)
        use[carries & ~pressed] = np.inf
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = self.gauges(friction) / normal
        use[pressed] = ratio[pressed]
        for i in self._fallback:
            ask = pressed[i]
            if known is not None:
                found = ask & np.isfinite(known[i])
                use[i, found] = known[i, found]
                ask = ask & ~found
            if ask.any():
                use[i, ask] = friction_use(
                    self._models[i], friction[self._slices[i]].T[ask], normal[i, ask]
                )
        return use


def friction_use(model: FrictionModel, load: np.ndarray, normal_force: np.ndarray) -> np.ndarray:
    """Fraction of its friction set that each load ``(K, d)`` uses at ``normal_force`` ``(K,)``
    (positive) [N], from the model's ``safety_factor``."""
    per_unit = load / normal_force[:, None]  # the model at unit normal force
    safety = np.atleast_1d(model.safety_factor(per_unit, normal_force=1.0))
    with np.errstate(divide="ignore"):
        return 1.0 / safety


def _stacked(found: list, contacts: int):
    """The terms of one kind as stacked rows ``(R, D)``, the first row of each term and the map
    ``(C, T)`` from terms to their contacts; ``None`` without terms."""
    if not found:
        return None
    sizes = [len(placed) for placed, _ in found]
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    owners = sp.csr_array(
        (np.ones(len(found)), ([owner for _, owner in found], np.arange(len(found)))),
        shape=(contacts, len(found)),
    )
    rows = np.vstack([placed for placed, _ in found])
    if rows.size <= DENSE_MAX_ENTRIES:  # small products are faster dense
        return rows, starts, owners.toarray()
    return sp.csr_array(rows), starts, owners
