"""The one exception family of fixplan.

Every error raised on purpose by the library derives from :class:`FixplanError` and from the
builtin that fits it, so callers may catch either. Messages name the bad value, what is allowed
and, where it helps, how to fix it.
"""


class FixplanError(Exception):
    """Base class of every error fixplan raises on purpose."""


class InvalidArgumentError(FixplanError, ValueError):
    """An argument is out of its allowed range, of the wrong shape, or not finite."""


class GeometryError(InvalidArgumentError):
    """A shape is degenerate or self-intersecting, or points are too few to bear torsion."""


class ModelError(FixplanError, TypeError):
    """A friction model cannot answer the question asked (e.g. a cone has no motion map)."""


class ConvergenceError(FixplanError, ArithmeticError):
    """An iterative computation did not reach its documented accuracy."""


class MissingExtraError(FixplanError, ImportError):
    """An optional extra (``pip install 'fixplan[...]'``) that a request needs is not installed."""
