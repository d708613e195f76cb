"""What the fuzzers share: the seeds asked for on the command line, and the closing count."""

from __future__ import annotations

import argparse
import collections
import warnings
from collections.abc import Iterator


def seeds(description: str) -> Iterator[int]:
    """The seeds of the ranges ``FIRST:STOP ...`` given on the command line (warnings off: a
    fuzzer reports outcomes, not the solvers' notes on the way)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("seeds", nargs="+", help="ranges of seeds, FIRST:STOP")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    for text in args.seeds:
        first, stop = (int(v) for v in text.split(":"))
        yield from range(first, stop)


def summary(outcomes: collections.Counter) -> str:
    """``outcomes`` as ``"count name, ..."`` in the names' order."""
    return ", ".join(f"{count} {name}" for name, count in sorted(outcomes.items()))
