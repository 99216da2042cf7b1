"""The geometrically exact static solver: shooting on the base wrench, with continuation along
the loading path (see docs/solver.md and README.md beside this file).

Python-side preparation (validation, cutting the arm into uniform pieces at segment joints,
point loads and span ends, writing every load into the kernel's load channels) lives here;
the numerical work, for the whole batch at once, is :func:`softarm.kernels.solve_cases`.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
import warnings
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .. import kernels
from .._admissible import batch_part, check_stretch, load_case, tendon_limit
from .._threads import in_threads, threads_for
from .._validate import (
    BYTES_PER_CASE,
    BYTES_PER_STATION,
    CASES_PER_PART,
    MAX_STEPS,
    check_allocation,
    count,
    real,
    rigid_transform,
    stations,
)
from ..contact import balance
from ..equilibrium import Equilibrium, Stability
from ..errors import ApproximationWarning, ConvergenceError, InadmissibleStateError
from ..kernels import _prefetch
from ..lie import se3
from ..loads import (
    Gravity,
    Tendon,
    as_loads,
    batch_shape,
    check_magnitudes,
    largest_force,
    path_tangent,
)
from ..model import Arm, Circle, Material, SegmentedArm
from ..routing import Straight
from ._stiff import STIFF_KL, tension_kl
from .displacement import solve_displaced
from .stability import verdict
from .tip_contact import solve_tip_contact

__all__ = ["METHOD", "PreparedSolve", "ShootResult", "Shooter", "Snapshot", "Solver",
           "check_base", "check_tol", "solve_numeric"]

#: Equilibrium.method of every result of this solver.
METHOD = "numeric.shooting"

_N_MAX = MAX_STEPS  # largest step count of the fine solution is 2 * _N_MAX / 2
_IDENTITY = np.eye(4)
_IDENTITY.setflags(write=False)
#: Fewest load cases per thread of a batch: below it a thread costs more than it saves.
CASES_PER_THREAD = 16


def check_base(base) -> np.ndarray:
    """The base pose as a (4, 4) rigid transform (a nearly rigid one re-orthonormalised, the
    same rule on every route), or ValueError naming ``base``."""
    return _IDENTITY if base is None else rigid_transform(base, "base")


def _check_arm(arm):
    if not isinstance(arm, (Arm, SegmentedArm)):
        raise TypeError(f"arm must be a softarm.Arm or SegmentedArm, got {arm!r}")
    return arm


def check_tol(tol) -> float:
    tol = real(tol, "tol", "units of the arm length")
    if not 1e-13 <= tol <= 1e-1:
        raise ValueError(
            f"tol must be a relative tip-position tolerance in [1e-13, 0.1], got {tol!r}"
        )
    return tol


def _normal_positive(values, what: str) -> None:
    """ValueError unless every value is finite and a positive normal float."""
    values = np.asarray(values, dtype=np.float64)
    bad = ~(np.isfinite(values) & (values >= np.finfo(np.float64).tiny))
    if np.any(bad):
        raise ValueError(f"{what} must be finite, positive and representable (normal floats), "
                         f"got {float(values[bad][0])!r}")


class _ArmData:
    """What the solver needs of an arm, computed once per arm (see :func:`_arm_data`).

    The arrays go to the compiled kernel as they are: they are private and never written.
    """

    def __init__(self, arm):
        segments = arm.segments
        self.arm = arm
        self.length = float(arm.length)
        self.bounds = np.array(arm.boundaries, dtype=np.float64)
        self.K = np.array([seg.stiffness for seg in segments], dtype=np.float64)
        _normal_positive(np.diagonal(self.K, axis1=1, axis2=2),
                         "the arm's stiffnesses (EA, GA, GJ, EI)")
        self.C = np.linalg.inv(self.K)
        if not np.all(np.isfinite(self.C)):
            raise ValueError("the arm's stiffness matrices must be invertible with a finite "
                             "compliance")
        self.f0 = np.array([seg.reference_strain for seg in segments], dtype=np.float64)
        if not np.all(np.isfinite(self.f0 * self.length)):
            raise ValueError("the arm's reference strains (curvature) times its length must "
                             "be finite")
        mu = [seg.linear_density for seg in segments]
        self.mu = np.array([np.nan if m is None else m for m in mu], dtype=np.float64)
        if not np.all(np.isnan(self.mu) | (np.isfinite(self.mu) & (self.mu >= 0.0))):
            raise ValueError(f"the arm's linear density (mass per length, density × area) must "
                             f"be finite and >= 0 kg/m, got {self.mu.tolist()!r}")
        #: the largest bending compliance 1/EI (the tension's kL, _stiff.py)
        self.soft = float(np.max(self.C[:, [4, 5], [4, 5]]))
        #: the unloaded arm's own turning Σ |κ⁰| L (rad): steps it needs at the least
        self.turning = float(sum(np.linalg.norm(seg.curvature) * seg.length
                                 for seg in segments))
        #: the narrowest shear zone √(EI/GA) (m; bending about z with shear along y, and
        #: about y with shear along z): where contact spreads a point reaction (contact.md)
        self.shear_zone = float(np.sqrt(np.min(self.C[:, [1, 2], [1, 2]]
                                               / self.C[:, [5, 4], [5, 4]])))
        bending = float(np.max(self.K[:, [3, 4, 5], [3, 4, 5]]))
        self.force_scale = bending / self.length**2
        _normal_positive([self.force_scale, bending / self.length],
                         "the arm's bending scale EI/L² and EI/L")
        self.scale = np.array([self.force_scale] * 3 + [bending / self.length] * 3)
        self.least_bending = float(np.min(self.K[:, [4, 5], [4, 5]]))  # the smallest EI
        self.diag = bool(np.all(self.C[:, ~np.eye(6, dtype=bool)] == 0.0))
        # hard magnets: the magnetisation per length of each segment, and the dipole at each
        # segment's distal end (material components)
        self.magnetization = np.array([_magnet(seg, "magnetization") for seg in segments])
        self.dipoles = np.array([_magnet(seg, "tip_magnet") for seg in segments])
        # what solves of one load structure share (:meth:`remember`): a dict per kind
        self._remembered = {}

    def remembered(self, kind: str, key):
        """What :meth:`remember` stored under (kind, key), or None (also for a key that
        cannot be hashed: a user's routing class without ``__hash__``)."""
        try:
            return self._remembered.get(kind, {}).get(key)
        except TypeError:
            return None

    def remember(self, kind: str, key, value, most: int = 8):
        """Store ``value`` under (kind, key), keeping at most ``most`` entries of that kind
        (the oldest go); returns it. Solvers in several threads may share an arm's data:
        every step is one dict operation, and a lost entry is only computed again. A key
        that cannot be hashed is not stored (it is computed again each time)."""
        store = self._remembered.setdefault(kind, {})
        while len(store) >= most:
            try:
                store.pop(next(iter(store)), None)
            except (StopIteration, RuntimeError):  # emptied or changed by another thread
                break
        try:
            store[key] = value
        except TypeError:
            pass
        return value

    @functools.lru_cache(maxsize=16)  # noqa: B019 (per arm data, itself cached per arm)
    def pieces(self, cuts: tuple[float, ...]) -> tuple:
        """The arm cut at the segment joints and at ``cuts``: (starts, lengths, C, f0, zero,
        diag, length, scale, K: the kernel's ``arm``; magnetisation, dipoles: ``act``'s
        magnets; linear density, segment of each piece)."""
        starts = np.unique(np.concatenate([self.bounds, np.asarray(cuts, dtype=np.float64)]))
        starts = starts[(starts >= 0.0) & (starts < self.length)]
        ends = np.append(starts[1:], self.length)
        lengths = ends - starts
        middle = starts + 0.5 * lengths
        segment = np.clip(np.searchsorted(self.bounds, middle) - 1, 0, len(self.K) - 1)
        f0 = np.ascontiguousarray(self.f0[segment])
        dipoles = np.zeros((starts.size + 1, 3))
        for k, end in enumerate(self.bounds[1:]):  # segment k's dipole at its distal end
            dipoles[np.searchsorted(starts, end) if end < self.length else -1] += \
                self.dipoles[k]
        return (starts, lengths, np.ascontiguousarray(self.C[segment]), f0,
                np.zeros_like(f0), self.diag, self.length, self.scale,
                np.ascontiguousarray(self.K[segment]),
                np.ascontiguousarray(self.magnetization[segment]), dipoles,
                self.mu[segment], segment)


@functools.cache
def _no_contact() -> tuple:
    """``act``'s contact arrays out of contact: no obstacle (kernels/rod.py, act[5], act[6];
    made on first use: reading the kernels' layout loads them)."""
    return np.zeros((0, 8)), np.zeros((1, kernels.CONTACT_PARAMS))


#: Retries of a solve whose answer penetrates an obstacle, each with the penalty raised
#: (:func:`_penetration`), before it is an error.
_CONTACT_RETRIES = 4


def _contact_key(load) -> tuple:
    """What makes a Contact (as given, before the solver sets its law) the same one for
    a kept penalty (Solver._kept_law): its obstacles and settings (a stiffness the user
    gives among them: theirs is never replaced)."""
    return (tuple(tuple(obstacle.kernel_row()) for obstacle in load.obstacles),
            load.distance, load.radius, load.stiffness, load.friction, load.slip_velocity)


def _penetration(solver, contact, gaps, forces, attempt: int,
                 given: bool) -> np.ndarray | None:
    """None if no station of the solved cases (their ``gaps`` (B, S) and contact ``forces``
    (B, S, 3) with the law ``contact``, its stiffness (B,): :meth:`Contact.gaps`) is inside
    an obstacle by more than tol·L; else each
    case's new stiffness: a case that penetrates gets the one that carries its largest
    pressure within the band (k δ/2 = 1.25 × it, and at least twice its last k), the others
    keep theirs (a case's answer never depends on the others': batch = loop). A
    ConvergenceError when this was the solve's last attempt (``attempt`` counts from 0), or
    at once for a stiffness the user ``given`` (it is theirs to raise)."""
    depth = -gaps.min(axis=-1)
    deep = depth > solver.tol * solver.length
    if not deep.any():
        return None
    worst = int(np.argmax(depth))
    k = contact.stiffness
    if given:
        raise ConvergenceError(
            f"the arm penetrates an obstacle by {depth[worst]:.3g} m (more than tol·L = "
            f"{solver.tol * solver.length:.3g} m) with the given Contact(stiffness="
            f"{k[worst]:.3g}) N/m²: give a larger one, or none (the solver then raises it "
            f"until no case penetrates)", residual=float(depth[worst]))
    if attempt >= _CONTACT_RETRIES:
        raise ConvergenceError(
            f"the arm penetrates an obstacle by {depth[worst]:.3g} m (more than tol·L = "
            f"{solver.tol * solver.length:.3g} m) at the contact stiffness k = "
            f"{k[worst]:.3g} N/m², raised {attempt} times: pass a larger "
            f"Contact(stiffness=...) or distance=", residual=float(depth[worst]))
    peak = np.linalg.norm(forces, axis=-1).max(axis=-1)
    return np.where(deep, np.maximum(2.5 * peak / contact.distance, 2.0 * k), k)


#: Widenings of a default contact distance (×_WIDER each) after a loading path that failed.
_WIDENINGS = 3
_WIDER = 4.0


def _widened_contact(solver, loads, contact, widened: int) -> tuple | None:
    """``loads`` with the Contact's distance δ widened _WIDER times, or None: where the
    loading path failed in contact with the default δ (the user gave none) and it has been
    widened fewer than _WIDENINGS times. A band of a few µm that a free tip enters edge-on
    is narrower than the steps resolve, and the path fails there (docs/contact.md); the
    answer then lies within the wider δ of the hard-contact one, which the warning says
    (the whole batch takes the wider band: each case's law is then that of the batch)."""
    if contact is None or widened >= _WIDENINGS:
        return None
    given = next(load for load in loads if load.kind == "contact")
    if given.distance is not None and not widened:
        return None
    distance = contact.distance * _WIDER
    warnings.warn(
        f"softarm: the loading path could not be followed in contact with the contact "
        f"distance {contact.distance:.3g} m; solved with {distance:.3g} m "
        f"({distance / solver.length:.1e} L): the shape is within about that of the "
        f"hard-contact one "
        f"(docs/contact.md)", ApproximationWarning, stacklevel=4)
    wider = given.replace(distance=distance)
    return tuple(wider if load.kind == "contact" else load for load in loads)


#: Stations of a solve in contact at the least (uniform, with the ones asked for): the
#: penetration check needs the contact zones resolved (about √(EI/GA) wide).
CONTACT_STATIONS = 2001


def _contact_stations(s: np.ndarray, length: float, cuts) -> tuple[np.ndarray, np.ndarray]:
    """(the solver's stations: ``s``, CONTACT_STATIONS uniform ones and the pieces' ``cuts``
    (the contact wrench's balance integrates the other loads piece by piece), the index of
    each of ``s`` among them)."""
    fine = np.union1d(np.union1d(s, np.linspace(0.0, length, CONTACT_STATIONS)), cuts)
    return fine, np.searchsorted(fine, s)


def _contact_wrench(solver, forces, loads, shape, s, poses, base_wrench) -> np.ndarray:
    """(*shape, 6): :func:`softarm.contact.balance` on the solver's fine stations ``s``
    (``poses`` (B, S, 4, 4), B the flattened cases; ``forces`` (B, S, 3) the contact forces
    there), exactly zero for a case where no station is within the contact distance (the
    balance leaves round-off there: the stations resolve the zones, as the penetration
    check assumes)."""
    touching = np.any(forces != 0.0, axis=(-1, -2)).reshape(shape)
    wrench = balance(solver.arm, loads, s, poses.reshape(*shape, s.size, 4, 4),
                     base_wrench.reshape(*shape, 6))
    return np.where(touching[..., None], wrench, 0.0)


def unloaded_poses(arm, s, base) -> np.ndarray:
    """The unloaded arm's poses (S, 4, 4) at stations s, clamped at ``base`` (4, 4): each
    segment the exponential of its reference strain f⁰ (a helix, a circle or a line)."""
    bounds = np.asarray(arm.boundaries)
    segment = np.clip(np.searchsorted(bounds, s, side="right") - 1, 0, len(bounds) - 2)
    strains = np.array([seg.reference_strain for seg in arm.segments], dtype=np.float64)
    starts = [np.asarray(base, dtype=np.float64)]
    for k, seg in enumerate(arm.segments[:-1]):
        starts.append(starts[-1] @ se3.exp(strains[k] * seg.length))
    along = (np.asarray(s) - bounds[segment])[:, None] * strains[segment]
    return np.stack(starts)[segment] @ se3.exp(along)


def _check_outside(solver, contact) -> None:
    """ValueError if the unloaded arm (clamped at the solver's base) is inside an obstacle
    at some station: no path from it leads out."""
    s = np.linspace(0.0, solver.length, 201)
    poses = unloaded_poses(solver.arm, s, solver._base_kernel)
    gaps, _ = contact.gaps(poses[:, :3, 3], contact.station_radii(solver.arm, s))
    inside = np.flatnonzero(gaps < -solver.tol * solver.length)
    if inside.size:
        i = inside[0]
        raise ValueError(
            f"Contact: the unloaded arm starts inside an obstacle (its surface {-gaps[i]:.3g} "
            f"m deep at station s = {s[i]:.6g} m): the equilibrium connected to it is not "
            f"defined; move the obstacles or the base")


def _magnet(segment, name: str) -> np.ndarray:
    """A segment's ``magnetization`` or ``tip_magnet`` (material components), zeros if None."""
    value = getattr(segment, name, None)
    return np.zeros(3) if value is None else np.asarray(value, dtype=np.float64)


@functools.lru_cache(maxsize=64)
def _cached_arm_data(arm) -> _ArmData:
    return _ArmData(arm)


def _arm_data(arm) -> _ArmData:
    """The solver's data of ``arm``, cached per (equal) arm: arms are frozen dataclasses."""
    try:
        return _cached_arm_data(arm)
    except TypeError:  # an unhashable field (never with the model's own types)
        return _ArmData(arm)


@functools.lru_cache(maxsize=64)
def _uniform_stations(length: float, count: int):
    """``count`` uniform stations on [0, L]: (read-only for results, private for the kernel)."""
    s = np.linspace(0.0, length, count)
    public = s.copy()
    public.setflags(write=False)
    return public, s


class _Channels:
    """The kernel's load channels of a batch (a :class:`~softarm.loads.LoadTarget`): per
    piece (B, P, PIECE_LOADS) and at the tip (B, TIP_LOADS), filled by each load's
    :meth:`~softarm.Load.apply`. Views with the batch shape let loads broadcast into them
    without broadcast copies."""

    def __init__(self, data: _ArmData, pieces: tuple, shape: tuple, count: int):
        k = kernels
        self.k = k
        self.arm = data.arm
        self.length = data.length
        self.pieces = pieces
        self.starts, self.lengths, self.mu = pieces[0], pieces[1], pieces[11]
        self.shape, self.count = shape, count
        P = self.starts.size
        self.piece = np.zeros((count, P, k.PIECE_LOADS))
        self.tip_loads = np.zeros((count, k.TIP_LOADS))
        self._piece = self.piece.reshape(*shape, P, k.PIECE_LOADS)
        self._tip = self.tip_loads.reshape(*shape, k.TIP_LOADS)
        self.data = data
        self.actuators = []  # (kind code, routing, active rows, span) per actuator column
        #: the Contact load, if any (:meth:`contact`); its arrays for the kernel, made once
        self.contact_load = self._contact_given = None  # (as resolved, as given)
        self.contact_given_stiffness = False  # (the user's k: never raised, resolve_contact)
        self._contact_arrays = None

    def _rows(self, span):
        if span is None or (span[0] <= 0.0 and span[1] >= self.length):  # the whole arm
            return slice(None)
        middle = self.starts + 0.5 * self.lengths
        return np.flatnonzero((middle > span[0]) & (middle < span[1]))

    def distributed(self, *, force=None, moment=None, follower=False, span=None,
                    per_mass=False):
        k, rows = self.k, self._rows(span)
        weight = self.mu[rows][:, None] if per_mass else 1.0
        if force is not None:
            at = k.FF if follower else k.FD
            self._piece[..., rows, at:at + 3] += np.asarray(force)[..., None, :] * weight
        if moment is not None:
            at = k.LF if follower else k.LD
            self._piece[..., rows, at:at + 3] += np.asarray(moment)[..., None, :]

    def point(self, s, *, force=None, moment=None):
        k = self.k
        if s >= self.length:
            self.tip(force=force, moment=moment)
            return
        j = max(int(np.searchsorted(self.starts, s, side="right")) - 1, 0)
        if force is not None:
            self._piece[..., j, k.JD:k.JD + 3] += force
        if moment is not None:
            self._piece[..., j, k.JD + 3:k.JD + 6] += moment

    def tip(self, *, force=None, moment=None, follower=False):
        at = self.k.TF if follower else self.k.TD
        if force is not None:
            self._tip[..., at:at + 3] += force
        if moment is not None:
            self._tip[..., at + 3:at + 6] += moment

    def actuator(self, kind, magnitude, routing, span):
        k = self.k
        rows = self._rows(span)
        # one more column (actuators are few; the batch's piece array grows by one column)
        P = self.starts.size
        self.piece = np.concatenate([self.piece, np.zeros((self.count, P, 1))], axis=2)
        self._piece = self.piece.reshape(*self.shape, P, self.piece.shape[2])
        column = self.piece.shape[2] - 1
        self._piece[..., rows, column] = np.asarray(magnitude)[..., None]
        active = np.zeros(P)
        active[rows] = 1.0
        self.actuators.append((k.TENDON if kind == "tendon" else k.CHAMBER, routing, active,
                               (float(span[0]), float(span[1]))))

    def displaced_tendon(self, displacement, routing, span):
        raise ValueError(
            "a displacement-controlled Tendon (Tendon(displacement=...)) is solved by "
            "softarm.solve and Solver.solve only; this route (shoot, continuation, "
            "branch='stable', stability sweeps) takes tension-controlled tendons: use "
            "Tendon.with_tension(eq.tendon_tensions[...]) from a solved equilibrium")

    def field(self, field, gradient=None):
        k = self.k
        self._piece[..., :, k.FB:k.FB + 3] += np.asarray(field)[..., None, :]
        if gradient is not None:
            G = np.asarray(gradient).reshape(*np.shape(gradient)[:-2], 9)
            self._piece[..., :, k.FG:k.FG + 9] += G[..., None, :]

    def contact(self, load):
        if self.contact_load is not None:
            raise ValueError("loads may hold one Contact: put every obstacle in it, "
                             "Contact([obstacle, ...])")
        self.contact_load = self._contact_given = load
        self._piece[..., :, self.k.CT] = 1.0

    def arm_tuple(self) -> tuple:
        """The kernel's (arm, act) pair, passed on as ``*arm_tuple()``: the pieces, and the
        actuators' paths, the magnets and the obstacles, or None for a passive arm out of
        contact (see softarm.kernels: a passive arm's solve is compiled without them)."""
        arm, act = self._actuated_arm()[0]
        if self.contact_load is None:
            return arm, (None if act is None else (*act, *_no_contact()))
        if self._contact_arrays is None:
            self._contact_arrays = self._contact_kernel_arrays()
        if act is None:  # a passive arm: no actuators, no magnets
            P = self.starts.size
            act = (np.zeros((0, 6)), np.zeros(0, dtype=np.int64), np.zeros((P, 0)),
                   self.pieces[9], self.pieces[10])
        return arm, (*act, *self._contact_arrays)

    def resolve_contact(self, stiffness: np.ndarray | None = None, *,
                        dt: float | None = None):
        """The Contact with its contact distance and each case's penalty stiffness set, made
        this channels' contact (``contact_load``, its stiffness (B,) per flattened case;
        returned with it in the batch shape, for the result); None without contact.

        The stiffness: ``stiffness`` (B,) (a retry after a penetration), else the load's
        own, else :meth:`_contact_stiffness`'s estimate per case. It goes to the kernel in
        the channel CT (the kernel's own k is 1), so that each case's law is its own (batch
        = loop) and a path from the unloaded arm stiffens the contact with the loads.

        ``dt`` (s): for time steps of that length, an estimated k above μ/Δt² (μ the
        lightest linear density) is lowered to it, with δ widened by the same factor (the
        same pressure k δ/2 carried within the band), unless the Contact gives its own
        distance or stiffness: a stiffer penalty rings at ω Δt > 1, and an implicit step's
        Newton iteration does not converge across a band much thinner than the arm moves
        in a step (contact.md, "Dynamics")."""
        load = self._contact_given
        if load is None:
            return None
        band = load.band(self.length)
        if load.zones:  # hard contact zones (Contact.zones): their law at full strength
            self.piece[:, :, self.k.CT] = 1.0
            self.contact_given_stiffness = False
            self.contact_load = load.replace(distance=band)
            self._contact_arrays = None
            return self.contact_load
        if load.stiffness is not None and np.ndim(load.stiffness):
            raise ValueError("Contact.stiffness must be one number for a solve (N/m²), got an "
                             "array: it varies per case only where the solver raised it")
        self.contact_given_stiffness = load.stiffness is not None
        if stiffness is None:
            stiffness = np.full(self.count, load.stiffness) if load.stiffness is not None \
                else self._contact_stiffness(band)
        if dt is not None and load.distance is None and load.stiffness is None:
            lightest = float(np.nanmin(self.mu)) if np.any(self.mu > 0.0) else 0.0
            ratio = float(np.max(stiffness, initial=0.0)) * dt**2 / lightest \
                if lightest > 0.0 else 0.0
            if ratio > 1.0:
                band, stiffness = band * ratio, stiffness / ratio
        self.piece[:, :, self.k.CT] = stiffness[:, None]
        self.contact_load = load.replace(distance=band, stiffness=stiffness)
        self._contact_arrays = None
        single = stiffness.size == 1 or np.all(stiffness == stiffness[0])
        return load.replace(distance=band, stiffness=float(stiffness[0]) if single
                            else stiffness.reshape(self.shape))

    def _contact_stiffness(self, band: float, piece=None, tip=None) -> np.ndarray:
        """Each case's penalty stiffness k (N/m², (B,)) that carries the largest pressure
        expected within the band (k δ/2, contact.md): the loads' size W (forces, and
        moments over L/2, the actuators' tension times their offset counted as a moment)
        spread over the width of the arm's shear zone √(EI/GA), where a shearable rod
        carries what an unshearable one would carry as a point reaction. ``piece``,
        ``tip``: other channels than these (a simulation's inputs, or a bound of them)."""
        k, lengths = self.k, self.lengths
        piece = np.abs(self.piece if piece is None else piece)
        tip = np.abs(self.tip_loads if tip is None else tip)
        forces = ((piece[..., k.FD:k.FD + 6].sum(-1) @ lengths)
                  + piece[..., k.JD:k.JD + 3].sum((-1, -2))
                  + piece[..., k.JF:k.JF + 3].sum((-1, -2))
                  + tip[:, k.TD:k.TD + 3].sum(-1) + tip[:, k.TF:k.TF + 3].sum(-1))
        moments = ((piece[..., k.LD:k.LD + 3].sum(-1) @ lengths)
                   + (piece[..., k.LF:k.LF + 3].sum(-1) @ lengths)
                   + piece[..., k.JD + 3:k.JD + 6].sum((-1, -2))
                   + piece[..., k.JF + 3:k.JF + 6].sum((-1, -2))
                   + tip[:, k.TD + 3:k.TD + 6].sum(-1) + tip[:, k.TF + 3:k.TF + 6].sum(-1))
        if self.actuators:
            offsets = self._actuated_arm()[0][1][0][:, 0]  # routes' _RHO column
            moments = moments + (piece[..., k.ACT:].max(-2) * offsets).sum(-1)
        W = np.maximum(forces + 2.0 * moments / self.length, 1e-12 * self.data.force_scale)
        return 2.0 * W / (self.data.shear_zone * band)

    def _contact_kernel_arrays(self) -> tuple:
        load = self.contact_load
        radii = load.surface_radii(self.arm)[self.pieces[12]]
        params = np.zeros((self.starts.size, kernels.CONTACT_PARAMS))
        params[:, 0] = radii
        params[:, 1] = load.distance
        params[:, 2] = 1.0  # (each case's k is in its channel CT)
        params[:, 3] = load.friction
        params[:, 4] = load.slip_velocity
        if load.zones:  # hard contact zones: the penalty off, each zone's pieces flagged
            params[:, 2] = 0.0
            middles = self.starts + 0.5 * self.lengths
            for obstacle, start, end in load.zones:
                params[(middles > start) & (middles < end), kernels.ZONE] = obstacle + 1
        return load.kernel_rows(), params

    def tendons(self) -> tuple[np.ndarray, np.ndarray]:
        """The actuator columns that are tendons (in the order given) and their lengths in
        the unloaded arm (m)."""
        return self._actuated_arm()[1:]

    def _actuated_arm(self) -> tuple:
        """((arm, act) kernel pair, tendon columns, unloaded tendon lengths): what depends on
        the cut and
        on the actuators' kinds, paths and spans alone, not on their magnitudes. A control
        loop or a sweep solves many cases of one structure, so it is remembered per arm
        (40-60 µs of every robot solve otherwise: routing rows, tendon quadratures)."""
        mine = self.__dict__.get("_actuated")  # (this batch's solve and its verdict)
        if mine is not None and mine[0] == len(self.actuators):
            return mine[1]
        key = (self.starts.tobytes(), self.signature())
        found = self.data.remembered("actuated arm", key)
        if found is None or found[0][0][0] is not self.pieces[0]:  # (arm, act): arm[0]
            found = self.data.remember("actuated arm", key, self._build_actuated_arm())
        self._actuated = (len(self.actuators), found)
        return found

    def _build_actuated_arm(self) -> tuple:
        pieces = self.pieces
        degree = max([1] + [routing.degree for _, routing, _, _ in self.actuators])
        A = len(self.actuators)
        routes = np.zeros((A, 4 + 2 * degree))
        kinds = np.zeros(A, dtype=np.int64)
        active = np.zeros((self.starts.size, A))
        for a, (kind, routing, rows, _) in enumerate(self.actuators):
            routes[a] = routing.kernel_row(degree, self.length)
            kinds[a] = kind
            active[:, a] = rows
        magnets, dipoles = pieces[9], pieces[10]
        passive = A == 0 and not (np.any(magnets) or np.any(dipoles))
        arm = (pieces[:9], None if passive else (routes, kinds, active, magnets, dipoles))
        columns = np.flatnonzero(kinds == self.k.TENDON)
        unloaded = np.array([_unloaded_length(pieces, self.actuators[a]) for a in columns])
        return arm, columns, unloaded

    def cases(self, piece, tip, shape) -> _Channels:
        """A copy of these channels (the same pieces and actuators) holding the cases
        ``piece`` (B, P, PIECE_LOADS + A), ``tip`` (B, TIP_LOADS) of batch shape ``shape``."""
        out = object.__new__(_Channels)  # (a shallow copy; copy.copy's protocol: 3× the cost)
        out.__dict__.update(self.__dict__)
        out.shape, out.count = shape, piece.shape[0]
        out.piece, out.tip_loads = piece, tip
        out._piece = piece.reshape(*shape, *piece.shape[1:])
        out._tip = tip.reshape(*shape, tip.shape[-1])
        return out

    def signature(self) -> tuple:
        """What identifies the actuators (kinds, paths, where they act): a chained solve
        continues from the last case only if this is unchanged."""
        return tuple((kind, routing, span) for kind, routing, _, span in self.actuators)


@dataclass(frozen=True)
class ShootResult:
    """One integration of the arm from a base reaction (:meth:`Solver.shoot`).

    Attributes
    ----------
    residual : ndarray, shape (6,)
        r(x, λ) = (n(L) - F_d - R(L) F_f; m(L) - M_d - R(L) M_f), N and N m, spatial.
    jacobian_x : ndarray, shape (6, 6)
        ∂r/∂x, x = (n(0); m(0)) the base reaction in spatial components.
    jacobian_load : ndarray, shape (6,)
        ∂r/∂λ at fixed x.
    tip_pose : ndarray, shape (4, 4)
    tip_motion_x : ndarray, shape (6, 6)
        ∂(δp(L); δθ(L))/∂x, both in spatial components (δR = δθ~ R).
    """

    residual: np.ndarray
    jacobian_x: np.ndarray
    jacobian_load: np.ndarray
    tip_pose: np.ndarray
    tip_motion_x: np.ndarray
    #: with ``inputs=True``: ∂r/∂q (6, n) and ∂(δp(L); δθ(L))/∂q (6, n, spatial), q the
    #: actuation inputs in load order (as ``Equilibrium.actuation_jacobian``)
    jacobian_inputs: np.ndarray | None = None
    tip_motion_inputs: np.ndarray | None = None


class Shooter:
    """:meth:`Solver.shoot` with the input columns, prepared for one load set
    (:meth:`Solver.shooter`). The load channels are affine in the actuation inputs q (a
    tension, a pressure, a field component), piece(q) = piece(q₀) + Σᵢ (qᵢ - q₀ᵢ) unitᵢ, so a
    call with new inputs only recombines the prepared arrays.

    Attributes
    ----------
    inputs : ndarray, shape (n,)
        q₀: the loads' own input values, in load order (``Equilibrium.actuation_jacobian``'s
        columns).
    """

    def __init__(self, solver, prepared, arm, inputs, unit_piece, unit_tip):
        self._solver, self._arm = solver, arm
        _, _, _, pieces, channels = prepared
        self._piece_lengths, self._actuators = pieces[1], len(channels.actuators)
        piece, tip = channels.piece[0], channels.tip_loads[0]
        self.inputs = inputs
        self._unit_tip = unit_tip
        # the kernel reads the first rate row even at λ = 0: loads without inputs get a zero
        # row, and its column is dropped from the result
        self._rates = (unit_piece, unit_tip) if inputs.size else (
            np.zeros((1, *piece.shape)), np.zeros((1, tip.size)))
        self._piece0, self._unit_flat, self._tip0 = _at_zero_inputs(piece, tip, inputs,
                                                                     unit_piece, unit_tip)
        self._counts = {}  # step counts per `steps` argument

    def __call__(self, x, inputs=None, *, load_factor=1.0, steps=None) -> ShootResult:
        """One integration from the base reaction ``x`` (N, N m, spatial) with the inputs
        ``inputs`` (default :attr:`inputs`) at load factor λ (every load, inputs included,
        scaled by λ); ``steps`` as in :meth:`Solver.shoot`. Inputs are not validated (a
        negative tension is integrated as given): the caller keeps them in their bounds."""
        q = self.inputs if inputs is None else np.asarray(inputs, dtype=np.float64)
        if q.shape != self.inputs.shape:
            raise ValueError(f"inputs must have shape {self.inputs.shape} (every actuation "
                             f"input of the loads, in load order), got {q.shape}")
        lam = float(load_factor)
        piece, tip = self._at(q)
        k = kernels
        case = (piece, self._rates[0], tip, self._rates[1]) if lam == 1.0 else (
            lam * piece, lam * self._rates[0], lam * tip, lam * self._rates[1])
        result = _shoot(k, x, 0.0, self._steps(steps), self._solver._base_kernel, self._arm,
                        case, self._actuators)
        if not self.inputs.size:
            result = dataclasses.replace(result, jacobian_inputs=result.jacobian_inputs[:, :0],
                                         tip_motion_inputs=result.tip_motion_inputs[:, :0])
        return result

    def kernel_arrays(self, steps) -> tuple:
        """What a compiled caller of the kernel's ``shoot`` needs to integrate these loads
        at any inputs q (inverse statics' ``inverse_newton``): the step counts (``steps`` as
        in :meth:`Solver.shoot`), the base pose, the kernel's (arm, act) pair (passed on as
        ``*arm``), and the channels at q = 0
        and per unit input (piece0 (P, W), unit piece (n, P, W), tip0 (12,), unit tip
        (n, 12); piece(q) = piece0 + Σᵢ qᵢ unitᵢ)."""
        return (self._steps(steps), self._solver._base_kernel, self._arm,
                (self._piece0, self._rates[0], self._tip0, self._rates[1]))

    def _steps(self, steps) -> np.ndarray:
        """The step counts per piece for ``steps`` (as in :meth:`Solver.shoot`), kept."""
        key = steps if steps is None or isinstance(steps, (int, tuple)) else None
        counts = self._counts.get(key) if key is not None else None
        if counts is None:
            counts = self._solver._step_counts(self._piece_lengths, steps)
            if key is not None and len(self._counts) < 64:
                self._counts[key] = counts
        return counts

    def _at(self, q):
        """The piece and tip channels (one case) at inputs q."""
        return (self._piece0 + (q @ self._unit_flat).reshape(self._piece0.shape),
                self._tip0 + q @ self._unit_tip)


class Snapshot(NamedTuple):
    """One answer of a :class:`PreparedSolve`, copied out of its buffers (their names)."""

    inputs: np.ndarray
    poses: np.ndarray
    strains: np.ndarray
    stresses: np.ndarray
    info: np.ndarray
    base_wrench: np.ndarray
    lengths: np.ndarray
    jacobian: np.ndarray | None
    motion: np.ndarray | None
    index: int
    conservative: bool


class PreparedSolve:
    """:meth:`Solver.solve` (chained, quasi-static) of one load structure whose only changing
    values are the actuation inputs q, prepared once (:meth:`Solver.prepared`): the control
    loop's call, 1000 times a second.

    The same kernels as :meth:`Solver.solve`, without the Python around them that each call
    of it pays: the loads are not validated or written into channels again (the channels are
    affine in q, ``piece(q) = piece0 + Σᵢ qᵢ unitᵢ``, as for :class:`Shooter`), the outputs
    and the stability verdict's arrays are allocated once and overwritten by every call, and
    no :class:`Equilibrium` is built unless asked for (:meth:`equilibrium`). It shares the
    Solver's quasi-static state: a call continues from the Solver's last equilibrium, and a
    later :meth:`Solver.solve` from this one's. Without ``jacobians`` the answer is
    :meth:`Solver.solve`'s to the bit. With them, a call after this object's own last one
    predicts the path's step from that answer's -J_x⁻¹ J_q Δq and the fine solution from its
    grid offset (README.md beside this file, "The predicted step"): the answer is within
    1 % of tol of :meth:`Solver.solve`'s, and two integrations cheaper.

    Attributes (the buffers, after :meth:`solve`: views, overwritten by the next call)
    ----------
    inputs : (n,) every actuation input of the loads in load order (the columns of
        ``Equilibrium.actuation_jacobian``), the last call's.
    poses : (S, 4, 4); strains, stresses : (S, 6) (material); info : (5,) residual, tip
        error estimate (m), load factor reached, shootings, N (the solution is on 2N steps).
    base_wrench : (6,) the total wrench at the clamp (spatial); lengths : (A,) each
        actuator's length (m; a chamber's 0).
    jacobian : (6 + A, 6 + n), with ``jacobians``: rows 0:6 [J_x⁻¹ | J_x⁻¹ J_q], rows 6 + a
        [∂ℓ_a/∂W | ∂ℓ_a/∂q] (actuator a's length per dead tip wrench and per input).
    motion : (S, 6, 6 + n), with ``jacobians``: per station [compliance | actuation
        Jacobian], (δp; δθ) spatial.
    index, conservative : int, bool
        The stability verdict (Morse index; whether the loads are conservative), when the
        Solver computes verdicts.
    """

    def __init__(self, solver, loads, *, jacobians: bool):
        k = kernels
        loads, shape, _, pieces, channels = solver._prepare(loads)
        if shape != ():
            raise ValueError(f"Solver.prepared takes a single load case, got batch shape "
                             f"{shape}")
        self._solver, self._k, self.loads = solver, k, loads
        self._pieces, self._channels = pieces, channels
        self._signature = channels.signature()
        W = channels.piece.shape[2]
        unit_piece, unit_tip = solver._input_channels(loads, pieces, W)
        self.inputs = np.array([v for load in loads for name in load.inputs
                                for v in np.ravel(np.asarray(getattr(load, name), dtype=float))])
        n, P, A = self.inputs.size, pieces[0].size, len(channels.actuators)
        self._unit = (unit_piece, unit_tip) if jacobians else None
        self._piece0, self._unit_flat, self._tip0 = _at_zero_inputs(
            channels.piece[0], channels.tip_loads[0], self.inputs, unit_piece, unit_tip)
        self._unit_tip = unit_tip
        # the case's own channels (one row each), rewritten by every call
        self._piece, self._tip = channels.piece.copy(), channels.tip_loads.copy()
        self._start = (np.zeros((P, W)), np.zeros(k.TIP_LOADS))  # the path's start loads
        self._arm = channels.arm_tuple()
        self._jacobians = bool(jacobians)
        self._options = {near: solver._options(near) for near in (False, True)}
        # In contact the kernel writes the Solver's fine stations (_contact_stations), on
        # which every answer is checked for penetration (_raise_contact), and the buffers
        # take the stations asked for from them
        self._s_out, self._asked = solver._s_kernel, None
        if channels.contact_load is not None:
            self._s_out, self._asked = _contact_stations(
                solver._s_kernel, solver.length, np.append(pieces[0], solver.length))
            self._radii = channels.contact_load.station_radii(solver.arm, self._s_out)
        S = self._s_out.size
        self._outs = (np.empty((1, S, 4, 4)), np.empty((1, S, 6)), np.empty((1, S, 6)),
                      np.zeros((1, 5)), np.zeros(1, dtype=np.int64),
                      np.zeros((1, 6 + A, 6 + n)) if jacobians else solver._unused((0, 6, 6)),
                      np.zeros((1, S, 6, 6 + n)) if jacobians else solver._unused((1, S, 6, 6)),
                      np.empty((1, 6)), np.empty((1, A)))
        poses, strains, stresses, info, _, jac, motion, base_wrench, lengths = self._outs
        self.poses, self.strains, self.stresses = poses[0], strains[0], stresses[0]
        self.info, self.base_wrench, self.lengths = info[0], base_wrench[0], lengths[0]
        self.jacobian = jac[0] if jacobians else None
        self.motion = motion[0] if jacobians else None
        if self._asked is not None:  # the asked stations' own buffers
            self.poses, self.strains, self.stresses = (
                np.empty((self._asked.size, *a.shape[1:])) for a in
                (self.poses, self.strains, self.stresses))
            if jacobians:
                self.motion = np.empty((self._asked.size, *self.motion.shape[1:]))
        # the verdict's arrays (writable and C-contiguous: one compiled version)
        self._tips = np.empty((1, 4, 4)) if solver.s[-1] == solver.length \
            else np.zeros((0, 4, 4))
        self._Ns = np.zeros(1)
        self._index, self._theta0 = np.zeros(1, dtype=np.int64), np.zeros((1, 6, 6))
        self._flags = np.zeros(1, dtype=np.bool_)
        self.index, self.conservative = 0, True
        self._last = None  # what this object last wrote as the Solver's _last
        #: whether the last call succeeded (its answer is in the buffers), on either route
        self.solved = False
        self._q_last, self._dq = np.empty(n), np.empty(n)  # its inputs; their change
        # The route (_stiff.py): fixed when no input changes the loads' largest force (a
        # tendon's tension, a chamber's pressure and a field's B0 do not: measured at zero
        # and at each unit input), else decided at every call
        self._route = None
        if solver.shooting != "auto":
            self._route = solver.shooting == "multiple"
        elif channels.contact_load is not None:
            self._route = True  # (as Solver._stiff)
        else:
            units = np.eye(n)
            kls = {float(self._kl(self.loads_at(q))) for q in (np.zeros(n), *units)}
            if len(kls) == 1:
                self._route = float(self._kl(loads)) >= STIFF_KL

    def _kl(self, loads) -> float:
        return tension_kl(self._solver.arm, loads, (), self._solver._data.soft)[0]

    def _stiff(self) -> bool:
        """Whether the loads at the present inputs take multiple shooting (Solver's route,
        _stiff.py)."""
        if self._route is not None:
            return self._route
        return bool(self._kl(self.loads_at(self.inputs)) >= STIFF_KL)

    def solve(self, q, *, near=None) -> None:
        """Solve at the inputs q (every input, in :attr:`inputs`' order; not validated: the
        caller keeps them finite and tensions >= 0) from the Solver's last equilibrium, or
        with ``near`` = (x, steps) from the solution x on ``steps`` RK4 steps of these very
        loads (:meth:`Solver.solve_near`). Writes the buffers; a ConvergenceError if the
        kernel fails (the Solver then returns to the unloaded arm)."""
        k, solver = self._k, self._solver
        self.solved = False
        np.copyto(self.inputs, q)
        piece, tip = self._piece, self._tip
        np.dot(self.inputs, self._unit_flat, out=piece.reshape(-1))
        piece += self._piece0
        np.dot(self.inputs, self._unit_tip, out=tip[0])
        tip += self._tip0
        start_piece, start_tip = self._start
        stiff = self._stiff()
        if stiff:
            # multiple shooting, along the Solver's chain (_StiffChain: from its last
            # solution on this route, else from the unloaded arm), with its verdict
            memory = None
        elif near is not None:
            memory = solver._memory = np.zeros(k.MEMORY)
            memory[0:6] = memory[6:12] = near[0]
            memory[12], memory[13] = max(1, int(near[1]) // 2), 1.0
            np.copyto(start_piece, piece[0])
            np.copyto(start_tip, tip[0])
        else:
            last = solver._last
            if last is not None and last is not self._last and (
                    last[3] == self._signature and last[0] is self._pieces[0]):
                # another call of the Solver moved it since, with these actuators on this
                # cut: its path starts from there
                np.copyto(start_piece, last[1])
                np.copyto(start_tip, last[2])
            elif last is None or last is not self._last:  # from the unloaded arm
                solver.reset()
                start_piece[:] = 0.0
                start_tip[:] = 0.0
            if solver._memory is None:
                solver._memory = np.zeros(k.MEMORY)
            memory = solver._memory
            if self._jacobians and last is self._last and self._last is not None:
                # from this object's own last solution, whose output pass gave J_x⁻¹ J_q:
                # the step of x along the inputs' tangent, for the kernel's one-step path
                np.subtract(self.inputs, self._q_last, out=self._dq)
                np.dot(self.jacobian[:6, 6:], self._dq, out=memory[k.MSTEP:k.MSTEP + 6])
                np.negative(memory[k.MSTEP:k.MSTEP + 6], out=memory[k.MSTEP:k.MSTEP + 6])
                memory[k.MPREDICTED] = 1.0
        status = self._outs[4]
        if stiff:
            for attempt in range(_CONTACT_RETRIES + 1):
                k.solve_stiff_cases(solver._base_kernel, *self._arm, (piece, tip),
                                    self._options[False], self._s_out, self._outs,
                                    (self._index, self._flags) if solver.stability else None,
                                    self._unit, solver._stiff_chain(self._pieces,
                                                                    self._channels))
                if status[0] != k.OK or self._asked is None or \
                        not self._raise_contact(attempt):
                    break
        else:
            k.solve_cases(solver._base_kernel, *self._arm, (piece, tip), self._start,
                          self._options[near is not None], self._s_out, memory,
                          self._unit, self._outs)
        if status[0] != k.OK:
            solver.reset()
            self._last = None
            error = _failure(k, 0, (), status, self._outs[3], solver, near is not None)
            if status[0] == k.PATH_FAILED and near is None:
                error = _tendon_limit(solver, self.loads_at(self.inputs), (), 0, None,
                                      error.residual) or error
            raise error
        if self._asked is not None:
            for fine, asked in ((self._outs[0][0], self.poses), (self._outs[1][0], self.strains),
                                (self._outs[2][0], self.stresses)) + (
                    ((self._outs[6][0], self.motion),) if self._jacobians else ()):
                np.take(fine, self._asked, axis=0, out=asked)
        try:
            _admissible(solver, self.strains, self.stresses, solver._s_kernel, (),
                        self.info[0], True)
        except InadmissibleStateError:
            self._last = None
            raise
        self.solved = True
        if stiff:
            solver._forget_single()
            self._last = None
            if solver.stability:
                self.index, self.conservative = int(self._index[0]), bool(self._flags[0])
            return
        np.copyto(start_piece, piece[0])
        np.copyto(start_tip, tip[0])
        np.copyto(self._q_last, self.inputs)
        self._last = solver._last = (self._pieces[0], start_piece, start_tip, self._signature)
        if solver.stability:
            if self._tips.shape[0]:
                np.copyto(self._tips[0], self.poses[-1])
            self._Ns[0] = self.info[4]
            _prefetch.wait(_prefetch.kind(self._arm))
            k.stability_cases(solver._base_kernel, *self._arm, (piece, tip), self._outs[7],
                              self._Ns, self._tips, 1, self._index, self._theta0, self._flags,
                              None)
            self.index, self.conservative = int(self._index[0]), bool(self._flags[0])

    def _raise_contact(self, attempt: int) -> bool:
        """After a solve in contact (on the fine stations): False if no station penetrates
        an obstacle by more than tol·L; else True, the penalty raised in this object's
        channels for this call's retry and every later call (the law only grows, as in
        Solver.solve and the dynamics; :func:`_penetration`, which raises the
        ConvergenceError after its last attempt or for a stiffness the user gave)."""
        channels, k = self._channels, self._k
        law = channels.contact_load
        gaps, forces = law.gaps(self._outs[0][:, :, :3, 3], self._radii)
        stiffer = _penetration(self._solver, law, gaps, forces, attempt,
                               channels.contact_given_stiffness)
        if stiffer is None:
            return False
        for piece in (self._piece0, self._piece[0]):
            piece[:, k.CT] = stiffer[0]
        channels.contact_load = law.replace(stiffness=stiffer)
        return True

    def reset(self) -> None:
        """Back to the unloaded arm: the Solver's quasi-static state, and this object's last
        answer (no prediction from it)."""
        self._solver.reset()
        self._last = None
        self.solved = False

    def loads_at(self, q) -> tuple:
        """The loads with the inputs q (:attr:`inputs`' order), values not validated again."""
        out, at = [], 0
        for load in self.loads:
            changes = {}
            for name in load.inputs:
                shape = np.shape(getattr(load, name))
                size = math.prod(shape)
                changes[name] = np.reshape(q[at:at + size], shape).copy() if shape \
                    else float(q[at])
                at += size
            if load.kind == "contact":  # the law this object solves with (raised as needed)
                law = self._channels.contact_load
                load = law.replace(stiffness=float(np.max(law.stiffness)))
            out.append(load._with_checked(**changes) if changes else load)
        return tuple(out)

    def snapshot(self) -> Snapshot:
        """The last call's answer, copied (what :meth:`equilibrium` builds from)."""
        jacobians = self._jacobians
        return Snapshot(self.inputs.copy(), self.poses.copy(), self.strains.copy(),
                        self.stresses.copy(), self.info.copy(), self.base_wrench.copy(),
                        self.lengths.copy(), self.jacobian.copy() if jacobians else None,
                        self.motion.copy() if jacobians else None, self.index,
                        self.conservative)

    def equilibrium(self, snapshots=None, loads=None) -> Equilibrium:
        """The :class:`Equilibrium` of the last call (copies of the buffers), as
        :meth:`Solver.solve` would have returned it; of one :meth:`snapshot`; or, given a
        list of B snapshots, of those B answers batched (B,), with ``loads`` their loads
        (default: :attr:`loads` at the answer's inputs, for one answer)."""
        solver = self._solver
        single = snapshots is None or isinstance(snapshots, Snapshot)
        snapshots = [self.snapshot() if snapshots is None else snapshots] if single \
            else snapshots
        B, S = len(snapshots), solver.s.size
        shape = () if single else (B,)

        def stacked(name):  # (fresh arrays: frozen below where Equilibrium takes them)
            if single:  # (np.stack costs 8 µs a field)
                value = getattr(snapshots[0], name)
                value.setflags(write=False)  # (the snapshot's own copy: its views frozen)
                return value[None]
            return np.stack([getattr(snap, name) for snap in snapshots])

        poses, strains, stresses, info, base_wrench, lengths = (stacked(name) for name in (
            "poses", "strains", "stresses", "info", "base_wrench", "lengths"))
        inputs = stacked("inputs")
        P, W = self._piece0.shape
        piece = (inputs @ self._unit_flat).reshape(B, P, W) + self._piece0
        tip = inputs @ self._unit_tip + self._tip0
        actuation = _actuation(self._channels.cases(piece, tip, shape), base_wrench, lengths,
                               shape)
        tip_compliance = compliance = None
        if self._jacobians:
            tip_compliance, compliance, tip_inputs, station_inputs, lengths_inputs = \
                _compliances(stacked("jacobian"), stacked("motion"), shape, self.tendons)
            actuation.update(actuation_jacobian=tip_inputs,
                             station_actuation_jacobian=station_inputs,
                             tendon_length_jacobian=lengths_inputs)
        if solver.stability:
            actuation["stability"] = Stability.of(
                np.array([snap.index for snap in snapshots]),
                np.array([snap.conservative for snap in snapshots]), shape)
        for array in (poses, strains, stresses, info):
            array.setflags(write=False)
        residual, estimate = info[:, 0], info[:, 1]
        return Equilibrium(
            s=solver.s, poses=poses.reshape(*shape, S, 4, 4),
            strains=strains.reshape(*shape, S, 6), stresses=stresses.reshape(*shape, S, 6),
            arm=solver.arm, loads=self.loads_at(inputs[0]) if loads is None else loads,
            method=METHOD, exact=True,
            residual=float(residual[0]) if single else residual,
            error_estimate=float(estimate[0]) if single else estimate,
            tip_compliance=tip_compliance, compliance=compliance, **actuation)

    @property
    def tendons(self) -> np.ndarray:
        """The actuator columns (of :attr:`lengths`, of :attr:`jacobian`'s rows 6..) that
        are tendons."""
        return self._channels.tendons()[0]


def _at_zero_inputs(piece, tip, inputs, unit_piece, unit_tip) -> tuple:
    """The load channels of one case, affine in its actuation inputs q (piece(q) = piece0 +
    Σᵢ qᵢ unitᵢ, likewise the tip's), at q = 0: (piece0 (P, W), the unit pieces flattened
    (n, P W), tip0 (TIP_LOADS,)), from the case at ``inputs`` (n,)."""
    unit_flat = unit_piece.reshape(inputs.size, piece.size)  # (n = 0 too)
    return (piece - (inputs @ unit_flat).reshape(piece.shape), unit_flat,
            tip - inputs @ unit_tip)


def _shoot(k, x, lam, counts, base, arm, case, actuators) -> ShootResult:
    """One call of the kernel's ``shoot``: the tangent columns after x are those of
    ``case``'s rate rows (inputs, or the load factor), returned as ``jacobian_inputs`` and
    ``tip_motion_inputs``."""
    x = np.asarray(x, dtype=np.float64)
    if x.shape != (6,) or not np.all(np.isfinite(x)):
        raise ValueError(f"x must be 6 finite numbers (n(0); m(0)), got {x!r}")
    ncols = 6 + case[1].shape[0]
    r, J = np.empty(6), np.empty((6, ncols))
    y, T = np.empty(18 + actuators), np.empty((ncols, 12 + actuators))  # with the lengths
    k.shoot(x.copy(), lam, counts, base, *arm, case, r, J, y, T)
    R = y[3:12].reshape(3, 3)
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = R, y[:3]
    motion = np.empty((6, ncols))
    motion[:3] = T[:, :3].T
    motion[3:] = R @ T[:, 3:6].T
    return ShootResult(r, J[:, :6].copy(), None, pose, motion[:, :6].copy(), J[:, 6:].copy(),
                       motion[:, 6:].copy())


def _by_route(k, solver, arm, channels, options, s_kernel, first, memory, inputs, outs,
              stiff, count, verdicts, chain) -> None:
    """Solve the easy cases by single shooting (solve_cases) and the stiff ones by multiple
    shooting (solve_stiff_cases, with their stability verdicts into ``verdicts`` (index,
    conservative) when given, along ``chain`` when it is on), each route on its cases
    gathered, in threads, the outputs scattered back (unchained, a case's answer does not
    depend on the others: batch = loop; chained, one thread follows the batch in order)."""
    for route, index in ((False, np.flatnonzero(~stiff)), (True, np.flatnonzero(stiff))):
        if index.size == 0:
            continue
        whole = index.size == count
        pieces = channels.piece if whole else channels.piece[index]
        tips = channels.tip_loads if whole else channels.tip_loads[index]
        part = outs if whole else tuple(x[index] if x.shape[0] == count else x for x in outs)
        judged = None if verdicts is None else tuple(v[index] for v in verdicts)

        def run(a, b, pieces=pieces, tips=tips, part=part, route=route, size=index.size,
                judged=judged):
            cut = tuple(x[a:b] if x.shape[0] == size else x for x in part)
            if route:
                k.solve_stiff_cases(solver._base_kernel, *arm, (pieces[a:b], tips[a:b]),
                                    options, s_kernel, cut,
                                    None if judged is None else (judged[0][a:b],
                                                                 judged[1][a:b]), inputs,
                                    chain)
            else:
                k.solve_cases(solver._base_kernel, *arm, (pieces[a:b], tips[a:b]), first,
                              options, s_kernel, memory, inputs, cut)

        one_path = first is not None or chain[3][0] > 0.0
        in_threads(run, index.size, 1 if one_path else solver._threads(index.size))
        if route and judged is not None:
            for v, w in zip(verdicts, judged, strict=True):
                v[index] = w
        if not whole:
            for x, y in zip(outs, part, strict=True):
                if x.shape[0] == count:
                    x[index] = y


class _StiffChain:
    """A chained Solver's memory on the multiple-shooting route (solve_stiff_cases'
    ``chain``): the last solution's base reaction, nodes and steps, and its loads, from
    which the next chained solve follows its loading path instead of from the unloaded arm
    (the path from the last loads to the new ones, on the last solution's grid or that grid
    refined where the new loads need more intervals; a cold start where that fails or would
    take over twice a cold start's intervals: solve_stiff_cases). ``key``: the kernel problem it
    was solved on (Solver._stiff_chain). Measured on examples/gripper_finger.toml (201
    stations, tol 1e-6): a 0.5 N move of its tendon in contact, 1.0-1.4 s from the unloaded
    arm and 0.09-0.16 s from the last solution (docs/solver.md, "Chained solves")."""

    #: the most intervals a chain holds (a solution on more: the next solve starts cold)
    MOST_INTERVALS = 8192

    def __init__(self, key, pieces: int, width: int, intervals: int):
        k = kernels
        state = 18 + width - k.PIECE_LOADS  # the kernel's: p, R, n, m, tendon lengths
        self.key = key
        self.arrays = (np.zeros(6), np.zeros((intervals, state)),
                       np.ones(intervals, dtype=np.int64), np.array([1.0, 0.0, 0.0, 0.0]),
                       np.zeros((pieces, width)), np.zeros(k.TIP_LOADS))


def _chain_off() -> tuple:
    """solve_stiff_cases' ``chain`` off (every case from the unloaded arm)."""
    global _CHAIN_OFF
    if _CHAIN_OFF is None:
        _CHAIN_OFF = (np.zeros(6), np.zeros((1, 1)), np.ones(1, dtype=np.int64), np.zeros(4),
                      np.zeros((1, 1)), np.zeros(kernels.TIP_LOADS))
    return _CHAIN_OFF


_CHAIN_OFF = None


class Solver:
    """A prepared problem: an arm, output stations, a tolerance and a base pose.

    :meth:`solve` follows the arm *quasi-statically*, as a slowly driven arm moves: from its
    previous equilibrium (at first the unloaded arm) continuously to the new loads, and through
    a batch case after case in order, so hysteresis is possible; :meth:`reset` returns it to
    the unloaded arm. :func:`softarm.solve` instead solves every case from the unloaded arm,
    independently of the others. One Solver per thread or worker (it carries state).

    Parameters
    ----------
    arm : Arm or SegmentedArm
    s : None, int or array_like
        Output stations in m (default 101 uniform on [0, L]; an int gives that many).
    tol : float
        Tolerance on the tip position, relative to L: the step count is raised until the
        step-doubling (Richardson) estimate of the tip position error is ≤ tol·L.
    base : array_like, shape (4, 4), optional
        Pose of the clamped base (default identity).
    max_iterations : int
        Newton iterations per corrector.
    max_load_step : float
        Largest continuation step in the load factor λ, in (0, 1] (default 1: one step where
        the path is straight enough). Smaller values only cost time; the answer is the same.
    steps : int, optional
        Fix the number of RK4 steps of the solution (an even number, spread over the pieces in
        proportion to their length) instead of choosing it from ``tol``; the error estimate
        still compares it with half as many steps. For convergence studies.
    max_steps : int
        Largest number of RK4 steps tried before giving up on ``tol`` (ConvergenceError).
    max_shootings : int
        Budget of trajectory integrations per load case before a ConvergenceError.
    stability : bool
        Compute the stability verdict of every case (``Equilibrium.stability``; a backward
        sweep of the linearised equations, docs/stability.md). Default True.
    threads : int, optional
        Threads for a batch solved from the unloaded arm (:meth:`solve_from_unloaded`, what
        :func:`softarm.solve` calls) and for the stability verdicts, in chunks of at least
        16 cases; the answer is the same to the bit. Default: ``$SOFTARM_NUM_THREADS`` or
        every core this process may run on (``softarm._threads``). A chained :meth:`solve`
        runs its batch in order, in one thread.
    diagnose : bool
        When a case's loading path fails and tendons act, find out whether a tendon's path
        left the model there (its length vanishing: an :class:`~softarm.InadmissibleStateError`
        naming the tendon and the tension it can carry), by solving the case again near the
        failure. Default True; False for a caller that handles failures itself and reads no
        message (inverse statics' trial steps).
    shooting : str
        "auto" (default): each case by single shooting on the six base unknowns, or, where
        the loads put the arm in strong tension (kL = L √(F/EI) >= 15, docs/solver.md), by
        multiple shooting on the states at the starts of intervals of kL <= 3 each.
        "single" or "multiple" forces one route (for comparisons and studies).

    Examples
    --------
    >>> from softarm import Arm, TipLoad
    >>> arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    >>> solver = Solver(arm, s=3)
    >>> eq = solver.solve([TipLoad(force=[0.0, 0.0, 1.0])])   # k = PL²/EI = 1
    >>> round(float(eq.tip_position[2]), 5)  # Mattiasson (1981) Table 1: w/L = 0.30172
    0.30172
    """

    def __init__(self, arm, *, s=None, tol=1e-8, base=None, max_iterations=12,
                 max_load_step=1.0, steps=None, max_steps=_N_MAX, max_shootings=10000,
                 stability=True, threads=None, diagnose=True, shooting="auto"):
        self.arm = _check_arm(arm)
        self._data = _arm_data(arm)
        self.length = self._data.length
        if isinstance(s, (int, np.integer)) and not isinstance(s, (bool, np.bool_)):
            check_allocation(1, int(s), "s")
        if s is None or (isinstance(s, (int, np.integer)) and not isinstance(s, bool)
                         and s >= 2):
            self.s, self._s_kernel = _uniform_stations(self.length, 101 if s is None else int(s))
        else:
            self._s_kernel = stations(s, self.length)  # writable: one kernel type
            self.s = self._s_kernel.copy()
            self.s.setflags(write=False)
        self.tol = check_tol(tol)
        self.base = check_base(base)
        self._base_kernel = self.base.copy()  # private and writable (one kernel type)
        self.max_iterations = count(max_iterations, "max_iterations", 1)
        self.max_load_step = real(max_load_step, "max_load_step")
        if not 0.0 < self.max_load_step <= 1.0:
            raise ValueError(f"max_load_step must be a load-factor step in (0, 1], got "
                             f"{max_load_step!r}")
        if steps is not None and (count(steps, "steps", 2) % 2 or steps > _N_MAX):
            raise ValueError(f"steps must be an even integer in [2, {_N_MAX}], got {steps!r}")
        self.steps = steps
        self.max_steps = count(max_steps, "max_steps", 4)
        self.max_shootings = count(max_shootings, "max_shootings", 1)
        if not isinstance(stability, (bool, np.bool_)):
            raise TypeError(f"stability must be True or False, got {stability!r}")
        self.stability = bool(stability)
        self.threads = None if threads is None else count(threads, "threads", 1)
        if not isinstance(diagnose, (bool, np.bool_)):
            raise TypeError(f"diagnose must be True or False, got {diagnose!r}")
        self.diagnose = bool(diagnose)
        if shooting not in ("auto", "single", "multiple"):
            raise ValueError(f"shooting must be 'auto', 'single' or 'multiple', got "
                             f"{shooting!r}")
        self.shooting = shooting
        self._coarse_ratio = 4  # the path runs on N / 4 steps (benchmarks/run.py measures it)
        # (the Contact as given, the stiffness it needed): the stiffest penalty a chained
        # single case needed after a penetration, its next solves' start (_solve)
        self._kept_law = None
        self.reset()

    def _with_stations(self, s: np.ndarray, *, stability: bool) -> Solver:
        """A Solver like this one (arm, tol, base, options) at the stations ``s`` (checked:
        increasing, on [0, L]), with or without verdicts, at the unloaded arm."""
        other = copy.copy(self)
        other._s_kernel = np.array(s, dtype=np.float64)
        other.s = other._s_kernel.copy()
        other.s.setflags(write=False)
        other.stability = stability
        other._kept_law = None
        other.reset()
        return other

    def _stiff(self, loads, channels) -> np.ndarray:
        """Which cases go to multiple shooting (B,) bool: ``shooting`` "multiple" all,
        "single" none, "auto" those whose estimated kL reaches STIFF_KL (_stiff.py)."""
        if self.shooting != "auto":
            return np.full(channels.count, self.shooting == "multiple")
        if channels.contact_load is not None:  # (contact.md: why contact takes this route)
            return np.full(channels.count, True)
        return tension_kl(self.arm, loads, channels.shape, self._data.soft) >= STIFF_KL

    def _threads(self, cases: int) -> int:
        """Threads for a batch of ``cases`` independent cases."""
        if cases < 2 * CASES_PER_THREAD:  # one thread whatever the setting: no system call
            return 1
        return threads_for(cases, CASES_PER_THREAD, self.threads)

    def reset(self) -> None:
        """Return the quasi-static state to the unloaded arm."""
        self._forget_single()
        self._chain = None  # multiple shooting's: a _StiffChain, made on first use
        # a tip held with friction: (the contact's key, its free loads, its FrictionalTip),
        # from which a chained solve goes on (tip_friction.follow_on)
        self._friction = self._friction_found = None

    def _forget_single(self) -> None:
        """Forget single shooting's quasi-static memory (after a solve by multiple
        shooting, which keeps its own)."""
        self._memory = None  # the kernel's chained-solve memory, made on first use
        self._last = None  # (cut starts, piece loads, tip loads) of the last solved case

    def _stiff_chain(self, pieces, channels) -> tuple:
        """solve_stiff_cases' ``chain`` for a chained solve of these channels: this
        Solver's last solution on the multiple-shooting route if it was solved on the same
        kernel problem (the same cuts, actuators, and Contact as given with its band), else
        an empty chain (from the unloaded arm)."""
        given = channels._contact_given
        key = (pieces[0].tobytes(), channels.signature(),
               None if given is None else (_contact_key(given), channels.contact_load.distance))
        if self._chain is None or self._chain.key != key:
            intervals = min(_StiffChain.MOST_INTERVALS,
                            max(1, max(self.max_steps, self.steps or 0) // 4))
            self._chain = _StiffChain(key, pieces[0].size, channels.piece.shape[2], intervals)
        return self._chain.arrays

    # ---------------------------------------------------------------- preparation

    def check_loads(self, loads, *, jacobians: bool = False) -> tuple[tuple, tuple[int, ...]]:
        """(loads as a tuple, their batch shape), after checking that every load fits the arm
        and that the batch's outputs (with ``jacobians``, the compliances and actuation
        Jacobians too) fit in memory (ValueError before any allocation)."""
        loads = as_loads(loads)
        shape = batch_shape(loads)
        for load in loads:
            load.check(self.arm)
        self._check_memory(loads, shape, jacobians)
        check_magnitudes(self.arm, loads)
        return loads, shape

    def _check_memory(self, loads, shape, jacobians: bool) -> None:
        """:func:`check_allocation` of the batch's result; with Jacobians, per station the
        motion per column (6 + n inputs) and the compliances made of it (twice 48 B a
        column), per case the Jacobian's rows (6 + A actuators) likewise."""
        per_station, per_case = BYTES_PER_STATION, BYTES_PER_CASE
        if jacobians:
            n = sum(int(np.size(getattr(load, name))) // max(1, math.prod(load.batch_shape))
                    for load in loads for name in load.inputs)
            actuators = sum(1 for load in loads if load.acts_through_base)
            per_station += 2 * 48 * (6 + n)
            per_case += 2 * 8 * (6 + actuators) * (6 + n)
        check_allocation(math.prod(shape), self.s.size, "loads", per_station=per_station,
                         per_case=per_case)

    def _prepare(self, loads, extra_cuts=(), *, checked=False):
        """(loads, batch shape, count, the pieces (:meth:`_ArmData.pieces`), load channels);
        ``checked``:
        ``loads`` is what :meth:`check_loads` returned (not checked again)."""
        loads, shape = (loads, batch_shape(loads)) if checked else self.check_loads(loads)
        count = math.prod(shape)
        data = self._data
        cuts = tuple(sorted({float(c) for load in loads for c in load.cuts(self.arm)}
                            | {float(c) for c in extra_cuts}))
        pieces = data.pieces(cuts)
        channels = _Channels(data, pieces, shape, count)
        for load in loads:
            load.apply(channels)
        channels.resolve_contact()
        return loads, shape, count, pieces, channels

    def _options(self, near: bool = False) -> np.ndarray:
        n_fixed = self.steps if self.steps is not None else 0
        n_max = max(self.max_steps, self.steps or 0)
        tol = math.inf if self.steps is not None else self.tol * self.length
        return np.array([tol, self.max_iterations, self.max_load_step, n_fixed, n_max,
                         self.max_shootings, self._coarse_ratio, float(near)])

    # ---------------------------------------------------------------- solving

    def solve(self, loads, *, jacobians: bool = False) -> Equilibrium:
        """The equilibrium reached by driving the arm slowly from its previous equilibrium
        (the unloaded arm after construction or :meth:`reset`) to ``loads``; a batch is
        followed case after case in order. Loads with a displacement-controlled
        :class:`~softarm.Tendon` are solved from the unloaded arm instead (its tension is an
        unknown, ``docs/control.md``), and the quasi-static memory restarts after them.

        Raises
        ------
        ConvergenceError
            If the loading path meets a fold (the arm would snap; ``load_factor`` says where),
            Newton fails, or the error estimate cannot reach tol; its subclass
            :class:`~softarm.InadmissibleStateError` if the loads lead the arm out of the
            model (inside out, a tendon's path without length).
        ValueError
            For loads that do not fit the arm (point load off the arm, gravity without mass,
            a load too large to represent, a batch too large for memory).
        """
        return self._solve(loads, chained=True, jacobians=jacobians)

    def _settle(self, loads) -> None:
        """:meth:`solve` for the quasi-static memory only (the solution's base reaction and
        step count, :meth:`last_solution`): the tip is its one station and there is no
        verdict. Inverse statics' first target starts its fast route from it."""
        self._solve(loads, chained=True, jacobians=False, outputs=False)

    def solve_from_unloaded(self, loads, *, jacobians: bool = False) -> Equilibrium:
        """Every case of ``loads`` solved from the unloaded arm, independently of the others
        and of this Solver's state (what :func:`softarm.solve` returns)."""
        return self._solve(loads, chained=False, jacobians=jacobians)

    def _solve(self, loads, *, chained: bool, jacobians: bool, near: bool = False,
               outputs: bool = True, checked: bool = False,
               contact_retry: tuple | None = None) -> Equilibrium | None:
        """``near``: a single case whose path starts at its own loads, from the memory
        :meth:`solve_near` wrote (λ = 0 and λ = 1 the same loads); ``outputs=False``: only
        the memory of a chained solve (the tip its one station, no verdict), None;
        ``checked``: ``loads`` is what :meth:`check_loads` returned; ``contact_retry``:
        (each case's penalty stiffness or None, attempt, widenings) after a penetration
        (:func:`_penetration`) or a path that failed in contact (:func:`_widened_contact`)."""
        if not isinstance(jacobians, (bool, np.bool_)):
            raise TypeError(f"jacobians must be True or False, got {jacobians!r}")
        if not checked:
            loads = as_loads(loads)
        steps = max(self.max_steps, self.steps or 0)
        if self._data.turning > steps:
            raise ValueError(
                f"max_steps = {steps} RK4 steps cannot resolve this arm: it turns by "
                f"{self._data.turning:.4g} rad unloaded (its curvature |κ⁰| L), and a step "
                f"turns a section by a radian at most: give max_steps >= "
                f"{math.ceil(self._data.turning)}")
        if any(load.displacement_controlled for load in loads):
            # the tensions are unknowns: a bounded Newton method over tension-controlled
            # solves from the unloaded arm (statics/displacement.py); a chained Solver
            # restarts from the unloaded arm after it
            if chained:
                self.reset()
            return solve_displaced(self, loads, jacobians=jacobians)
        if not near:
            if not checked:
                loads, shape = self.check_loads(loads, jacobians=jacobians)
                checked = True
            else:
                shape = batch_shape(loads)
                if jacobians:  # (checked without them: by softarm.solve, for every route)
                    self._check_memory(loads, shape, jacobians)
            # (CASES_PER_PART, _validate's: a larger batch is solved in parts of that many
            # cases, each with its own channels, work arrays and result, copied into the
            # whole batch's; tests/test_memory.py)
            if math.prod(shape) > CASES_PER_PART:
                return self._solve_in_parts(loads, shape, chained=chained,
                                            jacobians=jacobians, outputs=outputs)
            if outputs and contact_retry is None and \
                    any(load.kind == "contact" for load in loads):
                held = self._held_at_tip(loads, shape, jacobians, chained)
                if held is not None:
                    # (every held solve is from the unloaded arm: a chained Solver goes on
                    # from there, whose answer this is where the held arm is stable; with
                    # friction it goes on from its last answer, tip_friction.py)
                    if chained:
                        found = self._friction_found
                        self.reset()
                        self._friction = found
                    return held
        k = kernels
        last = self._last if chained else None
        loads, shape, count, pieces, channels = self._prepare(
            loads, () if last is None else tuple(last[0]), checked=checked)
        if near:
            if shape != ():
                raise ValueError(f"Solver.solve_near takes a single load case, got batch "
                                 f"shape {shape}")
            last = (pieces[0], channels.piece[0], channels.tip_loads[0])
        elif last is not None and last[3] != channels.signature():
            # other actuators than the last case's: no continuous path from it
            self.reset()
            last = None
        stiffness, attempt, widened = contact_retry or (None, 0, 0)
        contact = channels.resolve_contact(stiffness) \
            if channels.contact_load is not None else None
        kept = self._kept_law
        if contact is not None and stiffness is None and chained and \
                kept is not None and kept[0] == _contact_key(channels._contact_given) and \
                np.any(kept[1] > channels.contact_load.stiffness):
            # A chained case starts at the stiffest penalty the last ones needed: its
            # estimate (from the loads' size) let the finger of examples/gripper_finger.toml
            # into the cylinder at every slider move of the app, and each move was solved
            # twice, the second time stiffer (2.5 s; 1.0 s from the kept law). The law only
            # grows, as in the dynamics (contact.md); the Equilibrium's Contact says which.
            contact = channels.resolve_contact(
                np.maximum(channels.contact_load.stiffness, kept[1]))
        given_loads = loads  # (a retry starts from them: their Contact as the user gave it)
        if contact is not None:
            if contact_retry is None:  # (a retry solves the same arm from the same start)
                _check_outside(self, channels.contact_load.replace(stiffness=None))
            loads = tuple(contact if load.kind == "contact" else load for load in loads)
        # unchained: no first loads, no memory (that code is not even compiled, softarm.kernels)
        first = memory = None
        if chained or near:
            if last is None:  # from the unloaded arm
                first = (np.zeros((pieces[0].size, channels.piece.shape[2])),
                         np.zeros(k.TIP_LOADS))
            elif near:
                first = (channels.piece[0].copy(), channels.tip_loads[0].copy())
            else:
                first = (_recut(last[0], last[1], pieces[0]), last[2])
            if self._memory is None:
                self._memory = np.zeros(k.MEMORY)
            memory = self._memory
        s_kernel = self._s_kernel if outputs else np.array([self.length])
        asked = None  # with contact: the stations asked for, among the solver's finer ones
        if contact is not None and outputs:
            s_kernel, asked = _contact_stations(s_kernel, self.length,
                                               np.append(pieces[0], self.length))
        S = s_kernel.size
        poses = np.empty((count, S, 4, 4))
        strains = np.empty((count, S, 6))
        stresses = np.empty((count, S, 6))
        info = np.zeros((count, 5))
        status = np.zeros(count, dtype=np.int64)
        inputs = self._input_channels(loads, pieces, channels.piece.shape[2]) \
            if jacobians else None
        n_in = inputs[0].shape[0] if jacobians else 0
        # rows 6 + a: actuator a's length per column (a tendon's; 0 for a chamber)
        jac = np.zeros((count, 6 + len(channels.actuators), 6 + n_in)) if jacobians \
            else self._unused((0, 6, 6))
        motion = np.zeros((count, S, 6, 6 + n_in)) if jacobians \
            else self._unused((1, S, 6, 6))
        base_wrench = np.empty((count, 6))
        lengths = np.empty((count, len(channels.actuators)))
        arm, options = channels.arm_tuple(), self._options(near)
        outs = (poses, strains, stresses, info, status, jac, motion, base_wrench, lengths)

        stiff = self._stiff(loads, channels)
        chain, along_chain = _chain_off(), False
        if stiff.any() and (chained or near):
            # multiple shooting keeps its own quasi-static memory (_StiffChain): a chained
            # batch follows its path from the last solution there, or from the unloaded arm
            # (solve_near's start too); single shooting's memory is then out of date
            stiff[:] = True
            if chained:
                chain, along_chain = self._stiff_chain(pieces, channels), True
            first = memory = None
            chained = near = False
            self._forget_single()
        elif chained or near:
            self._chain = None  # (single shooting moves the arm: the chain is out of date)

        def run(a, b):  # cases [a, b): per-case arrays cut, the rest (placeholders) whole
            k.solve_cases(self._base_kernel, *arm, (channels.piece[a:b],
                                                    channels.tip_loads[a:b]),
                          first, options, s_kernel, memory, inputs,
                          tuple(x[a:b] if x.shape[0] == count else x for x in outs))

        verdicts = None
        if not stiff.any():
            # (a chained batch is one path, case after case; unchained cases are independent)
            in_threads(run, count, 1 if chained or near else self._threads(count))
        else:
            if self.stability and outputs:
                verdicts = (np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.bool_))
            _by_route(k, self, arm, channels, options, s_kernel, first, memory, inputs, outs,
                      stiff, count, verdicts, chain)
        actuation = _actuation(channels, base_wrench, lengths, shape) if outputs else None
        failed = np.flatnonzero(status != k.OK) if status.any() else ()  # (OK is 0)
        if len(failed):
            if chained or along_chain:
                self.reset()
            wider = _widened_contact(self, given_loads, contact, widened)
            if wider is not None:  # a path the band was too thin to follow: a wider band
                return self._solve(wider, chained=chained, jacobians=jacobians, near=near,
                                   outputs=outputs, checked=True,
                                   contact_retry=(None, 0, widened + 1))
            b = int(failed[0])
            turns = None  # a single-shooting path from the unloaded arm: does it turn there?
            if status[b] == k.PATH_FAILED and not (chained or near or stiff[b]):
                turns = _path_turns(k, self, arm, channels, pieces, b, base_wrench[b],
                                    float(info[b, 2]), int(info[b, 4]))
            error = _failure(k, failed[0], shape, status, info, self, near, turns)
            if status[failed[0]] == k.PATH_FAILED and not near:
                error = _tendon_limit(self, loads, shape, int(failed[0]),
                                      None if chained else info[failed[0], 2],
                                      error.residual) or error
                if not chained:
                    error = _tension_limit(self, loads, shape, int(failed[0]), error) or error
            raise error
        if contact is not None:  # (the gaps and forces on the solver's stations, once)
            law = channels.contact_load
            gaps, forces = law.gaps(poses[..., :3, 3], law.station_radii(self.arm, s_kernel))
            stiffer = None if law.zones else _penetration(
                self, law, gaps, forces, attempt, channels.contact_given_stiffness)
            if stiffer is not None:  # raise the penalty until the pressure fits the band
                if chained or (along_chain and count > 1):
                    self.reset()
                # (a single case's retry along a chain starts from its penetrating answer,
                # which the chain holds)
                return self._solve(given_loads, chained=chained or along_chain,
                                   jacobians=jacobians, near=near, outputs=outputs,
                                   checked=True, contact_retry=(stiffer, attempt + 1, widened))
        _admissible(self, strains, stresses, s_kernel, shape, info[:, 0], chained)
        contact_resultant = None
        if asked is not None:  # the contact's total from the balance, then the asked stations
            contact_resultant = _contact_wrench(self, forces, loads, shape, s_kernel, poses,
                                                base_wrench)
            poses, strains, stresses = (np.ascontiguousarray(a[:, asked])
                                        for a in (poses, strains, stresses))
            if jacobians:
                motion = np.ascontiguousarray(motion[:, asked])
            S = asked.size
        if chained and count:
            self._last = (pieces[0], channels.piece[-1].copy(), channels.tip_loads[-1].copy(),
                          channels.signature())
        if contact is not None and (count == 1 or along_chain) and attempt > 0:
            # (raised after a penetration: kept for the next chained cases)
            self._kept_law = (_contact_key(channels._contact_given),
                              float(np.max(contact.stiffness)))
        if not outputs:
            return None
        tip_compliance = compliance = None
        if jacobians:
            tip_compliance, compliance, tip_inputs, station_inputs, lengths_inputs = \
                _compliances(jac, motion, shape, channels.tendons()[0])
            actuation.update(actuation_jacobian=tip_inputs,
                             station_actuation_jacobian=station_inputs,
                             tendon_length_jacobian=lengths_inputs)
        if self.stability:
            # from the tip (the last station when it is s = L) on the coarse grid N
            tips = poses[:, -1] if self.s[-1] == self.length else None
            actuation["stability"] = verdict(channels, self._base_kernel, base_wrench,
                                             info[:, 4], shape, tips,
                                             threads=self._threads(count),
                                             given=None if verdicts is None else
                                             (stiff, *verdicts))
        # fresh arrays, frozen before reshaping: Equilibrium takes them without a copy
        for array in (poses, strains, stresses, info):
            array.setflags(write=False)
        out_shape = (*shape, S)
        residual, estimate = info[:, 0], info[:, 1]
        return Equilibrium(
            s=self.s,
            poses=poses.reshape(*out_shape, 4, 4),
            strains=strains.reshape(*out_shape, 6),
            stresses=stresses.reshape(*out_shape, 6),
            arm=self.arm,
            loads=loads,
            method=METHOD,
            exact=True,
            residual=residual.reshape(shape) if shape else float(residual[0]),
            error_estimate=estimate.reshape(shape) if shape else float(estimate[0]),
            tip_compliance=tip_compliance,
            compliance=compliance,
            contact_resultant=contact_resultant,
            **actuation,
        )

    def _held_at_tip(self, loads, shape, jacobians: bool,
                     chained: bool = False) -> Equilibrium | None:
        """The solve of ``loads`` (checked, batch ``shape``, with a Contact) where the free
        tip alone touches an obstacle, held exactly (tip_contact.py); the cases it does not
        hold with the penalty; None where it holds none or a penalty is asked for.
        ``chained``: a tip held with friction goes on from the last answer's."""
        contact = next(load for load in loads if load.kind == "contact")
        self._friction_found = None
        if contact.stiffness is not None or contact.distance is not None:
            return None  # (a penalty asked for)
        _check_outside(self, contact)
        fine, asked = _contact_stations(self._s_kernel, self.length, np.array([self.length]))
        if contact.friction > 0.0 and math.prod(shape) > 1:
            # (friction: each case's own path, tip_friction.py)
            found = self._held_case_by_case(loads, shape, jacobians, fine, asked)
        else:
            try:
                found = solve_tip_contact(self, loads, shape, jacobians, fine, asked,
                                          self._friction if chained and not shape else None)
                if found is not None:
                    held = np.flatnonzero(found[1].reshape(-1))
                    found = ([(held, found[0], held)], found[1])
            except ConvergenceError:  # (some case's free arm, or a held iterate, failed)
                if not shape:
                    return None  # (the penalty follows the path, or says where it fails)
                found = self._held_case_by_case(loads, shape, jacobians, fine, asked)
        if found is None:
            return None
        parts, which = found
        if which.all() and len(parts) == 1:
            return parts[0][1]  # (every case held, in one solve)
        # the other cases with the penalty, each case's answer into the batch's result
        rest = np.flatnonzero(~which.reshape(-1))
        if rest.size:
            parts.append((rest, self._solve(
                [load.part(shape, np.unravel_index(rest, shape)) for load in loads],
                chained=False, jacobians=jacobians, checked=True,
                contact_retry=(None, 0, 0)), slice(None)))
        whole = _Parts(parts[-1][1], math.prod(shape))
        for cases, part, taken in parts:
            whole.put(part, cases, taken)
        law = parts[-1][1]._contact()
        if rest.size:  # the penalty's law, with no stiffness on the cases held at the tip
            stiffness = np.zeros(math.prod(shape))
            stiffness[rest] = np.broadcast_to(law.stiffness, rest.shape)
            law = law._with_checked_stiffness(stiffness.reshape(shape))
        return whole.equilibrium(shape, tuple(law if load.kind == "contact" else load
                                              for load in loads))

    def _held_case_by_case(self, loads, shape, jacobians: bool, fine, asked):
        """:func:`solve_tip_contact`'s answer, case by case: ([(flat cases, their
        Equilibrium, all of its cases)], held (``shape`` bool)), or None where no case is
        held."""
        parts, which = [], np.zeros(math.prod(shape), dtype=bool)
        for case in range(which.size):
            index = np.unravel_index(np.array([case]), shape)
            one = [load.part(shape, index) for load in loads]
            try:
                found = solve_tip_contact(self, one, (1,), jacobians, fine, asked)
            except ConvergenceError:
                continue
            if found is not None and found[1][0]:
                parts.append((np.array([case]), found[0], slice(None)))
                which[case] = True
        return (parts, which.reshape(shape)) if which.any() else None

    def _solve_in_parts(self, loads, shape, *, chained: bool, jacobians: bool,
                        outputs: bool) -> Equilibrium | None:
        """:meth:`_solve` of a batch larger than a part (:data:`CASES_PER_PART`), part after
        part (in the order of the flattened batch: a chained batch stays one path) into one
        result:
        each part's channels and work arrays are freed before the next, its outputs copied
        into the whole batch's arrays. The answer is the unparted one's to the bit (every case
        is solved from its own loads, or the path goes on from the part before)."""
        count, size = math.prod(shape), CASES_PER_PART
        whole = None
        for first in range(0, count, size):
            index = np.unravel_index(np.arange(first, min(first + size, count)), shape)
            with batch_part(shape, first, index[0].size):  # (messages: the whole batch's)
                result = self._solve([load.part(shape, index) for load in loads],
                                     chained=chained, jacobians=jacobians, outputs=outputs,
                                     checked=True)  # (the whole batch was)
            if outputs:
                if whole is None:
                    whole = _Parts(result, count)
                whole.put(result, slice(first, first + index[0].size))
        return whole.equilibrium(shape, loads) if outputs else None

    def _unused(self, shape: tuple) -> np.ndarray:
        """A placeholder whose contents the kernel never uses (the argument of a feature not
        asked for: the Jacobians' outputs), made once per shape."""
        placeholders = self.__dict__.setdefault("_placeholders", {})
        found = placeholders.get(shape)
        if found is None:
            found = placeholders[shape] = np.zeros(shape)
        return found

    def _input_channels(self, loads, pieces, width):
        """:func:`_input_channels`, remembered per arm for the last few load structures (the
        channels per unit input depend on the cut and on each load's fixed fields, not on
        the input values: a control loop re-solves with the same structure, and
        ``softarm.solve``, a new Solver each call, shares the arm's memory)."""
        if not any(load.inputs for load in loads):  # nothing to build, nothing to remember
            return _input_channels(loads, pieces, self._data, width)
        key = (pieces[0].tobytes(), width, tuple(_structure(load) for load in loads))
        found = self._data.remembered("input channels", key)
        if found is None:
            found = self._data.remember("input channels", key,
                                        _input_channels(loads, pieces, self._data, width))
        return found

    def solve_near(self, loads, x, steps: int) -> Equilibrium:
        """The equilibrium of the single case ``loads`` continued from the base reaction
        ``x`` (N, N m, spatial), a solution on ``steps`` RK4 steps over the arm (from
        continuation), refined to tol like any solve: the branch x is on, not the one
        connected to the unloaded arm. Leaves this Solver at that equilibrium."""
        return self._solve_near(loads, x, steps)

    def _solve_near(self, loads, x, steps, jacobians: bool = False) -> Equilibrium:
        k = kernels
        self.reset()
        memory = np.zeros(k.MEMORY)
        memory[0:6] = memory[6:12] = np.asarray(x, dtype=np.float64)
        memory[12] = max(1, int(steps) // 2)
        memory[13] = 1.0
        self._memory = memory
        return self._solve(loads, chained=True, jacobians=jacobians, near=True)

    def shoot(self, loads, x, load_factor=1.0, *, steps=None, inputs=False) -> ShootResult:
        """One integration from the base reaction ``x`` = (n(0); m(0)) (N, N m, spatial) at
        load factor λ (the loads scaled by λ): the shooting primitive that continuation,
        stability and inverse statics are written against.

        ``loads`` must be a single case (batch shape ()). ``steps``: RK4 steps over the arm
        (default: a fixed 200, spread over the pieces in proportion to their length), or
        ``("solution", N)``: the grid of a solve whose coarse step count is N (2N steps, as
        :meth:`last_solution` reports it). ``inputs=True`` adds the columns of every
        actuation input (``jacobian_inputs``, ``tip_motion_inputs``); :meth:`shooter`
        prepares that once for many integrations.
        """
        if inputs:
            return self.shooter(loads)(x, load_factor=load_factor, steps=steps)
        k = kernels
        loads, shape, _, pieces, channels = self._prepare(loads)
        if shape != ():
            raise ValueError(f"Solver.shoot takes a single load case, got batch shape {shape}")
        piece, tip = channels.piece[0], channels.tip_loads[0]
        case = (np.zeros_like(piece), piece[None].copy(), np.zeros(k.TIP_LOADS),
                tip[None].copy())
        result = _shoot(k, x, float(load_factor), self._step_counts(pieces[1], steps),
                        self._base_kernel, channels.arm_tuple(), case, len(channels.actuators))
        return dataclasses.replace(result, jacobian_load=result.jacobian_inputs[:, 0],
                                   jacobian_inputs=None, tip_motion_inputs=None)

    def shooter(self, loads) -> Shooter:
        """:meth:`shoot` with the input columns, prepared once for the single case ``loads``
        (validation, the cut, the channels per unit input): a :class:`Shooter`, called with
        new input values, integrates without any of that work. Inverse statics iterates on
        it. Valid while ``loads``' structure (kinds, routings, segments) stays the same."""
        loads, shape, _, pieces, channels = self._prepare(loads)
        if shape != ():
            raise ValueError(f"Solver.shooter takes a single load case, got batch shape "
                             f"{shape}")
        unit_piece, unit_tip = self._input_channels(loads, pieces, channels.piece.shape[2])
        values = np.array([v for load in loads for name in load.inputs
                           for v in np.ravel(np.asarray(getattr(load, name), dtype=float))])
        return Shooter(self, (loads, shape, 1, pieces, channels), channels.arm_tuple(), values,
                       unit_piece, unit_tip)

    def prepared(self, loads, *, jacobians: bool = True) -> PreparedSolve:
        """:meth:`solve` of the single case ``loads`` prepared once for many calls that change
        only its actuation inputs (tensions, pressures, field components): a
        :class:`PreparedSolve`. The answer is :meth:`solve`'s, without its per-call Python
        (validation, load channels, the Equilibrium): the control loop's call."""
        if not isinstance(jacobians, (bool, np.bool_)):
            raise TypeError(f"jacobians must be True or False, got {jacobians!r}")
        loads = as_loads(loads)
        if any(load.displacement_controlled for load in loads):
            raise ValueError("Solver.prepared takes tension-controlled tendons only (the "
                             "tension of a displacement-controlled Tendon is an unknown of "
                             "the problem: Solver.solve)")
        return PreparedSolve(self, loads, jacobians=jacobians)

    def _step_counts(self, piece_lengths, steps) -> np.ndarray:
        """RK4 steps per piece as the kernel's ``_fill_steps`` spreads them: factor × the
        nominal n in proportion to length, at least one (``steps`` as in :meth:`shoot`)."""
        if isinstance(steps, tuple) and len(steps) == 2 and steps[0] == "solution":
            n, factor = count(steps[1], "steps", 1), 2  # a solution's fine grid, 2N
        else:
            n, factor = 200 if steps is None else count(steps, "steps", 1), 1
        return factor * np.maximum(1, np.floor(n * piece_lengths / self.length + 0.5)).astype(
            np.int64)

    def last_solution(self):
        """(x, N) of the last case a chained :meth:`solve` reached: its base reaction (N, N m,
        spatial) and coarse step count (the solution is on 2N steps), or None."""
        memory = self._memory
        if memory is None or memory[13] != 1.0:
            return None
        return memory[6:12].copy(), int(memory[12])


def _actuation(channels, base_wrench, lengths, shape) -> dict:
    """The Equilibrium's actuation fields: the total base wrench and, per tendon (in the
    order given), its tension, length and length change from the unloaded arm."""
    k = channels.k
    base_wrench.setflags(write=False)
    out = {"base_wrench": base_wrench.reshape(*shape, 6)}
    tendons, unloaded = channels.tendons()
    if not tendons.size:
        return out
    length = lengths if tendons.size == lengths.shape[1] else lengths[:, tendons]
    # (the actuators' columns by a slice, then the tendons': fancy indexing first cost 3×)
    tension = channels.piece[:, :, k.ACT:].max(axis=1)
    if tendons.size != tension.shape[1]:
        tension = tension[:, tendons]
    for array in (length, tension):
        array.setflags(write=False)
    change = length - unloaded
    slack = tension == 0.0
    for array in (change, slack):
        array.setflags(write=False)
    out.update(tendon_tensions=tension.reshape(*shape, len(tendons)),
               tendon_lengths=length.reshape(*shape, len(tendons)),
               tendon_length_changes=change.reshape(*shape, len(tendons)),
               tendon_slack=slack.reshape(*shape, len(tendons)))
    return out


def _unloaded_length(pieces, actuator) -> float:
    """A tendon's length in the unloaded arm, ∫ |e1 + κ⁰ × r + r'| ds over the pieces it
    runs through (Gauss–Legendre, 24 nodes per piece and per quarter turn of a helix)."""
    _, routing, active, _ = actuator
    on = np.flatnonzero(active)
    starts, lengths, f0 = pieces[0][on], pieces[1][on], pieces[3][on]
    total = 0.0
    for j in range(starts.size):
        parts = max(1, int(np.ceil(4 * abs(routing.helix[1]) * lengths[j])))
        h = lengths[j] / parts
        a = starts[j] + h * np.arange(parts)
        s = (a[:, None] + 0.5 * h * (_NODES + 1.0)).ravel()
        w = f0[j, :3] + np.cross(f0[j, 3:], routing.position(s)) + routing.derivative(s)
        total += 0.5 * h * float(np.tile(_WEIGHTS, parts) @ np.linalg.norm(w, axis=-1))
    return total


_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(24)


def _recut(old_starts, old_piece, new_starts) -> np.ndarray:
    """Piece loads given on the cut ``old_starts`` re-expressed on ``new_starts`` (a cut that
    contains every old cut): distributed channels from the old piece that contains the new
    piece, point wrenches where an old piece started."""
    if np.array_equal(old_starts, new_starts):  # the same cut (a control loop's usual case)
        return old_piece.copy()
    k = kernels
    out = np.zeros((new_starts.size, old_piece.shape[1]))
    inside = np.clip(np.searchsorted(old_starts, new_starts, side="right") - 1, 0, None)
    out[:, :k.JD] = old_piece[inside, :k.JD]
    same = np.isin(new_starts, old_starts)
    out[same, k.JD:k.FB] = old_piece[inside[same], k.JD:k.FB]
    out[:, k.FB:] = old_piece[inside, k.FB:]  # the field and the actuators: distributed
    return out


def _compliances(jac, motion, shape, tendons):
    """Tip and station compliances C(s) = E_x(s) J_x⁻¹ (dead tip wrench → (δp; δθ)
    spatial) and the actuation Jacobians E_q - E_x J_x⁻¹ J_q, as the kernel left them
    (``kernels.shooting._implicit_function``): ``motion`` (B, S, 6, 6 + n) per station, ``jac``
    (B, 6 + A, 6 + n) rows 6 + a per actuator length (``tendons`` the actuators that are
    tendons). Returns (tip compliance, station compliances, tip actuation Jacobian, station
    actuation Jacobians, tendon length Jacobian (B..., T, n)), frozen; the last three None
    without inputs (the last also without tendons)."""
    S, m = motion.shape[1], motion.shape[3]
    n = m - 6
    station = motion if not n else np.ascontiguousarray(motion[..., :6])
    out = [station[:, -1].copy().reshape(*shape, 6, 6), station.reshape(*shape, S, 6, 6)]
    if n:
        inputs = np.ascontiguousarray(motion[..., 6:])
        out += [inputs[:, -1].copy().reshape(*shape, 6, n), inputs.reshape(*shape, S, 6, n),
                jac[:, 6 + tendons, 6:].reshape(*shape, -1, n) if tendons.size else None]
    else:
        out += [None, None, None]
    for array in out:
        if array is not None:
            array.setflags(write=False)
    return tuple(out)


def _structure(load) -> tuple:
    """What fixes a load's channels per unit input: its kind and the values of its fields
    that are not batchable (routing, span, area, anchor, ...: numbers, tuples and frozen
    routings, hashable; their repr cost 20 µs a solve)."""
    kind = type(load)
    return (kind, *(getattr(load, name) for name in _fixed_fields(kind)))


@functools.cache
def _fixed_fields(kind) -> tuple[str, ...]:
    """The names of a load class's schema fields that are not batchable arrays."""
    batchable = {name for name, _, _ in kind.arrays}
    return tuple(key.name for key in kind.schema if key.name not in batchable)


def _input_channels(loads, pieces, data, width) -> tuple[np.ndarray, np.ndarray]:
    """The load channels per unit of each actuation input (each load's ``inputs`` fields,
    every component, in the order of the loads): (piece (n, P, W), tip (n, TIP_LOADS)).
    The channels are linear in the inputs, so each is the channels of all loads zeroed but
    that one component at 1 (all loads applied, so that the actuator columns line up)."""
    k = kernels
    if not any(load.inputs for load in loads):
        return np.zeros((0, pieces[0].size, width)), np.zeros((0, k.TIP_LOADS))
    zeroed = [load.take((0,) * len(load.batch_shape)).scaled(0.0) for load in loads]
    piece, tip = [], []
    for i, load in enumerate(loads):
        for name in load.inputs:
            value = np.asarray(getattr(zeroed[i], name))
            for c in range(max(value.size, 1)):
                unit = np.zeros(value.shape)
                unit.flat[c] = 1.0
                one = list(zeroed)
                one[i] = zeroed[i].replace(**{name: unit})
                channels = _Channels(data, pieces, (), 1)
                for item in one:
                    item.apply(channels)
                piece.append(channels.piece[0])
                tip.append(channels.tip_loads[0])
    return np.ascontiguousarray(piece), np.ascontiguousarray(tip)


class _Parts:
    """The whole batch's result assembled from its parts' (Solver._solve_in_parts): every
    array field of the first part's Equilibrium with a leading case axis gets an array for
    all ``count`` cases, and each part is copied in at its first case."""

    def __init__(self, first: Equilibrium, count: int):
        self.template = first
        self.arrays = {}
        for field in dataclasses.fields(Equilibrium):
            value = getattr(first, field.name)
            if isinstance(value, Stability):
                value = np.stack([value.index, value.conservative], axis=-1)
            if isinstance(value, np.ndarray) and field.name != "s":
                self.arrays[field.name] = np.empty((count, *value.shape[1:]), value.dtype)

    def put(self, part: Equilibrium, cases, taken=slice(None)) -> None:
        """Copy the cases ``taken`` of ``part`` (flat indices, default all) to the cases
        ``cases`` of the whole (a slice or flat indices)."""
        for name, array in self.arrays.items():
            value = getattr(part, name)
            if isinstance(value, Stability):
                value = np.stack([value.index, value.conservative], axis=-1)
            array[cases] = np.reshape(value, (-1, *array.shape[1:]))[taken]

    def equilibrium(self, shape, loads) -> Equilibrium:
        fields = {}
        for name, array in self.arrays.items():
            if name != "stability":
                array.setflags(write=False)  # (before the view: Equilibrium takes it uncopied)
            array = array.reshape(*shape, *array.shape[1:])
            fields[name] = Stability.of(array[..., 0], array[..., 1].astype(bool), shape) \
                if name == "stability" else array
        return dataclasses.replace(self.template, loads=loads, **fields)


def _failure(k, b, shape, status, info, solver, near=False, turns=None) -> ConvergenceError:
    """The ConvergenceError of the first failed case (``near``: of :meth:`Solver.solve_near`,
    whose path has no load to follow: a failure there means no solution near its start;
    ``turns``: whether the loading path turns back where it stopped, :func:`_path_turns`)."""
    b = int(b)
    where = load_case(b, shape)
    residual, estimate, reached, shootings, N = info[b]
    code = int(status[b])
    tried = f"{int(shootings)} shootings, {2 * int(N)} RK4 steps"
    if near and code in (k.PATH_FAILED, k.NEWTON_FAILED):
        return ConvergenceError(
            "Solver.solve_near found no equilibrium of these loads near the given base "
            "reaction (neither the correction from it nor the path from its own loads "
            "converged): start from a solution's base reaction (Solver.last_solution(), a "
            "continuation point)", residual, tried)
    if code == k.TOO_MANY_STEPS:
        return ConvergenceError(
            f"the tip error estimate {estimate:.3e} m stayed above tol·L = "
            f"{solver.tol * solver.length:.3e} m{where}", residual,
            f"step doubling up to {2 * int(N)} RK4 steps")
    if code == k.PATH_FAILED:
        followed = f"the loading path could not be followed beyond load factor λ = {reached:.6g}"
        if turns is None:
            why = (": a limit point (fold), where the arm would snap to another shape, or a "
                   "point the solver cannot resolve (not told apart on this route)")
        elif turns:
            why = (": a limit point (fold): the path turns back there (pseudo-arclength "
                   "continuation from it), and the arm would snap to another shape "
                   "(softarm.continuation follows the branch around it)")
        else:
            why = (", where the path does not turn (not a fold: pseudo-arclength continuation "
                   "passes it): the solver could not follow it there")
        return ConvergenceError(f"{followed}{where}{why}", residual, tried,
                                load_factor=float(reached))
    if code == k.BUDGET:
        return ConvergenceError(
            f"the shooting budget max_shootings={solver.max_shootings} ran out{where} with the "
            f"loading path followed to load factor λ = {reached:.6g}", residual, tried,
            load_factor=float(reached))
    if code == k.SINGULAR:
        return ConvergenceError(
            f"jacobians=True: ∂r/∂x is singular at the equilibrium{where} (a critical point, "
            "where the compliance and the actuation Jacobians do not exist)", residual, tried)
    if code == k.NOT_FINITE:
        return ConvergenceError(f"the solution became non-finite{where}", residual, tried)
    return ConvergenceError(
        f"Newton's method on the base wrench did not converge at the full load{where}",
        residual, tried)


#: The pseudo-arclength probe of :func:`_path_turns`: its largest number of steps and its
#: first step (in the nondimensional (x, λ) of continuation.py), and how far past the
#: load factor where natural continuation stopped the path must go (relative) to be seen
#: not to turn there.
_PROBE_STEPS = 60
_PROBE_FIRST = 1e-4
_PROBE_PAST = 1e-6


def _path_turns(k, solver, arm, channels, pieces, b, x, lam, N) -> bool | None:
    """Whether the loading path of case ``b`` (from the unloaded arm, single shooting) turns
    back at the load factor ``lam`` where natural continuation stopped (x: the solution
    there, on N steps): a few steps of pseudo-arclength continuation from it, in (x in the
    bending scale times the load size, λ), each a Newton corrector on the residual and the
    arclength. True if λ turns back (a fold), False if the path goes on past ``lam``, None
    if neither can be seen (the correctors fail: single shooting cannot resolve the arm
    there). Only on a failure: a few milliseconds."""
    piece, tip = channels.piece[b], channels.tip_loads[b]
    case = (np.zeros_like(piece), piece[None].copy(), np.zeros(k.TIP_LOADS), tip[None].copy())
    counts = solver._step_counts(pieces[1], N)
    actuators = len(channels.actuators)
    scale = solver._data.scale

    def at(z):
        """(the scaled residual (6,), its Jacobian (6, 7)) at z = (x / xscale, λ)."""
        result = _shoot(k, z[:6] * xscale, float(z[6]), counts, solver._base_kernel, arm, case,
                        actuators)
        J = np.column_stack([result.jacobian_x * xscale[None, :],
                             result.jacobian_inputs[:, :1]]) / scale[:, None]
        return result.residual / scale, J

    try:
        first = _shoot(k, np.asarray(x, dtype=np.float64), lam, counts, solver._base_kernel,
                       arm, case, actuators)
    except ValueError:  # (a non-finite x)
        return None
    xscale = scale * (1.0 + float(np.max(np.abs(first.jacobian_inputs[:, 0]) / scale)))
    z = np.append(np.asarray(x) / xscale, lam)
    with np.errstate(all="ignore"):
        r, J = at(z)
        tangent = np.linalg.svd(J)[2][-1]
        if tangent[6] < 0.0:
            tangent = -tangent
        h = _PROBE_FIRST
        for _ in range(_PROBE_STEPS):
            if h < 1e-12:
                return None
            predicted = z + h * tangent
            w = predicted.copy()
            converged = False
            for _ in range(8):
                r, J = at(w)
                if not np.all(np.isfinite(J)) or not np.all(np.isfinite(r)):
                    break
                if np.max(np.abs(r)) <= 1e-10:
                    converged = True
                    break
                try:
                    w = w - np.linalg.solve(np.vstack([J, tangent]),
                                            np.append(r, tangent @ (w - predicted)))
                except np.linalg.LinAlgError:
                    break
            if not converged or np.max(np.abs(w - predicted)) > 0.5 * h:
                h *= 0.5
                continue
            new = np.linalg.svd(J)[2][-1]
            if new @ tangent < 0.0:
                new = -new
            if new @ tangent < 0.9:  # turned too much in one step: a shorter one
                h *= 0.5
                continue
            z, tangent = w, new
            if tangent[6] < 0.0:
                return True
            if z[6] > lam * (1.0 + _PROBE_PAST) + _PROBE_PAST:
                return False
            h *= 2.0
    return None


def _admissible(solver, strains, stresses, s, shape, residual, chained: bool) -> None:
    """The model's limits on what the kernel returned (``softarm._admissible``): an
    :class:`~softarm.InadmissibleStateError` where the axial stretch v₁ <= 0 at a station
    (the shooting passes through v₁ = 0 without noticing: the equations stay smooth there);
    a chained Solver then returns to the unloaded arm, as after a failure."""
    try:
        check_stretch(strains.reshape(*shape, *strains.shape[-2:]), s, residual,
                      stresses.reshape(*shape, *stresses.shape[-2:]))
    except InadmissibleStateError:
        if chained:
            solver.reset()
        raise


#: Load factors, relative to the one the path reached, at which :func:`_tendon_limit` looks
#: at the tendons' paths: two equilibria just before the failure.
_PROBES = np.array([1.0 - 1e-3, 1.0 - 2e-3])


def _tendon_limit(solver, loads, shape, b: int, reached, residual: float
                  ) -> ConvergenceError | None:
    """Why the loading path of case ``b`` failed, if a tendon's path leaves the model
    there: its length |w| (w = v + u × r + r') or its forward component w₁ reaching 0 at the
    load factor λ the path reached, ``reached`` (None: the path was not from the unloaded
    arm; then the case is solved from it, which diagnoses its own failure).

    The kernel says only that its path could not be followed (PATH_FAILED: the constitutive
    law has no root past that point). Here the equilibria at two load factors just before it
    are solved again (a Solver of its own, stations every L/200, that diagnoses nothing
    itself) and each tendon's |w| and w₁ extrapolated linearly to zero in λ
    (:func:`_tendon_zero`): an :class:`~softarm.InadmissibleStateError` if that zero is where
    the path stopped (within 1 %); a ConvergenceError that says so if the path stopped short
    of it with the tendon's path already short (the kernel's law lost its root there). None
    otherwise (a fold of the arm, or a failure of a path that did not start from the
    unloaded arm)."""
    tendons = [load for load in loads if load.kind == "tendon"]
    if not tendons or not solver.diagnose:
        return None
    case = _case_loads(loads, shape, b)
    options = dict(tol=solver.tol, base=solver.base, stability=False,
                   max_iterations=solver.max_iterations, max_load_step=solver.max_load_step,
                   steps=solver.steps, max_steps=solver.max_steps,
                   max_shootings=solver.max_shootings)
    if reached is None:  # not from the unloaded arm: the path from it says where it fails
        try:
            Solver(solver.arm, s=2, diagnose=False, **options).solve_from_unloaded(case)
        except ConvergenceError as error:
            if error.load_factor is not None:  # (diagnosed here, named as case b)
                return _tendon_limit(solver, loads, shape, b, error.load_factor, residual)
        return None
    probe = Solver(solver.arm, s=201, diagnose=False, **options)
    factors = reached * _PROBES
    try:
        eq = probe.solve_from_unloaded([load.scaled(factors) for load in case])
    except ConvergenceError:
        return None
    lam, number, station, vanishes, left = _tendon_zero(eq, tendons, factors)
    tendon = tendons[number]
    tension = float(np.asarray(case[loads.index(tendon)].tension))
    if abs(lam - reached) <= 1e-2 * reached:
        return tendon_limit(number, tendon.describe(), tension, load_case(b, shape), lam,
                            f"s = {station:.4g} m", residual, vanishes, station)
    if lam > reached and left < 0.2:
        # the kernel's constitutive law lost its root before the limit (its Newton method,
        # from the tendons-along-d1 guess, can overshoot a tendon's kink where K couples
        # extension, shear and bending): say so, and where the limit is
        what = "length" if vanishes else "forward component w₁/|w|"
        return ConvergenceError(
            f"the loading path could not be followed beyond load factor λ = {reached:.6g}"
            f"{load_case(b, shape)}: the constitutive law found no root near tendon {number}'s "
            f"limit ({tendon.describe()}; its path's {what} has fallen to {left:.3g} of the "
            f"unloaded arm's at s = {station:.4g} m and would vanish at λ ≈ {lam:.4g}, a "
            f"tension of about {lam * tension:.4g} N)", residual, load_factor=float(reached))
    return None


def _tension_limit(solver, loads, shape, b: int, error) -> ConvergenceError | None:
    """Why the loading path of case ``b`` (from the unloaded arm) failed, if its loads can
    pull beyond the tension T* = EA GA/(EA − GA) of a segment whose shear is softer than its
    extension (GA < EA) at the load factor it reached (``error.load_factor``): past T* the
    straight rod in tension is unstable in this model, and a path into that regime fails
    among its many branches (docs/solver.md, "The model's limits"). None otherwise."""
    reached = error.load_factor
    if reached is None:
        return None
    K = solver._data.K
    EA, GA = K[:, 0, 0], np.minimum(K[:, 1, 1], K[:, 2, 2])
    soft = GA < EA
    if not soft.any():
        return None
    limits = np.where(soft, EA * GA / np.where(soft, EA - GA, 1.0), np.inf)
    j = int(np.argmin(limits))
    pull = reached * float(np.max(largest_force(solver.arm, _case_loads(loads, shape, b))))
    if pull < limits[j]:
        return None
    segment = f" of segment {j}" if len(K) > 1 else ""
    return ConvergenceError(
        f"{error.message}; there the loads pull with up to {pull:.4g} N, beyond the tension "
        f"T* = EA·GA/(EA − GA) = {limits[j]:.4g} N{segment} (EA = {EA[j]:.4g} N, GA = "
        f"{GA[j]:.4g} N): past T*, at an axial strain of {limits[j] / EA[j]:.2g}, far beyond "
        "an elastic material's range, the straight rod in tension is unstable in this "
        "model (the linear law's shear turns the centreline against its sections: tensile "
        "buckling), with a Morse index in the hundreds on a slender rod, and a path into it "
        "fails among the buckled branches (docs/solver.md, \"The model's limits\")",
        error.residual, error.tried, load_factor=reached)


def _case_loads(loads, shape, b: int) -> list:
    """The loads of case ``b`` (C order) of a batch of shape ``shape``, unbatched."""
    index = np.unravel_index(b, shape) if shape else ()
    return [load if not load.batch_shape else load.take(
        tuple(i if n > 1 else 0 for i, n in zip(index[len(index) - len(load.batch_shape):],
                                                load.batch_shape, strict=True)))
            for load in loads]


def _tendon_zero(eq, tendons, factors) -> tuple:
    """(λ, tendon number, s, vanishes, value) of the first zero in λ of any tendon's path
    length |w|/|w₀| (``vanishes``) or forward component w₁/|w| at any station, extrapolated
    linearly from the equilibria ``eq`` (2, S) at the load factors ``factors`` (2,), and that
    quantity's value at the first of them."""
    found = (np.inf, 0, 0.0, True, 1.0)
    for number, tendon in enumerate(tendons):
        on = eq.s <= tendon.path_span(eq.arm.length)[1]
        s = eq.s[on]
        position, derivative = tendon.routing.position(s), tendon.routing.derivative(s)
        unloaded = _reference_strains(eq.arm, s)
        w = path_tangent(position, derivative, eq.strains[:, on] + unloaded)  # (2, S, 3)
        length = np.linalg.norm(w, axis=-1)
        w0 = np.linalg.norm(path_tangent(position, derivative, unloaded), axis=-1)
        for values, vanishes in ((length / w0, True), (w[..., 0] / length, False)):
            with np.errstate(divide="ignore", invalid="ignore"):
                zero = np.where(values[0] < values[1], factors[0] + values[0] * (
                    factors[0] - factors[1]) / (values[1] - values[0]), np.inf)
            j = int(np.argmin(zero))
            if zero[j] < found[0]:
                found = (float(zero[j]), number, float(s[j]), vanishes, float(values[0, j]))
    return found


def _reference_strains(arm, s) -> np.ndarray:
    """f⁰ (N, 6) of the segment each station s (N,) lies in."""
    bounds = np.asarray(arm.boundaries)
    segment = np.clip(np.searchsorted(bounds, s, side="right") - 1, 0, len(arm.segments) - 1)
    return np.array([seg.reference_strain for seg in arm.segments])[segment]


def solve_numeric(arm, loads, *, s=None, tol=1e-8, base=None, jacobians=False,
                  **options) -> Equilibrium:
    """Solve the full static Cosserat rod by shooting with continuation from the unloaded arm
    (every case independently); see :class:`Solver` for the options."""
    return Solver(arm, s=s, tol=tol, base=base, **options).solve_from_unloaded(
        loads, jacobians=jacobians)


def compile_beside(kind: str) -> None:
    """Compile (or load) what a first solve of an arm of this kind ("passive" or "actuated")
    needs after its solver's own path, with the same argument types as every solve: the
    output pass (``_record``, through ``record_points``, whose stations of a given solution
    are the output pass's) and the stability verdict. ``_prefetch`` runs this in another
    process beside a cold first solve, which then loads both from numba's cache."""
    arm = Arm(0.2, Circle(0.01), Material(youngs_modulus=1e6, poisson_ratio=0.49,
                                          density=1000.0))
    loads = [Gravity()] + ([Tendon(0.1, Straight(0.0, 0.005))] if kind == "actuated" else [])
    solver = Solver(arm)
    _, shape, count, pieces, channels = solver._prepare(loads)
    S, A = solver._s_kernel.size, len(channels.actuators)
    out = (np.empty((count, S, 4, 4)), np.empty((count, S, 6)), np.empty((count, S, 6)),
           np.zeros((count, 5)), np.zeros(count, dtype=np.int64), solver._unused((0, 6, 6)),
           solver._unused((1, S, 6, 6)), np.empty((count, 6)), np.empty((count, A)))
    kernels.record_points(solver._base_kernel, *channels.arm_tuple(),
                             (channels.piece, channels.tip_loads), np.zeros((count, 6)),
                             np.full(pieces[0].size, 4, dtype=np.int64), solver._s_kernel, out)
    verdict(channels, solver._base_kernel, np.zeros((count, 6)), np.full(count, 8.0), shape,
            np.zeros((count, 4, 4)))
