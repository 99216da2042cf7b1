"""Compiled kernels of the shooting solver (numba, the only compiled module of softarm).

State along the arm, from the clamped base to the tip: centreline p (3), material frame R
(3×3, row-major), internal force n and moment m in *spatial* components (3 + 3):

    p' = R v,   R' = R û,   n' = -f,   m' = -p' × n,   (v; u) = f⁰ + K⁻¹ (Rᵀn; Rᵀm),

the static Cosserat (Simo–Reissner) rod with the linear law σ = K ε (Grazioso et al. 2018,
eq. 20 written in spatial components of the stress resultant). Point loads make n and m jump.
The unknowns are the base reaction x = (n(0); m(0)); the tip boundary condition is

    r(x) = (n(L) - F_dead - R(L) F_follower;  m(L) - M_dead - R(L) M_follower) = 0.

Integration: classical RK4 on (p, R, n, m) with R projected back onto SO(3) after every step
(one Newton–Schulz / Björck step, R ← R (3I - RᵀR)/2, Hairer–Lubich–Wanner, *Geometric
Numerical Integration*, §IV.4: projection keeps the order 4). The Jacobian ∂r/∂x comes from the
variational equations integrated with the same RK4 stages, with the rotation perturbation
δR = R δθ~ (δθ in material components):

    δθ' = -u × δθ + δu,   δp' = R (δθ × v + δv),   δm' = -δp' × n - p' × δn,   δn' = 0,
    (δv; δu) = K⁻¹ (Rᵀn × δθ + Rᵀδn;  Rᵀm × δθ + Rᵀδm).

Everything per load case (Newton, load stepping, step doubling, output) runs here, so a batch
of cases is one call with no Python in the loop.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["MEMORY", "PIECE_MEMORY", "solve_cases"]

# Status codes returned per load case.
OK = 0
NEWTON_FAILED = 1  # Newton and load stepping did not converge
TOO_MANY_STEPS = 2  # the error estimate stayed above tol up to the largest step count

# Layout of the flat state y (18) and of each tangent row (9).
_P, _R, _N, _M = 0, 3, 12, 15

# What a solved case leaves for the next one (the warm start and its first-order predictor):
# ``memory`` holds the base wrench x (6), the Jacobian ∂r/∂x (36, row-major), the dead and
# follower tip wrenches (6 + 6), the tip rotation R(L) (9, row-major) and position p(L) (3);
# ``piece_memory`` (one row per piece) the distributed force (3), the point wrench at the
# piece start (6), p at the piece start (3) and ∫ p ds over the piece (3).
_MX, _MJ, _MTD, _MTF, _MRL, _MPL = 0, 6, 42, 48, 54, 63
MEMORY = 66
PIECE_MEMORY = 15
# ``memory_level``: 0 nothing, 1 the base wrench only, 2 everything (predictor usable).


@njit(cache=True)
def _cmul(piece_C, j, diag, a0, a1, a2, a3, a4, a5):
    """C a for the compliance C = K⁻¹ of piece j (6 products if ``diag``, else 36)."""
    if diag:
        return (piece_C[j, 0, 0] * a0, piece_C[j, 1, 1] * a1, piece_C[j, 2, 2] * a2,
                piece_C[j, 3, 3] * a3, piece_C[j, 4, 4] * a4, piece_C[j, 5, 5] * a5)
    C = piece_C
    return (C[j, 0, 0] * a0 + C[j, 0, 1] * a1 + C[j, 0, 2] * a2 + C[j, 0, 3] * a3
            + C[j, 0, 4] * a4 + C[j, 0, 5] * a5,
            C[j, 1, 0] * a0 + C[j, 1, 1] * a1 + C[j, 1, 2] * a2 + C[j, 1, 3] * a3
            + C[j, 1, 4] * a4 + C[j, 1, 5] * a5,
            C[j, 2, 0] * a0 + C[j, 2, 1] * a1 + C[j, 2, 2] * a2 + C[j, 2, 3] * a3
            + C[j, 2, 4] * a4 + C[j, 2, 5] * a5,
            C[j, 3, 0] * a0 + C[j, 3, 1] * a1 + C[j, 3, 2] * a2 + C[j, 3, 3] * a3
            + C[j, 3, 4] * a4 + C[j, 3, 5] * a5,
            C[j, 4, 0] * a0 + C[j, 4, 1] * a1 + C[j, 4, 2] * a2 + C[j, 4, 3] * a3
            + C[j, 4, 4] * a4 + C[j, 4, 5] * a5,
            C[j, 5, 0] * a0 + C[j, 5, 1] * a1 + C[j, 5, 2] * a2 + C[j, 5, 3] * a3
            + C[j, 5, 4] * a4 + C[j, 5, 5] * a5)


@njit(cache=True)
def _deriv(work, twork, nt, stage, piece_C, piece_f0, piece_fd, j, diag, lam):
    """F(y) and the variational right-hand side of the first nt tangent rows, on piece j.

    Reads the state y from ``work[4]`` and the tangents from ``twork[4]``; writes F(y) into
    ``work[stage]`` and the tangent derivatives into ``twork[stage]``. Scalars throughout:
    no array views (each costs reference counting in the innermost loop), no scratch array
    (stores into it would alias the state and stop the compiler keeping values in
    registers), no allocation.
    """
    Y = 4
    R00, R01, R02 = work[Y, _R], work[Y, _R + 1], work[Y, _R + 2]
    R10, R11, R12 = work[Y, _R + 3], work[Y, _R + 4], work[Y, _R + 5]
    R20, R21, R22 = work[Y, _R + 6], work[Y, _R + 7], work[Y, _R + 8]
    nx, ny, nz = work[Y, _N], work[Y, _N + 1], work[Y, _N + 2]
    mx, my, mz = work[Y, _M], work[Y, _M + 1], work[Y, _M + 2]
    # σ = (Rᵀn; Rᵀm), material components
    s0 = R00 * nx + R10 * ny + R20 * nz
    s1 = R01 * nx + R11 * ny + R21 * nz
    s2 = R02 * nx + R12 * ny + R22 * nz
    s3 = R00 * mx + R10 * my + R20 * mz
    s4 = R01 * mx + R11 * my + R21 * mz
    s5 = R02 * mx + R12 * my + R22 * mz
    c0, c1, c2, c3, c4, c5 = _cmul(piece_C, j, diag, s0, s1, s2, s3, s4, s5)
    v0, v1, v2 = piece_f0[j, 0] + c0, piece_f0[j, 1] + c1, piece_f0[j, 2] + c2
    u0, u1, u2 = piece_f0[j, 3] + c3, piece_f0[j, 4] + c4, piece_f0[j, 5] + c5
    # p' = R v, R' = R û, n' = -f, m' = -p' × n
    px = R00 * v0 + R01 * v1 + R02 * v2
    py = R10 * v0 + R11 * v1 + R12 * v2
    pz = R20 * v0 + R21 * v1 + R22 * v2
    work[stage, _P] = px
    work[stage, _P + 1] = py
    work[stage, _P + 2] = pz
    work[stage, _R] = R01 * u2 - R02 * u1
    work[stage, _R + 1] = -R00 * u2 + R02 * u0
    work[stage, _R + 2] = R00 * u1 - R01 * u0
    work[stage, _R + 3] = R11 * u2 - R12 * u1
    work[stage, _R + 4] = -R10 * u2 + R12 * u0
    work[stage, _R + 5] = R10 * u1 - R11 * u0
    work[stage, _R + 6] = R21 * u2 - R22 * u1
    work[stage, _R + 7] = -R20 * u2 + R22 * u0
    work[stage, _R + 8] = R20 * u1 - R21 * u0
    work[stage, _N] = -lam * piece_fd[j, 0]
    work[stage, _N + 1] = -lam * piece_fd[j, 1]
    work[stage, _N + 2] = -lam * piece_fd[j, 2]
    work[stage, _M] = -(py * nz - pz * ny)
    work[stage, _M + 1] = -(pz * nx - px * nz)
    work[stage, _M + 2] = -(px * ny - py * nx)
    for d in range(nt):
        th0, th1, th2 = twork[Y, d, 3], twork[Y, d, 4], twork[Y, d, 5]
        dm0, dm1, dm2 = twork[Y, d, 6], twork[Y, d, 7], twork[Y, d, 8]
        # δσ = (Rᵀδn + σ_n × δθ; Rᵀδm + σ_m × δθ), δn = e_d for d < 3, else 0
        e0 = (R00 if d == 0 else (R10 if d == 1 else R20)) if d < 3 else 0.0
        e1 = (R01 if d == 0 else (R11 if d == 1 else R21)) if d < 3 else 0.0
        e2 = (R02 if d == 0 else (R12 if d == 1 else R22)) if d < 3 else 0.0
        c0, c1, c2, c3, c4, c5 = _cmul(
            piece_C, j, diag,
            e0 + s1 * th2 - s2 * th1,
            e1 + s2 * th0 - s0 * th2,
            e2 + s0 * th1 - s1 * th0,
            R00 * dm0 + R10 * dm1 + R20 * dm2 + s4 * th2 - s5 * th1,
            R01 * dm0 + R11 * dm1 + R21 * dm2 + s5 * th0 - s3 * th2,
            R02 * dm0 + R12 * dm1 + R22 * dm2 + s3 * th1 - s4 * th0)
        # δθ × v + δv, rotated to spatial
        a0 = th1 * v2 - th2 * v1 + c0
        a1 = th2 * v0 - th0 * v2 + c1
        a2 = th0 * v1 - th1 * v0 + c2
        q0 = R00 * a0 + R01 * a1 + R02 * a2
        q1 = R10 * a0 + R11 * a1 + R12 * a2
        q2 = R20 * a0 + R21 * a1 + R22 * a2
        twork[stage, d, 0] = q0
        twork[stage, d, 1] = q1
        twork[stage, d, 2] = q2
        twork[stage, d, 3] = -(u1 * th2 - u2 * th1) + c3
        twork[stage, d, 4] = -(u2 * th0 - u0 * th2) + c4
        twork[stage, d, 5] = -(u0 * th1 - u1 * th0) + c5
        # δm' = -δp' × n - p' × δn
        twork[stage, d, 6] = -(q1 * nz - q2 * ny) - (py if d == 2 else 0.0) + (
            pz if d == 1 else 0.0)
        twork[stage, d, 7] = -(q2 * nx - q0 * nz) - (pz if d == 0 else 0.0) + (
            px if d == 2 else 0.0)
        twork[stage, d, 8] = -(q0 * ny - q1 * nx) - (px if d == 1 else 0.0) + (
            py if d == 0 else 0.0)


@njit(cache=True)
def _rk4(y, T, h, piece_C, piece_f0, piece_fd, j, diag, lam, work, twork):
    """One RK4 step of length h on piece j in place (state, and the tangents T (6 or 0
    rows)), then R ← R (3I - RᵀR)/2: one Björck step towards the nearest rotation.

    All loops are written out (no slice assignment, no array expression): numba compiles
    those with shape checks whose error messages pull in its string machinery. No literal
    argument either (the tangent count is T's row count): numba compiles a callee once per
    distinct literal it is called with.
    """
    nt = T.shape[0]
    for stage in range(4):  # work rows 0-3: the stage derivatives; row 4: the stage state
        a = 0.0 if stage == 0 else (h if stage == 3 else 0.5 * h)
        prev = max(stage - 1, 0)
        for i in range(18):
            work[4, i] = y[i] + a * work[prev, i] if stage else y[i]
        for d in range(nt):
            for i in range(9):
                twork[4, d, i] = T[d, i] + a * twork[prev, d, i] if stage else T[d, i]
        _deriv(work, twork, nt, stage, piece_C, piece_f0, piece_fd, j, diag, lam)
    w = h / 6.0
    for i in range(18):
        y[i] += w * (work[0, i] + 2.0 * work[1, i] + 2.0 * work[2, i] + work[3, i])
    for d in range(nt):
        for i in range(9):
            T[d, i] += w * (twork[0, d, i] + 2.0 * twork[1, d, i] + 2.0 * twork[2, d, i]
                            + twork[3, d, i])
    g00 = 1.5 - 0.5 * (y[3] * y[3] + y[6] * y[6] + y[9] * y[9])
    g11 = 1.5 - 0.5 * (y[4] * y[4] + y[7] * y[7] + y[10] * y[10])
    g22 = 1.5 - 0.5 * (y[5] * y[5] + y[8] * y[8] + y[11] * y[11])
    g01 = -0.5 * (y[3] * y[4] + y[6] * y[7] + y[9] * y[10])
    g02 = -0.5 * (y[3] * y[5] + y[6] * y[8] + y[9] * y[11])
    g12 = -0.5 * (y[4] * y[5] + y[7] * y[8] + y[10] * y[11])
    for i in range(3):
        a, b, c = y[_R + 3 * i], y[_R + 3 * i + 1], y[_R + 3 * i + 2]
        y[_R + 3 * i] = a * g00 + b * g01 + c * g02
        y[_R + 3 * i + 1] = a * g01 + b * g11 + c * g12
        y[_R + 3 * i + 2] = a * g02 + b * g12 + c * g22


@njit(cache=True)
def _fill_steps(length, piece_len, N, factor, out):
    """Steps per piece for a nominal N steps over the whole arm (at least one per piece),
    times ``factor`` (2 for the fine solution)."""
    for j in range(piece_len.size):
        out[j] = factor * max(1, math.ceil(N * piece_len[j] / length - 1e-9))


@njit(cache=True)
def _start(y, base, x):
    for i in range(3):
        y[_P + i] = base[i, 3]
        for j in range(3):
            y[_R + 3 * i + j] = base[i, j]
        y[_N + i] = x[i]
        y[_M + i] = x[3 + i]


@njit(cache=True)
def _tip_residual(y, lam, tip_dead, tip_fol, r, tip):
    """The tip position and the boundary residual r of the state y at the tip."""
    for i in range(3):
        tip[i] = y[_P + i]
        R0, R1, R2 = y[_R + 3 * i], y[_R + 3 * i + 1], y[_R + 3 * i + 2]
        rf = R0 * tip_fol[0] + R1 * tip_fol[1] + R2 * tip_fol[2]
        rm = R0 * tip_fol[3] + R1 * tip_fol[4] + R2 * tip_fol[5]
        r[i] = y[_N + i] - lam * (tip_dead[i] + rf)
        r[3 + i] = y[_M + i] - lam * (tip_dead[3 + i] + rm)


@njit(cache=True)
def _shoot(x, lam, steps, base, pieces, loads, r, J, tip, y, T, work, twork):
    """Integrate base → tip from the base reaction x: residual r (6) and, if T has 6 rows,
    the Jacobian J (6×6); with 0 rows the state alone (about half the cost)."""
    nt = T.shape[0]
    piece_len, piece_C, diag, piece_f0, piece_fd = pieces
    jumps, tip_dead, tip_fol = loads
    for d in range(nt):
        for i in range(9):
            T[d, i] = 0.0
    for d in range(nt // 2):
        T[3 + d, 6 + d] = 1.0  # δm(0) = e_d; δn = e_d is implicit (constant)
    _start(y, base, x)
    for j in range(piece_len.size):
        for i in range(6):
            y[_N + i] -= lam * jumps[j, i]
        h = piece_len[j] / steps[j]
        for _ in range(steps[j]):
            _rk4(y, T, h, piece_C, piece_f0, piece_fd, j, diag, lam, work, twork)
    _tip_residual(y, lam, tip_dead, tip_fol, r, tip)
    for d in range(nt):
        th0, th1, th2 = T[d, 3], T[d, 4], T[d, 5]
        for half in range(2):
            F0, F1, F2 = (lam * tip_fol[3 * half], lam * tip_fol[3 * half + 1],
                          lam * tip_fol[3 * half + 2])
            # R (F × δθ)
            c0 = F1 * th2 - F2 * th1
            c1 = F2 * th0 - F0 * th2
            c2 = F0 * th1 - F1 * th0
            for i in range(3):
                J[3 * half + i, d] = (y[_R + 3 * i] * c0 + y[_R + 3 * i + 1] * c1
                                      + y[_R + 3 * i + 2] * c2)
        for i in range(3):
            J[i, d] += 1.0 if d == i else 0.0
            J[3 + i, d] += T[d, 6 + i]


@njit(cache=True)
def _newton_step(A, r, out):
    """out = -A⁻¹ r by Gaussian elimination with partial pivoting; False if singular."""
    M = np.empty((6, 6))
    v = np.empty(6)
    for i in range(6):
        v[i] = -r[i]
        for k in range(6):
            M[i, k] = A[i, k]
    for c in range(6):
        p = c
        best = abs(M[c, c])
        for i in range(c + 1, 6):
            if abs(M[i, c]) > best:
                best = abs(M[i, c])
                p = i
        if not best > 0.0:
            return False
        if p != c:
            for k in range(6):
                M[c, k], M[p, k] = M[p, k], M[c, k]
            v[c], v[p] = v[p], v[c]
        for i in range(c + 1, 6):
            g = M[i, c] / M[c, c]
            for k in range(c, 6):
                M[i, k] -= g * M[c, k]
            v[i] -= g * v[c]
    for c in range(5, -1, -1):
        acc = v[c]
        for k in range(c + 1, 6):
            acc -= M[c, k] * out[k]
        out[c] = acc / M[c, c]
    for c in range(6):
        if not math.isfinite(out[c]):
            return False
    return True


@njit(cache=True)
def _norm_scaled(r, scale):
    out = 0.0
    for i in range(6):
        a = abs(r[i]) / scale[i]
        if not a <= out:  # also catches NaN
            out = a if math.isfinite(a) else np.inf
    return out


@njit(cache=True)
def _solve_load(x, x_warm, warm, steps, base, pieces, loads, scale, threshold,
                max_iterations, continuation, max_step, max_shootings, extrapolate, r, J,
                tip, dtip, y, T, T0, work, twork, counter):
    """Full-load Newton from x_warm; failing that, load stepping from the unloaded arm.

    Newton: each step is limited to ``max_step`` in scaled units (a trust region that keeps
    load stepping on the branch it started from) and halved until the residual decreases.
    When the last two full steps show quadratic convergence that predicts the next residual
    below the threshold, the trial is integrated without tangents (about half the cost) and
    only re-integrated with them if it did not converge after all; with ``extrapolate`` (at
    full load) it is not integrated at all: x takes the step and the tip position its
    linearisation tip + (∂p/∂x) dx (an error of order dx², far below the threshold), which
    is all the coarse solution of the step doubling is used for. Load stepping: λ from 0
    (the unloaded arm, x = 0, exact) to 1, secant predictor, the step doubled after a success
    and halved after a failure, down to 1e-5. True when converged; x, r, J, tip in place.
    """
    dx = np.zeros(6)
    trial = np.empty(6)
    r_trial = np.empty(6)
    J_trial = np.empty((6, 6))
    tip_trial = np.empty(3)
    x_c = np.zeros(6)
    x_p = np.zeros(6)
    lam_c, lam_p = 0.0, 0.0
    have_prev = False
    dl = 1.0
    direct = warm
    for _ in range(400):
        if direct:
            lam = 1.0
            for i in range(6):
                x[i] = x_warm[i]
        else:
            lam = min(1.0, lam_c + dl)
            for i in range(6):
                if have_prev:
                    x[i] = x_c[i] + (lam - lam_c) * (x_c[i] - x_p[i]) / (lam_c - lam_p)
                else:
                    x[i] = x_c[i]
        # a load step with a good predictor converges fast or not at all: fail it early
        budget = max_iterations if direct else min(max_iterations, 8)
        # --- damped Newton at load factor lam, from x ---
        ok = False
        res = np.inf
        res_old = np.inf
        alpha = 0.0
        full = False
        light = False
        iterations = 0
        halvings = 0
        for i in range(6):
            trial[i] = x[i]
        while True:
            _shoot(trial, lam, steps, base, pieces, loads, r_trial, J_trial, tip_trial, y,
                   T0 if light else T, work, twork)
            counter[0] += 1
            res_trial = _norm_scaled(r_trial, scale)
            if res_trial < res or res_trial <= threshold or (iterations == 0 and halvings == 0):
                if light and res_trial > threshold:
                    light = False  # accepted but not converged: its Jacobian is needed
                    continue
                for i in range(6):
                    x[i] = trial[i]
                    r[i] = r_trial[i]
                    if not light:
                        for k in range(6):
                            J[i, k] = J_trial[i, k]
                        for k in range(3):
                            dtip[k, i] = T[i, k]  # ∂p(L)/∂x_i
                for i in range(3):
                    tip[i] = tip_trial[i]
                res_old = res
                res = res_trial
                halvings = 0
                if res <= threshold:
                    ok = True
                    break
                if not math.isfinite(res) or iterations >= budget:
                    break
                if not _newton_step(J, r, dx):
                    break
                size = 0.0
                for i in range(6):
                    size = max(size, abs(dx[i]) / scale[i])
                alpha = 1.0 if size <= max_step else max_step / size
                # e_k+1 ≈ e_k³ / e_k-1² after two full steps (quadratic convergence)
                predicted = res**3 / res_old**2 if full and alpha == 1.0 else np.inf
                light = predicted <= 0.01 * threshold
                if predicted <= threshold and extrapolate and lam >= 1.0:
                    for i in range(6):
                        x[i] += dx[i]
                    for k in range(3):
                        for i in range(6):
                            tip[k] += dtip[k, i] * dx[i]
                    ok = True
                    break
                full = alpha == 1.0
                iterations += 1
            else:
                halvings += 1
                if halvings > 5:
                    break
                alpha *= 0.5
                light = False
                full = False
            for i in range(6):
                trial[i] = x[i] + alpha * dx[i]
        # --- load stepping ---
        if ok and lam >= 1.0:
            return True
        if direct:
            direct = False
            if not continuation:
                return False
        elif ok:
            for i in range(6):
                x_p[i] = x_c[i]
                x_c[i] = x[i]
            lam_p = lam_c
            lam_c = lam
            have_prev = True
            dl = min(2.0 * dl, 1.0 - lam_c)
        else:
            if not continuation:
                return False
            dl *= 0.5
            if dl < 1e-5 or counter[0] > max_shootings:
                return False
    return False


@njit(cache=True)
def _predict(x, memory, piece_memory, pieces, loads, scale, max_step, dx):
    """x ← x_prev - J⁻¹ Δr: the first-order change of the base wrench for the change of the
    loads since the previous case, with Δr the change of the tip residual along the previous
    trajectory (tip loads, point loads and distributed forces; exact to first order for tip
    loads), limited to the trust radius ``max_step``."""
    piece_len, _, _, _, piece_fd = pieces
    jumps, tip_dead, tip_fol = loads
    dr = np.zeros(6)
    for half in range(2):
        for i in range(3):
            k = 3 * half + i
            acc = memory[_MTD + k] - tip_dead[k]
            for j in range(3):
                acc -= memory[_MRL + 3 * i + j] * (tip_fol[3 * half + j]
                                                   - memory[_MTF + 3 * half + j])
            dr[k] = acc
    # A: the force removed from n so far (n(s) = n_prev(s) - A(s)); m' = -p' × n
    A0, A1, A2 = 0.0, 0.0, 0.0
    npieces = piece_len.size
    for j in range(npieces):
        A0 += jumps[j, 0] - piece_memory[j, 3]
        A1 += jumps[j, 1] - piece_memory[j, 4]
        A2 += jumps[j, 2] - piece_memory[j, 5]
        for i in range(3):
            dr[3 + i] -= jumps[j, 3 + i] - piece_memory[j, 6 + i]
        last = j == npieces - 1
        s0 = (memory[_MPL] if last else piece_memory[j + 1, 9]) - piece_memory[j, 9]
        s1 = (memory[_MPL + 1] if last else piece_memory[j + 1, 10]) - piece_memory[j, 10]
        s2 = (memory[_MPL + 2] if last else piece_memory[j + 1, 11]) - piece_memory[j, 11]
        # ∫ (s - s_j) p' ds over the piece = l p(s_j+1) - ∫ p ds
        length = piece_len[j]
        w0 = length * (s0 + piece_memory[j, 9]) - piece_memory[j, 12]
        w1 = length * (s1 + piece_memory[j, 10]) - piece_memory[j, 13]
        w2 = length * (s2 + piece_memory[j, 11]) - piece_memory[j, 14]
        f0 = piece_fd[j, 0] - piece_memory[j, 0]
        f1 = piece_fd[j, 1] - piece_memory[j, 1]
        f2 = piece_fd[j, 2] - piece_memory[j, 2]
        dr[3] += s1 * A2 - s2 * A1 + w1 * f2 - w2 * f1
        dr[4] += s2 * A0 - s0 * A2 + w2 * f0 - w0 * f2
        dr[5] += s0 * A1 - s1 * A0 + w0 * f1 - w1 * f0
        A0 += length * f0
        A1 += length * f1
        A2 += length * f2
    dr[0] -= A0
    dr[1] -= A1
    dr[2] -= A2
    J = np.empty((6, 6))
    for i in range(6):
        x[i] = memory[_MX + i]
        for k in range(6):
            J[i, k] = memory[_MJ + 6 * i + k]
    if not _newton_step(J, dr, dx):
        return
    size = 0.0
    for i in range(6):
        size = max(size, abs(dx[i]) / scale[i])
    alpha = 1.0 if size <= max_step else max_step / size
    for i in range(6):
        x[i] += alpha * dx[i]


@njit(cache=True)
def _record(x, steps, base, pieces, loads, s_out, poses, strains, stresses, r, tip, y, ys,
            T0, work, twork, memory, piece_memory):
    """Integrate the solution x once more, write every station's outputs, and the tip
    residual r and position (the same steps as :func:`_shoot`, so the same numbers: this
    pass doubles as the check of the last chord iteration).

    A station inside a step is reached by its own RK4 step from the start of that step, so
    the stations never change the steps of the solution itself. Also leaves the trajectory
    data of the predictor in ``memory`` and ``piece_memory``.
    """
    piece_len, piece_C, diag, piece_f0, piece_fd = pieces
    jumps, tip_dead, tip_fol = loads
    _start(y, base, x)
    k = 0
    ns = s_out.size
    start = 0.0
    npieces = piece_len.size
    for j in range(npieces):
        for i in range(6):
            y[_N + i] -= jumps[j, i]
        for i in range(3):
            piece_memory[j, 9 + i] = y[_P + i]
            piece_memory[j, 12 + i] = 0.0
        h = piece_len[j] / steps[j]
        end = start + piece_len[j]
        last_piece = j == npieces - 1
        for i in range(steps[j]):
            t0 = start + i * h
            t1 = end if i == steps[j] - 1 else start + (i + 1) * h
            last = last_piece and i == steps[j] - 1
            while True:
                station = k < ns and (s_out[k] < t1 or (last and s_out[k] <= t1))
                for a in range(18):
                    ys[a] = y[a]
                _rk4(ys, T0, s_out[k] - t0 if station else h, piece_C, piece_f0,
                     piece_fd, j, diag, 1.0, work, twork)
                if not station:
                    for a in range(3):  # trapezoidal ∫ p ds
                        piece_memory[j, 12 + a] += 0.5 * h * (y[_P + a] + ys[_P + a])
                    for a in range(18):
                        y[a] = ys[a]
                    break
                _write(ys, piece_C[j], poses[k], strains[k], stresses[k])
                k += 1
        start = end
    for i in range(k, ns):  # only reached through rounding at s = L
        for a in range(4):
            for b in range(4):
                poses[i, a, b] = poses[k - 1, a, b]
        for a in range(6):
            strains[i, a] = strains[k - 1, a]
            stresses[i, a] = stresses[k - 1, a]
    for i in range(9):
        memory[_MRL + i] = y[_R + i]
    for i in range(3):
        memory[_MPL + i] = y[_P + i]
    _tip_residual(y, 1.0, tip_dead, tip_fol, r, tip)


@njit(cache=True)
def _write(y, C, pose, strain, stress):
    for i in range(4):
        for j in range(4):
            pose[i, j] = 0.0
    pose[3, 3] = 1.0
    for i in range(3):
        pose[i, 3] = y[_P + i]
        for j in range(3):
            pose[i, j] = y[_R + 3 * i + j]
    for i in range(3):
        stress[i] = y[_R + i] * y[_N] + y[_R + 3 + i] * y[_N + 1] + y[_R + 6 + i] * y[_N + 2]
        stress[3 + i] = (y[_R + i] * y[_M] + y[_R + 3 + i] * y[_M + 1]
                         + y[_R + 6 + i] * y[_M + 2])
    for i in range(6):
        acc = 0.0
        for k in range(6):
            acc += C[i, k] * stress[k]
        strain[i] = acc


@njit(cache=True)
def _first_guess(length, tol, scale, piece_len, piece_f0, piece_mu, gravity, dist_force,
                 jumps, tip_dead, tip_fol):
    """(load scale, first step count) of a batch.

    The load scale (≥ 1) is the largest load in units of the bending scale; the step count
    comes from an estimate of the total turning of the arm: 0.1 (1 + turning) tol^-1/4.
    """
    fs, ms = scale[0], scale[3]
    tip_f, tip_m, tip_fn, tip_mn, jump, g, gn, dist, distn = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, \
        0.0, 0.0, 0.0
    for b in range(tip_dead.shape[0]):
        fn, mn, gb, db = 0.0, 0.0, 0.0, 0.0
        for i in range(3):
            tip_f = max(tip_f, abs(tip_dead[b, i]) + abs(tip_fol[b, i]))
            tip_m = max(tip_m, abs(tip_dead[b, 3 + i]) + abs(tip_fol[b, 3 + i]))
            fn += (tip_dead[b, i] + tip_fol[b, i]) ** 2
            mn += (tip_dead[b, 3 + i] + tip_fol[b, 3 + i]) ** 2
            g = max(g, abs(gravity[b, i]))
            dist = max(dist, abs(dist_force[b, i]))
            gb += gravity[b, i] ** 2
            db += dist_force[b, i] ** 2
        tip_fn = max(tip_fn, math.sqrt(fn))
        tip_mn = max(tip_mn, math.sqrt(mn))
        gn = max(gn, math.sqrt(gb))
        distn = max(distn, math.sqrt(db))
        for j in range(jumps.shape[1]):
            for i in range(6):
                jump = max(jump, abs(jumps[b, j, i]))
    mu, kappa0 = 0.0, 0.0
    for j in range(piece_len.size):
        mu = max(mu, piece_mu[j])
        kappa0 += piece_len[j] * math.sqrt(piece_f0[j, 3] ** 2 + piece_f0[j, 4] ** 2
                                           + piece_f0[j, 5] ** 2)
    load_scale = max(tip_f / fs, tip_m / ms, jump / fs, (g * mu + dist) * length / fs, 1.0)
    fd = gn * mu + distn
    wrench = (tip_fn * length**2 / 2 + tip_mn * length + jump * length**2
              + fd * length**3 / 6) / (fs * length**2)
    n = math.ceil(0.1 * (1.0 + kappa0 + wrench) * (tol / length) ** -0.25)
    return load_scale, min(256, max(2, n))


@njit(cache=True)
def solve_cases(base, length, piece_len, piece_C, piece_f0, piece_mu, gravity,
                dist_force, jumps, tip_dead, tip_fol, s_out, scale, tol, max_iterations,
                continuation, max_step, n_initial, n_max, max_shootings, memory,
                piece_memory, memory_level, poses, strains, stresses, residual,
                error_estimate, status, work_done):
    """Solve every load case of a flattened batch, each warm-started from the previous one.

    For each case: a first-order prediction of the base wrench from the previous case
    (its solution and Jacobian, and the change of the loads); Newton (with load stepping if
    needed) with N steps; then the 2N-step solution by chord iterations with the N-step
    Jacobian, from the N-step solution, without tangents (full Newton only if they stall).
    The tip positions give the Richardson estimate of the error of the 2N solution,
    |p_2N - p_N| / (2⁴ - 1). N grows (order-4 model) until the estimate is ≤ tol; the 2N
    solution is the result.

    Parameters (B cases, P pieces, S stations)
    ----------
    base : (4, 4) base pose.  piece_* : (P, ...) the arm cut at joints and point loads.
    gravity, dist_force : (B, 3); jumps : (B, P, 6) point wrenches at piece starts (spatial);
    tip_dead : (B, 6) spatial; tip_fol : (B, 6) tip material components.
    scale : (6,) residual scale (the bending scale of forces and moments); tol : tip position
    tolerance in m (inf with a fixed step count). n_initial : first N (0: estimate it).
    Outputs are written into poses (B, S, 4, 4), strains and stresses (B, S, 6), residual,
    error_estimate (B,), status (B,) and work_done (B, 2) (trajectory integrations, final N).
    memory (MEMORY,), piece_memory (P, PIECE_MEMORY), memory_level (1,): the warm start,
    read at the start and overwritten with the last solved case.
    """
    nb = tip_dead.shape[0]
    npieces = piece_len.size
    work = np.empty((6, 24))  # RK4 stages, stage state, scratch
    twork = np.empty((5, 6, 9))
    y = np.empty(18)
    ys = np.empty(18)
    T = np.empty((6, 9))
    T0 = np.empty((0, 9))  # no tangents
    r = np.empty(6)
    J = np.empty((6, 6))
    J_c = np.empty((6, 6))
    dx = np.empty(6)
    tip = np.empty(3)
    tip_c = np.empty(3)
    dtip = np.empty((3, 6))
    x = np.zeros(6)
    x_c = np.empty(6)
    guess = np.zeros(6)
    steps = np.empty(npieces, dtype=np.int64)
    piece_fd = np.empty((npieces, 3))
    counter = np.zeros(1, dtype=np.int64)
    off_diagonal = 0.0
    for j in range(npieces):
        for i in range(6):
            for k in range(6):
                off_diagonal += abs(piece_C[j, i, k]) if i != k else 0.0
    diag = off_diagonal == 0.0  # a computed bool: a literal True would type a second version
    load_scale, n_guess = _first_guess(length, tol, scale, piece_len, piece_f0, piece_mu,
                                       gravity, dist_force, jumps, tip_dead, tip_fol)
    threshold = 1e-12 * load_scale
    N = min(n_initial if n_initial > 0 else n_guess, n_max // 2)
    level = memory_level[0]
    if level > 0:
        for i in range(6):
            x[i] = memory[_MX + i]
    for b in range(nb):
        counter[0] = 0
        for j in range(npieces):
            for i in range(3):
                piece_fd[j, i] = piece_mu[j] * gravity[b, i] + dist_force[b, i]
        pieces = (piece_len, piece_C, diag, piece_f0, piece_fd)
        loads = (jumps[b], tip_dead[b], tip_fol[b])
        if level > 1:
            _predict(guess, memory, piece_memory, pieces, loads, scale, max_step, dx)
        else:
            for i in range(6):
                guess[i] = x[i]
        status[b] = OK
        estimate = np.inf
        stage = 0  # 0: Newton with N steps; 1: chord with 2N; 2: Newton with 2N (fallback)
        recorded = False  # the outputs hold the final solution
        while True:
            _fill_steps(length, piece_len, N, 1 if stage == 0 else 2, steps)
            if stage == 1:
                converged = False
                res_prev = np.inf
                recorded = False  # the first shot, from x_N, never converges
                for _ in range(max_iterations):
                    if recorded:
                        _record(x, steps, base, pieces, loads, s_out, poses[b], strains[b],
                                stresses[b], r, tip, y, ys, T0, work, twork, memory,
                                piece_memory)
                    else:
                        _shoot(x, 1.0, steps, base, pieces, loads, r, J, tip, y, T0, work,
                               twork)
                    counter[0] += 1
                    res = _norm_scaled(r, scale)
                    if res <= threshold:
                        converged = True
                        break
                    if not res < 0.5 * res_prev or not _newton_step(J_c, r, dx):
                        break  # stalled (or NaN): full Newton instead
                    # the chord contraction: observed, or at first ~ 0.1 res (the Jacobians
                    # of N and 2N steps differ by the discretisation error, as r does)
                    rate = res / res_prev if math.isfinite(res_prev) else 0.1 * res
                    # the next pass records the outputs if it should be the last one
                    recorded = rate * res <= threshold
                    res_prev = res
                    for i in range(6):
                        x[i] += dx[i]
                if not converged:
                    for i in range(6):
                        guess[i] = x_c[i]
                    stage = 2
                    recorded = False
                    continue
            else:
                ok = _solve_load(x, guess, level > 0 or stage == 2, steps, base, pieces,
                                 loads, scale, threshold, max_iterations, continuation,
                                 max_step, max_shootings, stage == 0, r, J, tip, dtip, y, T,
                                 T0, work, twork, counter)
                if not ok:
                    status[b] = NEWTON_FAILED
                    break
                if stage == 0:
                    for i in range(6):
                        x_c[i] = x[i]
                        for k in range(6):
                            J_c[i, k] = J[i, k]
                    for i in range(3):
                        tip_c[i] = tip[i]
                    stage = 1
                    continue
            d2 = 0.0
            for i in range(3):
                d2 += (tip[i] - tip_c[i]) ** 2
            estimate = math.sqrt(d2) / 15.0
            if estimate <= tol:
                break
            if 2 * N >= n_max:
                status[b] = TOO_MANY_STEPS
                break
            # order 4: the coarse N whose fine partner meets tol with a margin
            grow = (estimate / (0.3 * tol)) ** 0.25
            N = min(n_max // 2, max(N + 1, math.ceil(N * grow)))
            for i in range(6):
                guess[i] = x[i]
            stage = 0
            recorded = False
            level = max(level, 1)
        residual[b] = 0.0
        for i in range(6):
            if not abs(r[i]) <= residual[b]:  # NaN propagates
                residual[b] = abs(r[i])
        error_estimate[b] = estimate
        work_done[b, 0] = counter[0]
        work_done[b, 1] = N
        if status[b] != OK:
            level = 0
            for i in range(6):
                x[i] = 0.0
            continue
        if not recorded:
            _record(x, steps, base, pieces, loads, s_out, poses[b], strains[b], stresses[b],
                    r, tip, y, ys, T0, work, twork, memory, piece_memory)
        for i in range(6):
            memory[_MX + i] = x[i]
            memory[_MTD + i] = tip_dead[b, i]
            memory[_MTF + i] = tip_fol[b, i]
            for k in range(6):
                memory[_MJ + 6 * i + k] = J_c[i, k]
        for j in range(npieces):
            for i in range(3):
                piece_memory[j, i] = piece_fd[j, i]
            for i in range(6):
                piece_memory[j, 3 + i] = jumps[b, j, i]
        level = 2
        if math.isfinite(tol) and estimate < 0.01 * tol:  # next case: fewer steps may do
            N = max(2, math.ceil(N * (estimate / (0.3 * tol)) ** 0.25))
    memory_level[0] = level
