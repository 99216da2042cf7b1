"""Single shooting: the corrector, the continuation along the load factor with its branch
guard and step control, the refinement in the step count, the output pass, the chained
memory, and the entry points ``solve_cases`` (a batch of cases) and ``shoot`` (one
integration: statics/README.md, "The shooting primitive")."""

from __future__ import annotations

import math

import numpy as np

from ._compile import _entry, _given, _inline, _jit, _per_arm
from .layout import (
    _ACT,
    _FB,
    _FD,
    _FF,
    _FG,
    _JD,
    _JF,
    _LD,
    _LF,
    _M,
    _MN,
    _MPREDICTED,
    _MSIGN,
    _MSTEP,
    _MVALID,
    _MXC,
    _MXF,
    _N,
    _O_BUDGET,
    _O_COARSE,
    _O_ITER,
    _O_LOADSTEP,
    _O_NEAR,
    _O_NFIXED,
    _O_NMAX,
    _O_TOL,
    _P,
    _R,
    _RHO,
    _TD,
    _TF,
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
from .linear import _copy, _crossings, _eliminate, _eliminate_columns, _linear_solve
from .rod import (
    _actuated,
    _integrate,
    _jump,
    _law,
    _set_loads,
    _start,
    _station_rotation,
    _steps,
    _tip_residual,
)


def _solver(args):
    """solve_cases' capability: passive or actuated (``act``), chained (``memory``), with
    Jacobians (``inputs``)."""
    actuated, chained, jacobians = _given(args[2]), _given(args[7]), _given(args[8])
    key = "+".join(["actuated" if actuated else "solve"] + ["chained"] * chained
                   + ["jacobians"] * jacobians)
    text = "the solver for " + ("actuated, magnetic or touching arms" if actuated
                                else "passive arms")
    text += " (quasi-static, chained)" * chained + " with Jacobians" * jacobians
    return key, text

# Continuation: largest first-corrector distance accepted, the distance aimed at by the step
# control, largest contraction of successive corrector steps, smallest load-factor step.
_DIST_MAX = 0.15
_DIST_AIM = 0.05
_CONTRACTION_MAX = 0.5
_DLAM_FLOOR = 1e-13
# Corrector steps no larger than this end a corrector on the way (not at λ = 1), and the
# first load step predicts a tip motion of about _FIRST_MOTION (L or rad).
_LOOSE = 1e-2
_FIRST_MOTION = 0.15
# A residual that stops decreasing is accepted within this factor of the threshold (round-off
# of an ill-conditioned shooting map; still 1e-9 of the case's own load).
_STALL = 1e3
# The branch guard (_follow, _ms_follow; docs/solver.md, "Branch guard"). A step across
# which a singular point is detected (_crossings: an eigenvalue of J_before⁻¹ J_after with a
# negative real part, so that a double root, as a round section's two bending planes
# buckling at one load, counts too) is accepted only when no longer than _CROSS_REL times
# the load factor's scale: only a singular point that the path itself passes (a perfect
# bifurcation, like a column compressed exactly along its axis) is crossed; the sharp turn
# of an imperfect one (a load a hair off the axis) is resolved by steps this short.
_CROSS_REL = 1e-7
# A step may not advance the path's phase Φ = ∫ √(F/EI) ds + ½ ∫ M/EI ds (F, M: bounds of
# the loads' forces and moments; Jacobi fields oscillate with about that phase under
# compression or torsion, and a singular point lies about every π of it) by more than
# _PHASE_STEP: at most one crossing per bending direction in a step, which the eigenvalue
# test then sees. Both apply while Φ <= _PHASE_TESTED; beyond, the arm is in strong
# tension (its growing Jacobi fields make J's eigenvalues ill-conditioned), and det's sign
# and the tip's direction of motion guard the path.
_PHASE_STEP = 0.5 * math.pi
_PHASE_TESTED = 12.0
# Refinement of a solution under a change of step count: distances are of the order of the
# discretisation error, far below this.
_REFINE_MAX = 0.05
# A predicted fine solution's output pass is accepted when its Newton step would move the
# arm by less than this fraction of tol (the answer is then that step from the converged one).
_PREDICTED_FINE = 0.01


@_jit
def _newton_step(J, r, dx):
    """dx = -J_x⁻¹ r."""
    neg = np.empty(6)
    for i in range(6):
        neg[i] = -r[i]
    return _linear_solve(J, neg, dx)


@_jit
def _norm_scaled(r, scale):
    out = 0.0
    for i in range(6):
        a = abs(r[i]) / scale[i]
        if not a <= out:  # also catches NaN
            out = a if math.isfinite(a) else np.inf
    return out


@_jit
def _distance(dx, T, scale, length):
    """The size of a change dx of the base reaction, nondimensional: the largest of the tip
    displacement / L and tip rotation (rad) it causes (to first order, from the tip tangents
    T[:6]) and of its components in units of ``scale`` (the bending scale times the case's
    load size, so that a given relative change of the reaction counts alike at any load)."""
    out = 0.0
    for i in range(6):
        out = max(out, abs(dx[i]) / scale[i])
    for row in range(6):
        acc = 0.0
        for d in range(6):
            acc += T[d, row] * dx[d]
        out = max(out, abs(acc) / (length if row < 3 else 1.0))
    if not math.isfinite(out):
        return np.inf
    return out


@_jit
def _corrector(x, lam, nt, steps, base, arm, act, case, scratch, scale, dscale, length, threshold,
               max_iterations, first_limit, loose, r, J, tip, counter):
    """Newton at fixed λ from the prediction x, accepted only if it stays near it.

    The steps together must be no larger than ``first_limit`` (nondimensional, see
    _distance) and every step after the first at most half the one before (contraction): a
    corrector that wanders or stalls is rejected instead of accepted at whatever root it
    reaches. Converged when the
    residual is below ``threshold``, or when a step is no larger than ``loose``: that step is
    taken without integrating again (its error is of the order of its square), the tip
    position ``tip`` is moved by its linearisation and J is the one of the point before.
    True when converged; x, r, J (nt columns) and tip hold the solution; x changes even on
    failure.
    """
    dx = np.empty(6)
    previous = np.inf
    travelled = 0.0
    y, T = scratch[0], scratch[1]
    for k in range(max_iterations + 1):
        _integrate(x, lam, nt, steps, base, arm, act, case, scratch, r, J)
        counter[0] += 1
        for i in range(3):
            tip[i] = y[_P + i]
        res = _norm_scaled(r, scale)
        if res <= threshold:
            return True
        if k == max_iterations or not math.isfinite(res) or not _newton_step(J, r, dx):
            return False
        size = _distance(dx, T, dscale, length)
        if k == 0:
            if size > first_limit:
                return False
        elif size > _CONTRACTION_MAX * previous:
            # a step at round-off level cannot contract further: accept a tiny residual
            return res <= _STALL * threshold
        previous = size
        travelled += size
        if travelled > first_limit:
            return False  # wandered: the sum of the steps is a bound of the distance moved
        for i in range(6):
            x[i] += dx[i]
        if size <= loose:
            for i in range(3):
                for d in range(6):
                    tip[i] += T[d, _TP + i] * dx[d]
            return True
    return False


@_jit
def _det_sign(J):
    """The sign of det ∂r/∂x (J[:, :6]); 0 if singular. Its parity is that of the number of
    unstable directions: a change between two points of the path means a singular point
    (fold or bifurcation) between them."""
    M = np.empty((6, 6))
    for i in range(6):
        for k in range(6):
            M[i, k] = J[i, k]
    return _eliminate(M)


@_jit
def _tip_motion(T, t, out):
    """The tip displacement (spatial) per unit load factor along the path tangent t."""
    for i in range(3):
        acc = 0.0
        for d in range(6):
            acc += T[d, _TP + i] * t[d]
        out[i] = acc


@_jit
def _cosine(a, b):
    """The cosine of the angle between two 3-vectors (1 if either is zero). The norms are
    multiplied, not their squares: two tiny motions (an input of 1e-113 N) have squares
    whose product underflows to 0 (a ZeroDivisionError)."""
    aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2]
    if not (aa > 0.0 and bb > 0.0):
        return 1.0
    return (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (math.sqrt(aa) * math.sqrt(bb))


@_jit
def _tangent(J, t):
    """The path tangent dx/dλ = -J_x⁻¹ J_λ."""
    rhs = np.empty(6)
    for i in range(6):
        rhs[i] = -J[i, LAM]
    return _linear_solve(J, rhs, t)


@_inline
def _load_step(lam, dl, end):
    """(Δλ, the target λ + Δλ): a step that would leave less than half a step to ``end``
    (the path's end, λ = 1 but on a level of the stiff path) is stretched to reach it."""
    if lam + 1.5 * dl >= end:
        dl = end - lam
    target = lam + dl
    if target >= end - 1e-12 * end:
        target = end
    return dl, target


@_inline
def _grown(dl, moved, max_load_step):
    """The next Δλ after an accepted step whose corrector moved ``moved`` from the
    prediction: Δλ (aim/δ)^(1/3) within [Δλ/2, 2Δλ], at most max_load_step."""
    grow = 2.0 if moved <= 0.0 else min(2.0, max(0.5, (_DIST_AIM / moved) ** (1 / 3)))
    return min(max_load_step, dl * grow)


@_jit
def _sizes(arm, act, loads, tip):
    """(F, M): bounds of the total force (N) and moment (N m) that one set of load channels
    (``loads`` (P, W) per piece, ``tip`` (TIP_LOADS,)) applies to the arm, each the sum of
    its components' magnitudes: tip, distributed (times the piece length) and point forces
    and moments, and the magnets' forces and torques (|m| |G| and |m| |B| per length, |B|
    bounded as in :func:`_load_size`). Not the actuators': a tendon's tension or a chamber's
    pressure is internal to the arm (it bends it without buckling it)."""
    piece_len = arm[1]
    L = arm[6]
    force = moment = 0.0
    for i in range(3):
        force += abs(tip[_TD + i]) + abs(tip[_TF + i])
        moment += abs(tip[_TD + 3 + i]) + abs(tip[_TF + 3 + i])
    for j in range(piece_len.size):
        f = m = 0.0
        for i in range(3):
            f += abs(loads[j, _FD + i]) + abs(loads[j, _FF + i])
            m += abs(loads[j, _LD + i]) + abs(loads[j, _LF + i])
            force += abs(loads[j, _JD + i]) + abs(loads[j, _JF + i])
            moment += abs(loads[j, _JD + 3 + i]) + abs(loads[j, _JF + 3 + i])
        if act is not None:
            mag, dipoles = act[3], act[4]
            field = gradient = 0.0
            for i in range(3):
                field += abs(loads[j, _FB + i])
            for i in range(9):
                gradient += abs(loads[j, _FG + i])
            field += gradient * 2.0 * L
            strength = abs(mag[j, 0]) + abs(mag[j, 1]) + abs(mag[j, 2])
            dipole = abs(dipoles[j, 0]) + abs(dipoles[j, 1]) + abs(dipoles[j, 2])
            if j == piece_len.size - 1:
                dipole += (abs(dipoles[j + 1, 0]) + abs(dipoles[j + 1, 1])
                           + abs(dipoles[j + 1, 2]))
            f += strength * gradient
            m += strength * field
            force += dipole * gradient
            moment += dipole * field
        force += f * piece_len[j]
        moment += m * piece_len[j]
    return force, moment


@_jit
def _path_bounds(arm, act, case, scale, out):
    """What the branch guard needs to know of a case's homotopy, loads(λ) = start + λ rate
    (``case``), in ``out`` (7,): Q = ∫ √(1/EI) ds and ∫ ds/EI (each piece's softest
    bending), the force bounds (N) of the start loads and of the rate, the moment bounds
    (N m) likewise (:func:`_sizes`; the phase is Φ(λ) = Q √(F(λ)) + ½ ∫ds/EI M(λ)), and the
    load factor's offset: the start loads' size over the rate's (0 from the unloaded arm),
    so that λ + offset measures the loads on the path's own scale (a chained Solver's
    small step from large loads)."""
    piece_len, C = arm[1], arm[2]
    Q = flex = 0.0
    for j in range(piece_len.size):
        c = max(C[j, 4, 4], C[j, 5, 5])
        Q += piece_len[j] * math.sqrt(c)
        flex += piece_len[j] * c
    start, rate, tip_start, tip_rate = case
    fs, ms = _sizes(arm, act, start, tip_start)
    fr, mr = _sizes(arm, act, rate[0], tip_rate[0])
    ws, _ = _load_size(arm, act, scale, start, start, tip_start, tip_start)
    wr, _ = _load_size(arm, act, scale, rate[0], rate[0], tip_rate[0], tip_rate[0])
    out[0], out[1], out[2], out[3], out[4], out[5] = Q, flex, fs, fr, ms, mr
    out[6] = 0.0 if ws == 0.0 else (ws / wr if wr > 0.0 else np.inf)


@_jit
def _phase(bounds, lam):
    """The path's phase Φ at load factor λ (:func:`_path_bounds`)."""
    return (bounds[0] * math.sqrt(bounds[2] + lam * bounds[3])
            + 0.5 * bounds[1] * (bounds[4] + lam * bounds[5]))


@_jit
def _phase_limited(bounds, lam, dl):
    """Δλ, shortened so that the step from λ advances the phase by at most _PHASE_STEP
    (half of it by the forces, half by the moments), while Φ <= _PHASE_TESTED."""
    if not _phase(bounds, lam) <= _PHASE_TESTED:
        return dl
    Q, flex, fs, fr, mr = bounds[0], bounds[1], bounds[2], bounds[3], bounds[5]
    if fr > 0.0 and Q > 0.0:
        u0 = math.sqrt(fs + lam * fr)
        u1 = u0 + 0.5 * _PHASE_STEP / Q
        dl = min(dl, (u1 * u1 - u0 * u0) / fr)
    if mr > 0.0 and flex > 0.0:
        dl = min(dl, _PHASE_STEP / (flex * mr))
    return dl


@_jit
def _crossed(J_before, J_after, scale, guard):
    """How many singular points the path passed between two of its points: the
    :func:`_crossings` of ∂r/∂x there (columns in units of the bending scale), -1 if the
    first is singular. ``guard``: work arrays (:func:`_guard_work`)."""
    A, B, work, M = guard
    for i in range(6):
        for k in range(6):
            A[i, k] = J_before[i, k] * scale[k]
            B[i, k] = J_after[i, k] * scale[k]
    return _crossings(A, B, np.int64(6), work, M, 0.0)


@_jit
def _guard_work():
    """The branch guard's work arrays: two 6 × 6 matrices, the elimination's 6 × 12, the
    product's 6 × 6."""
    return (np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 12)), np.empty((6, 6)))


