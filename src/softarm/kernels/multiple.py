"""Multiple shooting for stiff problems (strong tension, contact): the block-banded Newton
system, its path from the unloaded arm, refinement, output and verdict (entry point
``solve_stiff_cases``; docs/solver.md, "Multiple shooting")."""

from __future__ import annotations

import math

import numpy as np

from ._compile import _entry, _given, _jit, _per_arm
from .layout import (
    _CT,
    _M,
    _N,
    _P,
    _R,
    _TM,
    _TN,
    _TP,
    _TT,
    BUDGET,
    LAM,
    NEWTON_FAILED,
    NOT_FINITE,
    NT,
    OK,
    PATH_FAILED,
    PIECE_LOADS,
    SINGULAR,
    TIP_LOADS,
    TOO_MANY_STEPS,
)
from .linear import _band_factor, _band_solve, _copy, _crossings
from .rod import ZONE, _jump, _rotated, _set_loads, _start, _steps, _tip_residual
from .shooting import (
    _CONTRACTION_MAX,
    _DIST_MAX,
    _FIRST_MOTION,
    _LOOSE,
    _PHASE_TESTED,
    _REFINE_MAX,
    _STALL,
    _cosine,
    _cross_step,
    _fill_steps,
    _first_steps,
    _grown,
    _guard_work,
    _load_size,
    _load_step,
    _path_bounds,
    _phase,
    _phase_limited,
    _read_options,
    _retry_finer,
    _scratch,
    _smallest_step,
    _write,
)
from .stability import _conservative, _sweep, _tangent_columns

# ------------------------------------------------------------------ multiple shooting
# Stiff problems (tension: k = √(T/EI), kL large). Single shooting's map x -> r(x) grows like
# e^{kL}; here [0, L] is cut into M intervals of kL/M <= _GROWTH each, the state at every
# interval start is an unknown, and continuity at the joins closes the system: a block-banded
# Newton system solved by banded Gaussian elimination with partial pivoting (never condensed
# back into a 6 × 6 transfer product, which would restore e^{kL}). statics/README.md, "Multiple
# shooting"; docs/solver.md for users.
#
# Unknowns (scaled, n = 12 M - 6): the base reaction x (6, in units of the bending scale),
# then per interior node i = 1..M-1 the corrections (δn, δm, δp, δθ) of its state (forces in
# the bending scale, δp in L, δθ material, rad): the order of the tangent columns below.
# Equations: per join (12 rows, p, θ, n, m: the end of interval i minus node i + 1), then the
# tip residual (6). An interval from a node integrates 13 tangent columns: 0-5 δ(n; m) at the
# node, 6 the load factor, 7-9 δp, 10-12 δθ; columns 7-12 use the rate rows 1-6 of the
# case, which are zero (the homogeneous variational equations: the same _steps, no new
# compiled right-hand side).

_GROWTH = 5.0  # kL per shooting interval at most (the tangents grow by about e^5 across it)
_STIFF_STEPS = 0.6  # coarse RK4 steps per unit of kL at least: hk <= 1.7 (RK4 is stable for the
#                    decaying mode e^{-ks} up to hk = 2.78; the error estimate then decides)
# The smallest load-factor step of the stiff path: the path from the unloaded arm bends
# sharply near λ = 0 (k grows like √λ: the predicted lateral motion at λ = 0 is that of an
# arm without tension), so steps far below a single-shooting path's are needed there,
# doubling from then on.
_DLAM_MIN_STIFF = 1e-12
# With contact the branch guard is det's sign alone, and a step no longer than this crosses
# (the guard of before issue 42): the penalty's band switches on within a step at a
# touchdown, and J changes there by more than the eigenvalue test and the phase's step allow
# (a path that the old guard followed failed and widened the band). Contact is to be solved
# as a constraint instead (issue 39).
_DLAM_CROSS_CONTACT = 1e-3
# The corrector's contraction test with contact: Newton on a penalty contracts slowly until
# it is within the band of the answer (a contact that closes between prediction and answer).
_CONTRACTION_CONTACT = 0.9
# The Richardson estimate |p_2N - p_N| / 15 times this: at hk near 1 (a boundary layer of
# width 1/k resolved by a few steps) RK4 is not yet in its asymptotic regime, and the fine
# solution's error against the separatrix was measured up to 2.2 times |p_2N - p_N| / 15
# (a hard pull at 150°, kL = 1e4).
_STIFF_SAFETY = 2.0
_NODE_WEIGHT = 0.2
# The levels of the stiff path: each has 2^_LEVEL times the intervals of the one before
_LEVEL = 2  # the interior nodes' weight in the path's distance (_ms_distance)
_BAND = 17  # the Jacobian's lower and upper bandwidth (rows of a join, columns of two nodes)
_COLS = 13  # tangent columns of an interval from an interior node
# Chunk rows (_chunk_table): piece, start s, length, 1.0 if it starts its piece (the point
# wrench there is its own), the interval it belongs to.
_CJ, _CS, _CL, _CFIRST, _CI = 0, 1, 2, 3, 4


@_jit
def _stiffness_size(arm, act, w, loads):
    """kL estimated from the case's load size ``w`` (in EI/L² of the *stiffest* bending,
    :func:`_load_size`) with the softest bending stiffness of the arm: the growth exponent of
    single shooting under a tension of that size; with contact, the larger of that and the
    penalty's own, L max(√(k/GA), (k/EI)^¼) (the growth rates of a shearable rod on an
    elastic foundation of stiffness k times the case's scale, the channel CT of ``loads``
    (P, W): contact.md)."""
    soft = 0.0
    for j in range(arm[1].size):
        soft = max(soft, arm[2][j, 4, 4], arm[2][j, 5, 5])
    stiff = arm[7][3] * arm[6]  # the bending scale's EI
    kl = math.sqrt(max(w, 0.0) * stiff * soft)
    if act is not None and act[5].shape[0] > 0:
        for j in range(arm[1].size):
            C, k = arm[2][j], act[6][j, 2] * loads[j, _CT]
            shear = max(C[1, 1], C[2, 2])
            bending = max(C[4, 4], C[5, 5])
            kl = max(kl, arm[6] * max(math.sqrt(k * shear), (k * bending) ** 0.25))
            if act[6][j, ZONE] > 0.0:  # a hard contact zone: rates ±1/ℓ, ℓ = √(EI/GA)
                kl = max(kl, arm[6] * math.sqrt(bending / shear))
    return kl


@_jit
def _chunk_table(arm, M, out):
    """Cut [0, L] at the interval starts i L / M and at the piece starts: out[c] = (piece,
    start, length, starts its piece, interval); returns (chunks, first chunk of each
    interval (M + 1,))."""
    piece_start, piece_len, length = arm[0], arm[1], arm[6]
    first = np.empty(M + 1, dtype=np.int64)
    c = 0
    for i in range(M):
        first[i] = c
        a = length * i / M
        b = length if i == M - 1 else length * (i + 1) / M
        for j in range(piece_len.size):
            s0 = piece_start[j]
            s1 = s0 + piece_len[j] if j < piece_len.size - 1 else length
            lo, hi = max(a, s0), min(b, s1)
            if hi > lo or (j == 0 and i == 0 and hi >= lo):
                out[c, _CJ] = j
                out[c, _CS] = lo
                out[c, _CL] = hi - lo
                out[c, _CFIRST] = 1.0 if lo == s0 else 0.0
                out[c, _CI] = i
                c += 1
    first[M] = c
    return c, first


