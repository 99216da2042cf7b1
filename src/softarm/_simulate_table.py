"""The ``[simulate]`` table of a case file as plain data: how long and how finely to simulate,
the damping, where the arm starts, the actuators' inputs over time and the base's motion.

:class:`Simulation` holds the table; :class:`Schedule` is one actuator's inputs over time
(piecewise linear, held outside its times) and :class:`BaseMotion` the base pose over time
(a clamped cubic spline through its knots: the velocity is continuous and zero at the first
and last knot, so the motion starts and ends at rest and holds its end poses). The reader is
:mod:`softarm.case` (keys: :mod:`softarm._schema`); :func:`softarm.case.simulate_case` runs
it. Every constructor checks its values and raises ValueError/TypeError naming the attribute
(``Schedule.times must ...``), which the reader reports at the file's key path.

Examples
--------
>>> Schedule(1, times=(0.0, 0.1, 0.3), values=(0.0, 2.0, 2.0))(0.05)
array([1.])
>>> BaseMotion(times=(0.0, 1.0), positions=((0, 0, 0), (0.2, 0, 0)))(0.5)[:3, 3]
array([0.1, 0. , 0. ])
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._validate import format_value
from .dynamics import Damping
from .lie import so3
from .statics.solver import check_tol

__all__ = ["INITIAL", "BaseMotion", "Schedule", "Simulation"]

#: ``initial`` choices: the unloaded arm at rest, or the case's equilibrium at rest.
INITIAL = ("rest", "equilibrium")


def _times(values, owner: str) -> np.ndarray:
    """Finite, strictly increasing times (s), at least one."""
    try:
        times = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{owner}.times must be a list of numbers in s, got "
                        f"{format_value(values)}") from None
    if times.ndim != 1 or times.size < 1 or not np.all(np.isfinite(times)):
        raise ValueError(f"{owner}.times must be a non-empty list of finite numbers in s, got "
                         f"{format_value(values)}")
    if np.any(np.diff(times) <= 0):
        raise ValueError(f"{owner}.times must be strictly increasing, got "
                         f"{format_value(values)}")
    return times


def _rows(values, owner: str, name: str, count: int, width: int | None, unit: str):
    """``values`` as ``count`` rows of ``width`` finite numbers (width None: any one width;
    a flat list is one number per row)."""
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        array = None
    if array is not None and array.ndim == 1:
        array = array[:, None]
    what = "one number" if width == 1 else \
        f"a list of {width} numbers" if width else "a number or a list of numbers"
    if array is None or array.ndim != 2 or array.shape[0] != count or \
            (width is not None and array.shape[1] != width):
        raise ValueError(f"{owner}.{name} must hold {what} in {unit} for each of the "
                         f"{count} times, got {format_value(values)}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{owner}.{name} must be finite, got {format_value(values)}")
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class Schedule:
    """One actuator's inputs over time: piecewise linear through ``(times, values)``, the
    first value before the first time and the last after the last (held).

    Parameters
    ----------
    load : int
        The actuator's [[load]], counted from 0 (from 1 in the file).
    times : sequence of float
        Strictly increasing times in s.
    values : array_like, shape (len(times),) or (len(times), n)
        The load's n inputs at each time (a tension in N, a pressure in Pa, a magnetic
        field's 3 components in T), in the order of the load's inputs.
    """

    load: int
    times: tuple
    values: np.ndarray

    def __post_init__(self):
        times = _times(self.times, "Schedule")
        object.__setattr__(self, "times", tuple(times.tolist()))
        object.__setattr__(self, "values", _rows(self.values, "Schedule", "values",
                                                 times.size, None, "the input's unit"))

    @property
    def width(self) -> int:
        """The number of inputs n."""
        return self.values.shape[1]

    def __call__(self, t: float) -> np.ndarray:
        """The inputs (n,) at time ``t`` (s)."""
        return np.array([np.interp(t, self.times, column) for column in self.values.T])


@dataclass(frozen=True, eq=False)
class BaseMotion:
    """The base pose over time: positions and rotation vectors at knots, joined by a
    clamped cubic spline per component (zero velocity at the first and last knot, the end
    poses held outside), R = exp(θ(t)).

    Parameters
    ----------
    times : sequence of float
        Strictly increasing knot times in s (one knot: a fixed pose).
    positions : array_like, shape (K, 3)
        The base's position p at each knot (m, spatial frame).
    rotations : array_like, shape (K, 3), optional
        Its rotation vector θ at each knot (rad, spatial frame; R = exp(θ) maps the material
        frame of the base section, e1 the arm axis, to the spatial one). Interpolated
        component by component, so consecutive knots must not jump by 2π. Default zero.
    """

    times: tuple
    positions: np.ndarray
    rotations: np.ndarray | None = None
    _splines: tuple = field(default=(), repr=False)

    def __post_init__(self):
        times = _times(self.times, "BaseMotion")
        object.__setattr__(self, "times", tuple(times.tolist()))
        object.__setattr__(self, "positions", _rows(self.positions, "BaseMotion", "positions",
                                                    times.size, 3, "m"))
        rotations = np.zeros((times.size, 3)) if self.rotations is None else self.rotations
        object.__setattr__(self, "rotations", _rows(rotations, "BaseMotion", "rotations",
                                                    times.size, 3, "rad"))
        if np.any(np.linalg.norm(np.diff(self.rotations, axis=0), axis=-1) >= math.pi):
            raise ValueError("BaseMotion.rotations must not turn by π or more between two "
                             f"knots (they are interpolated component-wise), got "
                             f"{format_value(self.rotations)}")
        knots = np.hstack([self.positions, self.rotations])
        if times.size > 1:
            from scipy.interpolate import CubicSpline

            spline = CubicSpline(times, knots, bc_type="clamped")
            object.__setattr__(self, "_splines", (spline,))

    def __call__(self, t: float) -> np.ndarray:
        """The base pose (4, 4) at time ``t`` (s)."""
        if not self._splines:
            value = np.hstack([self.positions[0], self.rotations[0]])
        else:
            value = self._splines[0](min(max(t, self.times[0]), self.times[-1]))
        pose = np.eye(4)
        pose[:3, :3] = so3.exp(value[3:])
        pose[:3, 3] = value[:3]
        return pose


@dataclass(frozen=True, eq=False)
class Simulation:
    """The ``[simulate]`` table: what :func:`softarm.case.simulate_case` runs.

    Attributes
    ----------
    duration, dt : float
        s; ``duration`` a whole number of steps of ``dt`` (to 1e-9).
    stations : int
        ≥ 3 (``softarm.simulate``'s).
    tol, alpha : float
        As ``softarm.simulate``'s (Newton tolerance of a step; BDF-α parameter in [-1/2, 0]).
    damping : Damping or None
    initial : str
        ``"rest"``: the unloaded arm at rest at t = 0; ``"equilibrium"``: the equilibrium of
        the case's loads and actuators at their t = 0 values, at rest.
    inputs : tuple of Schedule
        At most one per actuator load; the others keep the file's value.
    base : BaseMotion or None
        None: the base fixed at the identity pose.
    """

    duration: float
    dt: float
    stations: int = 101  # softarm.simulate's defaults (a test pins them)
    tol: float = 1e-6
    alpha: float = -0.5
    damping: Damping | None = None
    initial: str = "rest"
    inputs: tuple = ()
    base: BaseMotion | None = None

    def __post_init__(self):
        for name in ("duration", "dt"):
            value = getattr(self, name)
            if not (isinstance(value, float) and math.isfinite(value) and value > 0):
                raise ValueError(f"Simulation.{name} must be a positive number of s, got "
                                 f"{format_value(value)}")
        steps = round(self.duration / self.dt)
        if steps < 1 or abs(steps * self.dt - self.duration) > 1e-9 * self.duration:
            raise ValueError(f"Simulation.duration must be a whole number of time steps dt = "
                             f"{format_value(self.dt)} s, got {format_value(self.duration)} s "
                             f"({self.duration / self.dt:.6g} steps)")
        try:
            object.__setattr__(self, "tol", check_tol(self.tol))  # the solver's own rule
        except (TypeError, ValueError) as error:
            raise type(error)(f"Simulation.{error}") from None
        if self.stations < 3:
            raise ValueError(f"Simulation.stations must be >= 3, got {format_value(self.stations)}")
        if not -0.5 <= self.alpha <= 0.0:
            raise ValueError(f"Simulation.alpha must lie in [-0.5, 0] (BDF-α), got "
                             f"{format_value(self.alpha)}")
        if self.initial not in INITIAL:
            raise ValueError(f"Simulation.initial must be 'rest' or 'equilibrium', got "
                             f"{format_value(self.initial)}")
        loads = [schedule.load for schedule in self.inputs]
        if len(set(loads)) != len(loads):
            twice = next(k for k in loads if loads.count(k) > 1)
            raise ValueError(f"Simulation.inputs: load {twice + 1} has two schedules")

    @property
    def steps(self) -> int:
        """The number of time steps, duration / dt."""
        return round(self.duration / self.dt)
