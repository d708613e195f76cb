"""Layer 4: problem files (TOML, CSV), reports, figures and the command line.

Never mixed with the science: imports from every layer below, none imports it.
"""

from fixplan.io.problem_file import ProblemFileError, load_problem

__all__ = ["ProblemFileError", "load_problem"]