@_jit
def _chunk_steps(chunks, nc, length, N, factor, mult, out):
    """Steps per chunk for a nominal N over the arm (at least one), times ``factor`` and its
    interval's multiplier ``mult[i]`` (the intervals refined for their local error)."""
    for c in range(nc):
        out[c] = factor * mult[int(chunks[c, _CI])] * max(
            1, math.floor(N * chunks[c, _CL] / length + 0.5))


@_jit
def _run_chunks(y, T, nt, c0, c1, chunks, csteps, arm, act, rate, scratch):
    """Integrate the chunks c0..c1-1 in place (state and the first nt tangent columns),
    with the point wrench at the start of every chunk that starts its piece."""
    work, twork, now, law = scratch[2], scratch[3], scratch[4], scratch[8]
    for c in range(c0, c1):
        j = int(chunks[c, _CJ])
        if chunks[c, _CFIRST] > 0.0:
            _jump(y, T, nt, now, rate, j, arm, act, law)
        n = csteps[c]
        _steps(y, T, nt, chunks[c, _CL] / n, chunks[c, _CS], n, arm, act, j, now, rate, work,
               twork, law)


@_jit
def _node_start(y, T, nt, Z, i):
    """The state at node i (Z[i]: p, R, n, m) and the tangents' initial values (columns 0-5
    δ(n; m), 6 the load factor (0), 7-9 δp, 10-12 δθ)."""
    for a in range(18):
        y[a] = Z[i, a]
    for a in range(18, y.size):
        y[a] = 0.0
    for d in range(nt):
        for a in range(T.shape[1]):
            T[d, a] = 0.0
    for d in range(min(nt, 6)):
        T[d, _TN + d] = 1.0
    for d in range(3):
        if nt > 7 + d:
            T[7 + d, _TP + d] = 1.0
            T[10 + d, _TT + d] = 1.0


@_jit
def _rotation_mismatch(Ra, y, A, out):
    """A = Raᵀ R (R: y's rotation), out = vee(skew A) (zero where R = Ra; near it the
    material rotation from Ra to R)."""
    for a in range(3):
        for b in range(3):
            acc = 0.0
            for k in range(3):
                acc += Ra[_R + 3 * k + a] * y[_R + 3 * k + b]
            A[a, b] = acc
    out[0] = 0.5 * (A[2, 1] - A[1, 2])
    out[1] = 0.5 * (A[0, 2] - A[2, 0])
    out[2] = 0.5 * (A[1, 0] - A[0, 1])


@_jit
def _unknown(i, d):
    """The unknown index of tangent column d (not 6) of the interval from node i."""
    if i == 0:
        return d
    return 6 + 12 * (i - 1) + (d if d < 6 else d - 1)


@_jit
def _band_set(B, row, col, value):
    B[row, col - row + _BAND] = value


@_jit
def _ms_evaluate(x, Z, M, lam, nt, chunks, first, csteps, base, arm, act, case, scratch,
                 colscale, rowscale, F, B, G, ends, lengths, Gq):
    """Integrate every interval at load factor λ: the scaled residual F (n), and with
    tangents (nt > 0) the scaled Jacobian in band storage B (n, 3 _BAND + 1) and its load
    factor column G (n). ``ends``: each interval's end state (M, width), for the tip and the
    output. Returns the scaled residual's largest component. ``lengths``: the tendons'
    lengths summed over the intervals. ``Gq``: None, or (n, inputs) the scaled residual's
    derivatives by the inputs (tangent columns _COLS.. along the case's rate rows 7..: every
    interval then integrates nt = _COLS + inputs columns, the first one's node columns
    unused)."""
    y, T = scratch[0], scratch[1]
    rate, tip_rate = case[1], case[3]
    now, tip_now, law = scratch[4], scratch[5], scratch[8]
    _set_loads(lam, case, now, tip_now)
    n = 12 * M - 6
    if nt > 0:
        for r_ in range(n):
            G[r_] = 0.0
            for c in range(B.shape[1]):
                B[r_, c] = 0.0
    A = np.empty((3, 3))
    mis = np.empty(3)
    J = np.empty((6, max(nt, _COLS)))
    r6 = np.empty(6)
    if Gq is not None:
        for r_ in range(n):
            for c in range(Gq.shape[1]):
                Gq[r_, c] = 0.0
    for a in range(lengths.size):
        lengths[a] = 0.0
    worst = 0.0
    for i in range(M):
        ni = 0 if nt == 0 else (7 if i == 0 else _COLS)
        if Gq is not None:
            ni = nt
        if i == 0:
            _start(y, T, ni, base, x)
        else:
            _node_start(y, T, ni, Z, i)
        _run_chunks(y, T, ni, first[i], first[i + 1], chunks, csteps, arm, act, rate, scratch)
        for a in range(y.size):
            ends[i, a] = y[a]
        for a in range(lengths.size):
            lengths[a] += y[18 + a]
        if i < M - 1:
            row = 12 * i
            _rotation_mismatch(Z[i + 1], y, A, mis)
            for k in range(3):
                F[row + k] = (y[_P + k] - Z[i + 1, _P + k]) / rowscale[row + k]
                F[row + 3 + k] = mis[k]
                F[row + 6 + k] = (y[_N + k] - Z[i + 1, _N + k]) / rowscale[row + 6 + k]
                F[row + 9 + k] = (y[_M + k] - Z[i + 1, _M + k]) / rowscale[row + 9 + k]
            for k in range(12):
                worst = max(worst, abs(F[row + k])) if math.isfinite(F[row + k]) else np.inf
            if nt == 0:
                continue
            trace = A[0, 0] + A[1, 1] + A[2, 2]
            for d in range(ni):
                t = T[d]
                if d == LAM:
                    for k in range(12):
                        G[row + k] = 0.0
                    for k in range(3):
                        G[row + k] = t[_TP + k] / rowscale[row + k]
                        G[row + 3 + k] = 0.5 * (trace * t[_TT + k] - A[k, 0] * t[_TT]
                                                - A[k, 1] * t[_TT + 1] - A[k, 2] * t[_TT + 2])
                        G[row + 6 + k] = t[_TN + k] / rowscale[row + 6 + k]
                        G[row + 9 + k] = t[_TM + k] / rowscale[row + 9 + k]
                    continue
                if Gq is not None and d >= _COLS:  # an input's column
                    for k in range(3):
                        Gq[row + k, d - _COLS] = t[_TP + k] / rowscale[row + k]
                        Gq[row + 3 + k, d - _COLS] = 0.5 * (
                            trace * t[_TT + k] - A[k, 0] * t[_TT] - A[k, 1] * t[_TT + 1]
                            - A[k, 2] * t[_TT + 2])
                        Gq[row + 6 + k, d - _COLS] = t[_TN + k] / rowscale[row + 6 + k]
                        Gq[row + 9 + k, d - _COLS] = t[_TM + k] / rowscale[row + 9 + k]
                    continue
                if i == 0 and d > LAM:  # (the base's interval has no node columns)
                    continue
                col = _unknown(i, d)
                cs = colscale[col]
                for k in range(3):
                    _band_set(B, row + k, col, t[_TP + k] / rowscale[row + k] * cs)
                    _band_set(B, row + 3 + k, col, 0.5 * cs * (
                        trace * t[_TT + k] - A[k, 0] * t[_TT] - A[k, 1] * t[_TT + 1]
                        - A[k, 2] * t[_TT + 2]))
                    _band_set(B, row + 6 + k, col, t[_TN + k] / rowscale[row + 6 + k] * cs)
                    _band_set(B, row + 9 + k, col, t[_TM + k] / rowscale[row + 9 + k] * cs)
            # the next node's own columns: -1 on p, n, m; -(tr A I - Aᵀ)/2 on θ
            nxt = 6 + 12 * i
            for k in range(3):
                _band_set(B, row + k, nxt + 6 + k, -colscale[nxt + 6 + k] / rowscale[row + k])
                _band_set(B, row + 6 + k, nxt + k, -colscale[nxt + k] / rowscale[row + 6 + k])
                _band_set(B, row + 9 + k, nxt + 3 + k,
                          -colscale[nxt + 3 + k] / rowscale[row + 9 + k])
                for m in range(3):
                    v = -0.5 * ((trace if k == m else 0.0) - A[m, k])
                    _band_set(B, row + 3 + k, nxt + 9 + m, v * colscale[nxt + 9 + m])
        else:
            _tip_residual(y, T, ni, tip_now, tip_rate, r6, J, arm, act, now, rate, law)
            row = 12 * (M - 1)
            for k in range(6):
                F[row + k] = r6[k] / rowscale[row + k]
                worst = max(worst, abs(F[row + k])) if math.isfinite(F[row + k]) else np.inf
            if nt == 0:
                continue
            for d in range(ni):
                for k in range(6):
                    if d == LAM:
                        G[row + k] = J[k, d] / rowscale[row + k]
                    elif Gq is not None and d >= _COLS:
                        Gq[row + k, d - _COLS] = J[k, d] / rowscale[row + k]
                    elif i == 0 and d > LAM:
                        continue
                    else:
                        col = _unknown(i, d)
                        _band_set(B, row + k, col, J[k, d] / rowscale[row + k] * colscale[col])
    return worst


