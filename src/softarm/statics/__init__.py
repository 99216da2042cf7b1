"""The geometrically exact static solver (shooting on the base wrench, compiled kernels).

Independent of :mod:`softarm.analytic`: the two routes are compared in the tests.
"""

from .solver import METHOD, Solver, solve_numeric

__all__ = ["METHOD", "Solver", "solve_numeric"]