@_jit
def _cross_step(bounds, lam):
    """The longest step accepted across a singular point at load factor λ."""
    return _CROSS_REL * (lam + bounds[6])


@_jit
def _follow(x, steps, base, arm, act, case, scratch, scale, dscale, length, threshold,
            max_iterations, max_load_step, max_shootings, open_end, final, r, J, tip,
            counter, reached, J_path):
    """Follow the equilibrium path from λ = 0 (x: the solution there, exact or close) to
    λ = 1 by predictor–corrector continuation. True on success, with x, r, J (7 columns) and
    the tip position at λ = 1, converged as the caller's own corrector would leave them (a
    last step no larger than ``final``, or the threshold: no refinement is needed on these
    steps); otherwise ``reached[0]`` is the last load factor reached (a fold, or a point the
    path cannot be followed past) and x the solution there. Points on the way are converged
    to ``_LOOSE``. ``J_path`` receives ∂r/∂x at the last point
    accepted (the caller checks its own last correction against it).

    Predictor: the tangent dx/dλ = -J_x⁻¹ J_λ from the variational equations for the first
    step, then the cubic Hermite extrapolation of the last two points and their tangents.
    Corrector: :func:`_corrector` (distance and contraction tests). Step control: the first
    Δλ makes the predicted motion ``_FIRST_MOTION``; then Δλ ← Δλ (aim/δ)^(1/3) within
    [Δλ/2, 2Δλ], δ the corrector's distance from the predictor; Δλ × 0.4 after a failure; a
    step that would leave less than half a step to λ = 1 is stretched to reach it; no step
    advances the phase by more than _PHASE_STEP (:func:`_phase_limited`).

    Branch guard: a step is refused when a singular point lies in it (det ∂r/∂x changes
    sign, or :func:`_crossed` counts a crossing: a double root too) or the tip's direction of
    motion turns by more than 60°, unless the step is no longer than :func:`_cross_step`: a
    singular point of the path itself (a perfect bifurcation) is crossed; the sharp turn
    beside an imperfect one is followed in steps short enough to see it.

    With ``open_end``, the last step (to λ = 1) is predicted but not corrected: x is the
    prediction, for the caller's corrector on a finer grid (with the same first-step limit
    ``_DIST_MAX`` and contraction test, so the last step is checked as any other).
    """
    reached[0] = 0.0
    end = 1.0
    nt = J.shape[1]  # all 7 columns (a variable, not a literal: one compiled version)
    if not _corrector(x, 0.0, nt, steps, base, arm, act, case, scratch, scale, dscale, length,
                      threshold, max_iterations, _REFINE_MAX, _LOOSE, r, J, tip, counter):
        return False
    t = np.empty(6)
    t_new = np.empty(6)
    x0 = np.empty(6)
    xp = np.empty(6)  # the point before (λp), and its tangent
    tp = np.empty(6)
    dx = np.empty(6)
    if not _tangent(J, t):
        return False
    bounds = np.empty(7)
    _path_bounds(arm, act, case, scale, bounds)
    guard = _guard_work()
    _copy_jx(J, J_path)
    sign = _det_sign(J)
    reached[1] = sign
    motion_prev = np.empty(3)
    _tip_motion(scratch[1], t, motion_prev)
    motion_new = np.empty(3)
    lam = 0.0
    lam_p = -1.0  # no point before yet
    motion = _distance(t, scratch[1], dscale, length)
    dl = max_load_step if motion <= 0.0 else min(max_load_step, _FIRST_MOTION / motion)
    while lam < 1.0:
        if counter[0] > max_shootings:
            return False
        dl, target = _load_step(lam, _phase_limited(bounds, lam, dl), end)
        for i in range(6):
            x0[i] = x[i]
        h = lam - lam_p
        tau = (target - lam_p) / h
        if lam_p >= 0.0 and tau <= 3.0:
            # cubic Hermite through (λp, xp, tp) and (λ, x, t), evaluated at the target
            t2, t3 = tau * tau, tau * tau * tau
            h00, h10 = 2 * t3 - 3 * t2 + 1.0, t3 - 2 * t2 + tau
            h01, h11 = -2 * t3 + 3 * t2, t3 - t2
            for i in range(6):
                x[i] = h00 * xp[i] + h10 * h * tp[i] + h01 * x0[i] + h11 * h * t[i]
        else:
            for i in range(6):
                x[i] = x0[i] + (target - lam) * t[i]
        if open_end and target == 1.0:
            reached[0] = lam  # reached[1]: the sign of det ∂r/∂x there, for the caller
            return True
        for i in range(6):
            dx[i] = x[i]  # the prediction
        ok = _corrector(x, target, nt, steps, base, arm, act, case, scratch, scale, dscale, length,
                        threshold, max_iterations, _DIST_MAX,
                        final if target == 1.0 else _LOOSE, r, J, tip, counter)
        if ok:
            for i in range(6):
                dx[i] = x[i] - dx[i]  # the corrector's distance from the prediction
            ok = _tangent(J, t_new)
        if ok:
            new_sign = _det_sign(J)
            _tip_motion(scratch[1], t_new, motion_new)
            crossing = new_sign != sign or _crossed(J_path, J, scale, guard) != 0
            ok = dl <= _cross_step(bounds, lam) or (
                not crossing and _cosine(motion_prev, motion_new) >= 0.5)
            if ok:
                sign = new_sign
                reached[1] = sign
                for i in range(3):
                    motion_prev[i] = motion_new[i]
        if ok:
            for i in range(6):
                xp[i] = x0[i]
                tp[i] = t[i]
                t[i] = t_new[i]
            _copy_jx(J, J_path)
            lam_p = lam
            lam = target
            reached[0] = lam
            dl = _grown(dl, _distance(dx, scratch[1], dscale, length), max_load_step)
        else:
            for i in range(6):
                x[i] = x0[i]
            dl *= 0.4
            if dl < _smallest_step(bounds, lam):
                return False
    return True