@_jit
def _ms_apply(x, Z, M, du, colscale, sign):
    """x, Z += sign × du (scaled unknowns): forces and positions added, node rotations
    R ← R exp(δθ~) (material)."""
    for k in range(6):
        x[k] += sign * du[k] * colscale[k]
    before = np.empty(Z.shape[1])
    for i in range(1, M):
        o = 6 + 12 * (i - 1)
        for k in range(3):
            Z[i, _N + k] += sign * du[o + k] * colscale[o + k]
            Z[i, _M + k] += sign * du[o + 3 + k] * colscale[o + 3 + k]
            Z[i, _P + k] += sign * du[o + 6 + k] * colscale[o + 6 + k]
        _copy(Z[i], before)
        _rotated(before, sign * du[o + 9] * colscale[o + 9], sign * du[o + 10] * colscale[o + 10],
                 sign * du[o + 11] * colscale[o + 11], Z[i])


@_jit
def _ms_motion(T, M, du, colscale, lam_rate, out):
    """The tip's displacement (out[0:3]) and rotation (out[3:6], material) for the scaled
    change du of the unknowns, from the last interval's tangents T (and ``lam_rate`` times
    its load-factor column)."""
    nt = 7 if M == 1 else _COLS
    for k in range(3):
        acc_p = lam_rate * T[LAM, _TP + k]
        acc_t = lam_rate * T[LAM, _TT + k]
        for d in range(nt):
            if d == LAM:
                continue
            col = _unknown(M - 1, d)
            acc_p += T[d, _TP + k] * du[col] * colscale[col]
            acc_t += T[d, _TT + k] * du[col] * colscale[col]
        out[k] = acc_p
        out[3 + k] = acc_t


@_jit
def _ms_distance(du, n, T, M, colscale, w, length, motion):
    """The size of a scaled change du of the unknowns: as single shooting measures it
    (:func:`_distance`), the largest of the base reaction's change relative to the case's
    load size 1 + w and of the tip motion it causes (L, rad), and the interior nodes'
    changes at a fifth of their weight (forces relative to 1 + w, positions in L, angles in
    rad). Under a hard oblique pull the clamp's boundary layer sweeps past node after node as
    k grows like √λ, turning each by up to the pull's angle: at full weight those turns held
    the path to 300 steps at kL = 1e4; without them it jumped to an arm wound the wrong way
    round (a node turning by more than π in one step)."""
    out = 0.0
    for k in range(n):
        force = k < 6 or (k - 6) % 12 < 6
        size = abs(du[k]) / (1.0 + w) if force else abs(du[k])
        out = max(out, size if k < 6 else _NODE_WEIGHT * size)
    _ms_motion(T, M, du, colscale, 0.0, motion)
    for k in range(6):
        out = max(out, abs(motion[k]) / (length if k < 3 else 1.0))
    if not math.isfinite(out):
        return np.inf
    return out


@_jit
def _ms_corrector(x, Z, M, lam, nt, chunks, first, csteps, base, arm, act, case, scratch, colscale,
                  rowscale, work, w, length, threshold, max_iterations, first_limit, loose, tip,
                  counter):
    """Newton at fixed λ on the block system from the prediction (x, Z), with
    :func:`_corrector`'s tests (the first step within ``first_limit``, every further one at
    most half the one before, converged at the threshold or at a step no larger than
    ``loose``, taken without integrating again). On success the band matrix holds the
    factors of the Jacobian at the last point integrated (for the tangent and det's sign),
    returned as (True, sign, the distance travelled); ``tip`` the tip position."""
    F, B, G, ends, lengths, piv, Lm, du, motion = work
    n = 12 * M - 6
    previous = np.inf
    travelled = 0.0
    for k in range(max_iterations + 1):
        res = _ms_evaluate(x, Z, M, lam, nt, chunks, first, csteps, base, arm, act, case, scratch,
                           colscale, rowscale, F, B, G, ends, lengths, None)
        counter[0] += 1
        for i in range(3):
            tip[i] = ends[M - 1, _P + i]
        if not math.isfinite(res):
            return False, 0.0, travelled
        sign = _band_factor(B, n, np.int64(_BAND), piv, Lm)
        if res <= threshold:
            return sign != 0.0, sign, travelled
        if k == max_iterations or sign == 0.0:
            return False, 0.0, travelled
        for i in range(n):
            du[i] = -F[i]
        if not _band_solve(B, n, np.int64(_BAND), piv, Lm, du):
            return False, 0.0, travelled
        size = _ms_distance(du, n, scratch[1], M, colscale, w, length, motion)
        if k == 0:
            if size > first_limit:
                return False, 0.0, travelled
        elif size > (_CONTRACTION_MAX if act is None or act[5].shape[0] == 0
                     else _CONTRACTION_CONTACT) * previous:
            return res <= _STALL * threshold, sign, travelled
        previous = size
        travelled += size
        if travelled > first_limit:
            return False, 0.0, travelled
        _ms_apply(x, Z, M, du, colscale, 1.0)
        if size <= loose:
            for i in range(3):
                tip[i] += motion[i]
            return True, sign, travelled
    return False, 0.0, travelled


