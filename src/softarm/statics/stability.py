"""Stability of equilibria by the backward sweep of the linearised equations (docs/stability.md).

The numerical work is in :mod:`softarm.statics._kernels` (``stability_cases``,
``sweep_point``); this module prepares its inputs and reads its outputs.
"""

from __future__ import annotations

import numpy as np

from ..equilibrium import Stability

__all__ = ["conservative", "verdict"]


def _k():
    from .solver import _kernels

    return _kernels()


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
    k = _k()
    piece = np.abs(piece)
    tip = np.abs(tip)
    follower = (piece[..., k.FF:k.FF + 3].sum((-1, -2)) + piece[..., k.LF:k.LF + 3].sum((-1, -2))
                + piece[..., k.JF:k.JF + 6].sum((-1, -2)) + tip[..., k.TF:k.TF + 6].sum(-1))
    couple = (piece[..., k.LD:k.LD + 3].sum((-1, -2))
              + piece[..., k.JD + 3:k.JD + 6].sum((-1, -2)) + tip[..., k.TD + 3:k.TD + 6].sum(-1))
    return (follower == 0.0) & (couple == 0.0)


def verdict(channels, base, xs, Ns, shape, tips=None, factor=1) -> Stability:
    """The stability of every case solved by ``solve_cases`` (loads from zero to the
    channels' values, solution xs), swept on factor × Ns steps; ``tips`` (B, 4, 4): the
    solution's tip poses (the forward pass to the tip is then skipped)."""
    k = _k()
    count = xs.shape[0]
    index = np.zeros(count, dtype=np.int64)
    theta0 = np.zeros((count, 6, 6))
    tips = np.zeros((0, 4, 4)) if tips is None else np.ascontiguousarray(tips)
    flags = np.empty(count, dtype=np.bool_)
    k.stability_cases(base, channels.arm_tuple(), (channels.piece, channels.tip_loads), xs,
                      np.ascontiguousarray(Ns, dtype=np.float64), tips, int(factor), index,
                      theta0, flags)
    return make(index, flags, shape)


def make(index, conservative_, shape) -> Stability:
    """A :class:`Stability` of batch shape ``shape``."""
    return Stability.of(index, conservative_, shape)


#: RK4 steps of the sweep of a closed-form equilibrium (whose base reaction is exact): the
#: count of conjugate points needs the grid to resolve the Jacobi fields only, not 1e-8 L.
CLOSED_FORM_STEPS = 128


def closed_form_verdict(solver, loads, eq) -> Stability | None:
    """The stability of a closed-form equilibrium ``eq`` of ``loads`` on ``solver``'s arm:
    the backward sweep from its base reaction (the internal wrench at s = 0, spatial).
    None where that reaction is not available (no station at s = 0, or actuators, whose
    share of the base wrench the closed form does not return)."""
    if eq.s[0] != 0.0:
        return None
    _, shape, count, _, channels = solver._prepare(loads)
    if channels.actuators:
        return None
    xs = np.concatenate([eq.forces_spatial[..., 0, :], eq.moments_spatial[..., 0, :]], -1)
    xs = np.ascontiguousarray(np.broadcast_to(xs, (*shape, 6)).reshape(count, 6))
    Ns = np.full(count, CLOSED_FORM_STEPS, dtype=np.float64)
    return verdict(channels, solver._base_kernel, xs, Ns, shape)
