"""Stability of equilibria by the backward sweep of the linearised equations (docs/stability.md).

The numerical work is in :mod:`softarm.kernels.stability` (``stability_cases``,
``sweep_point``); this module prepares its inputs and reads its outputs.
"""

from __future__ import annotations

import math

import numpy as np

from .. import kernels
from .._threads import in_threads
from .._validate import PART_BYTES
from ..equilibrium import Stability
from ..kernels import _prefetch
from ..loads import TipLoad, as_loads
from ._stiff import STIFF_KL, tension_kl

__all__ = ["conservative", "verdict"]


def conservative(piece: np.ndarray, tip: np.ndarray) -> np.ndarray:
    """Per case of the kernel's load channels (piece (B, P, C), tip (B, 12)): False where a
    follower load (force or couple, distributed, point or at the tip) or a dead couple acts.

    A dead force, gravity, a tendon at fixed tension (potential τ × its length), a chamber at
    fixed pressure (potential -p × its volume change, linear in the strain) and a hard magnet
    in a field (potential -(R m)·B(p)) are conservative. A follower load is not (Beck's
    column). A couple of fixed direction is not conservative in 3D (Ziegler, *Principles of
    Structural Stability*: the work of an axial couple depends on the path of finite
    rotations), so a dead couple also makes the static test inconclusive.
    """
    k = kernels
    piece = np.abs(piece)
    tip = np.abs(tip)
    follower = (piece[..., k.FF:k.FF + 3].sum((-1, -2)) + piece[..., k.LF:k.LF + 3].sum((-1, -2))
                + piece[..., k.JF:k.JF + 6].sum((-1, -2)) + tip[..., k.TF:k.TF + 6].sum(-1))
    couple = (piece[..., k.LD:k.LD + 3].sum((-1, -2))
              + piece[..., k.JD + 3:k.JD + 6].sum((-1, -2)) + tip[..., k.TD + 3:k.TD + 6].sum(-1))
    return (follower == 0.0) & (couple == 0.0)


def verdict(channels, base, xs, Ns, shape, tips=None, factor=1, threads=1,
            given=None, states=None) -> Stability:
    """The stability of every case solved by ``solve_cases`` (loads from zero to the
    channels' values, solution xs), swept on factor × Ns steps; ``tips`` (B, 4, 4): the
    solution's tip poses (the forward pass to the tip is then skipped); in up to ``threads``
    threads (:func:`softarm._threads.in_threads`). ``given``: None, or (which (B,) bool,
    index (B,), conservative (B,)): the verdicts of the cases ``which`` already known (the
    stiff cases', from ``solve_stiff_cases``); only the others are swept here. ``states``:
    None, or (B, K + 1, 18) the solutions' states on the sweep's grid (every Ns the same),
    taken by the sweep instead of integrating the state backwards (stiff closed forms)."""
    if given is not None:
        which, index, flags = given
        rest = np.flatnonzero(~which)
        if rest.size:
            part = verdict(channels.cases(channels.piece[rest], channels.tip_loads[rest],
                                          (rest.size,)),
                           base, xs[rest], np.asarray(Ns)[rest], (rest.size,),
                           None if tips is None else np.asarray(tips)[rest], factor, threads)
            index[rest] = part.index.reshape(-1)
            flags[rest] = part.conservative.reshape(-1)
        return make(index, flags, shape)
    k = kernels
    count = xs.shape[0]
    index = np.zeros(count, dtype=np.int64)
    theta0 = np.zeros((count, 6, 6))
    # writeable C-contiguous copies: a read-only array (a broadcast view of a result) is
    # another type to numba, one more compiled version and a slow dispatch (80 µs a call)
    tips = np.zeros((0, 4, 4)) if tips is None else np.array(tips, dtype=np.float64)
    xs = np.array(xs, dtype=np.float64)
    flags = np.empty(count, dtype=np.bool_)
    arm, Ns, factor = channels.arm_tuple(), np.array(Ns, dtype=np.float64), int(factor)
    _prefetch.wait(_prefetch.kind(arm))  # a cold first solve's verdict compile, if launched

    def run(a, b):  # cases [a, b)
        k.stability_cases(base, *arm, (channels.piece[a:b], channels.tip_loads[a:b]), xs[a:b],
                          Ns[a:b], tips[a:b] if tips.shape[0] else tips, factor, index[a:b],
                          theta0[a:b], flags[a:b], None if states is None else states[a:b])

    in_threads(run, count, threads)
    return make(index, flags, shape)


