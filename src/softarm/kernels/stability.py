"""The stability verdict of an equilibrium: the Morse index by conjugate points (docs/
stability.md; entry points ``stability_cases``, ``sweep_point``, ``record_points``)."""

from __future__ import annotations

import math

import numpy as np

from .._jit import on_cold_compile
from . import _prefetch
from ._compile import _entry, _given, _inline, _jit, _per_arm
from .layout import (
    _FF,
    _FG,
    _JD,
    _JF,
    _LD,
    _LF,
    _N,
    _P,
    _R,
    _TD,
    _TF,
    _TM,
    _TN,
    _TP,
    _TT,
    NT,
    PIECE_LOADS,
    TIP_LOADS,
)
from .linear import _copy, _crossings
from .rod import _integrate, _jump, _set_loads, _steps, _tip_residual
from .shooting import _fill_steps, _record, _scratch, solve_cases

# In the last step (to the clamp), an eigenvalue of the transition within this of zero is a
# conjugate point at the clamp itself (a critical or neutral equilibrium: the orbit of a round
# section's buckled shape turning about the axis), not inside (0, L): not counted.
_AT_CLAMP = 1e-8


@_jit
def _block(T, nt, length, out):
    """Θ: the (δp/L; δθ) rows of the first nt tangent columns (nt = 3: δθ only, material),
    one seed per column."""
    for d in range(nt):
        for i in range(nt):
            if nt == 3:
                out[i, d] = T[d, _TT + i]
            elif i < 3:
                out[i, d] = T[d, _TP + i] / length
            else:
                out[i, d] = T[d, _TT + i - 3]


@_jit
def _orthonormalise(T, nt, weights, A):
    """Modified Gram–Schmidt on the first nt tangent columns, in the weighted norm
    (δp/L, δθ, δn L²/EI, δm L/EI): a change of basis of the same family of solutions (the
    conjugate points are those of the family, not of the basis), against growth and loss
    of independence along the sweep. A (nt × nt) receives the change of basis: the new
    columns are the old ones times A."""
    for d in range(nt):
        for e in range(nt):
            A[e, d] = 1.0 if e == d else 0.0
    for d in range(nt):
        for e in range(d):
            dot = 0.0
            for i in range(NT):
                dot += T[d, i] * T[e, i] * weights[i] * weights[i]
            for i in range(NT):
                T[d, i] -= dot * T[e, i]
            for i in range(nt):
                A[i, d] -= dot * A[i, e]
        norm = 0.0
        for i in range(NT):
            norm += (T[d, i] * weights[i]) ** 2
        norm = math.sqrt(norm)
        if norm > 0.0 and math.isfinite(norm):
            for i in range(NT):
                T[d, i] /= norm
            for i in range(nt):
                A[i, d] /= norm


