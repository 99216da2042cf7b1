"""The geometrically exact static solver: shooting on the base wrench (see docs/solver.md).

Python-side preparation (validation, cutting the arm into uniform pieces at segment joints and
point-load stations, flattening the batch of loads) lives here; the numerical work, for the
whole batch at once, is :func:`softarm.statics._kernels.solve_cases`.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .._validate import as_matrices, stations
from ..equilibrium import Equilibrium
from ..errors import ConvergenceError
from ..loads import DistributedForce, Gravity, PointLoad, TipLoad, as_loads, batch_shape
from ..model import Arm, SegmentedArm
from . import _kernels

__all__ = ["METHOD", "Solver", "check_base", "check_tol", "solve_numeric"]

#: Equilibrium.method of every result of this solver.
METHOD = "numeric.shooting"

_N_MAX = 1 << 15  # largest step count of the fine solution is 2 * _N_MAX / 2
_IDENTITY = np.eye(4)
_IDENTITY.setflags(write=False)


def check_base(base) -> np.ndarray:
    """The base pose as a (4, 4) rigid transform, or ValueError naming ``base``."""
    if base is None:
        return _IDENTITY
    H = as_matrices(base, "base", 4)
    if H.shape != (4, 4):
        raise ValueError(f"base must be a single 4×4 rigid transform, got shape {H.shape}")
    R = H[:3, :3]
    if not (np.allclose(H[3], [0.0, 0.0, 0.0, 1.0], rtol=0.0, atol=1e-12)
            and np.allclose(R.T @ R, np.eye(3), rtol=0.0, atol=1e-9)
            and np.linalg.det(R) > 0.0):
        raise ValueError(
            "base must be a rigid transform [[R, p], [0, 0, 0, 1]] with R a proper rotation "
            f"(RᵀR = I to 1e-9, det R = +1), got {H.tolist()!r}"
        )
    out = H.copy()
    out[3] = (0.0, 0.0, 0.0, 1.0)
    return out


def _check_arm(arm):
    if not isinstance(arm, (Arm, SegmentedArm)):
        raise TypeError(f"arm must be a softarm.Arm or SegmentedArm, got {arm!r}")
    return arm


def check_tol(tol) -> float:
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating)):
        raise TypeError(f"tol must be a number (tip position tolerance / L), got {tol!r}")
    tol = float(tol)
    if not (math.isfinite(tol) and 1e-13 <= tol <= 1e-1):
        raise ValueError(
            f"tol must be a relative tip-position tolerance in [1e-13, 0.1], got {tol!r}"
        )
    return tol


def _check_count(value, name: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)


class _ArmData:
    """What the solver needs of an arm, computed once per arm (see :func:`_arm_data`).

    The arrays go to the compiled kernel as they are: they are private and never written.
    """

    def __init__(self, arm):
        segments = arm.segments
        self.length = float(arm.length)
        self.bounds = np.array(arm.boundaries)
        self.K = np.array([seg.stiffness for seg in segments], dtype=np.float64)
        self.C = np.linalg.inv(self.K)
        self.f0 = np.array([seg.reference_strain for seg in segments], dtype=np.float64)
        mu = [seg.linear_density for seg in segments]
        self.massless = any(m is None for m in mu)
        self.mu = np.array([0.0 if m is None else m for m in mu], dtype=np.float64)
        bending = float(np.max(self.K[:, [3, 4, 5], [3, 4, 5]]))
        self.force_scale = bending / self.length**2
        self.scale = np.array([self.force_scale] * 3 + [bending / self.length] * 3)
        # the pieces without interior point loads: the segments themselves
        self.pieces = self.cut(np.empty(0))

    def cut(self, point_s):
        """Cut the segments at interior point-load stations.

        Returns (starts, lengths, C, f0, mu), one row per piece.
        """
        cuts = np.unique(np.concatenate([self.bounds, point_s]))
        cuts = cuts[(cuts >= 0.0) & (cuts <= self.length)]
        lengths = np.diff(cuts)
        keep = lengths > 0.0
        starts, lengths = cuts[:-1][keep], lengths[keep]
        middle = starts + 0.5 * lengths
        segment = np.clip(np.searchsorted(self.bounds, middle) - 1, 0, len(self.K) - 1)
        return (starts, lengths, np.ascontiguousarray(self.C[segment]),
                np.ascontiguousarray(self.f0[segment]), self.mu[segment])


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


class Solver:
    """A prepared problem: an arm, output stations, a tolerance and a base pose.

    Calling :meth:`solve` with a list of loads returns an :class:`~softarm.Equilibrium`. The
    arm-side preparation is done once, and each call starts from the previous call's solution
    and step count, corrected to first order for the change of the loads (the previous
    Jacobian): the fast path for control loops that solve the same arm many times.

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
        Newton iterations per attempt (one attempt per load step).
    continuation : bool
        If True (default), a failed full-load Newton solve falls back to load stepping from
        the unloaded arm with adaptive step halving.
    max_step : float
        Trust radius of a Newton step, in units of the bending scale (EI/L² for forces, EI/L
        for moments). Small values keep the load stepping on the branch connected to the
        unloaded arm.
    steps : int, optional
        Fix the number of RK4 steps of the solution (an even number, spread over the pieces in
        proportion to their length) instead of choosing it from ``tol``; the error estimate
        still compares it with half as many steps. For convergence studies.
    max_steps : int
        Largest number of RK4 steps tried before giving up on ``tol`` (ConvergenceError).
    max_shootings : int
        Budget of trajectory integrations per load case (Newton iterations, backtracking and
        load steps together) before a ConvergenceError.

    Examples
    --------
    >>> from softarm import Arm, TipLoad
    >>> arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    >>> solver = Solver(arm, s=3)
    >>> eq = solver.solve([TipLoad(force=[0.0, 0.0, 1.0])])   # k = PL²/EI = 1
    >>> round(float(eq.tip_position[2]), 5)  # Mattiasson (1981) Table 1: w/L = 0.30172
    0.30172
    """

    def __init__(self, arm, *, s=None, tol=1e-8, base=None, max_iterations=30,
                 continuation=True, max_step=4.0, steps=None, max_steps=_N_MAX,
                 max_shootings=2000):
        self.arm = _check_arm(arm)
        self._data = _arm_data(arm)
        self.length = self._data.length
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
        self.max_iterations = _check_count(max_iterations, "max_iterations", 1)
        if not isinstance(continuation, (bool, np.bool_)):
            raise TypeError(f"continuation must be True or False, got {continuation!r}")
        self.continuation = bool(continuation)
        if not (isinstance(max_step, (int, float)) and math.isfinite(max_step) and max_step > 0):
            raise ValueError(f"max_step must be a positive number, got {max_step!r}")
        self.max_step = float(max_step)
        if steps is not None and (_check_count(steps, "steps", 2) % 2 or steps > _N_MAX):
            raise ValueError(f"steps must be an even integer in [2, {_N_MAX}], got {steps!r}")
        self.steps = steps
        self.max_steps = _check_count(max_steps, "max_steps", 4)
        self.max_shootings = _check_count(max_shootings, "max_shootings", 1)
        # warm start: step count, and what the last solved case left for the next one
        self._n = None
        self._memory = np.zeros(_kernels.MEMORY)
        self._memory_level = np.zeros(1, dtype=np.int64)
        self._piece_memory = None
        self._piece_lengths = None

    def _prepare(self, loads):
        loads = as_loads(loads)
        shape = batch_shape(loads)
        count = math.prod(shape)
        data = self._data
        tip_dead = np.zeros((count, 6))
        tip_fol = np.zeros((count, 6))
        gravity = np.zeros((count, 3))
        dist = np.zeros((count, 3))
        # views with the batch shape: the loads broadcast into them (no broadcast copies)
        dead_b, fol_b = tip_dead.reshape(*shape, 6), tip_fol.reshape(*shape, 6)
        points = []
        for load in loads:
            if isinstance(load, TipLoad):
                target = fol_b if load.follower else dead_b
                target[..., :3] += load.force
                target[..., 3:] += load.moment
            elif isinstance(load, Gravity):
                if data.massless:
                    raise ValueError(
                        "Gravity needs the arm's mass: give the material a density or the arm "
                        "a mass_per_length (Arm.linear_density is None)"
                    )
                gravity.reshape(*shape, 3)[...] += load.acceleration
            elif isinstance(load, DistributedForce):
                dist.reshape(*shape, 3)[...] += load.force
            elif isinstance(load, PointLoad):
                if not 0.0 <= load.s <= self.length:
                    raise ValueError(
                        f"PointLoad.s must lie on the arm, in [0, L] = [0, {self.length!r}] m, "
                        f"got {load.s!r}"
                    )
                points.append(load)
        interior = [p.s for p in points if p.s < self.length]
        pieces = data.cut(np.array(interior, dtype=np.float64)) if interior else data.pieces
        starts = pieces[0]
        jumps = np.zeros((count, starts.size, 6))
        jumps_b = jumps.reshape(*shape, starts.size, 6)
        for point in points:
            if point.s >= self.length:
                dead_b[..., :3] += point.force
                dead_b[..., 3:] += point.moment
            else:
                j = max(int(np.searchsorted(starts, point.s, side="right") - 1), 0)
                jumps_b[..., j, :3] += point.force
                jumps_b[..., j, 3:] += point.moment
        return loads, shape, count, pieces, (gravity, dist, jumps, tip_dead, tip_fol)

    def solve(self, loads) -> Equilibrium:
        """The equilibrium under ``loads`` (a load or a list of loads, possibly batched).

        Raises
        ------
        ConvergenceError
            If Newton with load stepping fails, or the error estimate cannot reach tol.
        ValueError
            For loads that do not fit the arm (point load off the arm, gravity without mass).
        """
        loads, shape, count, pieces, (gravity, dist, jumps, tip_dead, tip_fol) = \
            self._prepare(loads)
        _, lengths, piece_C, piece_f0, piece_mu = pieces
        if self.steps is not None:
            n_initial, tol = self.steps // 2, math.inf
        else:  # 0: the kernel estimates it from the loads
            n_initial = min(self._n, self.max_steps // 2) if self._n else 0
            tol = self.tol * self.length
        if self._piece_lengths is None or not np.array_equal(self._piece_lengths, lengths):
            # a different cut of the arm (point loads moved): keep only the base wrench
            self._piece_memory = np.zeros((lengths.size, _kernels.PIECE_MEMORY))
            self._piece_lengths = lengths
            self._memory_level[0] = min(self._memory_level[0], 1)
        S = self.s.size
        poses = np.empty((count, S, 4, 4))
        strains = np.empty((count, S, 6))
        stresses = np.empty((count, S, 6))
        residual = np.empty(count)
        estimate = np.empty(count)
        status = np.empty(count, dtype=np.int64)
        work = np.zeros((count, 2), dtype=np.int64)
        _kernels.solve_cases(
            self._base_kernel, self.length, lengths, piece_C, piece_f0, piece_mu, gravity,
            dist, jumps, tip_dead, tip_fol, self._s_kernel, self._data.scale, tol,
            self.max_iterations, self.continuation, self.max_step, n_initial,
            max(self.max_steps, 2 * n_initial), self.max_shootings, self._memory,
            self._piece_memory, self._memory_level, poses, strains, stresses, residual,
            estimate, status, work)
        failed = np.flatnonzero(status != _kernels.OK)
        if failed.size:
            self._n = None
            self._memory_level[0] = 0
            b = int(failed[0])
            where = f" for load case {np.unravel_index(b, shape)}" if shape else ""
            if status[b] == _kernels.TOO_MANY_STEPS:
                raise ConvergenceError(
                    f"the tip error estimate {estimate[b]:.3e} m stayed above tol·L = "
                    f"{self.tol * self.length:.3e} m{where}",
                    residual[b],
                    f"step doubling up to {2 * int(work[b, 1])} RK4 steps",
                )
            raise ConvergenceError(
                f"Newton's method on the base wrench did not converge{where}",
                residual[b],
                f"{int(work[b, 0])} shootings: Newton (max_iterations={self.max_iterations}) "
                + ("with load stepping down to a load-factor step of 1e-5"
                   if self.continuation else "without load stepping")
                + f", {2 * int(work[b, 1])} RK4 steps",
            )
        self._n = int(work[-1, 1]) if count else None
        # fresh arrays, frozen before reshaping (the views are read-only throughout):
        # Equilibrium takes them as they are, with no copy
        for array in (poses, strains, stresses, residual, estimate):
            array.setflags(write=False)
        out_shape = (*shape, S)
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
        )


def solve_numeric(arm, loads, *, s=None, tol=1e-8, base=None, **options) -> Equilibrium:
    """Solve the full static Cosserat rod by shooting; see :class:`Solver` for the options."""
    return Solver(arm, s=s, tol=tol, base=base, **options).solve(loads)