def make(index, conservative_, shape) -> Stability:
    """A :class:`Stability` of batch shape ``shape``."""
    return Stability.of(index, conservative_, shape)


def _closed_form_steps(channels, data) -> np.ndarray:
    """RK4 steps for the sweep of each closed-form case: the Jacobi fields vary on the
    scales 1/√(F/EI) and EI/(F L), EI/M; 8 + 2 (kL + F L²/EI + M L/EI) steps keep h k and
    the turning per step below about 1/2, in [12, 256]; and at least 2 per radian of the
    unloaded arm's own turning Σ |κ⁰| L (a step turning by more than 2.8 rad is unstable)."""
    k = kernels
    EI, L = data.least_bending, data.length
    curved = math.ceil(2.0 * data.turning)
    if channels.count == 1:  # one case: scalar arithmetic (numpy's per-call cost dominates)
        t = channels.tip_loads[0].tolist()
        force = math.sqrt(sum((abs(t[k.TD + i]) + abs(t[k.TF + i])) ** 2 for i in range(3)))
        moment = math.sqrt(sum((abs(t[k.TD + 3 + i]) + abs(t[k.TF + 3 + i])) ** 2
                               for i in range(3)))
        return np.array([max(min(max(math.ceil(_sweep_steps(force, moment, L, EI)), 12.0),
                                  256.0), curved)])
    tip = np.abs(channels.tip_loads)
    force = tip[:, k.TD:k.TD + 3] + tip[:, k.TF:k.TF + 3]
    moment = tip[:, k.TD + 3:k.TD + 6] + tip[:, k.TF + 3:k.TF + 6]
    force = np.sqrt((force * force).sum(-1))  # (not np.linalg.norm: 4× its cost here)
    moment = np.sqrt((moment * moment).sum(-1))
    n = _sweep_steps(force, moment, L, EI)
    # (np.clip: 3× the cost)
    return np.maximum(np.minimum(np.maximum(np.ceil(n), 12.0), 256.0), curved)


def _sweep_steps(force, moment, L, EI):
    """8 + 2 (kL + F L²/EI + M L/EI), k = √(F/EI): floats or arrays alike."""
    return 8 + 2 * ((force * L * L / EI) ** 0.5 + force * L * L / EI + moment * L / EI)


def _axial_index(eq, data, loads):
    """The Morse index of the straight arm under a dead axial tip force (a compression P),
    in closed form, or None where it does not apply: each bending plane loses stability at
    every P_n with P_n (1 + P_n (1/GA - 1/EA)) = (2n - 1)² π² EI/(4L²) (the linearised
    extensible, shearable rod; buckling.json, cosserat_cantilever_extensible_shearable).
    Its roots P < 0 are tensions beyond EA GA/(EA - GA) where GA < EA, at which the
    shearable rod buckles in tension (docs/solver.md, "The model's limits")."""
    K = data.K
    if K.shape[0] != 1 or np.any(K[0] != np.diag(np.diagonal(K[0]))) or np.any(data.f0[:, 1:]):
        return None
    if not all(isinstance(load, TipLoad) and not load.follower for load in loads):
        return None
    P = -np.asarray(eq.stresses[..., 0, 0])  # the compression (material axial force)
    EA, GAy, GAz, _, EIy, EIz = np.diagonal(K[0])
    L = data.length
    index = np.zeros(P.shape, dtype=np.int64)
    for EI, GA in ((EIy, GAz), (EIz, GAy)):
        c = 1.0 / GA - 1.0 / EA
        # the n >= 1 with P_n < P: P (1 + c P) > (2n - 1)² Q1, Q1 = π² EI/(4 L²)
        Q1 = np.pi ** 2 * EI / (4 * L * L)
        root = np.sqrt(np.maximum(P * (1 + c * P), 0.0) / Q1)
        n = np.ceil((root + 1.0) / 2.0) - 1.0  # the n with 2n - 1 < root
        index += n.astype(np.int64)
    return index


