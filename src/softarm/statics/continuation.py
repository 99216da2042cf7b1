"""Pseudo-arclength continuation of equilibria in (x, λ), critical points and branch switching
(issue 15; docs/stability.md).

A homotopy is loads(λ) = fixed + λ varied; the unknowns are the base reaction x = (n(0); m(0))
(spatial) and λ. Every point is a solution of r(x, λ) = 0 on a fixed grid of RK4 steps, its
Jacobian [∂r/∂x | ∂r/∂λ] from the variational equations (the kernel's ``shoot``), and its
Morse index from the backward sweep (``sweep_point``). Everything is nondimensional before
any threshold: x and r in units of the bending scale (EI/L², EI/L) times (1 + the load size).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from .. import kernels
from .._admissible import check_stretch, inside_out, stretched
from ..equilibrium import Equilibrium
from ..errors import ConvergenceError
from ..loads import as_loads
from ._stiff import STIFF_KL, tension_kl
from .solver import METHOD, Solver
from .stability import conservative, make

__all__ = ["Branch", "CriticalPoint", "Mode", "Path", "Stopped"]

#: Default RK4 steps over the arm of a continuation grid (spread over the pieces).
STEPS = 256
_NEWTON_TOL = 1e-11  # nondimensional residual of a converged point
_NEWTON_ITER = 12
_DS_MAX = 0.25
_DS_MIN = 1e-9
_RANK = 1e-8  # singular values below this times the largest: a null direction


@dataclass(frozen=True, eq=False)
class Mode:
    """The buckling mode of a critical point: ``nullity`` independent Jacobi fields that
    vanish at the clamp and satisfy the linearised tip condition.

    Attributes
    ----------
    s : ndarray, shape (K,)
        Arc length of the sweep's grid points, m.
    displacement : ndarray, shape (nullity, K, 3)
        δp(s), spatial, each mode scaled so that its largest |δp| is 1 (L units: m per m).
    rotation : ndarray, shape (nullity, K, 3)
        δθ(s) in spatial components (δR = δθ~ R), same scaling (rad per m of δp).
    base_reaction : ndarray, shape (nullity, 6)
        The null vector(s) of ∂r/∂x: the change (δn(0); δm(0)) of the base reaction along the
        mode (N, N m, spatial, same scaling).
    """

    s: np.ndarray
    displacement: np.ndarray
    rotation: np.ndarray
    base_reaction: np.ndarray


@dataclass(frozen=True, eq=False)
class CriticalPoint:
    """A point of a branch where the Morse index changes.

    Attributes
    ----------
    factor : float
        The load factor λ_c.
    kind : str
        "fold" (the branch turns back in λ) or "bifurcation" (it goes on; another branch
        crosses it).
    nullity : int
        The number of independent modes (2 for a round section's symmetric buckling).
    mode : Mode
    x : ndarray, shape (6,)
        The base reaction at the critical point (N, N m, spatial).
    index_before, index_after : int
        The Morse index on either side along the branch.
    """

    factor: float
    kind: str
    nullity: int
    mode: Mode
    x: np.ndarray
    index_before: int
    index_after: int
    path: Path = field(repr=False, default=None)


class Path:
    """A homotopy loads(λ) = fixed + λ varied on an arm, on a fixed grid of RK4 steps."""

    def __init__(self, solver: Solver, fixed, varied, steps: int = STEPS):
        k = kernels
        self.k = k
        self.solver = solver
        fixed, varied = as_loads(fixed), as_loads(varied)
        everything = fixed + varied
        _, shape, _, pieces, channels = solver._prepare(everything)
        if shape != ():
            raise ValueError(f"loads must be a single load case (batch shape ()), got batch "
                             f"shape {shape}")
        # the same loads with the varied ones at zero: the same cut, the same actuator
        # columns, so that start and rate line up channel by channel
        zeroed = fixed + tuple(load.scaled(0.0) for load in varied)
        _, _, _, _, start = solver._prepare(zeroed, tuple(pieces[0]))
        self.loads, self.fixed, self.varied = everything, fixed, varied
        self.channels = channels
        self.arm = channels.arm_tuple()
        start_piece, start_tip = start.piece[0].copy(), start.tip_loads[0].copy()
        # the kernel's case: start loads and one rate row (the homotopy's direction)
        self.case = (start_piece, (channels.piece[0] - start_piece)[None], start_tip,
                     (channels.tip_loads[0] - start_tip)[None])
        self.base = solver._base_kernel
        n = int(steps)
        lengths = pieces[1]
        self.steps = np.maximum(1, np.floor(n * lengths / solver.length + 0.5)).astype(np.int64)
        self.n = int(self.steps.sum())
        data = solver._data
        size = max(np.max(np.abs(self.case[0])), np.max(np.abs(self.case[0] + self.case[1][0])),
                   np.max(np.abs(self.case[2])), np.max(np.abs(self.case[2] + self.case[3][0])))
        w = size * max(solver.length, 1.0) / min(data.scale[0], data.scale[3])
        self.xscale = data.scale * (1.0 + w)
        self.nt = 6 if (np.any(self.case[0][:, k.FG:k.FG + 9])
                        or np.any(self.case[1][0, :, k.FG:k.FG + 9])) else 3
        self.conservative = bool(conservative(channels.piece, channels.tip_loads)[0])
        grid = [np.zeros(1)]
        for j in range(lengths.size):
            grid.append(pieces[0][j] + lengths[j] * np.arange(1, self.steps[j] + 1)
                        / self.steps[j])
        self.grid = np.concatenate(grid)
        self._r, self._J = np.empty(6), np.empty((6, 7))
        self._y = np.empty(18 + len(channels.actuators))
        self._T = np.empty((7, 12 + len(channels.actuators)))
        self.shootings = 0

    # nondimensional variables: z = (x / xscale, λ)
    def z(self, x, lam) -> np.ndarray:
        return np.append(np.asarray(x) / self.xscale, lam)

    def x(self, z) -> np.ndarray:
        return z[:6] * self.xscale

    def residual(self, z):
        """r̃(z) (6) and its Jacobian J̃ (6 × 7), nondimensional."""
        self.k.shoot(self.x(z), float(z[6]), self.steps, self.base, *self.arm, self.case,
                     self._r, self._J, self._y, self._T)
        self.shootings += 1
        r = self._r / self.xscale
        J = self._J / self.xscale[:, None]
        J[:, :6] *= self.xscale[None, :]
        return r, J

    def index(self, z, store=False):
        """(Morse index or -1, Θ(0), states, fields) at the point z."""
        theta0 = np.empty((self.nt, self.nt))
        if store:
            states = np.empty((self.n + 1, self._y.size))
            fields = np.zeros((self.n + 1, 2 * self.nt, 12))
        else:
            states, fields = np.empty((0, 1)), np.empty((0, 1, 1))
        index = self.k.sweep_point(self.x(z), float(z[6]), self.steps, self.base, *self.arm,
                                   self.case, theta0, states, fields)
        return int(index), theta0, states, fields

    def correct(self, z, normal=None, anchor=None):
        """Newton from z on r̃ = 0 with, if ``normal`` is given, normal·(z - anchor) = 0
        (pseudo-arclength), else at fixed λ. Returns the point or None."""
        z = z.copy()
        for _ in range(_NEWTON_ITER):
            r, J = self.residual(z)
            res = float(np.max(np.abs(r)))
            if not np.isfinite(res):
                return None
            if res <= _NEWTON_TOL:
                return z
            if normal is None:
                try:
                    dz = np.linalg.solve(J[:, :6], -r)
                except np.linalg.LinAlgError:
                    return None
                z[:6] += dz
            else:
                # the least-squares (minimum-norm) step: a symmetry of the problem (a round
                # section's buckled branch turns freely about the axis) leaves a direction
                # along which r does not change, and the corrector must not drift along it
                A = np.vstack([J, normal])
                b = np.append(-r, -float(normal @ (z - anchor)))
                z += np.linalg.lstsq(A, b, rcond=_RANK)[0]
        return None

    def tangent(self, z, previous=None):
        """The unit tangent of the branch at z (null vector of J̃), oriented along
        ``previous`` (or towards increasing λ)."""
        _, J = self.residual(z)
        _, sv, V = np.linalg.svd(J)
        if previous is not None:
            # a second null direction (a symmetry orbit): the tangent closest to the last one
            null = V[-2:] if sv[-1] <= _RANK * sv[0] else V[-1:]
            t = null.T @ (null @ previous)
            t /= np.linalg.norm(t)
        else:
            t = V[-1]
            if t[6] < 0:
                t = -t
        return t

    def mode(self, z, nullity) -> Mode:
        """The ``nullity`` Jacobi fields of z whose (δp, δθ) vanish at the clamp."""
        _, theta0, states, fields = self.index(z, store=True)
        nt = self.nt
        c = np.linalg.svd(theta0)[2][-nullity:][::-1].T  # (nt, nullity)
        # the coefficients of the mode in each grid point's basis: c_k+1 = A_k c_k
        coef = np.empty((fields.shape[0], nt, nullity))
        coef[0] = c
        for k in range(fields.shape[0] - 1):
            coef[k + 1] = fields[k, nt:, :nt] @ coef[k]
        fields = fields[:, :nt]
        dp = np.einsum("kdi,kdm->mki", fields[:, :, 0:3], coef)
        if self.nt == 3:
            # the rotation seeds carry δp(L) = 0; a rigid translation (itself a solution when
            # no load depends on position) brings δp(0) to 0
            dp -= dp[:, :1, :]
        R = states[:, 3:12].reshape(-1, 3, 3)
        dth = np.einsum("kij,kdj,kdm->mki", R, fields[:, :, 3:6], coef)
        base = np.einsum("di,dm->mi", fields[0, :, 6:12], c)
        size = np.max(np.linalg.norm(dp, axis=-1), axis=-1)
        size = np.where(size > 0, size, 1.0)
        # a fixed sign: the largest tip displacement component positive
        tip = dp[:, -1]
        sign = np.sign(tip[np.arange(tip.shape[0]), np.argmax(np.abs(tip), axis=-1)])
        sign = np.where(sign == 0, 1.0, sign)
        scale = (sign / size)[:, None, None]
        out = Mode(self.grid.copy(), dp * scale, dth * scale, base * scale[:, :, 0])
        for array in (out.s, out.displacement, out.rotation, out.base_reaction):
            array.setflags(write=False)
        return out

    def record(self, zs) -> Equilibrium:
        """The equilibria at the points zs (one batched Equilibrium, stations of the
        solver), with their stability; an :class:`~softarm.InadmissibleStateError` for the
        first point whose axial stretch v₁ <= 0 at a station (the arm inside out: the
        branch has left the model there)."""
        k, solver = self.k, self.solver
        zs = np.atleast_2d(zs)
        B = zs.shape[0]
        lam = zs[:, 6]
        piece = self.case[0][None] + lam[:, None, None] * self.case[1]
        tip = self.case[2][None] + lam[:, None] * self.case[3]
        S = solver.s.size
        poses, strains = np.empty((B, S, 4, 4)), np.empty((B, S, 6))
        stresses, info = np.empty((B, S, 6)), np.zeros((B, 5))
        xs = np.ascontiguousarray(zs[:, :6] * self.xscale)
        out = (poses, strains, stresses, info, np.zeros(B, dtype=np.int64),
               np.zeros((0, 6, 6)), np.zeros((1, S, 6, 6)), np.empty((B, 6)),
               np.empty((B, len(self.channels.actuators))))
        k.record_points(self.base, *self.arm, (np.ascontiguousarray(piece),
                                              np.ascontiguousarray(tip)),
                        xs, self.steps, solver._s_kernel, out)
        if not stretched(strains):  # (the common case: one reduction)
            first = int(np.argmax(inside_out(strains).any(axis=-1)))
            check_stretch(strains[first], solver.s, info[first, 0], stresses[first],
                          f"the branch's point at load factor λ = {lam[first]:.6g}",
                          float(lam[first]))
        index = np.array([self.index(z)[0] for z in zs])
        for array in (poses, strains, stresses):
            array.setflags(write=False)
        base_wrench = out[7]
        base_wrench.setflags(write=False)
        residual = info[:, 0].copy()
        return Equilibrium(s=solver.s, poses=poses, strains=strains, stresses=stresses,
                           arm=solver.arm, loads=self.loads, method=METHOD + ".continuation",
                           exact=True, residual=residual, error_estimate=np.full(B, np.nan),
                           base_wrench=base_wrench,
                           stability=make(index, np.full(B, self.conservative), (B,)))


@dataclass(frozen=True, eq=False)
class Branch:
    """A branch of equilibria followed by continuation (:func:`softarm.continuation`).

    Attributes
    ----------
    lam : ndarray, shape (K,)
        The load factors of the points, in the order followed.
    x : ndarray, shape (K, 6)
        The base reactions (N, N m, spatial).
    index : ndarray of int, shape (K,)
        The Morse index at each point (-1 at a critical point: a switched branch starts at
        its bifurcation).
    critical : tuple of CriticalPoint
        The critical points met (folds, bifurcations), in order.
    equilibria : Equilibrium
        The points as one batched Equilibrium (batch shape (K,)), with their stability.
    """

    lam: np.ndarray
    x: np.ndarray
    index: np.ndarray
    critical: tuple
    equilibria: Equilibrium
    path: Path = field(repr=False)
    conservative: bool = True
    #: False if the branch stops before the load factor asked for; ``reason`` says why
    #: (a RuntimeWarning said it too)
    complete: bool = True
    reason: str = ""

    @property
    def stable(self) -> np.ndarray:
        return (self.index == 0) & self.conservative

    def switch(self, point: CriticalPoint | int = 0, *, imperfection=None, lam=None,
               **options) -> Branch:
        """The branch that bifurcates at ``point`` (a CriticalPoint of this branch or its
        position in :attr:`critical`), followed from there along the null vector of ∂r/∂x
        (not an arbitrary perturbation) to ``lam`` (default: this branch's last λ).
        ``imperfection``: a spatial direction (3,) for the tip's displacement that picks one
        of two mirror branches (and, with nullity 2, the plane of buckling). ``options``:
        ``ds`` (first step), ``max_step`` (largest step, nondimensional arclength in
        (x, λ)), ``max_points``."""
        if isinstance(point, (int, np.integer)):
            point = self.critical[int(point)]
        if point.kind != "bifurcation":
            raise ValueError(f"point must be a bifurcation to switch branch at, got a "
                             f"{point.kind} at λ = {point.factor:.6g}")
        end = float(self.lam[-1]) if lam is None else float(lam)
        return _switch(self.path, point, imperfection, end, **options)


def _orient(mode: Mode, imperfection) -> np.ndarray:
    """The combination c (nullity,) of the modes whose tip displacement best follows the
    imperfection direction (default: the first mode as scaled)."""
    if imperfection is None:
        c = np.zeros(mode.base_reaction.shape[0])
        c[0] = 1.0
        return c
    d = np.asarray(imperfection, dtype=np.float64)
    if d.shape != (3,) or not np.all(np.isfinite(d)) or not np.any(d):
        raise ValueError(f"imperfection must be a nonzero spatial direction (3 numbers), got "
                         f"{imperfection!r}")
    tips = mode.displacement[:, -1, :]  # (nullity, 3)
    c = np.linalg.lstsq(tips.T, d, rcond=None)[0]
    if not np.any(c):
        c = np.zeros(tips.shape[0])
        c[0] = 1.0
    return c / np.linalg.norm(c)


class Stopped(ConvergenceError):
    """A branch that could not be followed to its end (:func:`follow`): a ConvergenceError
    that also holds what was followed, ``points``, ``indices``, ``critical``, for a caller
    that returns the branch so far (:func:`softarm.continuation`)."""

    def __init__(self, message, tried, load_factor, points, indices, critical):
        super().__init__(message, math.nan, tried, load_factor=load_factor)
        self.points, self.indices, self.critical = points, indices, critical


def _why_stopped(path: Path, lam: float) -> str:
    """Why a branch cannot be followed at λ, as far as the loads tell: the tension they can
    put the arm in (kL, statics/_stiff.py), which one shooting from the base does not carry
    beyond kL ≈ 20 (docs/solver.md, "Multiple shooting"); else the grid."""
    solver = path.solver
    loads = (*path.fixed, *(load.scaled(lam) for load in path.varied))
    kl = float(tension_kl(solver.arm, loads, (), solver._data.soft)[0])
    if kl >= STIFF_KL:
        return (f": there the loads can put the arm in tension up to kL = L √(F/EI) = "
                f"{kl:.3g}, and continuation shoots once from the base, whose tangents grow "
                f"like e^{{kL}} beyond what double precision carries from kL ≈ 20 (the solver "
                f"takes multiple shooting from kL = {STIFF_KL:g}; continuation does not: "
                f"softarm.solve gives the equilibrium at any one λ)")
    return (f" (the corrector failed at arclength steps below {_DS_MIN:g}: a finer grid, "
            f"steps > {path.n}, may follow it)")


def follow(path: Path, z0, lam_end, *, direction=None, ds=0.05, max_points=2000,
           locate=True, stop_at_critical=False, max_step=_DS_MAX) -> tuple:
    """Pseudo-arclength continuation from the point z0 (converged) until λ reaches
    ``lam_end``, with steps of at most ``max_step`` (nondimensional arclength in (x, λ)).
    Returns (points (K, 7), indices (K,), critical points); stops early at ``max_points``
    points (the caller compares the last λ with ``lam_end``). A :class:`Stopped` where the
    branch cannot be followed, with the points so far."""
    t = path.tangent(z0, direction)
    if direction is None and np.sign(t[6]) != np.sign(lam_end - z0[6]) and t[6] != 0:
        t = -t
    points, indices, critical = [z0], [path.index(z0)[0]], []
    z = z0
    goal = np.sign(lam_end - z0[6]) or 1.0
    while len(points) < max_points:
        if (lam_end - z[6]) * goal <= 1e-14 * max(1.0, abs(lam_end)):
            break
        pred = z + ds * t
        landed = False
        if (lam_end - pred[6]) * goal < 0 and t[6] * goal > 0:
            # the step passes λ_end: land on it (at fixed λ)
            zl = z + (lam_end - z[6]) / t[6] * t
            zl[6] = lam_end
            new = path.correct(zl)
            landed = new is not None
        else:
            new = path.correct(pred, normal=t, anchor=pred)
        if new is not None:
            t_new = path.tangent(new, t)
            if t_new @ t < 0.8 or np.max(np.abs(new - pred)) > 0.5 * ds + 1e-12:
                new = None  # turned too much or corrected too far: a smaller step
                landed = False
        if new is None:
            ds *= 0.5
            if ds < _DS_MIN:
                raise Stopped(
                    f"continuation could not be followed beyond load factor λ = {z[6]:.6g}"
                    f"{_why_stopped(path, float(z[6]))}", f"{path.shootings} shootings",
                    float(z[6]), np.array(points), np.array(indices), tuple(critical))
            continue
        index = path.index(new)[0]
        if index != indices[-1] and locate:
            critical.append(_locate(path, z, t, new, t_new, indices[-1], index))
            if stop_at_critical:
                points.append(new)
                indices.append(index)
                break
        points.append(new)
        indices.append(index)
        z, t = new, t_new
        if landed:
            break
        ds = min(max_step, ds * 1.4)
    return np.array(points), np.array(indices), tuple(critical)


def _locate(path, za, ta, zb, tb, index_a, index_b) -> CriticalPoint:
    """The first point between za and zb where the index leaves ``index_a``: bisection on
    the arclength of the pseudo-arclength corrector from za along ta."""
    lo, hi = 0.0, float(ta @ (zb - za))
    z_hi, i_hi = zb, index_b
    z_lo = za
    for _ in range(60):
        if hi - lo <= 1e-13 * max(1.0, np.max(np.abs(za))):
            break
        mid = 0.5 * (lo + hi)
        pred = za + mid * ta
        zm = path.correct(pred, normal=ta, anchor=pred)
        if zm is None:
            break
        im = path.index(zm)[0]
        if im == index_a:
            lo, z_lo = mid, zm
        else:
            hi, z_hi, i_hi = mid, zm, im
    t_lo, t_hi = path.tangent(z_lo, ta), path.tangent(z_hi, ta)
    kind = "fold" if t_lo[6] * t_hi[6] < 0 or (ta[6] * tb[6] < 0 and i_hi == index_b) \
        else "bifurcation"
    nullity = max(1, abs(i_hi - index_a)) if i_hi >= 0 and index_a >= 0 else 1
    zc = 0.5 * (z_lo + z_hi)
    mode = path.mode(z_hi, nullity)
    x = path.x(zc)
    x.setflags(write=False)
    return CriticalPoint(float(zc[6]), kind, int(nullity), mode, x, int(index_a), int(i_hi),
                         path)


def branch(path: Path, points, indices, critical, reason: str = "") -> Branch:
    """The Branch of the points followed; ``reason``: why it stops before its end ("" if
    it does not), after a RuntimeWarning that says so."""
    if reason:
        warnings.warn(f"softarm: {reason}", RuntimeWarning, stacklevel=4)
    eq = path.record(points)
    lam = points[:, 6].copy()
    x = points[:, :6] * path.xscale
    for array in (lam, x, indices):
        array.setflags(write=False)
    return Branch(lam, x, indices, critical, eq, path, path.conservative,
                  complete=not reason, reason=reason)


def follow_to(path: Path, z0, lam_end, *, max_points=2000, **options) -> tuple:
    """:func:`follow` to ``lam_end``: (points, indices, critical, reason), ``reason`` why the
    branch stops before it ("" if it does not): the budget of ``max_points``, or a point
    beyond which it cannot be followed (for :func:`branch`)."""
    try:
        points, indices, critical = follow(path, z0, lam_end, max_points=max_points,
                                           **options)
    except Stopped as stop:
        return stop.points, stop.indices, stop.critical, stop.message
    reason = ""
    if abs(points[-1, 6] - lam_end) > 1e-14 * max(1.0, abs(lam_end)):
        reason = (f"the branch stops at load factor λ = {points[-1, 6]:.6g}, short of "
                  f"{lam_end:.6g}: max_points = {max_points} points were followed")
    return points, indices, critical, reason


def _switch(path: Path, point: CriticalPoint, imperfection, lam_end, ds=0.005,
            max_points=2000, max_step=_DS_MAX) -> Branch:
    """Leave the bifurcation ``point`` along its null vector and follow the new branch."""
    mode = point.mode
    c = _orient(mode, imperfection)
    v = c @ mode.base_reaction  # δx (N, N m)
    zc = path.z(point.x, point.factor)
    zc = path.correct(zc) if path.correct(zc) is not None else zc
    direction = np.append(v / path.xscale, 0.0)
    direction /= np.linalg.norm(direction)
    first = None
    step = ds
    while step >= 1e-6 and first is None:
        pred = zc + step * direction
        first = path.correct(pred, normal=direction, anchor=pred)
        if first is not None and np.linalg.norm(first - zc) < 0.5 * step:
            first = None  # fell back onto the branch it left
        step *= 0.5
    if first is None:
        raise ConvergenceError(
            f"could not leave the bifurcation at λ = {point.factor:.6g} along its mode",
            math.nan, f"{path.shootings} shootings", load_factor=point.factor)
    t = path.tangent(first, direction)
    points, indices, critical, reason = follow_to(path, first, lam_end, direction=t, ds=ds,
                                                  max_points=max_points, max_step=max_step)
    points = np.vstack([zc[None], points])
    indices = np.concatenate([[-1], indices])  # the bifurcation point itself: critical
    return branch(path, points, indices, critical, reason)
