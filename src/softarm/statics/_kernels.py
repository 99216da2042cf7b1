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

__all__ = ["solve_cases"]

# Status codes returned per load case.
OK = 0
NEWTON_FAILED = 1  # Newton and load stepping did not converge
TOO_MANY_STEPS = 2  # the error estimate stayed above tol up to the largest step count

# Layout of the flat state y (18) and of each tangent row (9).
_P, _R, _N, _M = 0, 3, 12, 15


@njit(cache=True)
def _deriv(y, T, C, f0, fd, lam, dy, dT, scratch):
    """dy = F(y), and dT = the variational right-hand side for each row of T (6 or none).

    ``scratch`` (24) holds σ, f, δσ, δf: no allocation in the inner loop.
    """
    R = y[_R:_R + 9]
    sig = scratch[0:6]
    f = scratch[6:12]
    dsig = scratch[12:18]
    df = scratch[18:24]
    for i in range(3):
        sig[i] = R[i] * y[_N] + R[3 + i] * y[_N + 1] + R[6 + i] * y[_N + 2]
        sig[3 + i] = R[i] * y[_M] + R[3 + i] * y[_M + 1] + R[6 + i] * y[_M + 2]
    for i in range(6):
        acc = f0[i]
        for k in range(6):
            acc += C[i, k] * sig[k]
        f[i] = acc
    v0, v1, v2 = f[0], f[1], f[2]
    u0, u1, u2 = f[3], f[4], f[5]
    for i in range(3):
        r0, r1, r2 = R[3 * i], R[3 * i + 1], R[3 * i + 2]
        dy[_P + i] = r0 * v0 + r1 * v1 + r2 * v2
        # row i of R û: (R û)_ij = Σ_k R_ik û_kj
        dy[_R + 3 * i] = r1 * u2 - r2 * u1
        dy[_R + 3 * i + 1] = -r0 * u2 + r2 * u0
        dy[_R + 3 * i + 2] = r0 * u1 - r1 * u0
        dy[_N + i] = -lam * fd[i]
    px, py, pz = dy[_P], dy[_P + 1], dy[_P + 2]
    nx, ny, nz = y[_N], y[_N + 1], y[_N + 2]
    dy[_M] = -(py * nz - pz * ny)
    dy[_M + 1] = -(pz * nx - px * nz)
    dy[_M + 2] = -(px * ny - py * nx)
    for d in range(T.shape[0]):
        th0, th1, th2 = T[d, 3], T[d, 4], T[d, 5]
        # Rᵀ δn (δn = e_d for d < 3, else 0) and Rᵀ δm
        dm0, dm1, dm2 = T[d, 6], T[d, 7], T[d, 8]
        for i in range(3):
            rtdm = R[i] * dm0 + R[3 + i] * dm1 + R[6 + i] * dm2
            rtdn = R[3 * d + i] if d < 3 else 0.0
            dsig[i] = rtdn
            dsig[3 + i] = rtdm
        # + σ × δθ
        dsig[0] += sig[1] * th2 - sig[2] * th1
        dsig[1] += sig[2] * th0 - sig[0] * th2
        dsig[2] += sig[0] * th1 - sig[1] * th0
        dsig[3] += sig[4] * th2 - sig[5] * th1
        dsig[4] += sig[5] * th0 - sig[3] * th2
        dsig[5] += sig[3] * th1 - sig[4] * th0
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += C[i, k] * dsig[k]
            df[i] = acc
        # δθ × v + δv, rotated to spatial
        a0 = th1 * v2 - th2 * v1 + df[0]
        a1 = th2 * v0 - th0 * v2 + df[1]
        a2 = th0 * v1 - th1 * v0 + df[2]
        q0 = R[0] * a0 + R[1] * a1 + R[2] * a2
        q1 = R[3] * a0 + R[4] * a1 + R[5] * a2
        q2 = R[6] * a0 + R[7] * a1 + R[8] * a2
        dT[d, 0] = q0
        dT[d, 1] = q1
        dT[d, 2] = q2
        dT[d, 3] = -(u1 * th2 - u2 * th1) + df[3]
        dT[d, 4] = -(u2 * th0 - u0 * th2) + df[4]
        dT[d, 5] = -(u0 * th1 - u1 * th0) + df[5]
        dT[d, 6] = -(q1 * nz - q2 * ny)
        dT[d, 7] = -(q2 * nx - q0 * nz)
        dT[d, 8] = -(q0 * ny - q1 * nx)
        if d < 3:  # - p' × e_d
            if d == 0:
                dT[d, 7] -= pz
                dT[d, 8] += py
            elif d == 1:
                dT[d, 6] += pz
                dT[d, 8] -= px
            else:
                dT[d, 6] -= py
                dT[d, 7] += px