@_jit
def _copy_jx(J, out):
    """out = J[:, :6] (∂r/∂x of a Jacobian with more columns)."""
    for i in range(6):
        for k in range(6):
            out[i, k] = J[i, k]


@_jit
def _smallest_step(bounds, lam):
    """The shortest load step tried before a path is given up at λ (a fold, or a point it
    cannot pass): below any step that crosses a singular point (:func:`_cross_step`)."""
    return max(_DLAM_FLOOR, 0.01 * _cross_step(bounds, lam))


@_jit
def _write(y, T, nt, j, s, arm, act, now, law, pose, strain, stress, E):
    """One station's outputs: pose, the rod's own material strain ε - f⁰ and stress
    K (ε - f⁰) (with actuators, the total wrench less the tendons' and the fluid's share),
    and (nt >= 6) the station's motion per unit base reaction, E[:, :6] = ∂(δp; δθ)/∂x,
    and per unit input (E[:, 6:nt], the input columns), both rows in spatial components."""
    for i in range(4):
        for k in range(4):
            pose[i, k] = 0.0
    pose[3, 3] = 1.0
    for i in range(3):
        pose[i, 3] = y[_P + i]
        for k in range(3):
            pose[i, k] = y[_R + 3 * i + k]
    for i in range(3):
        stress[i] = y[_R + i] * y[_N] + y[_R + 3 + i] * y[_N + 1] + y[_R + 6 + i] * y[_N + 2]
        stress[3 + i] = (y[_R + i] * y[_M] + y[_R + 3 + i] * y[_M + 1]
                         + y[_R + 6 + i] * y[_M + 2])
    if act is not None and _actuated(act, j):
        f0, K = arm[3], arm[8]
        eps = _law(arm, act, j, s, now, law, np.int64(0), stress[0], stress[1], stress[2],
                   stress[3], stress[4], stress[5])
        for i in range(6):
            strain[i] = eps[i] - f0[j, i]
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += K[j, i, k] * strain[k]
            stress[i] = acc
    else:
        C = arm[2]
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += C[j, i, k] * stress[k]
            strain[i] = acc
    for d in range(nt):
        for i in range(3):
            E[i, d] = T[d, _TP + i]
            E[3 + i, d] = (y[_R + 3 * i] * T[d, _TT] + y[_R + 3 * i + 1] * T[d, _TT + 1]
                           + y[_R + 3 * i + 2] * T[d, _TT + 2])