@_inline
def _sweep(x, lam, steps, base, arm, act, case, scratch, nt, r, J, states, fields, theta0, tip,
           given):
    """The backward sweep of one equilibrium (base reaction x at load factor λ, ``steps``
    RK4 steps per piece, the solution's own grid): the state integrated forward to the tip
    (state only), then the state and nt seeded tangent columns back to the base with the
    same steps reversed (the point wrenches undone at each piece start); with a tip pose
    ``tip`` (4, 4) (the solution's own, e.g. its last station) the forward pass is skipped
    (n(L), m(L) are then the tip loads, by the tip condition). Returns the number
    of conjugate points in (0, L) with multiplicity (the Morse index), or -1 if one lies
    exactly on a grid point. ``theta0`` receives Θ(0) of the orthonormalised family; with
    ``states`` of length steps + 1, the state and the tangents at every grid point from the
    tip (index steps) to the base (0) are stored, and in ``fields[k, nt:2nt, :nt]`` the
    change of basis A_k of step k (the columns stored at k are those propagated from k + 1
    times A_k: a solution with coefficients c at k has A_k c at k + 1).

    ``given`` (None, or the solution's state at every grid point, base (0) to tip): the
    state is then not integrated backwards but taken from it at the top of every step (a
    piece's top excepted, reached from the state after the point wrench by undoing it).
    Backwards, the state has the growing modes e^{ks} of a rod in tension too; the multiple
    shooting solver gives its states (:func:`solve_stiff_cases`), so that the sweep of a
    stiff case integrates only the Jacobi fields, which it orthonormalises at every step."""
    y, T, work, twork, now = scratch[0], scratch[1], scratch[2], scratch[3], scratch[4]
    tip_now, law = scratch[5], scratch[8]
    rate, tip_rate = case[1], case[3]
    length = arm[6]
    scale = arm[7]
    # no tangents: a variable, not a literal 0, and x copied (it may be read-only), so that
    # the callees are the same compiled versions as the solver's (one compile, not two)
    none = nt - nt
    one = np.int64(1)
    if given is not None:
        _set_loads(lam, case, now, tip_now)
        _copy(given[given.shape[0] - 1], y)
    elif tip.shape[0] == 4:
        _set_loads(lam, case, now, tip_now)
        for i in range(y.size):
            y[i] = 0.0
        for i in range(3):
            y[_P + i] = tip[i, 3]
            for k2 in range(3):
                y[_R + 3 * i + k2] = tip[i, k2]
        _tip_residual(y, T, none, tip_now, tip_rate, r, J, arm, act, now, rate, law)
        for i in range(6):
            y[_N + i] = -r[i]  # the total wrench at the tip equals the tip loads
    else:
        _integrate(x.copy(), lam, none, steps, base, arm, act, case, scratch, r, J)
    # seeds: unit rotations of the tip section (and translations with nt = 6), with the δn,
    # δm of the linearised tip loads (follower and dipole terms), so that δr(L) = 0
    for d in range(nt):
        for i in range(NT):
            T[d, i] = 0.0
        if nt == 3:
            T[d, _TT + d] = 1.0
        elif d < 3:
            T[d, _TP + d] = 1.0
        else:
            T[d, _TT + d - 3] = 1.0
    _tip_residual(y, T, nt, tip_now, tip_rate, r, J, arm, act, now, rate, law)
    for d in range(nt):
        for i in range(6):
            T[d, _TN + i] = -J[i, d]
    undo = np.empty_like(now)
    for j in range(now.shape[0]):
        for i in range(now.shape[1]):
            undo[j, i] = -now[j, i]
    weights = np.empty(NT)
    for i in range(3):
        weights[_TP + i] = 1.0 / length
        weights[_TT + i] = 1.0
        weights[_TN + i] = 1.0 / scale[0]
        weights[_TM + i] = 1.0 / scale[3]
    old = np.empty((nt, nt))
    new = np.empty((nt, nt))
    M = np.empty((nt, nt))
    lu = np.empty((nt, 2 * nt))
    _block(T, nt, length, old)
    piece_start, piece_len = arm[0], arm[1]
    k = 0
    for j in range(piece_len.size):
        k += steps[j]
    store = states.shape[0] == k + 1
    if store:
        _copy(y, states[k])
        for d in range(nt):
            for i in range(NT):
                fields[k, d, i] = T[d, i]
    count = 0
    exact = False
    for j in range(piece_len.size - 1, -1, -1):
        h = piece_len[j] / steps[j]
        for i in range(steps[j] - 1, -1, -1):
            top = piece_start[j] + (i + 1) * h
            if given is not None and (i < steps[j] - 1 or j == piece_len.size - 1):
                _copy(given[k], y)
            _steps(y, T, nt, -h, top, one, arm, act, j, now, rate, work, twork, law)
            _block(T, nt, length, new)
            c = _crossings(old, new, nt, lu, M, _AT_CLAMP if j == 0 and i == 0 else 0.0)
            if c < 0:
                exact = True
            else:
                count += c
            _orthonormalise(T, nt, weights, M)
            _block(T, nt, length, old)
            k -= 1
            if store:
                _copy(y, states[k])
                for d in range(nt):
                    for i2 in range(NT):
                        fields[k, d, i2] = T[d, i2]
                    for i2 in range(nt):
                        fields[k, nt + i2, d] = M[i2, d]
        _jump(y, T, nt, undo, rate, j, arm, act, law)  # the point wrench there, undone
    for i in range(nt):
        for d in range(nt):
            theta0[i, d] = old[i, d]
    return -1 if exact else count


@_jit
def _tangent_columns(arm, act, piece):
    """3, or 6 where a load depends on position (a field gradient, contact): then a
    translation of the tip section is no longer a solution of the linearised equations by
    itself."""
    if act is not None and act[5].shape[0] > 0:
        return 6
    for j in range(piece.shape[0]):
        for i in range(9):
            if piece[j, _FG + i] != 0.0:
                return 6
    return 3


@_jit
def _conservative(piece, tip):
    """False if a follower load (any channel) or a dead couple acts (see
    softarm.statics.stability.conservative, which says why)."""
    for j in range(piece.shape[0]):
        for i in range(3):
            if (piece[j, _FF + i] != 0.0 or piece[j, _LF + i] != 0.0
                    or piece[j, _LD + i] != 0.0 or piece[j, _JF + i] != 0.0
                    or piece[j, _JF + 3 + i] != 0.0 or piece[j, _JD + 3 + i] != 0.0):
                return False
    for i in range(6):
        if tip[_TF + i] != 0.0:
            return False
    for i in range(3):
        if tip[_TD + 3 + i] != 0.0:
            return False
    return True


def _verdict_capability(args):
    key, text = _per_arm("verdict", "the stability verdict", 2)(args)
    if _given(args[11]):
        return key + "+given", text + " from given states (stiff closed forms)"
    return key, text


