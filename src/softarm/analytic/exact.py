"""The exact closed form for a load case, if there is one (used by ``softarm.solve``)."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..loads import as_loads, batch_shape, check_magnitudes
from ..model import SegmentedArm, StiffnessMatrix
from ._common import check_arm, checked_stations, moment_is_principal
from .actuation import solve_actuated
from .elastica import solve_elastica
from .force import axial_force
from .moment import helix_applies, solve_tip_moment

__all__ = ["closed_form", "exact_closed_form"]


class _TipWrench:
    """A :class:`~softarm.loads.LoadTarget` that sums the tip wrenches of the loads, dead and
    follower apart, and notes any other channel (distributed, interior point, or a channel it
    does not know): the closed forms here apply to tip wrenches alone. It fails closed, so a
    new kind of load never reaches a closed form that ignores it."""

    def __init__(self, arm, shape):
        self.arm, self.length = arm, arm.length
        self.wrench = {False: np.zeros((*shape, 6)), True: np.zeros((*shape, 6))}
        self.used = set()
        self.other = False

    def tip(self, *, force=None, moment=None, follower=False):
        self.used.add(bool(follower))
        if force is not None:
            self.wrench[bool(follower)][..., :3] += force
        if moment is not None:
            self.wrench[bool(follower)][..., 3:] += moment

    def point(self, s, *, force=None, moment=None):
        if s >= self.length:
            self.tip(force=force, moment=moment)
        else:
            self.other = True

    def distributed(self, *, per_mass=False, moment=None, **_):
        if per_mass and moment is None and self.arm.linear_density == 0.0:
            return  # a force per unit mass (gravity) on a massless arm acts on nothing
        self.other = True

    def __getattr__(self, name):  # any other channel: no closed form here
        if name.startswith("__"):
            raise AttributeError(name)
        self.other = True
        return lambda *args, **kwargs: None


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
    * a zero tip wrench: the undeformed arm (an empty list of loads gives None);
    * straight tendons and straight chambers alone, on any arm (segmented, curved, any K):
      :func:`~softarm.analytic.actuation.actuated` (piecewise constant strain).

    Several tip wrenches in the same frame are summed (through each load's
    :meth:`~softarm.Load.apply`, so a point load at s = L counts as one); any other load
    (gravity on an arm with mass, distributed, interior point loads), mixed dead/follower
    tip loads, a force together with a moment, a follower transverse force or a
    SegmentedArm give None.

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
    if not isinstance(arm, SegmentedArm):
        arm = check_arm(arm, "exact_closed_form")
    loads = as_loads(loads)
    check_magnitudes(arm, loads, "exact_closed_form")
    s = checked_stations(s, arm.length)
    return closed_form(arm, loads, s, batch_shape(loads)) if loads else None


def closed_form(arm, loads: tuple, s: np.ndarray, shape: tuple):
    """:func:`exact_closed_form` for checked arguments (``softarm.solve`` has checked them):
    ``arm`` an Arm or SegmentedArm, ``loads`` a tuple of Loads that fit it, of batch shape
    ``shape``, and ``s`` stations as ``_validate.stations`` returns them, read-only or fresh
    (never written; the result may keep them)."""
    if not loads:
        return None
    result = solve_actuated(arm, loads, s)
    if result is not None:
        return result
    if isinstance(arm, SegmentedArm) or isinstance(arm.section, StiffnessMatrix):
        return None  # segments, or a coupled stiffness: no closed form below
    target = _TipWrench(arm, shape)
    for load in loads:
        load.apply(target)
        if target.other:  # a load other than a tip wrench
            return None
    if len(target.used) != 1:  # dead and follower mixed
        return None
    follower = target.used.pop()
    force, moment = target.wrench[follower][..., :3], target.wrench[follower][..., 3:]
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
