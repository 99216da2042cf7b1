"""External loads on an arm, each stating its frame.

*Dead* loads keep their components in the fixed (spatial, base) frame whatever the arm does;
*follower* loads keep their components in the material frame of the cross-section they act on.
Force and moment arrays may carry leading batch axes, (..., 3): a batch of load cases solved
together, the batch axes reappearing on every output array.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validate import as_array, as_vectors

__all__ = [
    "DistributedForce",
    "Gravity",
    "Load",
    "PointLoad",
    "TipLoad",
    "as_loads",
    "batch_shape",
]


def _vector(obj, name: str) -> np.ndarray:
    # A private copy: freezing the caller's own array (np.asarray does not copy) would make it
    # read-only behind their back, and later writes to it would change the load.
    array = as_vectors(getattr(obj, name), f"{type(obj).__name__}.{name}", 3).copy()
    array.setflags(write=False)
    object.__setattr__(obj, name, array)
    return array


def _force_and_moment(obj) -> None:
    """Check that ``force`` and ``moment`` have batch shapes that broadcast together."""
    _vector(obj, "force")
    _vector(obj, "moment")
    try:
        np.broadcast_shapes(obj.force.shape[:-1], obj.moment.shape[:-1])
    except ValueError:
        name = type(obj).__name__
        raise ValueError(
            f"{name}.force and {name}.moment must have batch shapes that broadcast, got shapes "
            f"{obj.force.shape} and {obj.moment.shape}"
        ) from None


@dataclass(frozen=True, eq=False)
class TipLoad:
    """Force and moment applied at the free end (s = L).

    Parameters
    ----------
    force : array_like, shape (..., 3)
        N. Spatial components for a dead load, tip material components for a follower load.
    moment : array_like, shape (..., 3)
        N m, in the same frame as ``force``.
    follower : bool
        False (dead: fixed in space) or True (follower: fixed in the tip's material frame).

    Examples
    --------
    >>> TipLoad(force=[0.0, 0.0, -1.0]).force
    array([ 0.,  0., -1.])
    """

    force: np.ndarray = (0.0, 0.0, 0.0)
    moment: np.ndarray = (0.0, 0.0, 0.0)
    follower: bool = False

    def __post_init__(self):
        _force_and_moment(self)
        if not isinstance(self.follower, (bool, np.bool_)):
            raise TypeError(f"TipLoad.follower must be True or False, got {self.follower!r}")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return np.broadcast_shapes(self.force.shape[:-1], self.moment.shape[:-1])


@dataclass(frozen=True, eq=False)
class Gravity:
    """Weight of the arm: a dead distributed force μ g per unit length, μ the mass per length.

    Parameters
    ----------
    acceleration : array_like, shape (..., 3)
        g in m/s², spatial frame. Default (0, 0, -9.81).
    """

    acceleration: np.ndarray = (0.0, 0.0, -9.81)

    def __post_init__(self):
        _vector(self, "acceleration")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.acceleration.shape[:-1]


@dataclass(frozen=True, eq=False)
class DistributedForce:
    """A uniform dead force per unit length along the whole arm.

    Parameters
    ----------
    force : array_like, shape (..., 3)
        N/m, spatial frame.
    """

    force: np.ndarray

    def __post_init__(self):
        _vector(self, "force")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.force.shape[:-1]


@dataclass(frozen=True, eq=False)
class PointLoad:
    """A dead force and moment applied at an interior station s.

    Parameters
    ----------
    s : float
        Arc length in m, in [0, L] (checked against the arm when solving).
    force : array_like, shape (..., 3)
        N, spatial frame.
    moment : array_like, shape (..., 3)
        N m, spatial frame.
    """

    s: float
    force: np.ndarray = (0.0, 0.0, 0.0)
    moment: np.ndarray = (0.0, 0.0, 0.0)

    def __post_init__(self):
        s = as_array(self.s, "PointLoad.s")
        if s.ndim != 0:
            raise ValueError(f"PointLoad.s must be a single arc length in m, got {self.s!r}")
        object.__setattr__(self, "s", float(s))
        _force_and_moment(self)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return np.broadcast_shapes(self.force.shape[:-1], self.moment.shape[:-1])


Load = TipLoad | Gravity | DistributedForce | PointLoad
_LOAD_KINDS = (TipLoad, Gravity, DistributedForce, PointLoad)


def as_loads(loads) -> tuple:
    """A single load or a sequence of loads as a tuple, TypeError for anything else."""
    if isinstance(loads, _LOAD_KINDS):
        return (loads,)
    try:
        items = tuple(loads)
    except TypeError:
        items = None
    if items is None or not all(isinstance(item, _LOAD_KINDS) for item in items):
        raise TypeError(
            "loads must be a TipLoad, Gravity, DistributedForce or PointLoad, or a list of "
            f"them, got {loads!r}"
        )
    return items


def batch_shape(loads) -> tuple[int, ...]:
    """The broadcast batch shape of all loads, ValueError if they do not broadcast."""
    shapes = [load.batch_shape for load in as_loads(loads)]
    try:
        return np.broadcast_shapes(*shapes) if shapes else ()
    except ValueError as error:
        raise ValueError(f"loads have batch shapes {shapes} that do not broadcast") from error
