"""Designs of experiments: which values each varied input takes, case by case.

A :class:`Range` names an input (a key, e.g. a key path into a problem file) and the interval it
spans. :func:`grid` takes the Cartesian product of evenly spaced values; :func:`latin_hypercube`
draws ``samples`` cases so that each input's interval, cut into ``samples`` equal strata, has
exactly one case in every stratum. Either gives a table with one row per case, indexed by the
case id (the row number of the design, so that tables of the same design line up) and one column
per key.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from fixplan import validation
from fixplan.errors import InvalidArgumentError

METHODS = ("grid", "lhs")
#: Name of the case id (the index of a design and the first column of a sweep table).
CASE = "case"
#: Most cases of one design (a sweep of ten million cases is a job for several sweeps).
MAX_CASES = 10_000_000
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_RANGE = re.compile(
    rf"^(?P<key>[^=]+)=(?P<start>{_NUMBER}):(?P<stop>{_NUMBER})(?::(?P<count>\d+))?$"
)


@dataclass(frozen=True, slots=True, kw_only=True)
class Range:
    """An input varied from ``start`` to ``stop`` (inclusive, in the input's own units).

    ``count`` is the number of evenly spaced values of a grid; a Latin hypercube takes its
    number of cases from ``samples`` instead and leaves ``count`` out.
    """

    key: str
    start: float
    stop: float
    count: int | None = None

    def __post_init__(self):
        if not isinstance(self.key, str) or not self.key.strip():
            raise InvalidArgumentError(f"key must be a non-empty string, got {self.key!r}")
        for name in ("start", "stop"):
            object.__setattr__(self, name, validation.finite_scalar(name, getattr(self, name)))
        if self.count is not None:
            object.__setattr__(self, "count", validation.positive_int("count", self.count))
        if self.start == self.stop and self.count not in (None, 1):
            raise InvalidArgumentError(
                f"{self.key}: start and stop are both {self.start:g}; give count 1 or a range"
            )

    @classmethod
    def parse(cls, text: str) -> Range:
        """A range written ``KEY=start:stop:count`` (``KEY=start:stop`` for a Latin hypercube)."""
        match = _RANGE.match(text.strip())
        if match is None:
            raise InvalidArgumentError(
                f"--vary {text!r}: expected KEY=start:stop:count (e.g. contacts[1].mu=0.2:0.4:5; "
                "KEY=start:stop with --method lhs)"
            )
        count = match["count"]
        return cls(
            key=match["key"].strip(),
            start=float(match["start"]),
            stop=float(match["stop"]),
            count=None if count is None else int(count),
        )

    def values(self) -> np.ndarray:
        """The grid values: ``count`` of them, evenly spaced from start to stop."""
        if self.count is None:
            raise InvalidArgumentError(f"{self.key}: a grid needs a count (KEY=start:stop:count)")
        return np.linspace(self.start, self.stop, self.count)


def grid(ranges: Sequence[Range]) -> pd.DataFrame:
    """The Cartesian product of the ranges' values; the last key varies fastest."""
    _check_keys(ranges)
    rows = list(itertools.product(*(r.values() for r in ranges)))
    return _design(ranges, np.array(rows, dtype=float).reshape(len(rows), len(ranges)))


def latin_hypercube(ranges: Sequence[Range], *, samples: int, seed: int = 0) -> pd.DataFrame:
    """``samples`` cases of a Latin hypercube over the ranges (scipy's
    :class:`~scipy.stats.qmc.LatinHypercube`, points scattered within their strata), the same
    for the same ``seed``."""
    from scipy.stats import qmc

    _check_keys(ranges)
    samples = validation.positive_int("samples", samples)
    if samples > MAX_CASES:
        raise InvalidArgumentError(f"samples must be at most {MAX_CASES:,}, got {samples:,}")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise InvalidArgumentError(f"seed must be an integer >= 0, got {seed!r}")
    counted = [r.key for r in ranges if r.count is not None]
    if counted:
        raise InvalidArgumentError(
            f"{', '.join(counted)}: a Latin hypercube takes no count (its cases are --samples); "
            "give KEY=start:stop"
        )
    unit = qmc.LatinHypercube(len(ranges), seed=np.random.default_rng(int(seed))).random(samples)
    low = np.array([r.start for r in ranges])
    high = np.array([r.stop for r in ranges])
    return _design(ranges, low + unit * (high - low))


def design(
    ranges: Sequence[Range], *, method: str = "grid", samples: int | None = None, seed: int = 0
) -> pd.DataFrame:
    """The cases of ``method`` (``"grid"`` or ``"lhs"``) over ``ranges``."""
    method = validation.choice("method", method, METHODS)
    if method == "grid":
        if samples is not None:
            raise InvalidArgumentError("samples is for method 'lhs'; a grid has one case per point")
        return grid(ranges)
    if samples is None:
        raise InvalidArgumentError("method 'lhs' needs the number of samples (--samples N)")
    return latin_hypercube(ranges, samples=samples, seed=seed)


def _check_keys(ranges: Sequence[Range]) -> None:
    if not ranges or not all(isinstance(r, Range) for r in ranges):
        raise InvalidArgumentError("give at least one Range to vary")
    keys = [r.key for r in ranges]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise InvalidArgumentError(f"{', '.join(twice)}: varied twice; give each key once")
    cases = math.prod(r.count or 1 for r in ranges)
    if cases > MAX_CASES:
        raise InvalidArgumentError(
            f"the grid has {cases:,} cases, more than {MAX_CASES:,}; use fewer values or "
            "--method lhs"
        )


def _design(ranges: Sequence[Range], values: np.ndarray) -> pd.DataFrame:
    table = pd.DataFrame(values, columns=[r.key for r in ranges])
    table.index.name = CASE
    return table


__all__ = ["CASE", "MAX_CASES", "METHODS", "Range", "design", "grid", "latin_hypercube"]