@_jit
def _record(x, nt, steps, base, arm, act, case, lam, scratch, s_out, out, b, r, J):
    """Integrate the solution x at load factor ``lam`` once more and write every station's
    outputs (the same steps as :func:`_integrate`, so the same numbers), the tip residual r
    and, with nt >= 6, the Jacobian J and the station tangents (columns 6.. along the
    case's rate rows: the inputs); and the case's base reaction and tendon lengths.

    A station inside a step is interpolated: the cubic Hermite polynomial of the state and
    tangents on the step, from their values and derivatives at both ends (the derivative at
    the end is the next step's first stage, so it costs nothing inside a piece), then one
    Björck step on R. Its error is of the order of the step's own discretisation error
    (statics/README.md: measured against tight solves); the stations never change the
    steps of the solution. A station at a piece start gets the state after the point wrench
    there (the tip side). The station s = L (and any station past the last step's start) is
    written from the tip state itself.
    """
    y, T, work, twork, now, tip_now, ys, Ts, law = scratch
    poses, strains, stresses = out[0][b], out[1][b], out[2][b]
    E = out[6][b if nt > 0 else 0]  # a (1, S, 6, 6) placeholder without tangents
    rate, tip_rate = case[1], case[3]
    piece_start, piece_len = arm[0], arm[1]
    _set_loads(lam, case, now, tip_now)
    _start(y, T, nt, base, x)
    k = 0
    ns = s_out.size
    npieces = piece_len.size
    one = np.int64(1)  # not a literal 1: _steps is compiled once for every caller
    zero = one - one
    for j in range(npieces):
        _jump(y, T, nt, now, rate, j, arm, act, law)
        h = piece_len[j] / steps[j]
        i = 0
        known = False  # work[0], twork[0] hold the derivatives at (y, T, this step's start)
        while i < steps[j]:
            # the steps surely before the next station's step, as one run (one step of
            # margin against rounding: the step-by-step branch below decides exactly)
            run = steps[j] - i
            if k < ns:
                run = min(run, max(int((s_out[k] - piece_start[j]) / h) - 1 - i, 0))
            if run > 0:
                _steps(y, T, nt, h, piece_start[j] + i * h, -run if known else run, arm, act, j,
                       now, rate, work, twork, law)
                known = False
                i += run
                continue
            t0 = piece_start[j] + i * h
            last = j == npieces - 1 and i == steps[j] - 1
            t1 = piece_start[j] + (i + 1) * h if i < steps[j] - 1 else (
                piece_start[j + 1] if j < npieces - 1 else np.inf)
            inside = k < ns and s_out[k] < t1 and not (last and s_out[k] >= arm[6])
            if not inside:  # (the tip station is the tip state itself, below)
                _steps(y, T, nt, h, t0, -one if known else one, arm, act, j, now, rate, work,
                       twork, law)
                known = False
                i += 1
                continue
            # stations inside this step: the step from its start (kept with its derivative,
            # the step's first stage), the derivative at its end (the next step's first
            # stage on this piece), then each station by Hermite interpolation
            _copy(y, work[5])
            for d in range(nt):
                for a in range(T.shape[1]):
                    twork[5, d, a] = T[d, a]
            _steps(y, T, nt, h, t0, -one if known else one, arm, act, j, now, rate, work, twork,
                   law)
            _copy(work[0], work[6])
            for d in range(nt):
                for a in range(T.shape[1]):
                    twork[6, d, a] = twork[0, d, a]
            # (at the next step's own start, to the bit: its first stage is this one)
            _steps(y, T, nt, h, piece_start[j] + (i + 1) * h, zero, arm, act, j, now, rate, work,
                   twork, law)
            known = i + 1 < steps[j]
            while k < ns and s_out[k] < t1:
                if last and s_out[k] >= arm[6]:
                    break
                u = (s_out[k] - t0) / h
                c0 = (1.0 + 2.0 * u) * (1.0 - u) * (1.0 - u)  # cubic Hermite basis
                c1 = u * (1.0 - u) * (1.0 - u) * h
                c2 = u * u * (3.0 - 2.0 * u)
                c3 = -u * u * (1.0 - u) * h
                for a in range(y.size):
                    ys[a] = c0 * work[5, a] + c1 * work[6, a] + c2 * y[a] + c3 * work[0, a]
                for d in range(nt):
                    for a in range(T.shape[1]):
                        Ts[d, a] = (c0 * twork[5, d, a] + c1 * twork[6, d, a] + c2 * T[d, a]
                                    + c3 * twork[0, d, a])
                _station_rotation(work[5], work[6], y, work[0], u, h, ys)
                _write(ys, Ts, nt, j, s_out[k], arm, act, now, law, poses[k], strains[k],
                       stresses[k], E[k])
                k += 1
            i += 1
    for i in range(k, ns):
        _write(y, T, nt, npieces - 1, arm[6], arm, act, now, law, poses[i], strains[i],
               stresses[i], E[i])
    _tip_residual(y, T, nt, tip_now, tip_rate, r, J, arm, act, now, rate, law)
    for a in range(J.shape[0] - 6):  # rows 6 + a (when given): tendon a's length's tangents
        for d in range(nt):
            J[6 + a, d] = T[d, NT + a]
    base_out, lengths = out[7], out[8]
    for i in range(6):
        base_out[b, i] = x[i]
    for a in range(lengths.shape[1]):
        lengths[b, a] = y[18 + a]


@_jit
def _fill_steps(length, piece_len, N, factor, out):
    """Steps per piece for a nominal N steps over the whole arm (at least one per piece,
    rounded to the nearest whole number), times ``factor`` (2 for the fine solution)."""
    for j in range(piece_len.size):
        out[j] = factor * max(1, math.floor(N * piece_len[j] / length + 0.5))


