"""Exceptions and warnings raised by softarm."""

from __future__ import annotations

__all__ = ["ApproximationWarning", "ConvergenceError"]


class ConvergenceError(RuntimeError):
    """The numerical solver did not reach the requested tolerance.

    Attributes
    ----------
    residual : float
        Infinity norm of the boundary-condition residual at the last iterate, in the units of
        the tip wrench (N and N m).
    tried : str
        What the solver tried before giving up (iterations, load steps).
    """

    def __init__(self, message: str, residual: float, tried: str = ""):
        self.residual = float(residual)
        self.tried = tried
        text = f"{message} (residual {self.residual:.3e}"
        text += f"; tried {tried})" if tried else ")"
        super().__init__(text)


class ApproximationWarning(UserWarning):
    """A closed form was used outside the domain where it is exact."""
