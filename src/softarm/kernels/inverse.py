"""Bounded Newton steps and inverse statics: the bounded least squares of the bounded
Newton methods (``box_least_squares``, ``regularised_step``) and the compiled iteration of
inverse statics (``inverse_newton``, docs/control.md)."""

from __future__ import annotations

import math

import numpy as np

from ._compile import _entry, _fixed, _jit
from .layout import _P, _R, _TP, _TT, PIECE_LOADS
from .linear import _copy, _small_solve
from .shooting import _norm_scaled, shoot

# ---------------------------------------------------------------------------- bounded steps
#
# Bounded least squares for the bounded Newton methods (displacement-controlled tendons,
# statics/displacement.py; inverse statics, softarm.control), called through
# statics/_bounded.py; beside inverse statics' compiled iteration (``inverse_newton``), which
# calls them.

@_jit
def _free_least_squares(A, b, x, fixed, z, work, rhs):
    """z = x with the free variables replaced by argmin |A z - b|² over them (the fixed ones
    held at x), by Householder QR of the free columns (``work``: A's shape, ``rhs``: b's).
    A free variable whose column is dependent on the others (|R_kk| at round-off of the
    largest) is held at x: the basic solution, which the callers' full-rank A never meets."""
    m, n = A.shape
    k = 0  # the free columns, packed to the left of work
    for i in range(m):
        acc = b[i]
        for j in range(n):
            if fixed[j]:
                acc -= A[i, j] * x[j]
        rhs[i] = acc
    for j in range(n):
        z[j] = x[j]
        if not fixed[j]:
            for i in range(m):
                work[i, k] = A[i, j]
            k += 1
    largest = 0.0
    for c in range(k):  # Householder reflection of column c, applied to the rest and to rhs
        norm = 0.0
        for i in range(c, m):
            norm += work[i, c] * work[i, c]
        norm = math.sqrt(norm)
        if norm == 0.0:
            continue
        alpha = -norm if work[c, c] >= 0.0 else norm
        work[c, c] -= alpha  # v = column - alpha e_c, stored in place below the diagonal
        vv = 0.0
        for i in range(c, m):
            vv += work[i, c] * work[i, c]
        for cc in range(c + 1, k):
            dot = 0.0
            for i in range(c, m):
                dot += work[i, c] * work[i, cc]
            f = 2.0 * dot / vv
            for i in range(c, m):
                work[i, cc] -= f * work[i, c]
        dot = 0.0
        for i in range(c, m):
            dot += work[i, c] * rhs[i]
        f = 2.0 * dot / vv
        for i in range(c, m):
            rhs[i] -= f * work[i, c]
        work[c, c] = alpha  # R's diagonal
        largest = max(largest, abs(alpha))
    solution = np.zeros(k)
    for c in range(k - 1, -1, -1):  # back substitution R u = Qᵀ rhs
        if c >= m or abs(work[c, c]) <= 1e-14 * largest:
            continue
        acc = rhs[c]
        for cc in range(c + 1, k):
            acc -= work[c, cc] * solution[cc]
        solution[c] = acc / work[c, c]
    c = 0
    for j in range(n):
        if not fixed[j]:
            if c < m and abs(work[c, c]) > 1e-14 * largest:
                z[j] = solution[c]
            c += 1