@_jit
def _loose(act, length):
    """The corrector's tolerance on the way (a step no larger ends it): _LOOSE, or with
    contact a tenth of the thinnest contact distance (over L): a point on the way left
    _LOOSE L from the path lies far outside the band, and the next corrector, started
    there, does not find its way back into it."""
    loose = _LOOSE
    if act is not None and act[5].shape[0] > 0:
        for j in range(act[6].shape[0]):
            loose = min(loose, 0.1 * act[6][j, 1] / length)
    return loose


@_jit
def _ms_condensed(B, n, piv, Lm, v, P):
    """P (6 × 6): the block of B⁻¹ from the tip residual's rows to the base reaction's
    columns, i.e. the inverse of ∂r/∂x condensed onto the base reaction (single shooting's
    Jacobian, in the band's scaled units), by six band solves with B's factors. False if
    they fail. (Its eigenvalues' ratios between two points are the branch guard's
    :func:`_crossings`; formed only where the arm is not in strong tension, whose growing
    Jacobi fields make it ill-conditioned.)"""
    for k in range(6):
        for i in range(n):
            v[i] = 0.0
        v[n - 6 + k] = 1.0
        if not _band_solve(B, n, np.int64(_BAND), piv, Lm, v):
            return False
        for i in range(6):
            P[i, k] = v[i]
    return True


@_jit
def _ms_follow(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, colscale, rowscale,
               work, w, length, threshold, max_iterations, max_load_step, max_shootings, final,
               tip, counter, reached, lam0, end):
    """:func:`_follow` on the block system: the path from λ = lam0 (x, Z: the solution there,
    exact or close) to λ = ``end``, predicted along the tangent -J⁻¹ ∂F/∂λ, corrected by
    :func:`_ms_corrector`, with the same step control and branch guards: the sign of the
    whole banded Jacobian's determinant, the tip's direction of motion and, while the
    path's phase is at most _PHASE_TESTED (:func:`_phase`), the crossings of the condensed
    Jacobian (:func:`_ms_condensed`) and the phase's advance per step. True on success
    (x, Z at λ = end, the band factors there); else reached[0] is the last load factor
    reached."""
    B, G, piv, Lm, du, motion = work[1], work[2], work[5], work[6], work[7], work[8]
    n = 12 * M - 6
    nt = M - M + _COLS  # (a variable: one compiled version of the callees)
    reached[0] = lam0
    ok, sign, dist = _ms_corrector(x, Z, M, lam0, nt, chunks, first, csteps, base, arm, act, case,
                             scratch, colscale, rowscale, work, w, length, threshold,
                             max_iterations, _REFINE_MAX, _LOOSE, tip, counter)
    if not ok:
        return False
    bounds = np.empty(7)
    _path_bounds(arm, act, case, arm[7], bounds)
    touching = act is not None and act[5].shape[0] > 0
    guard = _guard_work()
    P_prev = np.empty((6, 6))
    P_new = np.empty((6, 6))
    v = np.empty(n)
    tested = (not touching and _phase(bounds, lam0) <= _PHASE_TESTED
              and _ms_condensed(B, n, piv, Lm, v, P_prev))
    t = np.empty(n)
    for i in range(n):
        t[i] = -G[i]
    if not _band_solve(B, n, np.int64(_BAND), piv, Lm, t):
        return False
    reached[1] = sign
    x_keep = np.empty(6)
    Z_keep = np.empty_like(Z)
    motion_prev = np.empty(6)
    motion_new = np.empty(6)
    _ms_motion(scratch[1], M, t, colscale, 1.0, motion_prev)
    moved = np.empty(n)
    lam = lam0
    loose = _loose(act, length)
    size = _ms_distance(t, n, scratch[1], M, colscale, w, length, motion)
    dl = max_load_step if size <= 0.0 else min(max_load_step, _FIRST_MOTION / size)
    while lam < end:
        if counter[0] > max_shootings:
            return False
        dl, target = _load_step(lam, dl if touching else _phase_limited(bounds, lam, dl), end)
        _copy(x, x_keep)
        _copy(Z, Z_keep)
        for i in range(n):
            moved[i] = (target - lam) * t[i]
        _ms_apply(x, Z, M, moved, colscale, 1.0)
        ok, new_sign, dist = _ms_corrector(x, Z, M, target, nt, chunks, first, csteps, base,
                                           arm, act, case, scratch, colscale, rowscale, work, w,
                                           length, threshold, max_iterations, _DIST_MAX,
                                           final if target == 1.0 else loose, tip, counter)
        if ok:
            for i in range(n):
                du[i] = -G[i]
            ok = _band_solve(B, n, np.int64(_BAND), piv, Lm, du)
        check = False  # the condensed Jacobian's crossings: only where it is well conditioned
        if ok:
            check = (tested and _phase(bounds, target) <= _PHASE_TESTED
                     and _ms_condensed(B, n, piv, Lm, v, P_new))
            _ms_motion(scratch[1], M, du, colscale, 1.0, motion_new)
            crossing = new_sign != sign or (
                check and _crossings(P_new, P_prev, np.int64(6), guard[2], guard[3], 0.0) != 0)
            # (with contact the tip turns where it touches: only det's sign guards)
            ok = dl <= (_DLAM_CROSS_CONTACT if touching else _cross_step(bounds, lam)) or (
                not crossing and (_cosine(motion_prev, motion_new) >= 0.5 or touching))
        if ok:
            sign = new_sign
            reached[1] = sign
            tested = check
            if check:
                _copy(P_new, P_prev)
            for i in range(3):
                motion_prev[i] = motion_new[i]
            # (dist: the corrector's distance from the prediction, the step control's measure)
            for i in range(n):
                t[i] = du[i]
            lam = target
            reached[0] = lam
            dl = _grown(dl, dist, max_load_step)
        else:
            _copy(x_keep, x)
            _copy(Z_keep, Z)
            dl *= 0.4
            if dl < min(_DLAM_MIN_STIFF, _smallest_step(bounds, lam)):
                return False
    return True


@_jit
def _ms_grid(arm, M, width):
    """The block system's grid with M intervals: (chunks, their count, each interval's first
    chunk, steps per chunk, work arrays, column scales, row scales)."""
    length, scale = arm[6], arm[7]
    chunks = np.empty((M + arm[1].size, 5))
    nc, first = _chunk_table(arm, M, chunks)
    n = 12 * M - 6
    colscale = np.empty(n)
    rowscale = np.empty(n)
    for k in range(6):
        colscale[k] = scale[k]
    for i in range(1, M):
        o = 6 + 12 * (i - 1)
        for k in range(6):
            colscale[o + k] = scale[k]
            colscale[o + 6 + k] = length if k < 3 else 1.0
    for i in range(M - 1):  # rows p, θ, n, m of join i
        o = 12 * i
        for k in range(3):
            rowscale[o + k] = length
            rowscale[o + 3 + k] = 1.0
            rowscale[o + 6 + k] = scale[k]
            rowscale[o + 9 + k] = scale[3 + k]
    for k in range(6):
        rowscale[n - 6 + k] = scale[k]
    return (chunks, nc, first, np.empty(nc, dtype=np.int64), _ms_work(M, width), colscale,
            rowscale)


