"""Layer 4: problem files (TOML, CSV), reports, figures and the command line.

Never mixed with the science: imports from every layer below, none imports it. Its public names
are loaded on first use, so that the command line starts without importing the solver stack.
"""

from __future__ import annotations

import importlib

__all__ = ["ProblemFileError", "check_problem", "load_problem"]


def __getattr__(name: str):
    if name not in __all__:
        raise AttributeError(f"module 'fixplan.io' has no attribute {name!r}")
    value = getattr(importlib.import_module("fixplan.io.problem_file"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