@_entry(_fixed("bounded", "the bounded least squares"))
def box_least_squares(A, b, lower, upper, iterations):
    """argmin |A x - b|² subject to lower <= x <= upper (A of full column rank; 0 feasible),
    by an active-set method (bounded-variable least squares, Stark & Parker 1995): the free
    variables solved by least squares; a variable that would leave its box is fixed at the
    bound it reaches first along the way; a fixed one is freed when the objective's slope
    points into the box. Returns x clipped to the box (the last iterate after ``iterations``
    without convergence)."""
    m, n = A.shape
    x = np.zeros(n)
    z = np.zeros(n)
    fixed = np.zeros(n, dtype=np.bool_)
    work = np.empty((m, n))
    rhs = np.empty(m)
    converged = False
    for _ in range(iterations):
        _free_least_squares(A, b, x, fixed, z, work, rhs)
        first, k = np.inf, -1  # the first free variable to reach a bound on the way x → z
        for j in range(n):
            if fixed[j]:
                continue
            if z[j] < lower[j]:
                t = (lower[j] - x[j]) / (z[j] - x[j])
            elif z[j] > upper[j]:
                t = (upper[j] - x[j]) / (z[j] - x[j])
            else:
                continue
            if t < first:
                first, k = t, j
        if k >= 0:
            t = min(max(first, 0.0), 1.0)
            for j in range(n):
                if not fixed[j]:
                    x[j] += t * (z[j] - x[j])
            x[k] = lower[k] if z[k] < lower[k] else upper[k]
            fixed[k] = True
            continue
        for j in range(n):
            x[j] = z[j]
        best, k = 0.0, -1  # the fixed variable whose slope points most into the box
        for j in range(n):
            if not fixed[j]:
                continue
            g = 0.0  # the objective's slope (half of it), (Aᵀ (A x - b))_j
            for i in range(m):
                r = -b[i]
                for jj in range(n):
                    r += A[i, jj] * x[jj]
                g += A[i, j] * r
            if (x[j] <= lower[j] and g < 0.0) or (x[j] >= upper[j] and g > 0.0):
                if abs(g) > best:
                    best, k = abs(g), j
        if k < 0:
            converged = True
            break
        fixed[k] = False
    for j in range(n):
        x[j] = min(max(x[j], lower[j]), upper[j])
    return x, converged


@_entry(_fixed("bounded", "the bounded least squares"))
def regularised_step(J, b, q, scales, mu, effort, lower, upper, iterations):
    """The bounded Gauss–Newton step of inverse statics, in scaled inputs u = q / s:
    argmin |J' δu - b|² + μ σ² |δu|² + ε σ² |u + δu|² within the bounds, J' = J s (columns
    scaled), σ = |J'|_F, ε = ``effort`` (1e-12 for a redundant task: the least effort along
    its null space; 0 otherwise, where it would only bias the answer); returns δq = s δu.
    The stacked system built here, one call instead of a dozen numpy ones per step."""
    m, n = J.shape
    sigma = 0.0
    for i in range(m):
        for j in range(n):
            sigma += (J[i, j] * scales[j]) ** 2
    sigma = max(math.sqrt(sigma), 1e-300)
    root_eps = math.sqrt(effort)
    A = np.zeros((m + 2 * n, n))
    rhs = np.zeros(m + 2 * n)
    lo = np.empty(n)
    hi = np.empty(n)
    for i in range(m):
        rhs[i] = b[i]
        for j in range(n):
            A[i, j] = J[i, j] * scales[j]
    for j in range(n):
        u = q[j] / scales[j]
        A[m + j, j] = math.sqrt(mu) * sigma
        A[m + n + j, j] = root_eps * sigma
        rhs[m + n + j] = -root_eps * sigma * u
        lo[j] = lower[j] / scales[j] - u
        hi[j] = upper[j] / scales[j] - u
    step, _ = box_least_squares(A, rhs, lo, hi, iterations)
    for j in range(n):
        step[j] *= scales[j]
    return step


# ---------------------------------------------------------------------------- inverse statics
#
# The fast route of softarm.control (docs/control.md): Newton on the base reaction x and the
# actuation inputs q together, one integration with the input columns per iteration, each
# step a bounded least-squares problem. Compiled whole: in Python the iteration's small numpy
# calls cost three times its integrations.

# inverse_newton's outcomes (info[0]): the stop rule met; the iteration cap; the merit grew
# (diverging); J_x singular or a value not finite.
NEWTON_DONE, NEWTON_CAP, NEWTON_DIVERGED, NEWTON_SINGULAR = 0, 1, 2, 3
#: The weight of the least effort along a redundant task's null space (regularised_step's
#: ε: it moves the task solution by about 1e-12 relative)
EFFORT = 1e-12


