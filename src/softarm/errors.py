"""Exceptions and warnings raised by softarm."""

from __future__ import annotations

__all__ = ["ApproximationWarning", "CaseError", "CaseTypeError", "ConvergenceError",
           "InadmissibleStateError", "StabilityWarning"]


class ConvergenceError(RuntimeError):
    """No admissible equilibrium was returned: the numerical solver did not reach the
    requested tolerance, or the loads lead the arm out of the model
    (:class:`InadmissibleStateError`).

    Attributes
    ----------
    message : str
        What failed, without the residual and what was tried (``str(error)`` has all three).
    residual : float
        Infinity norm of the boundary-condition residual at the last iterate, in the units of
        the tip wrench (N and N m).
    tried : str
        What the solver tried before giving up (iterations, load steps).
    load_factor : float or None
        The load factor λ (the loads scaled by λ) up to which the loading path was followed,
        when the failure is tied to one (a fold where the arm would snap); else None.
    """

    def __init__(self, message: str, residual: float, tried: str = "", *,
                 load_factor: float | None = None):
        self.message = message
        self.residual = float(residual)
        self.tried = tried
        self.load_factor = load_factor
        text = f"{message} (residual {self.residual:.3e}"
        text += f"; tried {tried})" if tried else ")"
        super().__init__(text)


class InadmissibleStateError(ConvergenceError):
    """The loads lead the arm out of the rod model, on every route: an axial stretch
    v₁ <= 0 somewhere (the centreline's tangent p' = R v turns through the cross-section's
    plane: the arm would be inside out), or a tendon whose path has no length left
    (|w| -> 0, w = v + u × r + r'), or whose path runs backwards through the sections
    (w₁ <= 0). The model has no equilibrium there: the message says where and how
    (docs/solver.md, "The model's limits").

    Attributes (besides :class:`ConvergenceError`'s)
    ----------
    station : float or None
        The arc length s (m) where the state leaves the model, when known.
    """

    def __init__(self, message: str, residual: float, tried: str = "", *,
                 load_factor: float | None = None, station: float | None = None):
        super().__init__(message, residual, tried, load_factor=load_factor)
        self.station = station


class ApproximationWarning(UserWarning):
    """A closed form was used outside the domain where it is exact."""


class CaseError(ValueError):
    """A case or result file that cannot be used: the message names the file, key and fault."""


class CaseTypeError(CaseError, TypeError):
    """A value of the wrong type in a case file (a string, bool or array where a number is
    expected, ...): a :class:`CaseError` that is also a TypeError, as the library raises."""


class StabilityWarning(UserWarning):
    """An equilibrium returned is unstable: a real arm would move away from it (its Morse
    index counts the unstable directions)."""
