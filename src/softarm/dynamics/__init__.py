"""Dynamics: the arm in motion (docs/dynamics.md).

Cosserat rod dynamics with translational and rotary inertia and Kelvin–Voigt damping,
discretised in time by BDF-α (Till, Aloi & Rucker 2019): each time step is a boundary value
problem in s, solved on the stations by Newton on a banded system, warm-started from the
last step. :func:`simulate` runs a whole trajectory; :class:`Simulator` steps in real time.
"""

from ._results import Energy, State, Trajectory
from ._simulator import Damping, Simulator, simulate

__all__ = ["Damping", "Energy", "Simulator", "State", "Trajectory", "simulate"]