@_jit
def _load_size(arm, act, scale, start, end, tip_start, tip_end):
    """(w, turning): the case's largest load in units of the bending scale (EI/L² for
    forces, EI/L for moments; distributed loads times the piece length, at either end of
    the homotopy) and an upper estimate of the total turning of the arm (rad), the largest
    load moment about the base times ∫ ds/EI with each piece's softest bending
    compliance (bending; the pieces of a very soft segment need as many steps as its
    turning). An actuator's tension or pressure force is internal (no net force on the arm)
    but bends it: it counts as a moment |q| ρ (ρ its largest distance from the centreline)
    on each piece it acts on; a magnetisation m as a moment |m| |B|
    per length, and a dipole as a moment |m| |B|, |B| bounded by |B0| + |G| (L + |p0|)."""
    piece_len, C = arm[1], arm[2]
    L = arm[6]
    fs, ms = scale[0], scale[3]
    flexibility = 0.0  # ∫ ds / EI, with each piece's largest rotational compliance
    for j in range(piece_len.size):
        flexibility += piece_len[j] * max(C[j, 4, 4], C[j, 5, 5])
    w = 0.0
    moment = 0.0
    for which in range(2):
        loads = start if which == 0 else end
        tip = tip_start if which == 0 else tip_end
        f_tip, m_tip = 0.0, 0.0
        for i in range(3):
            f_tip += abs(tip[_TD + i]) + abs(tip[_TF + i])
            m_tip += abs(tip[_TD + 3 + i]) + abs(tip[_TF + 3 + i])
        w = max(w, f_tip / fs, m_tip / ms)
        total = f_tip * L + m_tip
        f_along = 0.0
        actuators = 0.0
        for j in range(piece_len.size):
            f, m, jf, jm = 0.0, 0.0, 0.0, 0.0
            for i in range(3):
                f += abs(loads[j, _FD + i]) + abs(loads[j, _FF + i])
                m += abs(loads[j, _LD + i]) + abs(loads[j, _LF + i])
                jf += abs(loads[j, _JD + i]) + abs(loads[j, _JF + i])
                jm += abs(loads[j, _JD + 3 + i]) + abs(loads[j, _JF + 3 + i])
            actuated = 0.0  # internal: a moment along the piece, no net force
            if act is not None:
                routes, mag, dipoles = act[0], act[3], act[4]
                field = 0.0
                for i in range(3):
                    field += abs(loads[j, _FB + i])
                for i in range(9):
                    field += abs(loads[j, _FG + i]) * 2.0 * L
                dipole = abs(dipoles[j, 0]) + abs(dipoles[j, 1]) + abs(dipoles[j, 2])
                if j == piece_len.size - 1:
                    dipole += (abs(dipoles[j + 1, 0]) + abs(dipoles[j + 1, 1])
                               + abs(dipoles[j + 1, 2]))
                m += (abs(mag[j, 0]) + abs(mag[j, 1]) + abs(mag[j, 2])) * field
                jm += dipole * field
                for a in range(routes.shape[0]):
                    actuated += abs(loads[j, _ACT + a]) * routes[a, _RHO]
            actuators = max(actuators, actuated)
            f_along += f * piece_len[j] + jf
            w = max(w, f_along / fs, m * piece_len[j] / ms, jm / ms, actuated / ms)
            total += f * piece_len[j] * 0.5 * L + jf * L + m * piece_len[j] + jm
        w = max(w, f_along / fs)
        moment = max(moment, total + actuators)
    return w, moment * flexibility


#: Coarse steps per radian of the unloaded arm's turning Σ |κ⁰| L at the least
#: (_first_steps): one radian a step on the path's quarter grid.
_CURVED_STEPS = 4.0


@_jit
def _first_steps(arm, tol, turning):
    """The first coarse step count: 0.07 (1 + turning) (tol/L)^-1/4, in [2, 256] (the
    constant measured: the Richardson estimate then lands at 0.003-0.5 tol on the benchmark
    cases, so N rarely has to grow)."""
    kappa0 = 0.0
    for j in range(arm[1].size):
        kappa0 += arm[1][j] * math.sqrt(arm[3][j, 3] ** 2 + arm[3][j, 4] ** 2
                                        + arm[3][j, 5] ** 2)
    rel = tol / arm[6] if math.isfinite(tol) else 1e-8
    n = math.ceil(0.07 * (1.0 + kappa0 + turning) * rel ** -0.25)
    # and _CURVED_STEPS per radian of the unloaded arm's own turning, beyond the cap: the
    # path runs on a quarter of N, and RK4 turns a section stably by < 2.8 rad a step
    return max(min(256, max(2, n)), math.ceil(_CURVED_STEPS * kappa0))


@_inline
def _chord(x, J_c, steps, base, arm, act, case, scratch, scale, threshold, max_iterations,
           may_defer, r, J, tip, counter):
    """The solution at λ = 1 with another step count by chord iterations from x (a solution
    with a nearby step count) with that solution's Jacobian J_c, state only (no tangents).

    The first step may change x only by a discretisation-sized amount (``_REFINE_MAX``) and
    each iteration must at least halve the residual. Returns 0 (failed), 1 (converged: r and
    tip are x's) or 2 (the last step was taken without integrating it, because the observed
    contraction predicts a residual below the threshold: the output pass checks it, and
    ``tip`` is the position before that step, an error of the order of the step; only if
    ``may_defer``). A residual that stops halving is accepted if within ``_STALL`` times the
    threshold: the round-off floor of an ill-conditioned shooting map (a long, thin, stiff
    wire), still 1e-9 of the case's own load.
    """
    dx = np.empty(6)
    previous = np.inf
    none = J.shape[1] - 7  # no tangents (a variable, not a literal: one compiled version)
    for _ in range(max_iterations):
        _integrate(x, 1.0, none, steps, base, arm, act, case, scratch, r, J)
        counter[0] += 1
        for i in range(3):
            tip[i] = scratch[0][_P + i]
        res = _norm_scaled(r, scale)
        if res <= threshold:
            return 1
        if not res < 0.5 * previous:
            # stalled: at round-off for this problem's conditioning, if small against the
            # case's own load (1e-9 of it), else a failure
            return 1 if res <= _STALL * threshold else 0
        if not _newton_step(J_c, r, dx):
            return 0
        if not math.isfinite(previous):  # the first step: a change of discretisation only
            size = 0.0
            for i in range(6):
                size = max(size, abs(dx[i]) / scale[i])
            if not size <= _REFINE_MAX:
                return 0
        # the chord contraction: observed, or at first ~ 10 res (the Jacobians of N and 2N
        # steps differ by the discretisation error, as r does; a cautious guess, since a
        # wrong one costs a whole output pass)
        rate = res / previous if math.isfinite(previous) else 10.0 * res
        previous = res
        for i in range(6):
            x[i] += dx[i]
        if may_defer and rate * res <= threshold:
            return 2
    return 0


@_jit
def _scratch(npieces, nact, ncols):
    """Work arrays of one integration (state with the nact tendon lengths, ncols tangent
    columns, RK4 stages (rows 0-3 the stage derivatives, 4 the stage state, 5-6 the output
    pass's step start: state and derivative), loads at λ, a station's own state and
    tangents, and the
    constitutive law's: the 6 × (6 + ncols) elimination matrix, per actuator (t, |w|, y, z,
    y', z'), small vectors)."""
    width = 18 + nact
    law = (np.empty((6, 6 + ncols)), np.zeros((max(nact, 1), 8)), np.zeros((6, 6)),
           np.zeros((6, 6)))
    return (np.empty(width), np.empty((ncols, NT + nact)), np.empty((7, width)),
            np.empty((7, ncols, NT + nact)), np.empty((npieces, PIECE_LOADS + nact)),
            np.empty(TIP_LOADS), np.empty(width), np.empty((ncols, NT + nact)), law)


@_inline
def _output(x, nt, steps, base, arm, act, case, piece_loads, tip_loads, inputs, scratch, s_out,
            out, b, r, J, J_out):
    """The output pass of case b (:func:`_record` at λ = 1); with tangents (nt = 6) and
    actuation inputs, also one tangent column per input: the pass then runs on the case's
    final loads with the inputs as its rate rows (at λ = 0, the same loads), J_out gets the
    6 + n columns. (``inputs`` is None without Jacobians: that part is not compiled.)"""
    if inputs is None or nt == 0 or inputs[0].shape[0] == 0:
        _record(x, nt, steps, base, arm, act, case, 1.0, scratch, s_out, out, b, r, J)
        return
    n_inputs = inputs[0].shape[0]
    at_inputs = (piece_loads, inputs[0], tip_loads, inputs[1])
    _record(x, 6 + n_inputs, steps, base, arm, act, at_inputs, 0.0, scratch, s_out, out, b, r,
            J_out)


