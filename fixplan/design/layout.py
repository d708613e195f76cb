"""Layout synthesis: which of the candidate contacts to use (issue 14 §3).

:func:`search` picks, from candidate contacts (templates at candidate positions, given or from
:func:`~fixplan.design.candidates.sample_surface`), how many of each role ``choose`` asks for, so
that the problem's objective is best, and returns the best layouts with their plans.

- **Exact mode**: every combination per role is enumerated. A layout whose objective has nothing
  to choose is invalid; one that fails the cheap feasibility test (:mod:`fixplan.design.prune`)
  cannot hold and is skipped; layouts that a mirror symmetry of the problem maps onto each other
  (:mod:`fixplan.design.symmetry`) are solved once. The others are re-solved by one planner over
  all contacts with the contacts left out switched off (:mod:`fixplan.design.evaluator`), so the
  optimum is the global one over the layouts (to the solver's tolerance).
- **Large mode** (hundreds of candidates): the reweighted group-sparse relaxation
  (:mod:`fixplan.design.relaxation`) ranks the candidates by the force they carry; the
  ``choose`` counts with the most force per role start a best-improvement local search over
  swaps of one candidate (and additions or removals within a range), the swaps drawn from the
  ``SWAP_POOL`` best-ranked candidates of the role; ``KICKS`` restarts from the best layout with
  up to ``KICK_SIZE`` candidates per role swapped at random (seeded) escape some of its local
  optima. It finds a local optimum, not a proven one.
- ``mode="auto"``: exact when the enumeration has at most ``EXACT_MAX_LAYOUTS`` layouts.

The plans of the layouts returned are solved again on their own problems (only the chosen and the
fixed contacts), so that they list only those contacts.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from fixplan.design.evaluator import Counts, Evaluator
from fixplan.design.relaxation import relaxed_forces
from fixplan.design.symmetry import canonical, symmetries
from fixplan.errors import InvalidArgumentError
from fixplan.planner.plan import Plan
from fixplan.planner.planner import Planner
from fixplan.planner.problem import ROLES, Contact, Problem

MODES = ("auto", "exact", "large")
#: ``mode="auto"`` enumerates up to this many layouts, and runs the large mode above.
EXACT_MAX_LAYOUTS = 5000
#: Candidates per role, best-ranked by the relaxation, that the large mode's swaps draw from.
SWAP_POOL = 24
#: Restarts of the large mode's descent from a kicked copy of the best layout (iterated local
#: search), and how many candidates of each role a kick swaps.
KICKS = 8
KICK_SIZE = 2
#: A candidate carries force in the relaxation when its force is above this fraction of the
#: largest.
ACTIVE_RTOL = 1e-3


@dataclass(frozen=True, slots=True, kw_only=True)
class Layout:
    """A layout found by :func:`search`.

    Attributes
    ----------
    contacts : tuple of str
        Names of the candidates it uses (the problem's fixed contacts are used too).
    objective_value : float
        The objective's value [N, N² or the safety factor, as :attr:`Plan.objective_value`].
    plan : Plan
        The plan of the problem with these candidates and the fixed contacts.
    equivalents : tuple of tuple of str
        The other layouts that a mirror symmetry of the problem maps it onto (same value).
    """

    contacts: tuple[str, ...]
    objective_value: float
    plan: Plan
    equivalents: tuple[tuple[str, ...], ...] = ()


@dataclass(frozen=True, slots=True, kw_only=True)
class SearchStats:
    """What a search did.

    Attributes
    ----------
    mode : str
        ``"exact"`` or ``"large"``.
    layouts : int
        Layouts enumerated (exact) or visited (large).
    merged : int
        Layouts not solved because a symmetric one was (exact mode).
    symmetries : int
        Mirror symmetries of the problem found, the identity included.
    invalid, pruned, solved, feasible : int
        See :class:`~fixplan.design.evaluator.Counts`.
    seconds : float
        Wall time [s].
    """

    mode: str
    layouts: int
    merged: int
    symmetries: int
    invalid: int
    pruned: int
    solved: int
    feasible: int
    seconds: float


class LayoutSearch:
    """A layout search over ``candidates`` for ``problem`` (see :func:`search`).

    The planner over all contacts and the symmetries are built on construction; :meth:`run`
    searches and leaves what it did in :attr:`stats`.
    """

    def __init__(
        self,
        problem: Problem,
        candidates: Sequence[Contact],
        *,
        choose: Mapping[str, int | tuple[int, int]],
        objective: str | None = None,
        prune: bool = True,
        symmetry: bool = True,
    ):
        if not isinstance(problem, Problem):
            raise InvalidArgumentError(f"problem must be a Problem, got {type(problem).__name__}")
        candidates = tuple(candidates)
        if not candidates or not all(isinstance(c, Contact) for c in candidates):
            raise InvalidArgumentError("candidates must be a non-empty sequence of Contacts")
        own = {c.name: c for c in problem.contacts}
        for contact in candidates:
            if contact.name in own and own[contact.name] is not contact:
                raise InvalidArgumentError(
                    f"candidate {contact.name!r} has the name of another contact of the problem"
                )
        names = {c.name for c in candidates}
        fixed = tuple(c for c in problem.contacts if c.name not in names)
        contacts = fixed + candidates
        objective = problem.objective if objective is None else objective
        full = Problem(body=problem.body, contacts=contacts, loads=problem.loads,
                       objective=objective)  # fmt: skip
        self.fixed = tuple(range(len(fixed)))
        self.roles = _choose(choose, candidates, len(fixed))
        self.evaluator = Evaluator(full, prune=prune)
        self.permutations = [np.arange(len(contacts))]
        if symmetry:
            self.permutations = symmetries(
                full, self.evaluator.planner.models, set(range(len(fixed), len(contacts))),
                self.evaluator.planner.length_scale,
            )  # fmt: skip
        self.stats: SearchStats | None = None

    @property
    def size(self) -> int:
        """Number of layouts of the exact enumeration."""
        return math.prod(
            sum(math.comb(len(members), k) for k in range(low, high + 1))
            for members, low, high in self.roles.values()
        )

    def run(self, *, top: int = 5, mode: str = "auto") -> list[Layout]:
        """The ``top`` best layouts, best first (fewer if fewer hold; none if none does)."""
        if mode not in MODES:
            raise InvalidArgumentError(f"mode must be one of {', '.join(MODES)}; got {mode!r}")
        if isinstance(top, bool) or not isinstance(top, int) or top < 1:
            raise InvalidArgumentError(f"top must be a positive integer, got {top!r}")
        if mode == "auto":
            mode = "exact" if self.size <= EXACT_MAX_LAYOUTS else "large"
        start = time.perf_counter()
        self.evaluator.counts = Counts()
        if mode == "exact":
            ranked, layouts, merged = self._exact()
        else:
            ranked, layouts, merged = self._large(), 0, 0
            layouts = self.evaluator.counts.solved + self.evaluator.counts.pruned
        best = [self._layout(layout, others) for layout, others in ranked[:top]]
        counts = self.evaluator.counts
        self.stats = SearchStats(
            mode=mode, layouts=layouts, merged=merged, symmetries=len(self.permutations),
            invalid=counts.invalid, pruned=counts.pruned, solved=counts.solved,
            feasible=counts.feasible, seconds=time.perf_counter() - start,
        )  # fmt: skip
        return best

    # -- modes -----------------------------------------------------------------------------------

    def _exact(self):
        orbits: dict[tuple[int, ...], list[tuple[int, ...]]] = {}
        count = 0
        for layout in self._enumerate():
            count += 1
            orbits.setdefault(canonical(layout, self.permutations), []).append(layout)
        scored = []
        for representative, members in orbits.items():
            score = self.evaluator.score(representative)
            if math.isfinite(score):
                others = tuple(m for m in members if m != representative)
                scored.append((score, representative, others))
        scored.sort(key=lambda item: (item[0], item[1]))
        return [(layout, others) for _, layout, others in scored], count, count - len(orbits)

    def _enumerate(self):
        per_role = [
            [c for k in range(low, high + 1) for c in itertools.combinations(members, k)]
            for members, low, high in self.roles.values()
        ]
        for parts in itertools.product(*per_role):
            yield tuple(sorted(self.fixed + tuple(i for part in parts for i in part)))

    def _large(self):
        evaluator = self.evaluator
        chosen_count = sum(high for _, _, high in self.roles.values())
        forces = relaxed_forces(evaluator.planner, chosen_count + len(self.fixed))
        if forces is None:
            return []
        ranking = {
            role: sorted(members, key=lambda i: -forces[i])
            for role, (members, _, _) in self.roles.items()
        }
        carrying = forces > ACTIVE_RTOL * max(forces.max(), 1e-12)
        current = {}
        for role, (members, low, high) in self.roles.items():
            wanted = min(max(int(carrying[list(members)].sum()), low), high)
            current[role] = tuple(ranking[role][:wanted])
        score, current = self._descend(current, ranking)
        rng = np.random.default_rng(0)
        for _ in range(KICKS):
            kicked = self._kick(current, ranking, rng)
            kicked_score, kicked = self._descend(kicked, ranking)
            if kicked_score < score:
                score, current = kicked_score, kicked
        return [(visited, ()) for visited in evaluator.ranked()]

    def _descend(self, current, ranking):
        """Best-improvement descent over :meth:`_moves` from ``current``: its score and layout
        (per role)."""
        evaluator = self.evaluator
        layout = self._join(current)
        score = evaluator.score(layout)
        while True:
            moves = [
                (evaluator.score(self._join(m)), self._join(m))
                for m in self._moves(current, ranking)
            ]
            better = min(moves, default=(math.inf, None))
            if not better[0] < score:
                return score, current
            score, layout = better
            current = self._split(layout)

    def _kick(self, current, ranking, rng):
        """``current`` with up to ``KICK_SIZE`` candidates of each role swapped for random ones
        of its pool: a restart that a single swap cannot reach."""
        kicked = {}
        for role, chosen in current.items():
            pool = [i for i in ranking[role] if i not in chosen][:SWAP_POOL]
            count = min(KICK_SIZE, len(chosen), len(pool))
            out = set(rng.choice(len(chosen), count, replace=False).tolist()) if count else set()
            into = rng.choice(pool, count, replace=False).tolist() if count else []
            kicked[role] = (*(c for k, c in enumerate(chosen) if k not in out), *into)
        return kicked

    def _moves(self, current, ranking):
        for role, (_, low, high) in self.roles.items():
            chosen = current[role]
            pool = [i for i in ranking[role] if i not in chosen][:SWAP_POOL]
            for out in chosen:
                for into in pool:
                    kept = tuple(i for i in chosen if i != out)
                    yield {**current, role: (*kept, into)}
                if len(chosen) > low:
                    yield {**current, role: tuple(i for i in chosen if i != out)}
            if len(chosen) < high:
                for into in pool:
                    yield {**current, role: (*chosen, into)}

    def _join(self, parts) -> tuple[int, ...]:
        return tuple(sorted(self.fixed + tuple(i for part in parts.values() for i in part)))

    def _split(self, layout):
        return {
            role: tuple(i for i in layout if i in set(members))
            for role, (members, _, _) in self.roles.items()
        }

    def _layout(self, layout, others) -> Layout:
        contacts = self.evaluator.problem.contacts
        plan = Planner(self.evaluator.subproblem(layout)).solve()

        def names(indices):
            return tuple(contacts[i].name for i in indices if i not in self.fixed)

        return Layout(
            contacts=names(layout),
            objective_value=plan.objective_value,
            plan=plan,
            equivalents=tuple(names(other) for other in others),
        )


def search(
    problem: Problem,
    candidates: Sequence[Contact],
    *,
    choose: Mapping[str, int | tuple[int, int]],
    objective: str | None = None,
    top: int = 5,
    mode: str = "auto",
) -> list[Layout]:
    """The best layouts of ``candidates`` for ``problem``, best first.

    Parameters
    ----------
    problem : Problem
        The body, the loads, the objective and the fixed contacts: its contacts that are not
        among ``candidates`` (a problem needs a contact: to search with none fixed, give a
        problem whose contacts are the candidates themselves).
    candidates : sequence of Contact
        The candidate contacts (role, model, patch, ``mu``, forces at a candidate position).
    choose : mapping
        Role -> how many of its candidates a layout uses: a count, or ``(min, max)``. Every role
        of the candidates needs one.
    objective : str, optional
        Replaces the problem's objective. Force objectives are minimised, the safety factor of
        the fixed-force ones maximised.
    top : int
        Number of layouts returned.
    mode : str
        ``"exact"``, ``"large"`` or ``"auto"`` (see the module docstring).

    Returns
    -------
    list of Layout
        Best first; layouts that cannot hold are left out.
    """
    return LayoutSearch(problem, candidates, choose=choose, objective=objective).run(
        top=top, mode=mode
    )


def _choose(choose, candidates, offset) -> dict:
    """Role -> (candidate indices, min, max) from ``choose``."""
    if not isinstance(choose, Mapping) or not choose:
        raise InvalidArgumentError(f"choose must map roles to counts, got {choose!r}")
    roles = {}
    for role, count in choose.items():
        if role not in ROLES:
            raise InvalidArgumentError(
                f"choose: unknown role {role!r}; roles are {', '.join(ROLES)}"
            )
        members = tuple(offset + i for i, c in enumerate(candidates) if c.role == role)
        pair = isinstance(count, Sequence) and not isinstance(count, str) and len(count) == 2
        low, high = tuple(count) if pair else (count, count)
        if not all(isinstance(x, int) and not isinstance(x, bool) for x in (low, high)) or not (
            0 <= low <= high <= len(members)
        ):
            raise InvalidArgumentError(
                f"choose[{role!r}] must be a count or [min, max] with 0 <= min <= max <= "
                f"{len(members)} (the {role} candidates), got {count!r}"
            )
        roles[role] = (members, low, high)
    missing = sorted({c.role for c in candidates} - set(roles))
    if missing:
        raise InvalidArgumentError(
            f"choose gives no count for the candidates' roles {', '.join(missing)}"
        )
    return roles
