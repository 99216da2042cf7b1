"""The only place where the validation calls softarm's two routes to an answer.

Every case goes through :func:`numeric` (the geometrically exact solver) or
:func:`closed_form` (a function of :mod:`softarm.analytic`), so the checks do not depend on how
the routes are laid out inside the package.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from .. import analytic
from ..dispatch import solve
from ..errors import ApproximationWarning

#: Solver tolerance used for every numerical solve of the validation.
SOLVER_TOL = 1e-10

NUMERIC = "solve(method='numeric')"


def numeric(arm, loads, s=None):
    """``softarm.solve(arm, loads, method="numeric", s=s, tol=SOLVER_TOL)``."""
    return solve(arm, loads, method="numeric", s=s, tol=SOLVER_TOL)


def closed_form(name: str, arm, *args, **kwargs):
    """``softarm.analytic.<name>(arm, *args, **kwargs)``, its ApproximationWarning silenced.

    The approximations (e.g. the constant-strain end-moment formula off a principal axis) warn
    when used outside their domain; here that is the point of the comparison, and the finding
    is reported instead. Returns None if the function returns None (no closed form).
    """
    function = getattr(analytic, name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ApproximationWarning)
        return function(arm, *args, **kwargs)


def attempt(route, *args, **kwargs):
    """(result, "") or (None, "ErrorType: message") if ``route(*args, **kwargs)`` raised.

    A route that raises (or returns None) is reported as a failed check, not a crash.
    """
    try:
        result = route(*args, **kwargs)
    except Exception as error:
        return None, f"{type(error).__name__}: {error}"
    if result is None:
        return None, "returned None (no closed form)"
    return result, ""


def value(eq, extract, *args) -> float:
    """``float(extract(eq, *args))``, NaN if there is no result."""
    return math.nan if eq is None else float(extract(eq, *args))


def tip(eq, axis: int, scale: float = 1.0) -> float:
    """Tip position component ``axis`` divided by ``scale`` (e.g. L)."""
    return eq.tip_position[axis] / scale


def tip_angle(eq, axis: int, sign: float = 1.0) -> float:
    """``sign`` times the tip section's rotation angle about spatial axis ``axis`` (rad)."""
    return sign * planar_angle(eq.tip[:3, :3], axis)


def max_distance(eq, positions, scale: float = 1.0) -> float:
    """max over stations of |p(s) - positions(s)| / scale."""
    return np.max(np.linalg.norm(eq.positions - positions, axis=-1)) / scale


def planar_angle(rotation, axis: int) -> np.ndarray:
    """Rotation angle (rad) of a frame that turns about spatial axis ``axis`` (0, 1 or 2).

    About +x: atan2(R[2,1], R[1,1]); about +y: atan2(R[0,2], R[2,2]); about +z:
    atan2(R[1,0], R[0,0]). In (-π, π].
    """
    R = np.asarray(rotation)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    return np.arctan2(R[..., j, i], R[..., i, i])