@_jit
def _ms_fill_nodes(x, coarse, ratio, Z, M, chunks, first, csteps, base, arm, act, case,
                   scratch, lam):
    """The nodes Z (M) of a grid ``ratio`` times finer than a solution's (base reaction x,
    nodes ``coarse``) at load factor lam, to be corrected there: the coarse nodes where they
    fall (every ratio-th), the states between integrated from them on this grid (with ratio
    0, every node integrated from the clamp)."""
    y, T = scratch[0], scratch[1]
    none = M - M
    _set_loads(lam, case, scratch[4], scratch[5])
    _start(y, T, none, base, x)
    for i in range(M):
        if i > 0:
            if ratio > 0 and i % ratio == 0:
                _copy(coarse[i // ratio], y)
            _copy(y, Z[i])
        _run_chunks(y, T, none, first[i], first[i + 1], chunks, csteps, arm, act, case[1],
                    scratch)


@_jit
def _ms_path(x, Z, M, levels, kl, N, n_fixed, arm, act, base, case, scratch, w, threshold,
             max_iterations, max_load_step, budget, final_step, tip, counter, reached, chunks,
             first, csteps, work, colscale, rowscale):
    """The loading path from the unloaded arm to λ = 1 on the final grid (M intervals,
    ``csteps`` at N), in levels: k grows like √λ, so the path runs on M / 2^levels
    intervals and proportionally fewer steps while k√λ L <= _GROWTH times their number,
    then on four times as many, each finer grid's nodes the coarser's plus the states
    between (integrated on the finer grid from the coarser nodes, :func:`_ms_fill_nodes`,
    then corrected at that λ). The
    early load steps, most of the path's, cost a fraction of the last ones'. True on success,
    x and Z the solution at λ = 1 on the final grid (its band factors in ``work``)."""
    length = arm[6]
    y = scratch[0]
    lam = 0.0
    for k in range(6):
        x[k] = 0.0
    prev_Z = np.zeros((1, y.size))
    prev_M = 0
    for level in range(levels, -1, -1):
        Ml = M >> (_LEVEL * level)
        final = level == 0
        end = 1.0 if final or not kl > 0.0 else min(1.0, (_GROWTH * Ml / kl) ** 2)
        if final:
            g_chunks, g_first, g_csteps, g_work = chunks, first, csteps, work
            g_colscale, g_rowscale, Zl = colscale, rowscale, Z
        else:
            g_chunks, nc, g_first, g_csteps, g_work, g_colscale, g_rowscale = _ms_grid(
                arm, Ml, y.size)
            Zl = np.zeros((Ml, y.size))
            # steps in proportion to k at the level's end (N is the final grid's)
            Nl = N if n_fixed > 0 else max(nc, math.ceil(N * math.sqrt(end)))
            _chunk_steps(g_chunks, nc, length, Nl, np.int64(1), np.ones(Ml, dtype=np.int64),
                         g_csteps)
        # the nodes: the coarser level's (every fourth one) and the states between them,
        # integrated from those; on the first level the unloaded arm's (x = 0, λ = 0)
        _ms_fill_nodes(x, prev_Z, (1 << _LEVEL) if prev_M > 0 else 0, Zl, Ml, g_chunks,
                       g_first, g_csteps, base, arm, act, case, scratch, lam)
        if not _ms_follow(x, Zl, Ml, g_chunks, g_first, g_csteps, base, arm, act, case, scratch,
                          g_colscale, g_rowscale, g_work, w, length, threshold, max_iterations,
                          max_load_step, budget, final_step if final else _loose(act, length),
                          tip, counter,
                          reached, lam, end):
            return False
        lam = end
        if final:
            return True
        prev_Z = Zl
        prev_M = Ml
    return True


@_jit
def _ms_chord(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, colscale, rowscale,
              work, threshold, max_iterations, tip, counter):
    """The solution at λ = 1 on another grid by chord iterations from (x, Z) with the band
    factors left in ``work`` (a nearby grid's): :func:`_chord`'s tests (the first step a
    discretisation-sized change, the residual at least halved every iteration, a stall
    accepted at ``_STALL`` times the threshold). True if converged."""
    F, B, G, ends, lengths, piv, Lm, du = work[:8]
    n = 12 * M - 6
    none = M - M  # no tangents (a variable: one compiled version)
    previous = np.inf
    for _ in range(max_iterations):
        res = _ms_evaluate(x, Z, M, 1.0, none, chunks, first, csteps, base, arm, act, case,
                           scratch, colscale, rowscale, F, B, G, ends, lengths, None)
        counter[0] += 1
        for i in range(3):
            tip[i] = ends[M - 1, _P + i]
        if res <= threshold:
            return True
        if not res < 0.5 * previous:
            return res <= _STALL * threshold
        for i in range(n):
            du[i] = -F[i]
        if not _band_solve(B, n, np.int64(_BAND), piv, Lm, du):
            return False
        if not math.isfinite(previous):
            size = 0.0
            for i in range(n):
                size = max(size, abs(du[i]))
            if not size <= _REFINE_MAX:
                return False
        previous = res
        _ms_apply(x, Z, M, du, colscale, 1.0)
    return False


@_jit
def _ms_record(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, s_out, out, b,
               states, sens):
    """The output pass of the solution (x, Z) at λ = 1: each interval integrated from its
    start once more, and every station written (a station inside a step: the RK4 step from
    that step's start to the station; the tip station from the tip state). With ``states``
    (not None), the state itself at each station s_out instead (the stability sweep's grid).
    With ``sens`` (not None: (U, colscale, nt), :func:`_ms_sensitivities`), the tangents
    too (nt columns), and each station's compliance and actuation Jacobian into out[6][b],
    the tendons' lengths' into out[5][b] rows 6.. (:func:`_ms_motion_rows`)."""
    y, T, work, twork, now, tip_now, ys, Ts, law = scratch
    poses, strains, stresses, E = out[0][b], out[1][b], out[2][b], out[6][0]
    rate = case[1]
    one = np.int64(1)
    none = one - one
    nt = none if sens is None else sens[2]
    _set_loads(1.0, case, now, tip_now)
    ns = s_out.size
    k = 0
    lengths = out[8]
    for a in range(lengths.shape[1]):
        if states is None:
            lengths[b, a] = 0.0
    if sens is not None:
        for r_ in range(6, out[5].shape[1]):
            for c in range(out[5].shape[2]):
                out[5][b, r_, c] = 0.0
    for i in range(M):
        if i == 0:
            _start(y, T, nt, base, x)
        else:
            _node_start(y, T, nt, Z, i)
        for c in range(first[i], first[i + 1]):
            j = int(chunks[c, _CJ])
            if chunks[c, _CFIRST] > 0.0:
                _jump(y, T, nt, now, rate, j, arm, act, law)
            n = csteps[c]
            h = chunks[c, _CL] / n
            s0 = chunks[c, _CS]
            step = 0
            while step < n:
                run = n - step
                if k < ns:
                    run = min(run, max(int((s_out[k] - s0) / h) - 1 - step, 0))
                if run > 0:
                    _steps(y, T, nt, h, s0 + step * h, run, arm, act, j, now, rate, work,
                           twork, law)
                    step += run
                    continue
                t0 = s0 + step * h
                t1 = s0 + (step + 1) * h
                last = i == M - 1 and c == first[M] - 1 and step == n - 1
                while k < ns and s_out[k] < t1 and not (last and s_out[k] >= arm[6]):
                    _copy(y, ys)
                    _copy(T, Ts)
                    _steps(ys, Ts, nt, s_out[k] - t0, t0, one, arm, act, j, now, rate, work,
                           twork, law)
                    if states is not None:
                        _copy(ys, states[k])
                    else:
                        _write(ys, Ts, none, j, s_out[k], arm, act, now, law, poses[k],
                               strains[k], stresses[k], E[0])
                        if sens is not None:
                            _ms_motion_rows(ys, Ts, i, sens, out[6][b][k], np.int64(6))
                    k += 1
                _steps(y, T, nt, h, t0, one, arm, act, j, now, rate, work, twork, law)
                step += 1
        for a in range(lengths.shape[1]):
            if states is None:
                lengths[b, a] += y[18 + a]
        if sens is not None and out[5].shape[1] > 6:
            _ms_motion_rows(y, T, i, sens, out[5][b], -np.int64(6))
    for i in range(k, ns):
        if states is not None:
            _copy(y, states[i])
        else:
            _write(y, T, none, arm[1].size - 1, arm[6], arm, act, now, law, poses[i],
                   strains[i], stresses[i], E[0])
            if sens is not None:
                _ms_motion_rows(y, T, M - 1, sens, out[6][b][i], np.int64(6))
    if states is None:
        for i in range(6):
            out[7][b, i] = x[i]


@_jit
def _ms_motion_rows(y, T, i, sens, rows, which):
    """With the tangents T of interval i at a point: ``which`` = 6, the point's motion
    (δp; δθ spatial) per tip wrench and per input into rows (6, 6 + n), written; ``which``
    = -6, the tendons' lengths' (T's columns NT.., the interval's share) added into rows
    6.. of rows (6 + A, 6 + n). Through the unknowns' sensitivities U (scaled, per tip
    wrench component, then per input): Σ_d T[d] colscale U[unknown(i, d)], plus an input's
    own column."""
    U, colscale, nt = sens
    m = U.shape[1]
    count = 6 if which > 0 else T.shape[1] - NT
    for r_ in range(count):
        for c in range(m):
            acc = 0.0
            for d in range(min(nt, _COLS)):
                if d == LAM or (i == 0 and d > LAM):
                    continue
                col = _unknown(i, d)
                acc += _motion_entry(y, T, d, r_, which) * colscale[col] * U[col, c]
            if c >= 6:
                acc += _motion_entry(y, T, _COLS + c - 6, r_, which)
            if which > 0:
                rows[r_, c] = acc
            else:
                rows[6 + r_, c] += acc


@_jit
def _motion_entry(y, T, d, r_, which):
    """Row r_ of tangent column d: δp (r_ < 3) or δθ in spatial components (which = 6), or
    tendon r_'s length (which = -6)."""
    if which < 0:
        return T[d, NT + r_]
    if r_ < 3:
        return T[d, _TP + r_]
    i = r_ - 3
    return (y[_R + 3 * i] * T[d, _TT] + y[_R + 3 * i + 1] * T[d, _TT + 1]
            + y[_R + 3 * i + 2] * T[d, _TT + 2])


@_jit
def _ms_work(M, width):
    """Work arrays of the block system with M intervals: F, the band B, G, the interval end
    states, the tendons' lengths, pivots (and extents: _band_factor), multipliers, a step, a
    motion."""
    n = 12 * M - 6
    return (np.empty(n), np.empty((n, 3 * _BAND + 1)), np.empty(n), np.empty((M, width)),
            np.empty(width - 18), np.empty((3, n), dtype=np.int64), np.empty((n, _BAND)),
            np.empty(n), np.empty(6))


def _stiff_capability(args):
    key, text = _per_arm("stiff", "the multiple-shooting solver (stiff problems)", 2)(args)
    if _given(args[8]):
        key, text = key + "+jacobians", text + " with Jacobians"
    if _given(args[7]):
        key, text = key + "+verdict", text + " and its stability verdict"
    return key, text


@_entry(_stiff_capability, nogil=True)
def solve_stiff_cases(base, arm, act, loads, options, s_out, out, verdicts, inputs, chain):
    """Solve every load case of a flattened batch by multiple shooting, each from the
    unloaded arm (λ = 0) along its own loading path (the stiff route of
    :func:`solve_cases`: the same arguments where they exist, the same outputs), or, with
    ``chain`` on, from the last solution the chain holds (a chained Solver's quasi-static
    path: solver.py's ``_StiffChain``, docs/solver.md "Chained solves").

    The stages follow solve_cases': the path (in levels of intervals, :func:`_ms_path`),
    the solution at 2N (chord iterations with the factors at N, else Newton), the
    Richardson estimate |p_2N - p_N| / 15 times _STIFF_SAFETY against tol, the steps grown
    by the order-4 model until it is met (in the intervals whose local error calls for it,
    :func:`_ms_local_errors`; with one interval, N itself), the output pass. The intervals
    (kL/M <= _GROWTH, k from the case's load size) and their cut by the pieces are fixed per
    case; N spreads over them as over the arm.

    ``verdicts``: None, or (index (B,), conservative (B,)): each solved case's stability
    verdict (:func:`stability_cases`' Morse index on the grid of N steps per piece, its
    sweep taking the state at every grid point from this solution instead of integrating it
    backwards, where it would grow like e^{kL}). ``inputs``: None, or as solve_cases'
    (Jacobians): the compliances and actuation Jacobians by the implicit function theorem on
    the block system (:func:`_ms_sensitivities`), in solve_cases' outputs after its
    :func:`_implicit_function`. ``chain``: (x (6,), Z (cap, 18 + actuators), mult (cap,)
    int64, meta (4,), piece (pieces, width), tip (TIP_LOADS,)); meta[0] is 0 (off: neither
    read nor written), 1 (on, holding nothing) or 2 (holding a solution: meta[1] its M,
    meta[2] its N, meta[3] its error estimate, x, Z[:M] and mult[:M] its nodes on N steps,
    piece and tip its loads). A chain on holds each case's solution for the next (the
    batch is one path) and nothing after a case that failed.
    """
    piece_loads, tip_loads = loads
    nb = piece_loads.shape[0]
    npieces = arm[1].size
    length = arm[6]
    scale = arm[7]
    tol, max_iterations, max_load_step, n_fixed, n_max, budget = _read_options(options)
    info, status = out[3], out[4]
    width = piece_loads.shape[2]
    scratch = _scratch(npieces, width - PIECE_LOADS, _COLS)
    start = np.zeros((npieces, width))
    rate = np.zeros((7, npieces, width))  # rows 1-6: zero (the node columns 7-12)
    tip_start = np.zeros(TIP_LOADS)
    tip_rate = np.zeros((7, TIP_LOADS))
    case = (start, rate, tip_start, tip_rate)
    final_step = min(1e-3, math.sqrt(0.01 * tol / length)) if math.isfinite(tol) else 1e-9
    reached = np.zeros(2)
    counter = np.zeros(1, dtype=np.int64)
    x = np.zeros(6)
    x_f = np.zeros(6)
    tip_c = np.empty(3)
    tip_f = np.empty(3)
    y = scratch[0]
    chain_x, chain_Z, chain_mult, chain_meta, chain_piece, chain_tip = chain
    chained = chain_meta[0] > 0.0 and chain_Z.shape[1] == y.size and \
        chain_piece.shape[0] == npieces and chain_piece.shape[1] == width
    for b in range(nb):
        # from the chain's last solution when it holds one; a cold start if that fails
        warm = chained and chain_meta[0] == 2.0
        again = True
        while again:
            again = False
            counter[0] = 0
            for j in range(npieces):
                for i in range(width):
                    start[j, i] = chain_piece[j, i] if warm else 0.0
                    rate[0, j, i] = piece_loads[b, j, i] - start[j, i]
            for i in range(TIP_LOADS):
                tip_start[i] = chain_tip[i] if warm else 0.0
                tip_rate[0, i] = tip_loads[b, i] - tip_start[i]
            w, turning = _load_size(arm, act, scale, start, piece_loads[b], tip_start,
                                    tip_loads[b])
            threshold = 1e-12 * w + 1e-300
            kl = _stiffness_size(arm, act, w, piece_loads[b])
            # M = M_base 2^levels >= kL / _GROWTH (within 25 %): the path's levels halve it
            needed = max(1, min(math.ceil(kl / _GROWTH), n_max // 4))
            levels = 0
            while (needed >> (_LEVEL * (levels + 1))) >= 4:
                levels += 1
            M = ((needed + (1 << (_LEVEL * levels)) - 1) >> (_LEVEL * levels)) \
                << (_LEVEL * levels)
            ratio = 1  # a warm start's intervals per interval of the chain's grid
            if warm:
                # the chain's grid, on which its nodes were solved, or where the loads
                # stiffen past it (a raised penalty), that grid refined the fewest times
                # that hold them; a cold start where that is over twice the cold grid
                # (measured: refined 4 times at once, an inverse solve's raised penalties
                # took the finger's grid from 48 intervals to 3072) or the chain's grid is
                # over 8 times it (loads that soften: each shooting costs as many more)
                held = int(chain_meta[1])
                ratio = max(1, (needed + held - 1) // held)
                if held * ratio > 2 * M or held > 8 * M or held * ratio > n_max // 4 or \
                        held * ratio > chain_Z.shape[0]:
                    warm = False
                    again = True
                    continue
                M = held * ratio
                levels = 0
            chunks, nc, first, csteps, work, colscale, rowscale = _ms_grid(arm, M, y.size)
            n = 12 * M - 6
            Z = np.zeros((M, y.size))
            Z_f = np.zeros((M, y.size))
            mult = np.ones(M, dtype=np.int64)
            local = np.empty(M)
            if n_fixed > 0:
                N = n_fixed // 2
            else:
                N = max(_first_steps(arm, tol, turning), math.ceil(_STIFF_STEPS * kl))
            N = min(N, n_max // 2)
            path = True
            if warm:
                if n_fixed == 0:
                    # the chain's steps, half as many where its estimate allowed it (order
                    # 4: 16 times the error): a zone that moves on needs fewer again
                    held = int(chain_meta[2])
                    if chain_meta[3] <= tol / 32.0:
                        held = held // 2
                    N = min(n_max // 2, max(N, held))
                for i in range(M):
                    mult[i] = chain_mult[i // ratio]
            status[b] = OK
            estimate = np.inf
            failures = 0
            failed_at = -1.0
            done = False
            while not done:
                if path and warm:  # the path from the chain's solution, on N steps
                    _chunk_steps(chunks, nc, length, N, np.int64(1), mult, csteps)
                    _copy(chain_x, x)
                    if ratio == 1:
                        Z[:, :] = chain_Z[:M]
                    else:
                        _ms_fill_nodes(x, chain_Z, ratio, Z, M, chunks, first, csteps, base,
                                       arm, act, case, scratch, 0.0)
                    if not _ms_follow(x, Z, M, chunks, first, csteps, base, arm, act, case,
                                      scratch, colscale, rowscale, work, w, length, threshold,
                                      max_iterations, max_load_step, budget, final_step,
                                      tip_c, counter, reached, 0.0, 1.0):
                        status[b] = PATH_FAILED  # (then a cold start)
                        break
                    path = False
                if path:
                    _chunk_steps(chunks, nc, length, N, np.int64(1), mult, csteps)
                    if not _ms_path(x, Z, M, levels, kl, N, n_fixed, arm, act, base, case, scratch,
                                    w, threshold, max_iterations, max_load_step, budget,
                                    final_step, tip_c, counter, reached, chunks, first, csteps,
                                    work, colscale, rowscale):
                        if counter[0] > budget:
                            status[b] = BUDGET
                            break
                        if _retry_finer(n_fixed, N, n_max, failures, reached[0], failed_at):
                            failures += 1
                            failed_at = reached[0]
                            N = 2 * N
                            continue
                        status[b] = PATH_FAILED
                        break
                    path = False
                if counter[0] > budget:
                    status[b] = BUDGET
                    break
                # the fine solution at 2N: chord iterations with the factors at N, else Newton
                _copy(x, x_f)
                _copy(Z, Z_f)
                _chunk_steps(chunks, nc, length, N, np.int64(2), mult, csteps)
                if not _ms_chord(x_f, Z_f, M, chunks, first, csteps, base, arm, act, case, scratch,
                                 colscale, rowscale, work, threshold, max_iterations, tip_f,
                                 counter):
                    _copy(x, x_f)
                    _copy(Z, Z_f)
                    ok, _, _ = _ms_corrector(
                        x_f, Z_f, M, 1.0, M - M + _COLS, chunks, first, csteps, base, arm, act,
                        case, scratch, colscale, rowscale, work, w, length, threshold,
                        max_iterations, _REFINE_MAX, 1e-9, tip_f, counter)
                    if not ok:
                        if 4 * N > n_max or n_fixed > 0:
                            status[b] = NEWTON_FAILED
                            break
                        N = 2 * N
                        path = True
                        continue
                d2 = 0.0
                for i in range(3):
                    d2 += (tip_f[i] - tip_c[i]) ** 2
                estimate = _STIFF_SAFETY * math.sqrt(d2) / 15.0
                if estimate <= tol or n_fixed > 0:
                    done = True
                    break
                total = 0
                for c in range(nc):
                    total += csteps[c]  # (at 2N)
                if total >= n_max:
                    status[b] = TOO_MANY_STEPS
                    break
                grow = (estimate / (0.3 * tol)) ** 0.25
                if M > 1:
                    # refine where the error is made: the intervals whose local error (N against
                    # 2N from the same start) is within a factor 20 of the largest; a boundary
                    # layer (the clamp's, width 1/k) then gets the steps, not the whole arm
                    _ms_local_errors(x_f, Z_f, M, chunks, first, csteps, base, arm, act, case,
                                     scratch, colscale, rowscale, work, length, nc, N, mult,
                                     local)
                    largest = 0.0
                    for i in range(M):
                        largest = max(largest, local[i])
                    factor = max(2, math.ceil(grow))
                    for i in range(M):
                        if local[i] >= 0.05 * largest or not largest > 0.0:
                            mult[i] *= factor
                else:
                    N = min(n_max // 2, max(N + 1, math.ceil(N * grow)))
                _chunk_steps(chunks, nc, length, N, np.int64(1), mult, csteps)
                _copy(x_f, x)
                _copy(Z_f, Z)
                ok, _, _ = _ms_corrector(
                    x, Z, M, 1.0, M - M + _COLS, chunks, first, csteps, base, arm, act, case,
                    scratch, colscale, rowscale, work, w, length, threshold, max_iterations,
                    _REFINE_MAX, final_step, tip_c, counter)
                path = not ok
            if warm and status[b] != OK:  # a cold start, from the unloaded arm
                warm = False
                again = True
        info[b, 1] = estimate
        info[b, 2] = 1.0 if status[b] == OK else reached[0]
        info[b, 3] = counter[0]
        info[b, 4] = N
        F = work[0]
        residual = 0.0
        for i in range(6):  # the tip residual (N, N m), as solve_cases reports it
            v = abs(F[n - 6 + i]) * rowscale[n - 6 + i]
            if not v <= residual:
                residual = v
        info[b, 0] = residual
        if chained:  # the chain holds this solution (its nodes on N steps) for the next case
            chain_meta[0] = 1.0
            if status[b] == OK and M <= chain_Z.shape[0]:
                chain_x[:] = x
                chain_Z[:M] = Z
                chain_mult[:M] = mult
                chain_piece[:, :] = piece_loads[b]
                chain_tip[:] = tip_loads[b]
                chain_meta[1] = M
                chain_meta[2] = N
                chain_meta[3] = estimate
                chain_meta[0] = 2.0
        if status[b] != OK:
            continue
        _chunk_steps(chunks, nc, length, N, np.int64(2), mult, csteps)
        if inputs is None:
            _ms_record(x_f, Z_f, M, chunks, first, csteps, base, arm, act, case, scratch,
                       s_out, out, b, None, None)
        elif not _ms_sensitivities(x_f, Z_f, M, chunks, first, csteps, base, arm, act,
                                   piece_loads[b], tip_loads[b], inputs, colscale, rowscale,
                                   work, s_out, out, b):
            status[b] = SINGULAR
            continue
        if not math.isfinite(residual):
            status[b] = NOT_FINITE
        if verdicts is not None and status[b] == OK:
            _ms_verdict(x_f, Z_f, M, chunks, first, csteps, base, arm, act, case, scratch, N,
                        piece_loads[b], tip_loads[b], out, b, verdicts)


@_jit
def _ms_local_errors(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, colscale,
                     rowscale, work, length, nc, N, mult, local):
    """Each interval's local error ``local[i]`` (L, rad): its end state integrated from the
    solution's own start on N steps against on 2N (``work``'s ends: the last integration,
    at 2N, of this solution), in position / L and rotation. Leaves ``csteps`` at N."""
    F, B, G, ends, lengths = work[0], work[1], work[2], work[3], work[4]
    fine = ends.copy()
    _chunk_steps(chunks, nc, length, N, np.int64(1), mult, csteps)
    none = M - M
    _ms_evaluate(x, Z, M, 1.0, none, chunks, first, csteps, base, arm, act, case, scratch,
                 colscale, rowscale, F, B, G, ends, lengths, None)
    for i in range(M):
        e = 0.0
        for a in range(3):
            e = max(e, abs(ends[i, _P + a] - fine[i, _P + a]) / length)
        for a in range(9):
            e = max(e, abs(ends[i, _R + a] - fine[i, _R + a]))
        local[i] = e if math.isfinite(e) else np.inf


@_jit
def _ms_sensitivities(x, Z, M, chunks, first, csteps, base, arm, act, piece, tip, inputs,
                      colscale, rowscale, work, s_out, out, b):
    """The implicit function theorem on the block system at the solution (x, Z): the
    scaled unknowns' changes U per dead tip wrench component (J U = e_k / rowscale_k: the
    tip rows are n(L) - W) and per input (J U = -∂F/∂q), then the output pass with the
    tangents, which writes each station's compliance and actuation Jacobian and the
    tendons' lengths' (:func:`_ms_record`), and out[5][b] rows 0:6 = [∂x/∂W | -∂x/∂q], as
    solve_cases' :func:`_implicit_function` leaves them. False if J is singular."""
    F, B, G, ends, lengths, piv, Lm = work[:7]
    n = 12 * M - 6
    n_in = inputs[0].shape[0]
    npieces = arm[1].size
    width = piece.shape[1]
    nt = _COLS + n_in
    scratch = _scratch(npieces, width - PIECE_LOADS, nt)
    rate = np.zeros((7 + n_in, npieces, width))  # row 0 (λ) and the node rows 1-6: zero
    tip_rate = np.zeros((7 + n_in, TIP_LOADS))
    for q in range(n_in):
        for j in range(npieces):
            for i in range(width):
                rate[7 + q, j, i] = inputs[0][q, j, i]
        for i in range(TIP_LOADS):
            tip_rate[7 + q, i] = inputs[1][q, i]
    case = (piece, rate, tip, tip_rate)  # at λ = 1 the loads are piece, tip (rate 0 is zero)
    Gq = np.empty((n, max(n_in, 1)))
    _ms_evaluate(x, Z, M, 1.0, nt, chunks, first, csteps, base, arm, act, case, scratch,
                 colscale, rowscale, F, B, G, ends, lengths, Gq)
    if _band_factor(B, n, np.int64(_BAND), piv, Lm) == 0.0:
        return False
    U = np.zeros((n, 6 + n_in))
    column = np.empty(n)
    for c in range(6 + n_in):
        for i in range(n):
            column[i] = 0.0
        if c < 6:
            column[n - 6 + c] = 1.0 / rowscale[n - 6 + c]
        else:
            for i in range(n):
                column[i] = -Gq[i, c - 6]
        if not _band_solve(B, n, np.int64(_BAND), piv, Lm, column):
            return False
        for i in range(n):
            U[i, c] = column[i]
    _ms_record(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, s_out, out, b,
               None, (U, colscale, nt))
    jac = out[5][b]
    for i in range(6):
        for c in range(6 + n_in):
            jac[i, c] = U[i, c] * colscale[i] * (1.0 if c < 6 else -1.0)
    return True


@_jit
def _ms_verdict(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, N, piece, tip,
                out, b, verdicts):
    """Case b's stability verdict (see :func:`solve_stiff_cases`): the solution's state at
    every point of the sweep's grid (N steps spread over the pieces), then the sweep."""
    npieces = arm[1].size
    steps = np.empty(npieces, dtype=np.int64)
    _fill_steps(arm[6], arm[1], N, np.int64(1), steps)
    total = 0
    for j in range(npieces):
        total += steps[j]
    grid = np.empty(total + 1)
    k = 0
    for j in range(npieces):
        h = arm[1][j] / steps[j]
        for i in range(steps[j]):
            grid[k] = arm[0][j] + i * h
            k += 1
    grid[total] = arm[6]
    states = np.empty((total + 1, scratch[0].size))
    _ms_record(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, grid, out, b,
               states, None)
    nt = _tangent_columns(arm, act, piece)
    verdicts[1][b] = _conservative(piece, tip)
    one_case = (case[0], case[1][:1], case[2], case[3][:1])
    r = np.empty(6)
    J = np.empty((6, 7))
    t0 = np.zeros((nt, nt))
    verdicts[0][b] = _sweep(x, 1.0, steps, base, arm, act, one_case, scratch, nt, r, J,
                            np.empty((0, 1)), np.empty((0, 1, 1)), t0, np.empty((0, 1)), states)