@_jit
def _rotation_log(Q, out):
    """out = log(Q), the rotation vector of the rotation matrix Q (|out| <= π): from the
    skew part away from π, from the symmetric part near it (the skew part vanishes there)."""
    w0, w1, w2 = Q[2, 1] - Q[1, 2], Q[0, 2] - Q[2, 0], Q[1, 0] - Q[0, 1]
    sine = 0.5 * math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    cosine = 0.5 * (Q[0, 0] + Q[1, 1] + Q[2, 2] - 1.0)
    angle = math.atan2(sine, cosine)
    if angle < 1e-4:
        f = 0.5 + angle * angle / 12.0  # θ / (2 sin θ)
    elif angle < 3.0:
        f = 0.5 * angle / math.sin(angle)
    else:
        # near π: Q + Qᵀ = 2 cos θ I + 2 (1 - cos θ) a aᵀ; the axis from its largest diagonal
        # entry's column, the sign from the skew part
        d = 0
        for i in range(1, 3):
            if Q[i, i] > Q[d, d]:
                d = i
        a = np.empty(3)
        for i in range(3):
            a[i] = 0.5 * (Q[i, d] + Q[d, i]) - (cosine if i == d else 0.0)
        norm = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
        if w0 * a[0] + w1 * a[1] + w2 * a[2] < 0.0:
            norm = -norm
        for i in range(3):
            out[i] = angle * a[i] / norm
        return
    out[0], out[1], out[2] = f * w0, f * w1, f * w2


@_entry(_fixed("inverse", "inverse statics"))
def task_error(tip, target, orientation, length, e):
    """The weighted task error at the tip state ``tip`` (p, R row-major): e[:3] = (target - p)
    / L and, with a 6-row task, e[3:] = log(orientation Rᵀ) (spatial, rad)."""
    for i in range(3):
        e[i] = (target[i] - tip[_P + i]) / length
    if e.size == 6:
        Q = np.empty((3, 3))
        for i in range(3):
            for j in range(3):
                Q[i, j] = (orientation[i, 0] * tip[_R + 3 * j] + orientation[i, 1]
                           * tip[_R + 3 * j + 1] + orientation[i, 2] * tip[_R + 3 * j + 2])
        _rotation_log(Q, e[3:])


@_jit
def _task_size(e):
    """|δp|/L, or with an orientation the larger of that and |δθ| (rad)."""
    p = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
    r = e[3] * e[3] + e[4] * e[4] + e[5] * e[5] if e.size == 6 else 0.0
    return math.sqrt(max(p, r))


@_entry(_fixed("inverse", "inverse statics"))
def redundant_task(singular, n):
    """Whether a task Jacobian with these singular values (largest first) has a rank below
    its n inputs (values at most 1e-10 n σ₁ count as zero): the least-effort term then
    picks the answer among many (softarm.control)."""
    rank = 0
    for v in singular:
        if v > 1e-10 * n * singular[0]:
            rank += 1
    return n > rank


@_jit
def _scaled_singular_values(J, scales, out):
    """out = the singular values of J diag(scales), largest first."""
    Js = np.empty(J.shape)
    for i in range(J.shape[0]):
        for c in range(J.shape[1]):
            Js[i, c] = J[i, c] * scales[c]
    values = np.linalg.svd(Js)[1]
    for i in range(out.size):
        out[i] = values[i]