@_entry(_verdict_capability, nogil=True)
def stability_cases(base, arm, act, loads, xs, Ns, tips, factor, index, theta0, conservative,
                    given):
    """The Morse index of every solved case of a batch (loads at λ = 1 from zero, the
    solution x, as :func:`solve_cases` returns them), swept on ``factor`` × Ns[b] steps
    (the solution's coarse grid N: the count needs the Jacobi fields resolved, not the
    solution's 1e-8 L): ``index[b]`` (-1 if a conjugate point falls exactly on a grid
    point) and Θ(0) of the sweep (``theta0[b]``, nt × nt in its top-left corner). With
    ``tips`` (B, 4, 4), the solution's tip poses, the forward pass is skipped.
    ``conservative[b]``: whether case b's loads are conservative. ``given``: None, or the
    solutions' states on the sweep's grid (B, K + 1, 18 + A), base to tip (every case on
    the same grid), which the sweep then takes instead of integrating the state backwards
    (:func:`_sweep`)."""
    piece_loads, tip_loads = loads
    npieces = arm[1].size
    width = piece_loads.shape[2]
    scratch = _scratch(npieces, width - PIECE_LOADS, np.int64(7))
    start = np.zeros((npieces, width))
    tip_start = np.zeros(TIP_LOADS)
    r = np.empty(6)
    J = np.empty((6, 7))
    steps = np.empty(npieces, dtype=np.int64)
    none3 = np.empty((0, 1))
    none4 = np.empty((0, 1, 1))
    for b in range(piece_loads.shape[0]):
        case = (start, piece_loads[b:b + 1], tip_start, tip_loads[b:b + 1])
        nt = _tangent_columns(arm, act, piece_loads[b])
        conservative[b] = _conservative(piece_loads[b], tip_loads[b])
        _fill_steps(arm[6], arm[1], int(Ns[b]), factor, steps)
        t0 = np.zeros((nt, nt))
        if given is None:
            index[b] = _sweep(xs[b], 1.0, steps, base, arm, act, case, scratch, nt, r, J, none3,
                              none4, t0, tips[b] if tips.shape[0] > b else none3, None)
        else:
            index[b] = _sweep(xs[b], 1.0, steps, base, arm, act, case, scratch, nt, r, J, none3,
                              none4, t0, none3, given[b])
        for i in range(nt):
            for d in range(nt):
                theta0[b, i, d] = t0[i, d]


@_entry(_per_arm("branch", "the stability sweep of a branch (continuation)", 5))
def sweep_point(x, lam, steps, base, arm, act, case, theta0, states, fields):
    """One backward sweep at (x, λ) of a homotopy ``case`` (continuation, critical loads):
    the Morse index (or -1), Θ(0) into ``theta0`` (nt × nt, nt = its size), and with
    ``states`` (K + 1, 18 + A), ``fields`` (K + 1, 2 nt, 12), K the total number of steps,
    the state and the orthonormalised Jacobi fields at every grid point (with the changes of
    basis, see :func:`_sweep`)."""
    scratch = _scratch(arm[1].size, case[0].shape[1] - PIECE_LOADS, np.int64(7))
    r = np.empty(6)
    J = np.empty((6, 7))
    return _sweep(x, lam, steps, base, arm, act, case, scratch, theta0.shape[0], r, J, states,
                  fields, theta0, np.empty((0, 1)), None)


@_entry(_per_arm("branch", "the stations of a branch (continuation)", 2))
def record_points(base, arm, act, loads, xs, steps, s_out, out):
    """The outputs (stations) of equilibria given by their base reactions: case b has the
    loads (loads[0][b], loads[1][b]) and the solution xs[b] on ``steps`` RK4 steps per piece
    (continuation points); ``out`` as in :func:`solve_cases` (poses, strains, stresses,
    info, status, J, E, x, lengths), without tangents. info[b, 0] is the residual."""
    piece_loads, tip_loads = loads
    npieces = arm[1].size
    width = piece_loads.shape[2]
    scratch = _scratch(npieces, width - PIECE_LOADS, np.int64(7))
    start = np.zeros((npieces, width))
    tip_start = np.zeros(TIP_LOADS)
    r = np.empty(6)
    J = np.empty((6, 7))
    none = J.shape[1] - 7  # no tangents (a variable: one compiled version)
    for b in range(piece_loads.shape[0]):
        case = (start, piece_loads[b:b + 1], tip_start, tip_loads[b:b + 1])
        _record(xs[b], none, steps, base, arm, act, case, 1.0, scratch, s_out, out, b, r, J)
        residual = 0.0
        for i in range(6):
            if not abs(r[i]) <= residual:
                residual = abs(r[i])
        out[3][b, 0] = residual


# A cold compile of the solver starts its verdict's compile on another core (_prefetch.py)
on_cold_compile(solve_cases, lambda args: _prefetch.start(
    "actuated" if _given(args[2]) else "passive", stability_cases))