@njit(cache=True)
def _project(y):
    """R ← R (3I - RᵀR)/2: one Björck step towards the nearest rotation (error squared)."""
    R = y[_R:_R + 9]
    g00 = 1.5 - 0.5 * (R[0] * R[0] + R[3] * R[3] + R[6] * R[6])
    g11 = 1.5 - 0.5 * (R[1] * R[1] + R[4] * R[4] + R[7] * R[7])
    g22 = 1.5 - 0.5 * (R[2] * R[2] + R[5] * R[5] + R[8] * R[8])
    g01 = -0.5 * (R[0] * R[1] + R[3] * R[4] + R[6] * R[7])
    g02 = -0.5 * (R[0] * R[2] + R[3] * R[5] + R[6] * R[8])
    g12 = -0.5 * (R[1] * R[2] + R[4] * R[5] + R[7] * R[8])
    for i in range(3):
        a, b, c = R[3 * i], R[3 * i + 1], R[3 * i + 2]
        R[3 * i] = a * g00 + b * g01 + c * g02
        R[3 * i + 1] = a * g01 + b * g11 + c * g12
        R[3 * i + 2] = a * g02 + b * g12 + c * g22


@njit(cache=True)
def _rk4(y, T, h, C, f0, fd, lam, work, twork):
    """One RK4 step of length h in place (state, and the tangents T (6 or 0 rows)), project R.

    (Each compiled function calls its callees from one place only: LLVM inlines every call
    site, and keeping them single keeps the compile time low.)
    """
    ys = work[4]
    ts = twork[4]
    for stage in range(4):  # work rows 0-3: the stage derivatives
        a = 0.0 if stage == 0 else (h if stage == 3 else 0.5 * h)
        prev = max(stage - 1, 0)
        for i in range(18):
            ys[i] = y[i] + a * work[prev, i] if stage else y[i]
        for d in range(T.shape[0]):
            for i in range(9):
                ts[d, i] = T[d, i] + a * twork[prev, d, i] if stage else T[d, i]
        _deriv(ys, ts, C, f0, fd, lam, work[stage], twork[stage], work[5])
    w = h / 6.0
    for i in range(18):
        y[i] += w * (work[0, i] + 2.0 * work[1, i] + 2.0 * work[2, i] + work[3, i])
    for d in range(T.shape[0]):
        for i in range(9):
            T[d, i] += w * (twork[0, d, i] + 2.0 * twork[1, d, i] + 2.0 * twork[2, d, i]
                            + twork[3, d, i])
    _project(y)


@njit(cache=True)
def _steps(length, piece_len, N):
    """Steps per piece for a nominal N steps over the whole arm (at least one per piece)."""
    out = np.empty(piece_len.size, dtype=np.int64)
    for j in range(piece_len.size):
        out[j] = max(1, math.ceil(N * piece_len[j] / length - 1e-9))
    return out


@njit(cache=True)
def _start(y, base, x):
    for i in range(3):
        y[_P + i] = base[i, 3]
        for j in range(3):
            y[_R + 3 * i + j] = base[i, j]
        y[_N + i] = x[i]
        y[_M + i] = x[3 + i]