@_entry(_fixed("inverse", "inverse statics"))
def inverse_newton(x, q, every, first, steps, base, arm, act, units, goal, bounds, settings, warm,
                   out, info):
    """The fast route's iteration of inverse statics (softarm.control), in place on x (6)
    and q (n), from a solution of the same grid nearby.

    Per iteration one integration from x with the inputs q (``every``, every input of the
    loads, the actuators' at [first, first + n), updated with q): the residual r, J_x, J_q and
    the tip's motion E_x, E_q (spatial); G = J_x⁻¹ [r | J_q], A = E_q - E_x G[:, 1:] (the
    actuation Jacobian), the task error e at the tip and as linearised to the equilibrium,
    rhs = e + w (E_x G[:, 0]); the bounded step δq (``regularised_step``, μ = 0), then
    x -= G[:, 0] + G[:, 1:] δq. With ``warm`` (a solution: r = 0), the first step needs no
    integration: its tip, A and G are given, and the second-order term of the last target
    (its ``miss``, scaled by f = α², α the projection of this task step on that one, if
    0 < f <= 4) is added. Stops at an integration whose task error is within tol / 2, also
    as linearised, with max |r_i|/scale_i <= 1e-6 and, when the task is redundant, a step
    below 1e-7 relative (the least effort reached); the step from there is taken.

    units : (piece0 (P, W), unit piece (m, P, W), tip0 (12,), unit tip (m, 12)): the load
        channels at zero inputs and per unit input.
    goal : (target (3,), orientation (3, 3), weights w (t,)): t = 3 (position) or 6 (pose).
    bounds : (lower (n,), upper (n,), scales (n,)).
    settings : (tol, max_iterations, length, redundant: -1 unknown, 0, 1).
    warm : (flag (1,): 1.0 to take the warm step, tip state (12,), A (6, n), G (6, 1 + n),
        miss flag (1,), miss q (n,), miss x (6,), miss task step (t,)).
    out : (A (6, n), G (6, 1 + n), J (t, n), linear: x (6), q (n), its linear prediction
        (n), G (6, 1 + n), its task step (t,), the singular values of J s (min(t, n),)) at
        the end; linear is the warm step's.
    info : (outcome, iterations, redundant, warm step taken) on return.
    """
    n = q.size
    m = every.size
    t = goal[2].size
    tol, max_iterations, length = settings[0], int(settings[1]), settings[2]
    redundant = int(settings[3])
    piece0, unit_piece, tip0, unit_tip = units
    target, orientation, w = goal
    lower, upper, scales = bounds
    A, G, J, singular = out[0], out[1], out[2], out[4]
    scale = arm[7]
    P, W = piece0.shape
    piece = np.empty((P, W))
    tipv = np.empty(tip0.size)
    case = (piece, unit_piece, tipv, unit_tip)
    r = np.empty(6)
    x_shot = np.empty(6)
    Jfull = np.empty((6, 6 + m))
    y = np.empty(18 + W - PIECE_LOADS)
    T = np.empty((6 + m, 12 + W - PIECE_LOADS))
    E = np.empty((6, 6 + m))
    B = np.empty((6, 1 + n))
    work = np.empty((6, 7 + n))
    e = np.empty(t)
    rhs = np.empty(t)
    trial = np.empty(n)
    tip = np.empty(12)
    info[2] = redundant
    info[3] = 0.0
    warm_step = warm[0][0] > 0.0
    merit = np.inf
    iterations = 0
    while True:
        iterations += 1
        info[1] = iterations
        if iterations > max_iterations:
            info[0] = NEWTON_CAP
            return
        if warm_step:
            _copy(warm[1], tip)
            for i in range(6):
                for c in range(n):
                    A[i, c] = warm[2][i, c]
                for c in range(1 + n):
                    G[i, c] = warm[3][i, c]
            task_error(tip, target, orientation, length, e)
            for i in range(t):
                rhs[i] = e[i]
        else:
            for c in range(n):
                every[first + c] = q[c]
            for j in range(P):
                for i in range(W):
                    acc = piece0[j, i]
                    for k in range(m):
                        acc += every[k] * unit_piece[k, j, i]
                    piece[j, i] = acc
            for i in range(tip0.size):
                acc = tip0[i]
                for k in range(m):
                    acc += every[k] * unit_tip[k, i]
                tipv[i] = acc
            _copy(x, x_shot)
            shoot(x_shot, 0.0, steps, base, arm, act, case, r, Jfull, y, T)
            for c in range(6 + m):  # the tip's motion per column, spatial
                for i in range(3):
                    E[i, c] = T[c, _TP + i]
                    E[3 + i, c] = (y[_R + 3 * i] * T[c, _TT] + y[_R + 3 * i + 1] * T[c, _TT + 1]
                                   + y[_R + 3 * i + 2] * T[c, _TT + 2])
            for i in range(6):
                B[i, 0] = r[i]
                for c in range(n):
                    B[i, 1 + c] = Jfull[i, 6 + first + c]
            if not _small_solve(Jfull, B, np.int64(6), work, G):
                info[0] = NEWTON_SINGULAR
                return
            for i in range(6):
                for c in range(n):
                    acc = E[i, 6 + first + c]
                    for k in range(6):
                        acc -= E[i, k] * G[k, 1 + c]
                    A[i, c] = acc
            task_error(y, target, orientation, length, e)
            for i in range(t):
                acc = 0.0
                for k in range(6):
                    acc += E[i, k] * G[k, 0]
                rhs[i] = e[i] + w[i] * acc
        for i in range(t):
            for c in range(n):
                J[i, c] = w[i] * A[i, c]
        if redundant < 0:
            _scaled_singular_values(J, scales, singular)
            redundant = 1 if redundant_task(singular, n) else 0
            info[2] = redundant
        step = regularised_step(J, rhs, q, scales, 0.0, EFFORT if redundant else 0.0, lower,
                                upper, np.int64(100))
        for c in range(n):
            trial[c] = min(max(q[c] + step[c], lower[c]), upper[c])
        if warm_step:
            warm_step = False
            info[3] = 1.0
            linear = out[3]
            _copy(x, linear[0])
            _copy(q, linear[1])
            _copy(trial, linear[2])
            for i in range(6):
                for c in range(1 + n):
                    linear[3][i, c] = G[i, c]
            _copy(e, linear[4])
            factor = 0.0
            if warm[4][0] > 0.0:  # the second-order term carried over (f = α²)
                last = warm[7]
                norm = 0.0
                dot = 0.0
                for i in range(t):
                    norm += last[i] * last[i]
                    dot += e[i] * last[i]
                if norm > 0.0:
                    factor = (dot / norm) ** 2
                if not (0.0 < factor <= 4.0):
                    factor = 0.0
            for c in range(n):
                if factor > 0.0:
                    trial[c] = min(max(trial[c] + factor * warm[5][c], lower[c]), upper[c])
            for i in range(6):
                acc = factor * warm[6][i]
                for c in range(n):
                    acc -= G[i, 1 + c] * (trial[c] - q[c])
                x[i] += acc
            _copy(trial, q)
            continue
        size = _task_size(e)
        residual = _norm_scaled(r, scale)
        if not math.isfinite(size + residual):
            info[0] = NEWTON_SINGULAR
            return
        if size + residual > 2.0 * merit:
            info[0] = NEWTON_DIVERGED
            return
        merit = size + residual
        biggest_step, biggest_q = 0.0, 0.0
        for c in range(n):
            biggest_step = max(biggest_step, abs(trial[c] - q[c]) / scales[c])
            biggest_q = max(biggest_q, abs(q[c]) / scales[c])
        for i in range(6):
            acc = G[i, 0]
            for c in range(n):
                acc += G[i, 1 + c] * (trial[c] - q[c])
            x[i] -= acc
        _copy(trial, q)
        # stop at an integration that shows the task within tol, also as linearised to the
        # equilibrium, with the residual small enough for that linearisation (the step taken
        # from there only improves them; the solve at the answer checks). Not earlier: along
        # the inputs' weak direction (equal tensions compress the arm) the second-order terms
        # are large, and a step from a task error of 1e-4 was measured to leave 2e-7, not 1e-8
        if (size <= 0.5 * tol and _task_size(rhs) <= 0.5 * tol and residual <= 1e-6
                and (redundant == 0 or biggest_step <= 1e-7 * (1.0 + biggest_q))):
            _scaled_singular_values(J, scales, singular)  # (its condition, reported)
            info[0] = NEWTON_DONE
            return