def closed_form_verdict(solver, loads, eq, states_at=None) -> Stability | None:
    """The stability of a closed-form equilibrium ``eq`` of ``loads`` (as
    ``solver.check_loads`` returns them) on ``solver``'s arm.

    The straight arm under a dead axial force has its index in closed form; every other
    closed form gets the backward sweep from its base reaction (the internal wrench at
    s = 0, spatial) and its tip pose (when the last station is s = L), on a grid that
    resolves the Jacobi fields (:func:`_closed_form_steps`). None where the base reaction is
    not available (no station at s = 0, or actuators, whose share of the base wrench the
    closed form does not return).

    Under strong tension (kL >= STIFF_KL, _stiff.py) the state integrated backwards would
    grow like e^{kL}: there the sweep takes the states from the closed form itself,
    ``states_at(s)`` (the equilibrium at stations s), on a grid of hk <= 1/2, and None
    (no verdict) where those states would not fit in PART_BYTES."""
    if eq.s[0] != 0.0:
        return None
    data = solver._data
    if eq.method == "analytic.axial_force":
        index = _axial_index(eq, data, as_loads(loads))
        if index is not None:
            return make(index, np.ones(index.shape, dtype=bool), index.shape)
    _, shape, count, _, channels = solver._prepare(loads, checked=True)
    if channels.actuators:
        return None
    # the base reaction: the internal wrench at s = 0 in spatial components, R(0) (n; m)
    R0, base = eq.poses[..., 0, :3, :3], eq.stresses[..., 0, :]
    if R0.ndim == 2 and base.ndim == 1:  # one case
        xs = np.concatenate([R0 @ base[:3], R0 @ base[3:]])[None]
    else:
        xs = np.empty((*np.broadcast_shapes(R0.shape[:-2], base.shape[:-1]), 6))
        xs[..., :3] = (R0 @ base[..., :3, None])[..., 0]
        xs[..., 3:] = (R0 @ base[..., 3:, None])[..., 0]
        xs = np.ascontiguousarray(np.broadcast_to(xs, (*shape, 6)).reshape(count, 6))
    tips = None
    if eq.s[-1] == solver.length:
        tips = eq.poses[None, -1] if eq.poses.ndim == 3 else np.broadcast_to(
            eq.poses[..., -1, :, :], (*shape, 4, 4)).reshape(count, 4, 4)
    steps = _closed_form_steps(channels, data)
    states = None
    kl = tension_kl(solver.arm, loads, shape, data.soft)
    if np.any(kl >= STIFF_KL):
        if states_at is None:
            return None
        N = max(float(steps.max()), math.ceil(2.0 * float(kl.max())))
        grid = _sweep_grid(channels, int(N))
        if count * grid.size * 18 * 8 > PART_BYTES:
            return None
        states = _states(states_at(grid), count)
        steps = np.full(count, N)
    return verdict(channels, solver._base_kernel, xs, steps, shape, tips,
                   threads=solver._threads(count), states=states)


def _sweep_grid(channels, N: int) -> np.ndarray:
    """The sweep's grid on N steps spread over the pieces (kernels.shooting._fill_steps), base to
    tip: each piece's step starts, then L."""
    starts, lengths = channels.starts, channels.lengths
    counts = np.maximum(1, np.floor(N * lengths / channels.length + 0.5)).astype(int)
    parts = [start + np.arange(n) * (length / n)
             for start, length, n in zip(starts, lengths, counts, strict=True)]
    return np.concatenate([*parts, [channels.length]])


def _states(eq, count: int) -> np.ndarray:
    """The kernel's states (count, S, 18) of a passive equilibrium: p, R row-major, and the
    internal wrench in spatial components, R (its material stresses)."""
    poses = np.broadcast_to(eq.poses, (*eq.poses.shape[:-3], eq.s.size, 4, 4))
    R = poses[..., :3, :3]
    out = np.empty((*poses.shape[:-2], 18))
    out[..., 0:3] = poses[..., :3, 3]
    out[..., 3:12] = R.reshape(*R.shape[:-2], 9)
    stresses = np.broadcast_to(eq.stresses, (*poses.shape[:-2], 6))
    out[..., 12:15] = (R @ stresses[..., :3, None])[..., 0]
    out[..., 15:18] = (R @ stresses[..., 3:, None])[..., 0]
    return np.ascontiguousarray(np.broadcast_to(out.reshape(-1, eq.s.size, 18),
                                                (count, eq.s.size, 18)))