@njit(cache=True)
def _shoot(x, lam, steps, base, piece_len, piece_C, piece_f0, piece_fd, jumps, tip_dead,
           tip_fol, r, J, tip, work, twork):
    """Integrate base → tip from the base reaction x; residual r (6), Jacobian J (6×6)."""
    y = np.empty(18)
    T = np.zeros((6, 9))
    for d in range(3):
        T[3 + d, 6 + d] = 1.0  # δm(0) = e_d; δn = e_d is implicit (constant)
    _start(y, base, x)
    for j in range(piece_len.size):
        for i in range(6):
            y[_N + i] -= lam * jumps[j, i]
        h = piece_len[j] / steps[j]
        for _ in range(steps[j]):
            _rk4(y, T, h, piece_C[j], piece_f0[j], piece_fd[j], lam, work, twork)
    R = y[_R:_R + 9]
    for i in range(3):
        tip[i] = y[_P + i]
        rf = R[3 * i] * tip_fol[0] + R[3 * i + 1] * tip_fol[1] + R[3 * i + 2] * tip_fol[2]
        rm = R[3 * i] * tip_fol[3] + R[3 * i + 1] * tip_fol[4] + R[3 * i + 2] * tip_fol[5]
        r[i] = y[_N + i] - lam * (tip_dead[i] + rf)
        r[3 + i] = y[_M + i] - lam * (tip_dead[3 + i] + rm)
    for d in range(6):
        th0, th1, th2 = T[d, 3], T[d, 4], T[d, 5]
        for half in range(2):
            F0, F1, F2 = (lam * tip_fol[3 * half], lam * tip_fol[3 * half + 1],
                          lam * tip_fol[3 * half + 2])
            # R (F × δθ)
            c0 = F1 * th2 - F2 * th1
            c1 = F2 * th0 - F0 * th2
            c2 = F0 * th1 - F1 * th0
            for i in range(3):
                J[3 * half + i, d] = R[3 * i] * c0 + R[3 * i + 1] * c1 + R[3 * i + 2] * c2
        for i in range(3):
            J[i, d] += 1.0 if d == i else 0.0
            J[3 + i, d] += T[d, 6 + i]


@njit(cache=True)
def _solve6(A, b, out):
    """out = A⁻¹ b by Gaussian elimination with partial pivoting; False if singular."""
    M = A.copy()
    v = b.copy()
    n = 6
    for c in range(n):
        p = c
        best = abs(M[c, c])
        for i in range(c + 1, n):
            if abs(M[i, c]) > best:
                best = abs(M[i, c])
                p = i
        if not best > 0.0:
            return False
        if p != c:
            for k in range(n):
                M[c, k], M[p, k] = M[p, k], M[c, k]
            v[c], v[p] = v[p], v[c]
        for i in range(c + 1, n):
            g = M[i, c] / M[c, c]
            for k in range(c, n):
                M[i, k] -= g * M[c, k]
            v[i] -= g * v[c]
    for c in range(n - 1, -1, -1):
        acc = v[c]
        for k in range(c + 1, n):
            acc -= M[c, k] * out[k]
        out[c] = acc / M[c, c]
    for c in range(n):
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
def _newton(x, lam, steps, base, pieces, loads, scale, threshold, max_iterations,
            max_step, r, J, tip, work, twork, counter):
    """Damped Newton on r(x) = 0 at load factor lam; x in place. True when converged.

    Each step is limited to ``max_step`` in scaled units (a trust region that keeps load
    stepping on the branch it started from) and halved until the residual decreases.
    """
    piece_len, piece_C, piece_f0, piece_fd = pieces
    jumps, tip_dead, tip_fol = loads
    dx = np.zeros(6)
    trial = x.copy()
    r_trial = np.empty(6)
    J_trial = np.empty((6, 6))
    res = np.inf
    alpha = 0.0
    iterations = 0
    halvings = 0
    while True:
        _shoot(trial, lam, steps, base, piece_len, piece_C, piece_f0, piece_fd, jumps,
               tip_dead, tip_fol, r_trial, J_trial, tip, work, twork)
        counter[0] += 1
        res_trial = _norm_scaled(r_trial, scale)
        if res_trial < res or res_trial <= threshold or (iterations == 0 and halvings == 0):
            x[:] = trial
            r[:] = r_trial
            J[:, :] = J_trial
            res = res_trial
            halvings = 0
            if res <= threshold:
                return True
            if not math.isfinite(res) or iterations >= max_iterations:
                return False
            if not _solve6(J, -r, dx):
                return False
            size = 0.0
            for i in range(6):
                size = max(size, abs(dx[i]) / scale[i])
            alpha = 1.0 if size <= max_step else max_step / size
            iterations += 1
        else:
            halvings += 1
            if halvings > 5:
                return False
            alpha *= 0.5
        for i in range(6):
            trial[i] = x[i] + alpha * dx[i]