@_inline
def _retry_finer(n_fixed, N, n_max, failures, reached, failed_at):
    """Whether a path that failed at load factor ``reached`` is tried again on twice the
    steps: a fold persists under refinement at about the same load factor; a failure of an
    under-resolved path moves or disappears (at most 4 times, within the step limit)."""
    return (n_fixed == 0 and 2 * N <= n_max // 2 and failures < 4
            and abs(reached - failed_at) > 0.02)


@_inline
def _read_options(options):
    """(tol, max_iterations, max_load_step, fixed step count, largest step count, budget)
    from the solver options (see solve_cases)."""
    return (options[_O_TOL], int(options[_O_ITER]), options[_O_LOADSTEP],
            int(options[_O_NFIXED]), int(options[_O_NMAX]), int(options[_O_BUDGET]))


@_entry(_solver, nogil=True)
def solve_cases(base, arm, act, loads, first, options, s_out, memory, inputs, out):
    """Solve every load case of a flattened batch.

    Each case follows its own homotopy from λ = 0 to 1 (see the module docstring): from the
    unloaded arm (start loads 0, x = 0) unless chained (``memory`` given), where case b
    starts from case b - 1's loads and solution (case 0 from ``first`` and ``memory``): a
    slowly driven arm.

    Capabilities are compiled on first use (statics/README.md, "Compiled per capability"): ``act``,
    ``first`` and ``memory``, and ``inputs`` are None for a passive arm, an unchained batch
    and a solve without Jacobians, and numba then prunes the code that uses them before
    typing it: a first passive solve compiles neither the actuated law nor the chained
    starts nor the input columns.

    Per case, the stage machine of statics/README.md: the path at N steps (continuation),
    the solution at 2N (chord iterations, else a checked Newton, else the path at 2N), the
    Richardson estimate |p_2N - p_N| / 15 against tol, N grown by the order-4 model (a
    checked Newton from the 2N solution, else the path again) until it is met, then the
    output pass.

    Parameters (B cases, P pieces, S stations)
    ----------
    base : (4, 4) base pose.
    arm : (piece_start (P,), piece_len (P,), C (P, 6, 6) compliance, f0 (P, 6) reference
        strain, zero (P, 6), diag (bool: every C diagonal), length, scale (6,) residual
        scale, K (P, 6, 6) stiffness); see statics/README.md.
    act : None for a passive arm (no actuator, no magnet), else (routes (A, 4 + 2D)
        actuator paths, kinds (A,) TENDON or CHAMBER, active (P, A) 1.0 where actuator a
        acts on piece j, mag (P, 3) magnetisation (A m²/m, material), dipoles (P + 1, 3)
        dipole at each piece start and at the tip (A m², material)).
    loads : (piece (B, P, PIECE_LOADS + A), tip (B, TIP_LOADS)): each case's loads at λ = 1.
    first : None (every case from the unloaded arm), or with ``memory``: (piece
        (P, PIECE_LOADS + A), tip (TIP_LOADS,)), case 0's start loads.
    options : (OPTIONS,) tol (m; inf with a fixed step count), max_iterations, max_load_step,
        fixed step count (0: from tol), largest step count, shootings budget, the ratio of
        the step counts of the solution and of the path, near (0/1, chained only: case 0's
        start loads are its own and ``memory`` holds a solution on its fine grid,
        :meth:`Solver.solve_near`; its coarse solution is corrected from there, the path
        only if that fails).
    memory : None (unchained), or (MEMORY,) the chained start (x at N, x at 2N, N, valid,
        sign of det ∂r/∂x at N), read and rewritten; with a predicted step
        (``memory[_MPREDICTED]``, consumed), case 0 tries it before its path.
    inputs : None (no Jacobians), or (piece (n, P, PIECE_LOADS + A), tip (n, TIP_LOADS)):
        the load channels per unit of each actuation input (n = 0: none); the output pass
        then integrates the tangents, with one more column per input: J and E have 6 + n
        columns.
    out : (poses (B, S, 4, 4), strains (B, S, 6), stresses (B, S, 6), info (B, 5) [residual,
        error estimate, load factor reached, shootings, N], status (B,), J (B, 6, 6) at the
        solution (jacobians), E (B, S, 6, 6) station motion per unit x (jacobians), x (B, 6)
        the base reaction (total wrench at the clamp, spatial), lengths (B, A) each tendon's
        length).
    """
    piece_loads, tip_loads = loads
    nb = piece_loads.shape[0]
    npieces = arm[1].size
    scale = arm[7]
    length = arm[6]
    tol, max_iterations, max_load_step, n_fixed, n_max, budget = _read_options(options)
    near = memory is not None and options[_O_NEAR] > 0.0
    # (nb - nb: a variable, not the literal 0, which would compile _record and everything
    # below it a second time, for the type Literal[int](0))
    nt_out = nb - nb if inputs is None else 6
    coarse_ratio = int(options[_O_COARSE])
    info, status, jac = out[3], out[4], out[5]
    width = piece_loads.shape[2]
    n_inputs = 0 if inputs is None else inputs[0].shape[0]
    scratch = _scratch(npieces, width - PIECE_LOADS, 7 + n_inputs)
    start = np.zeros((npieces, width))
    rate = np.empty((1, npieces, width))
    tip_start = np.zeros(TIP_LOADS)
    tip_rate = np.empty((1, TIP_LOADS))
    case = (start, rate, tip_start, tip_rate)
    # the output pass's Jacobian: x, then the inputs; rows 6 + a: tendon a's length's
    J_out = np.empty((6 + width - PIECE_LOADS, 6 + n_inputs))
    r = np.empty(6)
    J = np.empty((6, 7))
    J_c = np.empty((6, 7))
    x = np.zeros(6)
    x_f = np.zeros(6)
    tip_c = np.empty(3)
    tip_f = np.empty(3)
    dscale = np.empty(6)
    six = nt_out * 0 + 6  # not a literal: one compiled version
    seven = six + 1
    t_end = np.empty(6)
    dx_f = np.empty(6)
    # a Newton step of this size at N leaves an error of about its square: far below tol
    final_step = min(1e-3, math.sqrt(0.01 * tol / length)) if math.isfinite(tol) else 1e-9
    reached = np.zeros(2)  # the load factor reached, the sign of det ∂r/∂x there
    J_path = np.empty((6, 6))  # ∂r/∂x at the path's last point
    guard = _guard_work()
    steps = np.empty(npieces, dtype=np.int64)
    counter = np.zeros(1, dtype=np.int64)
    for b in range(nb):
        counter[0] = 0
        # the homotopy of this case: start loads and their rate of change with λ
        if first is not None:
            for j in range(npieces):
                for i in range(width):
                    start[j, i] = first[0][j, i] if b == 0 else piece_loads[b - 1, j, i]
            for i in range(TIP_LOADS):
                tip_start[i] = first[1][i] if b == 0 else tip_loads[b - 1, i]
        for j in range(npieces):
            for i in range(width):
                rate[0, j, i] = piece_loads[b, j, i] - start[j, i]
        for i in range(TIP_LOADS):
            tip_rate[0, i] = tip_loads[b, i] - tip_start[i]
        w, turning = _load_size(arm, act, scale, start, piece_loads[b], tip_start, tip_loads[b])
        threshold = 1e-12 * w + 1e-300
        for i in range(6):
            dscale[i] = scale[i] * (1.0 + w)
        warm = memory is not None and memory[_MVALID] > 0.0
        if n_fixed > 0:
            N = n_fixed // 2
        elif memory is not None and warm:
            N = int(memory[_MN])
        else:
            N = _first_steps(arm, tol, turning)
        N = min(N, n_max // 2)
        status[b] = OK
        estimate = np.inf
        path = True  # the coarse solution must come from the path
        failures = 0
        failed_at = -1.0
        fine_path = False
        recorded = False
        resume = False
        deferred_failed = False
        if memory is not None and near and warm and b == 0:
            # a solution at 2N is known: its coarse partner at N is one correction away (the
            # distance between them is the discretisation error), no path needed
            _fill_steps(length, arm[1], N, np.int64(1), steps)
            for i in range(6):
                x[i] = memory[_MXF + i]
            if _corrector(x, 1.0, six, steps, base, arm, act, case, scratch, scale, dscale, length,
                          threshold, max_iterations, _REFINE_MAX, final_step, r, J, tip_c,
                          counter):
                _copy(J, J_c)
                path = False
                for i in range(6):  # the chord at 2N starts from the known solution
                    x_f[i] = memory[_MXF + i]
                resume = True
                # the output pass from it is also the fine check (a chord integration there
                # would repeat it without the stations): accepted if its residual is
                # converged and the estimate meets tol, else the stages below go on
                _fill_steps(length, arm[1], N, np.int64(2), steps)
                _output(x_f, nt_out, steps, base, arm, act, case, piece_loads[b], tip_loads[b],
                        inputs, scratch, s_out, out, b, r, J, J_out)
                counter[0] += 1
                d2 = 0.0
                for i in range(3):
                    d2 += (scratch[0][_P + i] - tip_c[i]) ** 2
                if _norm_scaled(r, scale) <= threshold and (math.sqrt(d2) / 15.0 <= tol
                                                            or n_fixed > 0):
                    estimate = math.sqrt(d2) / 15.0
                    recorded = True
        if (memory is not None and warm and b == 0 and not near
                and memory[_MPREDICTED] > 0.0 and N == int(memory[_MN])):
            # The path in one step whose tangent is given: the caller knows that only the
            # actuation inputs changed, by Δq, and the last solution's -J_x⁻¹ J_q (its output
            # pass), so the step x(1) - x(0) ≈ -J_x⁻¹ J_q Δq needs no integration at λ = 0.
            # One corrector from that prediction at λ = 1, accepted only as _follow accepts a
            # single step from λ = 0 to 1: near the prediction (within _REFINE_MAX, a third
            # of _follow's _DIST_MAX: a poor prediction costs little), the whole step
            # small enough to be one step (_FIRST_MOTION), det ∂r/∂x of the same sign, the
            # path's tangent turned by less than 60° (in x scaled by the bending scale).
            # Otherwise the path, from the last solution, as without a prediction.
            _fill_steps(length, arm[1], N, np.int64(1), steps)
            for i in range(6):
                x[i] = memory[_MXC + i] + memory[_MSTEP + i]
            if (_corrector(x, 1.0, seven, steps, base, arm, act, case, scratch, scale, dscale,
                           length, threshold, max_iterations, _REFINE_MAX, final_step, r, J,
                           tip_c, counter)
                    and _det_sign(J) == memory[_MSIGN] and _tangent(J, t_end)):
                aa = bb = ab = 0.0
                for i in range(6):
                    dx_f[i] = x[i] - memory[_MXC + i]  # the step taken
                    a = memory[_MSTEP + i] / scale[i]
                    c = t_end[i] / scale[i]
                    aa, bb, ab = aa + a * a, bb + c * c, ab + a * c
                if (_distance(dx_f, scratch[1], dscale, length) <= _FIRST_MOTION
                        and ab >= 0.5 * math.sqrt(aa * bb)):
                    _copy(J, J_c)
                    path = False
                    if nt_out > 0:
                        # The fine solution predicted too: the coarse one plus the last
                        # case's x_2N - x_N (the discretisation's offset, which the inputs'
                        # small change moves by O(h⁴ Δq)). The output pass from it is also
                        # the fine check: accepted, as near's, if it is converged, or if its
                        # Newton step would move the arm by under 1 % of tol (its error is
                        # then that step's size: the residual reported says how far);
                        # otherwise the chord from it, as without the prediction.
                        for i in range(6):
                            x_f[i] = x[i] + memory[_MXF + i] - memory[_MXC + i]
                        resume = True
                        _fill_steps(length, arm[1], N, np.int64(2), steps)
                        _output(x_f, nt_out, steps, base, arm, act, case, piece_loads[b],
                                tip_loads[b], inputs, scratch, s_out, out, b, r, J, J_out)
                        counter[0] += 1
                        d2 = 0.0
                        for i in range(3):
                            d2 += (scratch[0][_P + i] - tip_c[i]) ** 2
                        converged = _norm_scaled(r, scale) <= threshold or (
                            math.isfinite(tol)
                            and _newton_step(J_out if n_inputs > 0 else J, r, dx_f)
                            and _distance(dx_f, scratch[1], dscale, length) * length
                            <= _PREDICTED_FINE * tol)
                        if converged and math.sqrt(d2) / 15.0 <= tol:
                            estimate = math.sqrt(d2) / 15.0
                            recorded = True
        while not recorded:
            if path:
                # the path on a coarse grid (N / coarse_ratio steps) unless that failed
                n_path = N if fine_path or N <= 6 else max(3, (N + coarse_ratio - 1)
                                                           // coarse_ratio)
                _fill_steps(length, arm[1], n_path, np.int64(1), steps)
                for i in range(6):
                    x[i] = 0.0
                    if memory is not None and warm:
                        if n_path == int(memory[_MN]):
                            x[i] = memory[_MXC + i]  # exact at this step count
                        else:
                            x[i] = memory[_MXF + i]  # close: corrected at λ = 0
                coarse = n_path < N  # the last step is corrected on the grid of N
                if not _follow(x, steps, base, arm, act, case, scratch, scale, dscale, length,
                               threshold, max_iterations, max_load_step, budget, coarse,
                               final_step, r, J, tip_c, counter, reached, J_path):
                    if counter[0] > budget:
                        status[b] = BUDGET
                        break
                    if n_path < N:
                        fine_path = True
                        continue
                    if _retry_finer(n_fixed, N, n_max, failures, reached[0], failed_at):
                        failures += 1
                        failed_at = reached[0]
                        N = 2 * N
                        continue
                    status[b] = PATH_FAILED
                    break
                # the coarse solution at N: the end of a path on N steps; from the last
                # prediction of a path on a coarser grid, a checked Newton, which must not
                # cross a singular point either (the path's last step)
                _fill_steps(length, arm[1], N, np.int64(1), steps)
                if coarse and (not _corrector(x, 1.0, six, steps, base, arm, act, case, scratch,
                                              scale, dscale, length, threshold,
                                              max_iterations, _DIST_MAX, final_step, r, J,
                                              tip_c, counter)
                               or _det_sign(J) != reached[1]
                               or _crossed(J_path, J, scale, guard) != 0):
                    fine_path = True
                    continue
                _copy(J, J_c)
            if counter[0] > budget:
                status[b] = BUDGET
                break
            # the fine solution, 2N steps (from the coarse one, or where a check left it)
            _fill_steps(length, arm[1], N, np.int64(2), steps)
            if not resume:
                _copy(x, x_f)
            resume = False
            fine = _chord(x_f, J_c, steps, base, arm, act, case, scratch, scale, threshold,
                          max_iterations, not deferred_failed, r, J, tip_f, counter)
            if fine == 0:
                _copy(x, x_f)
                fine = _corrector(x_f, 1.0, six, steps, base, arm, act, case, scratch, scale,
                                  dscale, length, threshold, max_iterations, _REFINE_MAX, 1e-9,
                                  r, J, tip_f, counter)
                if not fine:
                    if 4 * N > n_max or n_fixed > 0:
                        status[b] = NEWTON_FAILED
                        break
                    N = 2 * N  # the fine solution is not near the coarse one: finer path
                    path = True
                    continue
            d2 = 0.0
            for i in range(3):
                d2 += (tip_f[i] - tip_c[i]) ** 2
            estimate = math.sqrt(d2) / 15.0
            if estimate <= tol or n_fixed > 0:
                if fine == 2:
                    # the output pass integrates the last chord step: it must converge
                    _output(x_f, nt_out, steps, base, arm, act, case, piece_loads[b], tip_loads[b],
                            inputs, scratch, s_out, out, b, r, J, J_out)
                    counter[0] += 1
                    if _norm_scaled(r, scale) <= threshold:
                        recorded = True
                        break
                    path = False
                    resume = True
                    deferred_failed = True  # from now on every chord step is integrated
                    continue  # not converged after all: chord again from here
                break
            if 2 * N >= n_max:
                status[b] = TOO_MANY_STEPS
                break
            # order 4: the coarse N whose fine partner meets tol with a margin
            grow = (estimate / (0.3 * tol)) ** 0.25
            N = min(n_max // 2, max(N + 1, math.ceil(N * grow)))
            _fill_steps(length, arm[1], N, np.int64(1), steps)
            _copy(x_f, x)
            path = not _corrector(x, 1.0, six, steps, base, arm, act, case, scratch, scale, dscale,
                                  length, threshold, max_iterations, _REFINE_MAX, final_step, r, J,
                                  tip_c, counter)
            if not path:
                _copy(J, J_c)
        info[b, 1] = estimate
        info[b, 2] = 1.0 if status[b] == OK else reached[0]
        info[b, 4] = N
        if status[b] != OK:
            info[b, 0] = _norm_scaled(r, scale)
            info[b, 3] = counter[0]
            if status[b] == PATH_FAILED:  # the path's last point on N steps: whether the
                for i in range(6):        # path turns there is for the caller to find out
                    out[7][b, i] = x[i]
            if memory is not None:
                memory[_MVALID] = memory[_MPREDICTED] = 0.0
            continue
        if not recorded:
            _fill_steps(length, arm[1], N, np.int64(2), steps)
            _output(x_f, nt_out, steps, base, arm, act, case, piece_loads[b], tip_loads[b],
                    inputs, scratch, s_out, out, b, r, J, J_out)
            counter[0] += 1
        residual = 0.0
        for i in range(6):
            if not abs(r[i]) <= residual:  # NaN propagates
                residual = abs(r[i])
        info[b, 0] = residual
        info[b, 3] = counter[0]
        if not math.isfinite(residual):
            status[b] = NOT_FINITE
        if inputs is not None:
            for i in range(jac.shape[1]):
                for k in range(jac.shape[2]):
                    jac[b, i, k] = J_out[i, k] if n_inputs else J[i, k]
            if status[b] == OK and not _implicit_function(jac[b], out[6][b]):
                status[b] = SINGULAR
        if memory is not None:
            for i in range(6):
                memory[_MXC + i] = x[i]
                memory[_MXF + i] = x_f[i]
            memory[_MN] = N
            memory[_MVALID] = 1.0 if status[b] == OK else 0.0
            memory[_MSIGN] = _det_sign(J_c)
            memory[_MPREDICTED] = 0.0


@_jit
def _implicit_function(J, E):
    """The implicit function theorem at a solution, in place. Given J (6 + A, 6 + n): rows
    0:6 [J_x | J_q] (∂r/∂x, ∂r/∂inputs), rows 6 + a [E_ℓx | E_ℓq] (actuator a's length per
    x and per input), and E (S, 6, 6 + n): each station's motion [E_x | E_q]. A dead tip
    wrench δW moves x by J_x⁻¹ δW, an input change δq by -J_x⁻¹ J_q δq, so every row
    e = [e_x | e_q] of E and of J's rows 6.. becomes [e_x J_x⁻¹ | e_q - e_x J_x⁻¹ J_q] (the
    compliance, then the actuation Jacobian), and J's rows 0:6 become [J_x⁻¹ | J_x⁻¹ J_q].
    False, nothing changed, if J_x is singular. (In Python, numpy's inverse and products on
    these small arrays cost 45-60 µs a call: a control loop's Python, not its arithmetic.)"""
    m = J.shape[1]
    X = np.empty((6, 6 + m))  # [J_x | I | J_q] -> [· | J_x⁻¹ | J_x⁻¹ J_q]
    for i in range(6):
        for k in range(6):
            X[i, k] = J[i, k]
            X[i, 6 + k] = 1.0 if i == k else 0.0
        for k in range(6, m):
            X[i, 6 + k] = J[i, k]
    if _eliminate_columns(X, m) == 0.0:
        return False
    row = np.empty(m)
    for a in range(6, J.shape[0]):
        _through_x(J[a], X, row)
    for s in range(E.shape[0]):
        for i in range(6):
            _through_x(E[s, i], X, row)
    for i in range(6):
        for k in range(m):
            J[i, k] = X[i, 6 + k]
    return True


@_jit
def _through_x(e, X, row):
    """e = [e_x | e_q] -> [e_x J_x⁻¹ | e_q - e_x J_x⁻¹ J_q] in place, X[:, 6:] = [J_x⁻¹ |
    J_x⁻¹ J_q] (:func:`_implicit_function`); ``row`` scratch of e's size."""
    m = e.size
    for k in range(m):
        acc = 0.0
        for i in range(6):
            acc += e[i] * X[i, 6 + k]
        row[k] = acc
    for k in range(6):
        e[k] = row[k]
    for k in range(6, m):
        e[k] -= row[k]


@_entry(_per_arm("shoot", "the shooting primitive (Solver.shoot)", 5))
def shoot(x, lam, steps, base, arm, act, case, r, J, tip_state, tip_tangents):
    """The shooting primitive: integrate from the base reaction x (6) at load factor λ with
    ``steps`` RK4 steps per piece; returns in place the residual r (6), its Jacobian J
    (6, 6 + R) (columns: ∂r/∂x, then the derivative along each of the case's R rate rows:
    ∂r/∂λ for the homotopy's own), the tip state (18 + A: p, R row-major, n, m spatial, the
    tendon lengths) and the tip tangents (6 + R, 12) (per column: δp spatial, δθ material,
    δn, δm spatial)."""
    scratch = _scratch(arm[1].size, case[0].shape[1] - PIECE_LOADS, J.shape[1])
    _integrate(x, lam, J.shape[1], steps, base, arm, act, case, scratch, r, J)
    _copy(scratch[0], tip_state)
    _copy(scratch[1], tip_tangents)
