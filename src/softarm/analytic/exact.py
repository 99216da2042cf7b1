"""The exact closed form for a load case, if there is one (used by ``softarm.solve``)."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..loads import TipLoad, as_loads, batch_shape
from ..model import SegmentedArm
from ._common import check_arm, checked_stations, moment_is_principal
from .elastica import solve_elastica
from .force import axial_force
from .moment import helix_applies, solve_tip_moment

__all__ = ["exact_closed_form"]


def _tip_wrench(loads, shape):
    """Summed force and moment of tip loads sharing one frame, shape B + (3,) each."""
    force = sum(np.broadcast_to(load.force, (*shape, 3)) for load in loads)
    moment = sum(np.broadcast_to(load.moment, (*shape, 3)) for load in loads)
    return np.array(force, dtype=np.float64), np.array(moment, dtype=np.float64)


def exact_closed_form(arm, loads, s=None):
    """An exact closed-form equilibrium for these loads on this arm, or None.

    Returns only solutions of the full Cosserat model (eq. 20), never an approximation, for
    every element of a batch of loads; None if any element falls outside:

    * tip moment only (dead or follower): :func:`tip_moment` when the moment is about a
      principal axis of K_ωω parallel to κ⁰ (or κ⁰ = 0), or for any moment on an arm with
      EIy = EIz and a straight (possibly twisted) reference axis (the helix);
    * tip force along the axis only, on a straight (possibly twisted) arm, dead or follower:
      :func:`axial_force` (the straight state, exact though unstable beyond the Euler load);
    * dead tip force only, on a straight arm, in a principal plane (any plane if EIy = EIz and
      GAy = GAz): the extensible, shearable :func:`elastica`;
    * a zero tip wrench: the undeformed arm (an empty list of loads gives None).

    Several TipLoads in the same frame are summed; any other load (Gravity, DistributedForce,
    PointLoad), mixed dead/follower tip loads, a force together with a moment, a follower
    transverse force or a SegmentedArm give None.

    Parameters
    ----------
    arm : Arm or SegmentedArm
    loads : load or sequence of loads
        As accepted by ``softarm.solve``; batched loads broadcast together.
    s : array_like, shape (N,), or int, optional
        Stations in m (default 101 uniform stations on [0, L]).

    Returns
    -------
    Equilibrium or None
        With ``exact=True`` and ``loads`` as given.

    Examples
    --------
    >>> from softarm import Arm, Gravity, TipLoad
    >>> from softarm.analytic import exact_closed_form
    >>> arm = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=0.5, EIy=1.0, EIz=2.0)
    >>> exact_closed_form(arm, [TipLoad(moment=[0.0, 1.0, 0.0])]).method
    'analytic.tip_moment.principal'
    >>> exact_closed_form(arm, [TipLoad(moment=[1.0, 1.0, 0.0])]) is None
    True
    >>> exact_closed_form(arm, [TipLoad(force=[0.0, 0.0, 1.0])]).method
    'analytic.elastica'
    >>> exact_closed_form(arm, [TipLoad(force=[0.0, 0.0, 1.0]), Gravity()]) is None
    True
    """
    if isinstance(arm, SegmentedArm):
        return None
    arm = check_arm(arm, "exact_closed_form")
    loads = as_loads(loads)
    s = checked_stations(s, arm.length)
    if not loads or not all(isinstance(load, TipLoad) for load in loads):
        return None
    if len({bool(load.follower) for load in loads}) != 1:
        return None
    follower = bool(loads[0].follower)
    if len(loads) == 1 and loads[0].force.shape == loads[0].moment.shape == (3,):
        force, moment = loads[0].force, loads[0].moment  # one unbatched load: no summing
    else:
        force, moment = _tip_wrench(loads, batch_shape(loads))
    result = _dispatch(arm, force, moment, follower, s, loads)
    if result is None or not result.exact:
        return None
    return result if result.loads is loads else dataclasses.replace(result, loads=loads)


def _dispatch(arm, force, moment, follower, s, loads):
    straight_axis = arm.curvature[1] == 0.0 and arm.curvature[2] == 0.0
    if not force.any():
        if helix_applies(arm) or np.all(moment_is_principal(arm, moment)):
            return solve_tip_moment(arm, moment, s, follower, loads)
        return None
    if moment.any():
        return None
    if straight_axis and not force[..., 1:].any():
        if np.all(force[..., 0] > -arm.rigidities.EA):
            return axial_force(arm, force, s)
        return None
    if follower or any(c != 0.0 for c in arm.curvature):
        return None
    try:
        return solve_elastica(arm, force, s, True, loads, "elastica")
    except ValueError:  # outside its domain: not a principal plane, or too large a load
        return None