@njit(cache=True)
def _continuation(x, x_warm, warm, steps, base, pieces, loads, scale, threshold,
                  max_iterations, continuation, max_step, max_shootings, r, J, tip, work,
                  twork, counter):
    """Full-load Newton from x_warm; failing that, load stepping from the unloaded arm.

    Load stepping: λ from 0 (the unloaded arm, x = 0, exact) to 1, secant predictor, the step
    doubled after a success and halved after a failure, down to 1e-5.
    """
    lam_c, lam_p = 0.0, 0.0
    x_c = np.zeros(6)
    x_p = np.zeros(6)
    have_prev = False
    dl = 1.0
    direct = warm
    for _ in range(400):
        if direct:
            lam_t = 1.0
            x[:] = x_warm
        else:
            lam_t = min(1.0, lam_c + dl)
            for i in range(6):
                if have_prev:
                    x[i] = x_c[i] + (lam_t - lam_c) * (x_c[i] - x_p[i]) / (lam_c - lam_p)
                else:
                    x[i] = x_c[i]
        # a load step with a good predictor converges fast or not at all: fail it early
        budget = max_iterations if direct else min(max_iterations, 8)
        ok = _newton(x, lam_t, steps, base, pieces, loads, scale, threshold, budget,
                     max_step, r, J, tip, work, twork, counter)
        if ok and lam_t >= 1.0:
            return True
        if direct:
            direct = False
            if not continuation:
                return False
        elif ok:
            x_p[:] = x_c
            lam_p = lam_c
            x_c[:] = x
            lam_c = lam_t
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
def _record(x, steps, base, pieces, jumps, s_out, poses, strains, stresses, work, twork):
    """Integrate the converged solution once more and write every station's outputs.

    A station inside a step is reached by its own RK4 step from the start of that step, so
    the stations never change the steps of the solution itself.
    """
    piece_len, piece_C, piece_f0, piece_fd = pieces
    y = np.empty(18)
    ys = np.empty(18)
    T = np.zeros((0, 9))  # no tangents
    _start(y, base, x)
    k = 0
    ns = s_out.size
    start = 0.0
    npieces = piece_len.size
    for j in range(npieces):
        for i in range(6):
            y[_N + i] -= jumps[j, i]
        h = piece_len[j] / steps[j]
        end = start + piece_len[j]
        last_piece = j == npieces - 1
        for i in range(steps[j]):
            t0 = start + i * h
            t1 = end if i == steps[j] - 1 else start + (i + 1) * h
            last = last_piece and i == steps[j] - 1
            while True:
                station = k < ns and (s_out[k] < t1 or (last and s_out[k] <= t1))
                ys[:] = y
                _rk4(ys, T, s_out[k] - t0 if station else h, piece_C[j], piece_f0[j],
                     piece_fd[j], 1.0, work, twork)
                if not station:
                    y[:] = ys
                    break
                _write(ys, piece_C[j], poses[k], strains[k], stresses[k])
                k += 1
        start = end
    for i in range(k, ns):  # only reached through rounding at s = L
        for a in range(4):
            for b in range(4):
                poses[i, a, b] = poses[k - 1, a, b]
        strains[i] = strains[k - 1]
        stresses[i] = stresses[k - 1]


@njit(cache=True)
def _write(y, C, pose, strain, stress):
    R = y[_R:_R + 9]
    for i in range(4):
        for j in range(4):
            pose[i, j] = 0.0
    pose[3, 3] = 1.0
    for i in range(3):
        pose[i, 3] = y[_P + i]
        for j in range(3):
            pose[i, j] = R[3 * i + j]
    for i in range(3):
        stress[i] = R[i] * y[_N] + R[3 + i] * y[_N + 1] + R[6 + i] * y[_N + 2]
        stress[3 + i] = R[i] * y[_M] + R[3 + i] * y[_M + 1] + R[6 + i] * y[_M + 2]
    for i in range(6):
        acc = 0.0
        for k in range(6):
            acc += C[i, k] * stress[k]
        strain[i] = acc


@njit(cache=True)
def solve_cases(base, length, piece_len, piece_C, piece_f0, piece_mu, gravity,
                dist_force, jumps, tip_dead, tip_fol, s_out, scale, threshold, tol,
                max_iterations, continuation, max_step, n_initial, n_max, max_shootings,
                x_start, warm_start,
                poses, strains, stresses, residual, error_estimate, status, work_done):
    """Solve every load case of a flattened batch, each warm-started from the previous one.

    For each case: Newton (with load stepping if needed) with N steps, then with 2N steps
    warm-started from it; the tip positions give the Richardson estimate of the error of the
    2N solution, |p_2N - p_N| / (2⁴ - 1). N grows (order-4 model) until the estimate is
    ≤ tol; the 2N solution is the result.

    Parameters (B cases, P pieces, S stations)
    ----------
    base : (4, 4) base pose.  piece_* : (P, ...) the arm cut at joints and point loads.
    gravity, dist_force : (B, 3); jumps : (B, P, 6) point wrenches at piece starts (spatial);
    tip_dead : (B, 6) spatial; tip_fol : (B, 6) tip material components.
    scale : (6,) residual scale; threshold : scaled residual for convergence; tol : tip
    position tolerance in m. Outputs are written into poses (B, S, 4, 4), strains and
    stresses (B, S, 6), residual, error_estimate (B,), status (B,) and work_done (B, 2)
    (trajectory integrations, final N). x_start (6,): base wrench to warm-start from if
    warm_start, overwritten with the last solution.
    """
    nb = tip_dead.shape[0]
    npieces = piece_len.size
    work = np.empty((6, 24))  # RK4 stages, stage state, scratch
    twork = np.empty((5, 6, 9))
    r = np.empty(6)
    J = np.empty((6, 6))
    tip = np.empty(3)
    tip_c = np.empty(3)
    x = x_start.copy()
    x_prev = x_start.copy()
    warm = warm_start
    counter = np.zeros(1, dtype=np.int64)
    N = n_initial
    piece_fd = np.empty((npieces, 3))
    for b in range(nb):
        counter[0] = 0
        for j in range(npieces):
            for i in range(3):
                piece_fd[j, i] = piece_mu[j] * gravity[b, i] + dist_force[b, i]
        pieces = (piece_len, piece_C, piece_f0, piece_fd)
        loads = (jumps[b], tip_dead[b], tip_fol[b])
        status[b] = OK
        estimate = np.inf
        fine = False
        while True:
            steps = _steps(length, piece_len, N)
            if fine:
                steps *= 2
            ok = _continuation(x, x_prev, warm, steps, base, pieces, loads, scale, threshold,
                               max_iterations, continuation, max_step, max_shootings, r, J,
                               tip, work, twork, counter)
            if not ok:
                status[b] = NEWTON_FAILED
                break
            x_prev[:] = x
            warm = True
            if not fine:
                tip_c[:] = tip
                fine = True
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
            fine = False
        residual[b] = 0.0
        for i in range(6):
            if not abs(r[i]) <= residual[b]:  # NaN propagates
                residual[b] = abs(r[i])
        error_estimate[b] = estimate
        work_done[b, 0] = counter[0]
        work_done[b, 1] = N
        if status[b] != OK:
            warm = False
            x[:] = 0.0
            x_prev[:] = 0.0
            continue
        _record(x, 2 * _steps(length, piece_len, N), base, pieces, jumps[b], s_out, poses[b],
                strains[b], stresses[b], work, twork)
        if math.isfinite(tol) and estimate < 0.01 * tol:  # next case: fewer steps may do
            N = max(2, math.ceil(N * (estimate / (0.3 * tol)) ** 0.25))
    x_start[:] = x_prev
