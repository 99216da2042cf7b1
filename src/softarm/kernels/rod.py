"""The rod: the RK4 step along the arm and its right-hand side, the constitutive laws (the
linear one and the actuated one, solved by Newton), the loads' point jumps, the tip residual
and the contact's penalty law. Everything that integrates the arm calls ``_steps``.

State along the arm, from the clamped base to the tip: centreline p (3), material frame R
(3×3, row-major), internal force n and moment m in *spatial* components (3 + 3):

    p' = R v,   R' = R û,   n' = -(f_d + R f_f),   m' = -p' × n - (l_d + R l_f),
    (v; u) = strain(Rᵀn, Rᵀm)   (today f⁰ + K⁻¹ (Rᵀn; Rᵀm), the linear law),

the static Cosserat (Simo–Reissner) rod (Grazioso et al. 2018, eq. 20, with the stress
resultant in spatial components), under distributed forces and moments that are dead (d,
spatial components) or follower (f, material components). Point wrenches make n and m jump.
The unknowns are the base reaction x = (n(0); m(0)); the tip boundary condition is

    r(x, λ) = (n(L) - F_d - R(L) F_f;  m(L) - M_d - R(L) M_f) = 0.

Every load is affine in the load factor λ: load(λ) = start + λ (end - start), the homotopy that
the continuation follows (start = 0: the unloaded arm; start = the previous case: a slowly
driven arm).

Integration: classical RK4 with R projected back onto SO(3) after every step (one Björck step,
R ← R (3I - RᵀR)/2, Hairer–Lubich–Wanner, *Geometric Numerical Integration*, §IV.4). The
tangents (δp, δθ, δn, δm), δR = R δθ~ with δθ in material components, are integrated with the
same stages:

    δθ' = -u × δθ + δu,   δp' = R (δθ × v + δv),
    δn' = -R (δθ × f_f) - ∂_λ(f_d + R f_f),
    δm' = -δp' × n - p' × δn - R (δθ × l_f) - ∂_λ(l_d + R l_f),
    (δv; δu) = dstrain(Rᵀδn + σ_n × δθ;  Rᵀδm + σ_m × δθ),

where the ∂_λ terms belong to the load-factor column only. Columns 0-5 are the derivatives
with respect to x (δn(0), δm(0) = e_d), column 6 the one with respect to λ.
"""

from __future__ import annotations

import math

import numpy as np

from ._compile import _inline, _jit
from .layout import (
    _ACT,
    _CT,
    _FB,
    _FD,
    _FF,
    _FG,
    _HP,
    _HR,
    _HW,
    _JD,
    _JF,
    _LD,
    _LF,
    _M,
    _N,
    _P,
    _POLY,
    _R,
    _TD,
    _TF,
    _TM,
    _TN,
    _TP,
    _TT,
    CHAMBER,
    LAM,
    NT,
    TENDON,
    TIP_LOADS,
)
from .linear import _eliminate_columns

# Newton on the actuated constitutive law: the largest number of iterations, and the size
# of a correction (strain; curvature times L) below which the next would be at round-off.
_LAW_ITER = 30
_LAW_TOL = 1e-9
# A Newton correction no larger than this may be followed by a chord step (_law).
_LAW_CHORD = 1e-3


@_inline
def _strain(C, f0, j, diag, s0, s1, s2, s3, s4, s5):
    """The constitutive step of piece j: strains (v; u) = f⁰ + C σ from the stress σ in
    material components. With ``f0`` zero rows it is the linear map of the tangents
    (dstrain); every future law (tendon coupling) replaces this one function."""
    if diag:
        return (f0[j, 0] + C[j, 0, 0] * s0, f0[j, 1] + C[j, 1, 1] * s1,
                f0[j, 2] + C[j, 2, 2] * s2, f0[j, 3] + C[j, 3, 3] * s3,
                f0[j, 4] + C[j, 4, 4] * s4, f0[j, 5] + C[j, 5, 5] * s5)
    return (f0[j, 0] + C[j, 0, 0] * s0 + C[j, 0, 1] * s1 + C[j, 0, 2] * s2 + C[j, 0, 3] * s3
            + C[j, 0, 4] * s4 + C[j, 0, 5] * s5,
            f0[j, 1] + C[j, 1, 0] * s0 + C[j, 1, 1] * s1 + C[j, 1, 2] * s2 + C[j, 1, 3] * s3
            + C[j, 1, 4] * s4 + C[j, 1, 5] * s5,
            f0[j, 2] + C[j, 2, 0] * s0 + C[j, 2, 1] * s1 + C[j, 2, 2] * s2 + C[j, 2, 3] * s3
            + C[j, 2, 4] * s4 + C[j, 2, 5] * s5,
            f0[j, 3] + C[j, 3, 0] * s0 + C[j, 3, 1] * s1 + C[j, 3, 2] * s2 + C[j, 3, 3] * s3
            + C[j, 3, 4] * s4 + C[j, 3, 5] * s5,
            f0[j, 4] + C[j, 4, 0] * s0 + C[j, 4, 1] * s1 + C[j, 4, 2] * s2 + C[j, 4, 3] * s3
            + C[j, 4, 4] * s4 + C[j, 4, 5] * s5,
            f0[j, 5] + C[j, 5, 0] * s0 + C[j, 5, 1] * s1 + C[j, 5, 2] * s2 + C[j, 5, 3] * s3
            + C[j, 5, 4] * s4 + C[j, 5, 5] * s5)


@_jit
def _route(routes, a, s):
    """Actuator a's path in the section at arc length s: (y, z, dy/ds, dz/ds), m and m/m,
    material frame (a power series in s plus a helix)."""
    D = (routes.shape[1] - _POLY) // 2
    y, z, dy, dz = 0.0, 0.0, 0.0, 0.0
    for k in range(D - 1, -1, -1):  # Horner, value and derivative together
        dy = dy * s + y
        y = y * s + routes[a, _POLY + k]
        dz = dz * s + z
        z = z * s + routes[a, _POLY + D + k]
    radius = routes[a, _HR]
    if radius != 0.0:
        angle = routes[a, _HP] + routes[a, _HW] * s
        c, sn = math.cos(angle), math.sin(angle)
        y += radius * c
        z += radius * sn
        dy -= radius * routes[a, _HW] * sn
        dz += radius * routes[a, _HW] * c
    return y, z, dy, dz


@_jit
def _law(arm, act, j, s, now, law, tangents, s0, s1, s2, s3, s4, s5):
    """The constitutive law of piece j at arc length s with its actuators (Rucker & Webster
    2011, in total-wrench form): the strains ε = (v; u) solving

        K (ε - f⁰) + Σ_tendons τ (t; r × t) = σ + Σ_chambers p A (e1; r × e1),
        t = w/|w|, w = v + u × r + r',

    σ the total wrench (rod, tendons, fluid) in material components, r(s) each actuator's
    path in the section. For τ ≥ 0 the left side is the gradient of a strictly convex
    function, so Newton from the tendons-along-d1 guess (exact for straight tendons on a
    diagonal K) converges to the unique root, to round-off: the last correction is at most
    ``_LAW_TOL`` (strain, curvature × L), so the error left is of its square.

    With ``tangents`` > 0 (the caller maps that many tangent columns with H⁻¹), every
    correction is a Newton step, and on return ``law[0][:, :6]`` holds
    H = K + Σ τ Jᵀ (I - t tᵀ) J / |w|, J = [I, -r~], at the point before the last
    correction (within ``_LAW_TOL`` relative of its value at the root): its LDLᵀ factors
    (:func:`_ldl_correction`) when the 7th value returned is 1.0, else H itself (no
    tendon, or a tension < 0: not definite).
    ``law[1][a]`` = (t, |w|, y, z, dy, dz) of every active actuator at that same point.

    With ``tangents`` = 0 (a state-only stage, a station), a correction that follows a
    Newton step reuses that step's factor (a chord step: the residual only, no new H): its
    own error is of the order of the two corrections' product, so after a small Newton
    step (at most ``_LAW_CHORD``; from the tendons-along-d1 guess, about 1e-4) it converges
    as a Newton step would; a chord step not yet below ``_LAW_TOL`` is followed by a Newton
    step.
    ``law[0]`` is then scratch. NaN strains if Newton fails (|w| → 0: a tendon path folded
    onto itself).
    """
    f0, C, K = arm[3], arm[2], arm[8]
    routes, kinds, active = act[0], act[1], act[2]
    M, tw, vec, jw = law
    length = arm[6]
    rhs, eps = vec[0], vec[2]
    rhs[0], rhs[1], rhs[2], rhs[3], rhs[4], rhs[5] = s0, s1, s2, s3, s4, s5
    g = vec[1]
    for i in range(6):
        g[i] = rhs[i]
    tendons = 0
    for a in range(routes.shape[0]):
        if active[j, a] == 0.0:
            continue
        y, z, dy, dz = _route(routes, a, s)
        tw[a, 4], tw[a, 5], tw[a, 6], tw[a, 7] = y, z, dy, dz
        q = now[j, _ACT + a]
        # the fluid's wrench p A (e1; r × e1), r × e1 = (0, z, -y); a tendon along d1: -τ that
        sign = 1.0 if kinds[a] == CHAMBER else -1.0
        if kinds[a] == CHAMBER:
            rhs[0] += q
            rhs[4] += q * z
            rhs[5] -= q * y
        else:
            tendons += 1
        g[0] += sign * q
        g[4] += sign * q * z
        g[5] -= sign * q * y
    for i in range(6):
        acc = f0[j, i]
        for k in range(6):
            acc += C[j, i, k] * g[k]
        eps[i] = acc
    if tendons == 0:  # (else the factors or H itself overwrite M[:, :6])
        for i in range(6):
            for k in range(6):
                M[i, k] = K[j, i, k]
        return eps[0], eps[1], eps[2], eps[3], eps[4], eps[5], 0.0
    F, H = vec[1], jw
    factored = False  # M[:, :6] holds the LDLᵀ factors of the last Newton step's H
    chord = False  # the next correction may reuse it
    for _ in range(_LAW_ITER):
        newton = not chord
        v0, v1, v2, u0, u1, u2 = eps[0], eps[1], eps[2], eps[3], eps[4], eps[5]
        for i in range(6):
            acc = -rhs[i]
            for k in range(6):
                acc += K[j, i, k] * (eps[k] - f0[j, k])
            F[i] = acc
        if newton:
            for i in range(6):
                for k in range(6):
                    H[i, k] = K[j, i, k]
        for a in range(routes.shape[0]):
            if active[j, a] == 0.0 or kinds[a] == CHAMBER:
                continue
            y, z, dy, dz = tw[a, 4], tw[a, 5], tw[a, 6], tw[a, 7]
            w0 = v0 + u1 * z - u2 * y
            w1 = v1 - u0 * z + dy
            w2 = v2 + u0 * y + dz
            nw = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            inv = 1.0 / nw
            t0, t1, t2 = w0 * inv, w1 * inv, w2 * inv
            tw[a, 0], tw[a, 1], tw[a, 2], tw[a, 3] = t0, t1, t2, nw
            q = now[j, _ACT + a]
            if q == 0.0:
                continue
            # g = Jᵀ t = (t; r × t), r = (0, y, z)
            g0, g1, g2, g3, g4, g5 = t0, t1, t2, y * t2 - z * t1, z * t0, -y * t0
            F[0] += q * g0
            F[1] += q * g1
            F[2] += q * g2
            F[3] += q * g3
            F[4] += q * g4
            F[5] += q * g5
            if not newton:
                continue
            # H += τ/|w| Jᵀ (I - t tᵀ) J = c (JᵀJ - g gᵀ), J = [I | N], N = -r~ =
            # (0 z -y; -z 0 0; y 0 0): JᵀJ = (I N; Nᵀ NᵀN), NᵀN = |r|² I - r rᵀ
            c = q * inv
            H[0, 0] += c
            H[1, 1] += c
            H[2, 2] += c
            H[0, 4] += c * z
            H[4, 0] += c * z
            H[0, 5] -= c * y
            H[5, 0] -= c * y
            H[1, 3] -= c * z
            H[3, 1] -= c * z
            H[2, 3] += c * y
            H[3, 2] += c * y
            H[3, 3] += c * (y * y + z * z)
            H[4, 4] += c * z * z
            H[5, 5] += c * y * y
            H[4, 5] -= c * y * z
            H[5, 4] -= c * y * z
            g = (g0, g1, g2, g3, g4, g5)
            for i in range(6):
                ci = c * g[i]
                for k in range(6):
                    H[i, k] -= ci * g[k]
        if not newton:
            _ldl_solve(M, F)  # the chord step, with the factors of the step before
        elif _ldl_correction(H, F, M):
            factored = True
        else:  # τ < 0 somewhere: not definite
            factored = False
            for i in range(6):
                for k in range(6):
                    M[i, k] = H[i, k]
                M[i, 6] = -F[i]
            if _eliminate_columns(M, np.int64(1)) == 0.0:
                return np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, 0.0
        size = 0.0
        for i in range(6):
            eps[i] += M[i, 6]
            size = max(size, abs(M[i, 6]) * (length if i >= 3 else 1.0))
        if not math.isfinite(size):
            return np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, 0.0
        if size <= _LAW_TOL:
            # converged (the next correction would be ~ size²); H is the Jacobian before
            # this last correction, within ~size of the one at ε (t and |w| likewise)
            if factored:
                return eps[0], eps[1], eps[2], eps[3], eps[4], eps[5], 1.0
            for i in range(6):
                for k in range(6):
                    M[i, k] = H[i, k]
            return eps[0], eps[1], eps[2], eps[3], eps[4], eps[5], 0.0
        # a chord step follows a small Newton step only, and is followed by a Newton step
        chord = newton and factored and tangents == 0 and size <= _LAW_CHORD
    return np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, 0.0


@_inline
def _ldl_correction(H, F, M):
    """The Newton correction M[:, 6] = -H⁻¹F by the square-root-free Cholesky factorisation
    H = L D Lᵀ (L unit lower triangular below M[:, :6]'s diagonal, 1/D on it, L D above
    it: see :func:`_ldl_substitute`): H is symmetric, and positive definite when every
    tension is >= 0 (K plus Σ τ/|w| Jᵀ (I - t tᵀ) J, each term semi-definite). No pivoting,
    about a third of the work of the general elimination, and one division a column, no
    square root (the law's time is the latency of these chains: LDLᵀ made it 17 % faster
    than L Lᵀ with a division per entry). False (M garbage) if H is not positive definite."""
    for c in range(6):
        d = H[c, c]
        for k in range(c):
            d -= M[c, k] * M[k, c]  # L[c, k] (L D)[c, k]
        if not d > 0.0:
            return False
        inv = 1.0 / d
        M[c, c] = inv
        for i in range(c + 1, 6):
            acc = H[i, c]
            for k in range(c):
                acc -= M[i, k] * M[k, c]
            M[c, i] = acc  # (L D)[i, c], kept above the diagonal
            M[i, c] = acc * inv
    _ldl_solve(M, F)
    return True


@_inline
def _ldl_solve(M, F):
    """M[:, 6] = -H⁻¹ F, H's factors in M[:, :6] (:func:`_ldl_correction`)."""
    for i in range(6):
        M[i, 6] = -F[i]
    _ldl_substitute(M, np.int64(1))


@_jit
def _ldl_substitute(M, k):
    """Solve H X = M[:, 6:6+k] in place (X overwrites those k columns), H = L D Lᵀ factored
    by :func:`_ldl_correction` in M[:, :6]: L (unit diagonal) below the diagonal, 1/D on it
    (kept)."""
    for col in range(6, 6 + k):
        for i in range(6):  # L z = b
            acc = M[i, col]
            for q in range(i):
                acc -= M[i, q] * M[q, col]
            M[i, col] = acc
        for i in range(5, -1, -1):  # D Lᵀ x = z
            acc = M[i, col] * M[i, i]
            for q in range(i + 1, 6):
                acc -= M[q, i] * M[q, col]
            M[i, col] = acc


@_jit
def _actuator_rates(act, j, rate, law, ds):
    """The actuators' own change with λ in the constitutive law, added to the λ column ds
    (material): Σ_chambers d(pA)/dλ (e1; r × e1) - Σ_tendons dτ/dλ (t; r × t)."""
    routes, kinds, active = act[0], act[1], act[2]
    tw = law[1]
    for a in range(routes.shape[0]):
        if active[j, a] == 0.0:
            continue
        q = rate[j, _ACT + a]
        y, z = tw[a, 4], tw[a, 5]
        if kinds[a] == CHAMBER:
            ds[0] += q
            ds[4] += q * z
            ds[5] -= q * y
        else:
            t0, t1, t2 = tw[a, 0], tw[a, 1], tw[a, 2]
            ds[0] -= q * t0
            ds[1] -= q * t1
            ds[2] -= q * t2
            ds[3] -= q * (y * t2 - z * t1)
            ds[4] -= q * z * t0
            ds[5] += q * y * t0


@_inline
def _actuated(act, j):
    """Whether actuators act on piece j (the constitutive law then is :func:`_law`)."""
    active = act[2]
    for a in range(active.shape[1]):
        if active[j, a] != 0.0:
            return True
    return False


@_inline
def _deriv(work, twork, nt, stage, s, arm, act, j, now, rate, law):
    """F(y) and the right-hand side of the first nt tangent columns, on piece j at arc
    length s.

    Reads the state from ``work[4]`` and the tangents from ``twork[4]``; writes F(y) into
    ``work[stage]`` and the tangent derivatives into ``twork[stage]``. Scalars throughout
    where it matters: no array views in the passive arm's path, no allocation.

    Design note: this function is inlined into :func:`_steps` by numba
    (``inline="always"``). Left to LLVM, it stays out of line once the actuated path is in
    the body, and every RK4 step and output station then pays calls that pass the arm's
    arrays by value: a passive solve measured 1.5-2× slower than 0.1's kernel that way,
    and at parity inlined. The actuated path's own work is in :func:`_law`.
    """
    C, f0, zero, diag = arm[2], arm[3], arm[4], arm[5]
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
    # (every use of ``act`` is behind ``act is not None``: compiled for a passive arm, the
    # actuated law, the tendons' lengths and the magnets are pruned before typing)
    actuated = act is not None and _actuated(act, j)
    if act is not None and actuated:
        v0, v1, v2, u0, u1, u2, factored = _law(arm, act, j, s, now, law, nt, s0, s1, s2, s3,
                                                s4, s5)
    else:
        v0, v1, v2, u0, u1, u2 = _strain(C, f0, j, diag, s0, s1, s2, s3, s4, s5)
        factored = 0.0
    # follower loads in spatial components: R f_f, R l_f
    ff0, ff1, ff2 = now[j, _FF], now[j, _FF + 1], now[j, _FF + 2]
    lf0, lf1, lf2 = now[j, _LF], now[j, _LF + 1], now[j, _LF + 2]
    px = R00 * v0 + R01 * v1 + R02 * v2
    py = R10 * v0 + R11 * v1 + R12 * v2
    pz = R20 * v0 + R21 * v1 + R22 * v2
    w = work[stage]
    w[_P] = px
    w[_P + 1] = py
    w[_P + 2] = pz
    w[_R] = R01 * u2 - R02 * u1
    w[_R + 1] = -R00 * u2 + R02 * u0
    w[_R + 2] = R00 * u1 - R01 * u0
    w[_R + 3] = R11 * u2 - R12 * u1
    w[_R + 4] = -R10 * u2 + R12 * u0
    w[_R + 5] = R10 * u1 - R11 * u0
    w[_R + 6] = R21 * u2 - R22 * u1
    w[_R + 7] = -R20 * u2 + R22 * u0
    w[_R + 8] = R20 * u1 - R21 * u0
    w[_N] = -(now[j, _FD] + R00 * ff0 + R01 * ff1 + R02 * ff2)
    w[_N + 1] = -(now[j, _FD + 1] + R10 * ff0 + R11 * ff1 + R12 * ff2)
    w[_N + 2] = -(now[j, _FD + 2] + R20 * ff0 + R21 * ff1 + R22 * ff2)
    w[_M] = -(py * nz - pz * ny) - (now[j, _LD] + R00 * lf0 + R01 * lf1 + R02 * lf2)
    w[_M + 1] = -(pz * nx - px * nz) - (now[j, _LD + 1] + R10 * lf0 + R11 * lf1 + R12 * lf2)
    w[_M + 2] = -(px * ny - py * nx) - (now[j, _LD + 2] + R20 * lf0 + R21 * lf1 + R22 * lf2)
    # a hard magnetisation m (material, A m²/m) in B(x) = B0 + G x: force Gᵀ (R m), torque
    # (R m) × B(p) per unit length
    ma0 = ma1 = ma2 = 0.0
    if act is not None:
        ma0, ma1, ma2 = act[3][j, 0], act[3][j, 1], act[3][j, 2]
    magnetic = ma0 != 0.0 or ma1 != 0.0 or ma2 != 0.0
    if act is not None and magnetic:
        _dipole(work[Y], twork[Y], np.int64(0), ma0, ma1, ma2, now[j], rate[0, j], law[2][3])
        for i in range(3):
            w[_N + i] -= law[2][3, i]
            w[_M + i] -= law[2][3, 3 + i]
    # contact with the obstacles: a force per unit length through the centreline (_contact),
    # or on a hard contact zone the pressure that holds the arm on it (_zone_forces)
    cf0 = cf1 = cf2 = c00 = c01 = c02 = c11 = c12 = c22 = 0.0
    touching = False
    contact = 0.0  # the penalty's scale at this λ (the channel CT)
    zoned = False  # a hard contact zone's piece (_zone_forces)
    if act is not None and act[5].shape[0] > 0:
        contact = now[j, _CT]
        zoned = act[6][j, ZONE] > 0.0
        if not zoned:
            cf0, cf1, cf2, c00, c01, c02, c11, c12, c22 = _contact(
                work[Y, _P], work[Y, _P + 1], work[Y, _P + 2], act[5], act[6][j])
            touching = cf0 != 0.0 or cf1 != 0.0 or cf2 != 0.0
        w[_N] -= contact * cf0
        w[_N + 1] -= contact * cf1
        w[_N + 2] -= contact * cf2
    # the tendons' lengths: ℓ' = |w| where they run
    if act is not None:
        for a in range(w.size - 18):
            w[18 + a] = law[1][a, 3] if actuated and act[2][j, a] != 0.0 and \
                act[1][a] == TENDON else 0.0
    if nt == 0:
        if act is not None and zoned:
            _zone_forces(work, twork, 0, stage, arm, act, j, rate, contact)
        return
    # δσ = (Rᵀδn + σ_n × δθ; Rᵀδm + σ_m × δθ), then δ(v; u) = dstrain δσ (+ the actuators'
    # own change with λ), all columns at once (a passive arm's δ(v; u) are computed in the
    # loop below, in registers: one loop, no round trip through memory; an actuated one's
    # need one solve with H for all columns, by substitution with the LDLᵀ factors the law
    # left, or by elimination where it left H itself)
    M = law[0]
    for d in range(nt if actuated else 0):
        t = twork[Y, d]
        th0, th1, th2 = t[_TT], t[_TT + 1], t[_TT + 2]
        dn0, dn1, dn2 = t[_TN], t[_TN + 1], t[_TN + 2]
        dm0, dm1, dm2 = t[_TM], t[_TM + 1], t[_TM + 2]
        M[0, 6 + d] = R00 * dn0 + R10 * dn1 + R20 * dn2 + s1 * th2 - s2 * th1
        M[1, 6 + d] = R01 * dn0 + R11 * dn1 + R21 * dn2 + s2 * th0 - s0 * th2
        M[2, 6 + d] = R02 * dn0 + R12 * dn1 + R22 * dn2 + s0 * th1 - s1 * th0
        M[3, 6 + d] = R00 * dm0 + R10 * dm1 + R20 * dm2 + s4 * th2 - s5 * th1
        M[4, 6 + d] = R01 * dm0 + R11 * dm1 + R21 * dm2 + s5 * th0 - s3 * th2
        M[5, 6 + d] = R02 * dm0 + R12 * dm1 + R22 * dm2 + s3 * th1 - s4 * th0
    if act is not None and actuated:
        for d in range(LAM, nt):
            _actuator_rates(act, j, rate[d - LAM], law, law[2][4])
            for i in range(6):
                M[i, 6 + d] += law[2][4, i]
                law[2][4, i] = 0.0
        if factored > 0.0:  # H's LDLᵀ factors, from the law's last Newton step
            _ldl_substitute(M, nt)
        elif _eliminate_columns(M, nt) == 0.0:
            for d in range(nt):
                for i in range(6):
                    M[i, 6 + d] = np.nan
    for d in range(nt):
        t = twork[Y, d]
        th0, th1, th2 = t[_TT], t[_TT + 1], t[_TT + 2]
        dn0, dn1, dn2 = t[_TN], t[_TN + 1], t[_TN + 2]
        if act is not None and actuated:
            c0, c1, c2 = M[0, 6 + d], M[1, 6 + d], M[2, 6 + d]
            c3, c4, c5 = M[3, 6 + d], M[4, 6 + d], M[5, 6 + d]
        else:  # δσ = (Rᵀδn + σ_n × δθ; Rᵀδm + σ_m × δθ), then the constitutive step
            dm0, dm1, dm2 = t[_TM], t[_TM + 1], t[_TM + 2]
            c0, c1, c2, c3, c4, c5 = _strain(
                C, zero, j, diag,
                R00 * dn0 + R10 * dn1 + R20 * dn2 + s1 * th2 - s2 * th1,
                R01 * dn0 + R11 * dn1 + R21 * dn2 + s2 * th0 - s0 * th2,
                R02 * dn0 + R12 * dn1 + R22 * dn2 + s0 * th1 - s1 * th0,
                R00 * dm0 + R10 * dm1 + R20 * dm2 + s4 * th2 - s5 * th1,
                R01 * dm0 + R11 * dm1 + R21 * dm2 + s5 * th0 - s3 * th2,
                R02 * dm0 + R12 * dm1 + R22 * dm2 + s3 * th1 - s4 * th0)
        # δp' = R (δθ × v + δv)
        a0 = th1 * v2 - th2 * v1 + c0
        a1 = th2 * v0 - th0 * v2 + c1
        a2 = th0 * v1 - th1 * v0 + c2
        q0 = R00 * a0 + R01 * a1 + R02 * a2
        q1 = R10 * a0 + R11 * a1 + R12 * a2
        q2 = R20 * a0 + R21 * a1 + R22 * a2
        # -R (δθ × f_f) and -R (δθ × l_f), material cross products rotated to spatial
        b0 = -(th1 * ff2 - th2 * ff1)
        b1 = -(th2 * ff0 - th0 * ff2)
        b2 = -(th0 * ff1 - th1 * ff0)
        e0 = -(th1 * lf2 - th2 * lf1)
        e1 = -(th2 * lf0 - th0 * lf2)
        e2 = -(th0 * lf1 - th1 * lf0)
        rr = max(d - LAM, 0)  # columns from LAM on: the loads' own change along rate[d - LAM]
        if d >= LAM:
            b0 -= rate[rr, j, _FF]
            b1 -= rate[rr, j, _FF + 1]
            b2 -= rate[rr, j, _FF + 2]
            e0 -= rate[rr, j, _LF]
            e1 -= rate[rr, j, _LF + 1]
            e2 -= rate[rr, j, _LF + 2]
        g0 = R00 * b0 + R01 * b1 + R02 * b2
        g1 = R10 * b0 + R11 * b1 + R12 * b2
        g2 = R20 * b0 + R21 * b1 + R22 * b2
        k0 = R00 * e0 + R01 * e1 + R02 * e2
        k1 = R10 * e0 + R11 * e1 + R12 * e2
        k2 = R20 * e0 + R21 * e1 + R22 * e2
        if d >= LAM:
            g0 -= rate[rr, j, _FD]
            g1 -= rate[rr, j, _FD + 1]
            g2 -= rate[rr, j, _FD + 2]
            k0 -= rate[rr, j, _LD]
            k1 -= rate[rr, j, _LD + 1]
            k2 -= rate[rr, j, _LD + 2]
        if act is not None and magnetic:  # the magnetic force and torque densities' variations
            _dipole(work[Y], twork[Y], d + 1, ma0, ma1, ma2, now[j], rate[rr, j], law[2][3])
            g0 -= law[2][3, 0]
            g1 -= law[2][3, 1]
            g2 -= law[2][3, 2]
            k0 -= law[2][3, 3]
            k1 -= law[2][3, 4]
            k2 -= law[2][3, 5]
        if act is not None and touching:  # -∂f/∂p δp (∂f/∂p symmetric: the obstacles' Hessians)
            dp0, dp1, dp2 = t[_TP], t[_TP + 1], t[_TP + 2]
            g0 -= contact * (c00 * dp0 + c01 * dp1 + c02 * dp2)
            g1 -= contact * (c01 * dp0 + c11 * dp1 + c12 * dp2)
            g2 -= contact * (c02 * dp0 + c12 * dp1 + c22 * dp2)
            if d >= LAM:  # the penalty's own change along the path
                g0 -= rate[rr, j, _CT] * cf0
                g1 -= rate[rr, j, _CT] * cf1
                g2 -= rate[rr, j, _CT] * cf2
        o = twork[stage, d]
        o[_TP] = q0
        o[_TP + 1] = q1
        o[_TP + 2] = q2
        o[_TT] = -(u1 * th2 - u2 * th1) + c3
        o[_TT + 1] = -(u2 * th0 - u0 * th2) + c4
        o[_TT + 2] = -(u0 * th1 - u1 * th0) + c5
        o[_TN] = g0
        o[_TN + 1] = g1
        o[_TN + 2] = g2
        # δm' = -δp' × n - p' × δn - R (δθ × l_f) - ∂_λ l
        o[_TM] = -(q1 * nz - q2 * ny) - (py * dn2 - pz * dn1) + k0
        o[_TM + 1] = -(q2 * nx - q0 * nz) - (pz * dn0 - px * dn2) + k1
        o[_TM + 2] = -(q0 * ny - q1 * nx) - (px * dn1 - py * dn0) + k2
    if act is not None and zoned:
        _zone_forces(work, twork, nt, stage, arm, act, j, rate, contact)
    if act is not None and twork.shape[2] > NT:  # the tendons' lengths' tangents
        _length_rates(twork[stage], nt, act, j, actuated, law)


@_inline
def _length_rates(out, nt, act, j, actuated, law):
    """The tangent rates of the tendons' lengths, out[d, NT + a] = δ|w_a| = g_aᵀ δε for
    the first nt columns: δw = δv + δu × r = J δε (J = [I, -r~]), so δ|w| = tᵀ J δε with
    Jᵀ t = g = (t; r × t), t = w/|w| (from ``law[1]``), δε the columns' strain variations
    (``law[0][:, 6 + d]``); 0 where tendon a does not run, and for a chamber."""
    kinds, active = act[1], act[2]
    tw, M = law[1], law[0]
    for a in range(out.shape[1] - NT):
        if not (actuated and active[j, a] != 0.0 and kinds[a] == TENDON):
            for d in range(nt):
                out[d, NT + a] = 0.0
            continue
        t0, t1, t2, y, z = tw[a, 0], tw[a, 1], tw[a, 2], tw[a, 4], tw[a, 5]
        g3, g4, g5 = y * t2 - z * t1, z * t0, -y * t0
        for d in range(nt):
            out[d, NT + a] = (t0 * M[0, 6 + d] + t1 * M[1, 6 + d] + t2 * M[2, 6 + d]
                              + g3 * M[3, 6 + d] + g4 * M[4, 6 + d] + g5 * M[5, 6 + d])


@_jit
def _dipole(y, T, which, m0, m1, m2, now, rate, out):
    """The wrench of a magnetic dipole m (material components, A m², or A m²/m for a
    density) carried by the section of state y in the field B(x) = B0 + G x of the load row
    ``now``: out = (Gᵀ (R m); (R m) × B(p)), spatial. With ``which`` = d + 1 instead its
    variation along tangent column d of T: R (δθ × m) = δ(R m) in both terms, G δp in the
    torque, and in a load column (d >= LAM) the field's own change (``rate``: that column's
    rate row of this piece)."""
    R = y[_R:_R + 9]
    a0 = R[0] * m0 + R[1] * m1 + R[2] * m2  # R m, spatial
    a1 = R[3] * m0 + R[4] * m1 + R[5] * m2
    a2 = R[6] * m0 + R[7] * m1 + R[8] * m2
    px, py, pz = y[_P], y[_P + 1], y[_P + 2]
    if which == 0:
        G, B = now[_FG:_FG + 9], now[_FB:_FB + 3]
        b0 = B[0] + G[0] * px + G[1] * py + G[2] * pz
        b1 = B[1] + G[3] * px + G[4] * py + G[5] * pz
        b2 = B[2] + G[6] * px + G[7] * py + G[8] * pz
        out[0] = G[0] * a0 + G[3] * a1 + G[6] * a2
        out[1] = G[1] * a0 + G[4] * a1 + G[7] * a2
        out[2] = G[2] * a0 + G[5] * a1 + G[8] * a2
        out[3] = a1 * b2 - a2 * b1
        out[4] = a2 * b0 - a0 * b2
        out[5] = a0 * b1 - a1 * b0
        return
    d = which - 1
    t = T[d]
    th0, th1, th2 = t[_TT], t[_TT + 1], t[_TT + 2]
    c0, c1, c2 = th1 * m2 - th2 * m1, th2 * m0 - th0 * m2, th0 * m1 - th1 * m0
    e0 = R[0] * c0 + R[1] * c1 + R[2] * c2  # δ(R m) = R (δθ × m)
    e1 = R[3] * c0 + R[4] * c1 + R[5] * c2
    e2 = R[6] * c0 + R[7] * c1 + R[8] * c2
    G, B = now[_FG:_FG + 9], now[_FB:_FB + 3]
    b0 = B[0] + G[0] * px + G[1] * py + G[2] * pz
    b1 = B[1] + G[3] * px + G[4] * py + G[5] * pz
    b2 = B[2] + G[6] * px + G[7] * py + G[8] * pz
    dp0, dp1, dp2 = t[_TP], t[_TP + 1], t[_TP + 2]
    g0 = G[0] * dp0 + G[1] * dp1 + G[2] * dp2  # G δp
    g1 = G[3] * dp0 + G[4] * dp1 + G[5] * dp2
    g2 = G[6] * dp0 + G[7] * dp1 + G[8] * dp2
    f0 = G[0] * e0 + G[3] * e1 + G[6] * e2
    f1 = G[1] * e0 + G[4] * e1 + G[7] * e2
    f2 = G[2] * e0 + G[5] * e1 + G[8] * e2
    if d >= LAM:
        Gr, Br = rate[_FG:_FG + 9], rate[_FB:_FB + 3]
        f0 += Gr[0] * a0 + Gr[3] * a1 + Gr[6] * a2
        f1 += Gr[1] * a0 + Gr[4] * a1 + Gr[7] * a2
        f2 += Gr[2] * a0 + Gr[5] * a1 + Gr[8] * a2
        g0 += Br[0] + Gr[0] * px + Gr[1] * py + Gr[2] * pz
        g1 += Br[1] + Gr[3] * px + Gr[4] * py + Gr[5] * pz
        g2 += Br[2] + Gr[6] * px + Gr[7] * py + Gr[8] * pz
    out[0], out[1], out[2] = f0, f1, f2
    out[3] = e1 * b2 - e2 * b1 + a1 * g2 - a2 * g1
    out[4] = e2 * b0 - e0 * b2 + a2 * g0 - a0 * g2
    out[5] = e0 * b1 - e1 * b0 + a0 * g1 - a1 * g0


# Contact (issue 33; docs/contact.md). ``act[5]``: the obstacles (K, 8), one row each: kind,
# then a plane's point and outward unit normal, a sphere's centre (and 0, 0, 0), or a
# capsule's two axis ends, then the radius (0 for a plane). ``act[6]`` (P, 6): per piece the
# arm's surface radius r (m), the contact distance δ (m), the penalty stiffness k
# (N/m per m of arm), Coulomb's μ, the friction's regularising speed w_ε (m/s; dynamics),
# then for a hard contact zone (:func:`_zone_pressure`) its obstacle's index + 1 (0: the
# piece is not a zone).
PLANE, SPHERE, CAPSULE = 0, 1, 2
OBSTACLE = 8
#: act[6]'s column of a zone's obstacle (index + 1), and its number of columns.
ZONE = 5
CONTACT_PARAMS = 6


@_jit
def _pressure(gap, band, stiffness):
    """The contact force per unit length at a gap g (the law's value and its derivative in
    g): zero for g >= δ, then k δ (t³ - t⁴/2) with t = (δ - g)/δ up to g = 0, then linear,
    k (δ/2 - g): twice continuously differentiable (RK4 keeps its order across the onset),
    k δ/2 at contact, and the slope k from g = 0 into the obstacle. Penetration is what is
    left of a pressure beyond k δ/2 (the Solver raises k until none is left; contact.md)."""
    if gap >= band:
        return 0.0, 0.0
    if gap <= 0.0:
        return stiffness * (0.5 * band - gap), -stiffness
    t = (band - gap) / band
    return stiffness * band * t * t * t * (1.0 - 0.5 * t), -stiffness * t * t * (3.0 - 2.0 * t)


@_jit
def _nearest(px, py, pz, row):
    """(distance d, outward unit normal n (3), curvature c, axis e (3)) of the point p from
    obstacle ``row`` (act[5]'s layout): d the signed distance from its surface, n = ∇d, and
    the Hessian ∇²d = c (I - n nᵀ - e eᵀ) (c = 1/|p - q| around a sphere's centre or a
    capsule's axis, e the axis on a capsule's cylinder, else 0)."""
    kind = row[0]
    if kind == PLANE:
        return ((px - row[1]) * row[4] + (py - row[2]) * row[5] + (pz - row[3]) * row[6],
                row[4], row[5], row[6], 0.0, 0.0, 0.0, 0.0)
    if kind == SPHERE:
        # row: a surface point q, the outward normal m there, the radius R (contact.py's
        # Sphere.kernel_row): with w = p - q, |p - c| - R = (2R m·w + w·w)/(|p - c| + R),
        # without the cancellation of |p - c| - R (a ball of 1e6 m as a floor: 1e-10 m of
        # rounding in every gap, a noisy law within a band of µm)
        wx, wy, wz = px - row[1], py - row[2], pz - row[3]
        radius = row[7]
        ux, uy, uz = wx + radius * row[4], wy + radius * row[5], wz + radius * row[6]
        r = math.sqrt(ux * ux + uy * uy + uz * uz)
        if r == 0.0:  # on the centre: the normal is undefined (deep inside)
            return -radius, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        d = (2.0 * radius * (wx * row[4] + wy * row[5] + wz * row[6])
             + wx * wx + wy * wy + wz * wz) / (r + radius)
        return d, ux / r, uy / r, uz / r, 1.0 / r, 0.0, 0.0, 0.0
    qx, qy, qz = row[1], row[2], row[3]
    e0 = e1 = e2 = 0.0
    if kind == CAPSULE:
        a0, a1, a2 = row[4] - qx, row[5] - qy, row[6] - qz
        aa = a0 * a0 + a1 * a1 + a2 * a2
        t = ((px - qx) * a0 + (py - qy) * a1 + (pz - qz) * a2) / aa
        if t > 0.0 and t < 1.0:
            qx, qy, qz = qx + t * a0, qy + t * a1, qz + t * a2
            norm = math.sqrt(aa)
            e0, e1, e2 = a0 / norm, a1 / norm, a2 / norm
        elif t >= 1.0:
            qx, qy, qz = row[4], row[5], row[6]
    dx, dy, dz = px - qx, py - qy, pz - qz
    r = math.sqrt(dx * dx + dy * dy + dz * dz)
    if r == 0.0:  # on the centre or the axis: the normal is undefined (deep inside)
        return -row[7], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return r - row[7], dx / r, dy / r, dz / r, 1.0 / r, e0, e1, e2


@_jit
def _contact(px, py, pz, obstacles, params):
    """The contact force per unit length on a section at p (spatial, N/m; frictionless,
    along each obstacle's normal, through the centreline: no moment) and its Jacobian
    ∂f/∂p (row-major), summed over the obstacles: f = φ(d - r) ∇d,
    ∂f/∂p = φ' ∇d ∇dᵀ + φ ∇²d (``params`` = the piece's act[6] row: r, δ, k)."""
    f0 = f1 = f2 = 0.0
    j00 = j01 = j02 = j11 = j12 = j22 = 0.0
    for k in range(obstacles.shape[0]):
        d, n0, n1, n2, c, e0, e1, e2 = _nearest(px, py, pz, obstacles[k])
        phi, dphi = _pressure(d - params[0], params[1], params[2])
        if phi == 0.0:
            continue
        f0 += phi * n0
        f1 += phi * n1
        f2 += phi * n2
        pc = phi * c
        j00 += dphi * n0 * n0 + pc * (1.0 - n0 * n0 - e0 * e0)
        j01 += dphi * n0 * n1 - pc * (n0 * n1 + e0 * e1)
        j02 += dphi * n0 * n2 - pc * (n0 * n2 + e0 * e2)
        j11 += dphi * n1 * n1 + pc * (1.0 - n1 * n1 - e1 * e1)
        j12 += dphi * n1 * n2 - pc * (n1 * n2 + e1 * e2)
        j22 += dphi * n2 * n2 + pc * (1.0 - n2 * n2 - e2 * e2)
    return f0, f1, f2, j00, j01, j02, j11, j12, j22


@_inline
def _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, x0, x1, x2):
    """Rᵀ x: a spatial vector's material components (R row-major, as scalars)."""
    return (R00 * x0 + R10 * x1 + R20 * x2, R01 * x0 + R11 * x1 + R21 * x2,
            R02 * x0 + R12 * x1 + R22 * x2)


@_jit
def _zone_pressure(row, Cj, px, py, pz, R00, R01, R02, R10, R11, R12, R20,
                   R21, R22, v0, v1, v2, u0, u1, u2, s0, s1, s2, s3, s4, s5, dx, dy, dz,
                   fn0, fn1, fn2, fm0, fm1, fm2):
    """The pressure c (N/m) that holds the arm on a hard contact zone of the obstacle ``row``
    (docs/contact.md, "Hard contact"), for the linear law's strains (v; u) = f⁰ + C σ
    (``Cj`` the piece's C, σ = (s0..s5) in material components), the centreline at p with
    p' = (dx, dy, dz) = R v, and n', m' without the contact (fn, fm: spatial).

    On the zone the gap g = d(p) - r is held at zero: with n̂ = ∇d, g' = n̂ · p' and
    g'' = p'ᵀ ∇²d p' + n̂ · R (u × v + v') = a - c b, where v' = C_v (σ') with
    σ' = (-u × σ_n + Rᵀ n'; -u × σ_m + Rᵀ m') and n' = fn - c n̂, so
    b = ñᵀ C_vv ñ (ñ = Rᵀ n̂, the section's compliance along the normal) and a is g'' at
    c = 0. The pressure that keeps g'' = 0 is

        c = a / b,

    so that g and g' keep the values they enter the zone with (zero on the hard-contact
    answer, which conditions at the zone's start must impose: contact.md). Returns c, n̂ (3),
    the curvature κ = 1/ρ of the obstacle's surface and its axis e (∇²d = κ (I - n̂ n̂ᵀ -
    e eᵀ)), ñ, C_vv ñ, b, the material vector u × v + v' at c = 0, ∇²d p', g', and Rᵀ n',
    Rᵀ m' (what :func:`_zone_variation` needs; C is symmetric, as the sections' K are)."""
    _, n0, n1, n2, kappa, e0, e1, e2 = _nearest(px, py, pz, row)
    m0, m1, m2 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, n0, n1, n2)  # ñ = Rᵀ n̂
    slope = n0 * dx + n1 * dy + n2 * dz  # g'
    # σ' at c = 0: -u × σ + Rᵀ (n'; m')
    f0, f1, f2 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, fn0, fn1, fn2)
    g0, g1, g2 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, fm0, fm1, fm2)
    a0 = -(u1 * s2 - u2 * s1) + f0
    a1 = -(u2 * s0 - u0 * s2) + f1
    a2 = -(u0 * s1 - u1 * s0) + f2
    a3 = -(u1 * s5 - u2 * s4) + g0
    a4 = -(u2 * s3 - u0 * s5) + g1
    a5 = -(u0 * s4 - u1 * s3) + g2
    w0 = u1 * v2 - u2 * v1 + (Cj[0, 0] * a0 + Cj[0, 1] * a1 + Cj[0, 2] * a2 + Cj[0, 3] * a3
                              + Cj[0, 4] * a4 + Cj[0, 5] * a5)
    w1 = u2 * v0 - u0 * v2 + (Cj[1, 0] * a0 + Cj[1, 1] * a1 + Cj[1, 2] * a2 + Cj[1, 3] * a3
                              + Cj[1, 4] * a4 + Cj[1, 5] * a5)
    w2 = u0 * v1 - u1 * v0 + (Cj[2, 0] * a0 + Cj[2, 1] * a1 + Cj[2, 2] * a2 + Cj[2, 3] * a3
                              + Cj[2, 4] * a4 + Cj[2, 5] * a5)
    # ∇²d p' = κ (p' - n̂ (n̂·p') - e (e·p'))
    ep = e0 * dx + e1 * dy + e2 * dz
    h0 = kappa * (dx - n0 * slope - e0 * ep)
    h1 = kappa * (dy - n1 * slope - e1 * ep)
    h2 = kappa * (dz - n2 * slope - e2 * ep)
    k0 = Cj[0, 0] * m0 + Cj[0, 1] * m1 + Cj[0, 2] * m2  # C_vv ñ
    k1 = Cj[1, 0] * m0 + Cj[1, 1] * m1 + Cj[1, 2] * m2
    k2 = Cj[2, 0] * m0 + Cj[2, 1] * m1 + Cj[2, 2] * m2
    b = m0 * k0 + m1 * k1 + m2 * k2
    a = dx * h0 + dy * h1 + dz * h2 + m0 * w0 + m1 * w1 + m2 * w2
    c = a / b
    return (c, n0, n1, n2, kappa, e0, e1, e2, m0, m1, m2, k0, k1, k2, b, w0, w1, w2, h0, h1,
            h2, slope, f0, f1, f2, g0, g1, g2)


@_jit
def _zone_variation(z, Cj, R00, R01, R02, R10, R11, R12, R20, R21, R22, v0, v1, v2,
                    u0, u1, u2, s0, s1, s2, s3, s4, s5, dx, dy, dz, dp0, dp1, dp2, th0, th1,
                    th2, ds0, ds1, ds2, ds3, ds4, ds5, c0, c1, c2, c3, c4, c5, q0, q1, q2,
                    dfn0, dfn1, dfn2, dfm0, dfm1, dfm2):
    """The variation of a zone's contact force per unit length c n̂ (spatial) along a
    tangent column: δp, δθ (material), δσ, δ(v; u) = (c0..c5), δp' = q, δn' and δm' without
    the contact (dfn, dfm); ``z`` is :func:`_zone_pressure`'s tuple at the state. Exact
    (the derivative of its formula, with ∇²d's own change on a ball or a cylinder:
    δκ = -κ² n̂·δp, δn̂ = ∇²d δp, the axis fixed)."""
    (c, n0, n1, n2, kappa, e0, e1, e2, m0, m1, m2, k0, k1, k2, b, w0, w1, w2, h0, h1, h2,
     slope, f0, f1, f2, g0, g1, g2) = z
    dg = n0 * dp0 + n1 * dp1 + n2 * dp2
    ed = e0 * dp0 + e1 * dp1 + e2 * dp2
    dn0 = kappa * (dp0 - n0 * dg - e0 * ed)  # δn̂ = ∇²d δp
    dn1 = kappa * (dp1 - n1 * dg - e1 * ed)
    dn2 = kappa * (dp2 - n2 * dg - e2 * ed)
    # δñ = Rᵀ δn̂ - δθ × ñ
    r0, r1, r2 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, dn0, dn1, dn2)
    r0 -= th1 * m2 - th2 * m1
    r1 -= th2 * m0 - th0 * m2
    r2 -= th0 * m1 - th1 * m0
    # δσ' = -δu × σ - u × δσ + Rᵀ δ(n'; m') - δθ × Rᵀ (n'; m')
    b0, b1, b2 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, dfn0, dfn1, dfn2)
    b3, b4, b5 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, dfm0, dfm1, dfm2)
    a0 = -(c4 * s2 - c5 * s1) - (u1 * ds2 - u2 * ds1) + b0 - (th1 * f2 - th2 * f1)
    a1 = -(c5 * s0 - c3 * s2) - (u2 * ds0 - u0 * ds2) + b1 - (th2 * f0 - th0 * f2)
    a2 = -(c3 * s1 - c4 * s0) - (u0 * ds1 - u1 * ds0) + b2 - (th0 * f1 - th1 * f0)
    a3 = -(c4 * s5 - c5 * s4) - (u1 * ds5 - u2 * ds4) + b3 - (th1 * g2 - th2 * g1)
    a4 = -(c5 * s3 - c3 * s5) - (u2 * ds3 - u0 * ds5) + b4 - (th2 * g0 - th0 * g2)
    a5 = -(c3 * s4 - c4 * s3) - (u0 * ds4 - u1 * ds3) + b5 - (th0 * g1 - th1 * g0)
    # δ(u × v + v')
    x0 = c4 * v2 - c5 * v1 + u1 * c2 - u2 * c1 + (
        Cj[0, 0] * a0 + Cj[0, 1] * a1 + Cj[0, 2] * a2 + Cj[0, 3] * a3 + Cj[0, 4] * a4
        + Cj[0, 5] * a5)
    x1 = c5 * v0 - c3 * v2 + u2 * c0 - u0 * c2 + (
        Cj[1, 0] * a0 + Cj[1, 1] * a1 + Cj[1, 2] * a2 + Cj[1, 3] * a3 + Cj[1, 4] * a4
        + Cj[1, 5] * a5)
    x2 = c3 * v1 - c4 * v0 + u0 * c1 - u1 * c0 + (
        Cj[2, 0] * a0 + Cj[2, 1] * a1 + Cj[2, 2] * a2 + Cj[2, 3] * a3 + Cj[2, 4] * a4
        + Cj[2, 5] * a5)
    # δa = 2 (∇²d p')·δp' + p'ᵀ δ(∇²d) p' + δñ·(u × v + v') + ñ·δ(u × v + v'), with
    # p'ᵀ δ(∇²d) p' = -κ (n̂·δp) p'ᵀ∇²d p' - 2 κ (δn̂·p') (n̂·p')
    hp = dx * h0 + dy * h1 + dz * h2
    da = (2.0 * (h0 * q0 + h1 * q1 + h2 * q2) - kappa * dg * hp
          - 2.0 * kappa * (dn0 * dx + dn1 * dy + dn2 * dz) * slope
          + r0 * w0 + r1 * w1 + r2 * w2 + m0 * x0 + m1 * x1 + m2 * x2)
    db = 2.0 * (r0 * k0 + r1 * k1 + r2 * k2)  # (C_vv symmetric)
    dc = (da - c * db) / b
    return dc * n0 + c * dn0, dc * n1 + c * dn1, dc * n2 + c * dn2


@_jit
def _zone_forces(work, twork, nt, stage, arm, act, j, rate, contact):
    """On a hard contact zone's piece j (a passive one: the linear law), subtract the zone's
    force per unit length ``contact`` × c n̂ (:func:`_zone_pressure`, ``contact`` the
    channel CT) from the stage's n' in ``work[stage]``, and its variation from the first nt
    tangent columns' δn' in ``twork[stage]`` (:func:`_zone_variation`; with the contact's
    own change along the path in the columns from LAM on). Called by :func:`_deriv` after
    the rest of the right-hand side, which it reads there (n', m', δp', δn', δm' without the
    contact): kept out of _deriv's loops, which it would slow on every other arm."""
    C, f0 = arm[2], arm[3]
    Y = 4
    y, w = work[Y], work[stage]
    R00, R01, R02 = y[_R], y[_R + 1], y[_R + 2]
    R10, R11, R12 = y[_R + 3], y[_R + 4], y[_R + 5]
    R20, R21, R22 = y[_R + 6], y[_R + 7], y[_R + 8]
    # σ (material)
    s0, s1, s2 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, y[_N], y[_N + 1],
                           y[_N + 2])
    s3, s4, s5 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, y[_M], y[_M + 1],
                           y[_M + 2])
    v0, v1, v2, u0, u1, u2 = _strain(C, f0, j, False, s0, s1, s2, s3, s4, s5)
    zone = _zone_pressure(
        act[5][int(act[6][j, ZONE]) - 1], C[j], y[_P], y[_P + 1], y[_P + 2], R00, R01, R02,
        R10, R11, R12, R20, R21, R22, v0, v1, v2, u0, u1, u2, s0, s1, s2, s3, s4, s5,
        w[_P], w[_P + 1], w[_P + 2], w[_N], w[_N + 1], w[_N + 2], w[_M], w[_M + 1], w[_M + 2])
    c = zone[0]
    for d in range(nt):
        t, o = twork[Y, d], twork[stage, d]
        th0, th1, th2 = t[_TT], t[_TT + 1], t[_TT + 2]
        # δσ = (Rᵀδn + σ_n × δθ; Rᵀδm + σ_m × δθ)
        ds0, ds1, ds2 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, t[_TN],
                                  t[_TN + 1], t[_TN + 2])
        ds3, ds4, ds5 = _material(R00, R01, R02, R10, R11, R12, R20, R21, R22, t[_TM],
                                  t[_TM + 1], t[_TM + 2])
        ds0 += s1 * th2 - s2 * th1
        ds1 += s2 * th0 - s0 * th2
        ds2 += s0 * th1 - s1 * th0
        ds3 += s4 * th2 - s5 * th1
        ds4 += s5 * th0 - s3 * th2
        ds5 += s3 * th1 - s4 * th0
        c0, c1, c2, c3, c4, c5 = _strain(C, arm[4], j, False, ds0, ds1, ds2, ds3, ds4, ds5)
        z0, z1, z2 = _zone_variation(
            zone, C[j], R00, R01, R02, R10, R11, R12, R20, R21, R22, v0, v1, v2, u0, u1, u2,
            s0, s1, s2, s3, s4, s5, w[_P], w[_P + 1], w[_P + 2], t[_TP], t[_TP + 1],
            t[_TP + 2], th0, th1, th2,
            ds0, ds1, ds2, ds3, ds4, ds5, c0, c1, c2, c3, c4, c5, o[_TP], o[_TP + 1],
            o[_TP + 2], o[_TN], o[_TN + 1], o[_TN + 2], o[_TM], o[_TM + 1], o[_TM + 2])
        scale = rate[d - LAM, j, _CT] if d >= LAM else 0.0  # the contact's own change
        for i in range(3):
            o[_TN + i] -= contact * (z0, z1, z2)[i] + scale * c * zone[1 + i]
    for i in range(3):
        w[_N + i] -= contact * c * zone[1 + i]


@_inline
def _station_rotation(y0, f0, y1, f1, u, h, out):
    """The rotation of a station at u ∈ [0, 1] of a step of length h, from the states y0, y1
    and derivatives f0, f1 at its ends: R = R0 exp(θ~), θ(u) the cubic Hermite polynomial of
    the rotation vector from R0 (θ(0) = 0, θ(1) = log(R0ᵀ R1), θ' = h u0 and h J_r⁻¹(θ1) u1,
    u the curvature R' = R u~). The rotation vector is what varies slowly (exactly linearly
    on an arc), so this interpolates R to the accuracy of the positions' Hermite polynomial,
    where interpolating R's entries was 10× worse; exactly a rotation. Writes out[3:12]."""
    # u0 = vee(R0ᵀ R0'), u1 = vee(R1ᵀ R1') (the antisymmetric part's axial vector)
    c = np.empty((2, 3))
    for e in range(2):
        y, f = (y0, f0) if e == 0 else (y1, f1)
        for a in range(3):  # (RᵀR')[a, b] = Σ_i R[i, a] R'[i, b]
            b, d = (a + 1) % 3, (a + 2) % 3
            m_db = (y[_R + d] * f[_R + b] + y[_R + 3 + d] * f[_R + 3 + b]
                    + y[_R + 6 + d] * f[_R + 6 + b])
            m_bd = (y[_R + b] * f[_R + d] + y[_R + 3 + b] * f[_R + 3 + d]
                    + y[_R + 6 + b] * f[_R + 6 + d])
            c[e, a] = 0.5 * (m_db - m_bd)  # û[d, b] = u_a
    # Q = R0ᵀ R1 and its rotation vector
    q = np.empty((3, 3))
    for a in range(3):
        for b in range(3):
            q[a, b] = (y0[_R + a] * y1[_R + b] + y0[_R + 3 + a] * y1[_R + 3 + b]
                       + y0[_R + 6 + a] * y1[_R + 6 + b])
    w0, w1, w2 = q[2, 1] - q[1, 2], q[0, 2] - q[2, 0], q[1, 0] - q[0, 1]
    sine = 0.5 * math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    cosine = 0.5 * (q[0, 0] + q[1, 1] + q[2, 2] - 1.0)
    angle = math.atan2(sine, cosine)
    scale = 0.5 + angle * angle / 12.0 if angle < 1e-4 else 0.5 * angle / math.sin(angle)
    t0, t1, t2 = scale * w0, scale * w1, scale * w2  # θ1
    # θ1' = J_r⁻¹(θ1) u1 = u1 + ½ θ1 × u1 + β θ1 × (θ1 × u1)
    beta = (1.0 / 12.0 + angle * angle / 720.0 if angle < 1e-3 else
            1.0 / (angle * angle) - (1.0 + math.cos(angle)) / (2.0 * angle * math.sin(angle)))
    v0, v1, v2 = c[1, 0], c[1, 1], c[1, 2]
    x0, x1, x2 = t1 * v2 - t2 * v1, t2 * v0 - t0 * v2, t0 * v1 - t1 * v0  # θ1 × u1
    z0, z1, z2 = t1 * x2 - t2 * x1, t2 * x0 - t0 * x2, t0 * x1 - t1 * x0
    d0, d1, d2 = v0 + 0.5 * x0 + beta * z0, v1 + 0.5 * x1 + beta * z1, v2 + 0.5 * x2 + beta * z2
    # the Hermite polynomial at u (θ(0) = 0)
    c1 = u * (1.0 - u) * (1.0 - u) * h
    c2 = u * u * (3.0 - 2.0 * u)
    c3 = -u * u * (1.0 - u) * h
    a0 = c1 * c[0, 0] + c2 * t0 + c3 * d0
    a1 = c1 * c[0, 1] + c2 * t1 + c3 * d1
    a2 = c1 * c[0, 2] + c2 * t2 + c3 * d2
    _rotated(y0, a0, a1, a2, out)


@_inline
def _rotated(y0, a0, a1, a2, out):
    """out's rotation = y0's R times exp(a~) (a material, by Rodrigues; the series below
    1e-4 rad, to round-off); ``out`` may be ``y0`` (a row is read before it is written)."""
    angle = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    if angle < 1e-4:
        sa, ca = 1.0 - angle * angle / 6.0, 0.5 - angle * angle / 24.0
    else:
        sa, ca = math.sin(angle) / angle, (1.0 - math.cos(angle)) / (angle * angle)
    e00 = 1.0 - ca * (a1 * a1 + a2 * a2)
    e11 = 1.0 - ca * (a0 * a0 + a2 * a2)
    e22 = 1.0 - ca * (a0 * a0 + a1 * a1)
    e01 = -sa * a2 + ca * a0 * a1
    e10 = sa * a2 + ca * a0 * a1
    e02 = sa * a1 + ca * a0 * a2
    e20 = -sa * a1 + ca * a0 * a2
    e12 = -sa * a0 + ca * a1 * a2
    e21 = sa * a0 + ca * a1 * a2
    for a in range(3):
        r0, r1, r2 = y0[_R + 3 * a], y0[_R + 3 * a + 1], y0[_R + 3 * a + 2]
        out[_R + 3 * a] = r0 * e00 + r1 * e10 + r2 * e20
        out[_R + 3 * a + 1] = r0 * e01 + r1 * e11 + r2 * e21
        out[_R + 3 * a + 2] = r0 * e02 + r1 * e12 + r2 * e22


@_inline
def _bjorck(y):
    """R ← R (3I - RᵀR)/2 on the state's rotation: one Björck step towards the nearest
    rotation (quadratic: an error ε of RᵀR = I becomes about ε²)."""
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


@_jit
def _steps(y, T, nt, h, s, n, arm, act, j, now, rate, work, twork, law):
    """``n`` RK4 steps of length h (negative: towards the base) from arc length s on piece j,
    in place (the state and the first nt tangent columns of T), each followed by
    R ← R (3I - RᵀR)/2: one Björck step towards the nearest rotation. ``n`` < 0: |n| steps,
    the first one's first-stage derivatives already in ``work[0]`` and ``twork[0]`` (left
    there by the output pass: not evaluated again); ``n`` = 0: those derivatives at (y, T, s)
    only, y and T unchanged (encodings, not more arguments, so that every caller shares one
    compiled version, with one inlined copy of the right-hand side).

    Design note: this is the one function the right-hand side (:func:`_deriv`) is compiled
    into. Every integration (the shooting pass, the output pass, the stability sweep) calls
    it for a run of steps, so numba and LLVM build and optimise the right-hand side once
    instead of once per caller (cold compile: see statics/README.md), and a call costs once
    per run of steps, not once per stage. The RK4 step is written here, not in a function of
    its own: each level of numba inlining deep-copies the inlined IR twice, and the step's
    own level cost about 5 s of cold compile.

    Loops are written out (no slice assignment, no array expression): numba compiles those
    with shape checks whose error messages pull in its string machinery.
    """
    lengths = act is not None and T.shape[1] > NT  # the tendons' lengths' tangents
    for step in range(max(abs(n), 1)):
        at = s + step * h
        for stage in range(4):  # work rows 0-3: the stage derivatives; row 4: the stage state
            if stage == 0 and n < 0 and step == 0:
                continue
            a = 0.0 if stage == 0 else (h if stage == 3 else 0.5 * h)
            prev = max(stage - 1, 0)
            for i in range(y.size):
                work[4, i] = y[i] + a * work[prev, i] if stage else y[i]
            for d in range(nt):
                for i in range(NT):
                    twork[4, d, i] = T[d, i] + a * twork[prev, d, i] if stage else T[d, i]
            if act is not None and lengths:
                for d in range(nt):
                    for i in range(NT, T.shape[1]):
                        twork[4, d, i] = T[d, i] + a * twork[prev, d, i] if stage else T[d, i]
            _deriv(work, twork, nt, stage, at + a, arm, act, j, now, rate, law)
            if n == 0:
                return
        w = h / 6.0
        for i in range(y.size):
            y[i] += w * (work[0, i] + 2.0 * work[1, i] + 2.0 * work[2, i] + work[3, i])
        for d in range(nt):
            for i in range(NT):
                T[d, i] += w * (twork[0, d, i] + 2.0 * twork[1, d, i] + 2.0 * twork[2, d, i]
                                + twork[3, d, i])
        if act is not None and lengths:
            for d in range(nt):
                for i in range(NT, T.shape[1]):
                    T[d, i] += w * (twork[0, d, i] + 2.0 * twork[1, d, i]
                                    + 2.0 * twork[2, d, i] + twork[3, d, i])
        _bjorck(y)


@_jit
def _jump(y, T, nt, now, rate, j, arm, act, law):
    """The point wrench at the start of piece j: n and m drop by W_d + R W_f (and their
    tangents by R (δθ × W_f), plus ∂_λ W in the load-factor column), and by the wrench of a
    magnetic dipole there (a segment's ``tip_magnet``)."""
    if act is not None:
        _dipole_jump(y, T, nt, act[4], j, now[j], rate, j, law[2][5], y, T, -1.0)
    for half in range(2):
        at = 3 * half
        W0, W1, W2 = now[j, _JF + at], now[j, _JF + at + 1], now[j, _JF + at + 2]
        for i in range(3):
            y[_N + at + i] -= now[j, _JD + at + i] + (
                y[_R + 3 * i] * W0 + y[_R + 3 * i + 1] * W1 + y[_R + 3 * i + 2] * W2)
        for d in range(nt):
            th0, th1, th2 = T[d, _TT], T[d, _TT + 1], T[d, _TT + 2]
            c0 = th1 * W2 - th2 * W1
            c1 = th2 * W0 - th0 * W2
            c2 = th0 * W1 - th1 * W0
            if d >= LAM:
                c0 += rate[d - LAM, j, _JF + at]
                c1 += rate[d - LAM, j, _JF + at + 1]
                c2 += rate[d - LAM, j, _JF + at + 2]
            for i in range(3):
                T[d, _TN + at + i] -= (y[_R + 3 * i] * c0 + y[_R + 3 * i + 1] * c1
                                       + y[_R + 3 * i + 2] * c2)
                if d >= LAM:
                    T[d, _TN + at + i] -= rate[d - LAM, j, _JD + at + i]


@_jit
def _dipole_jump(y, T, nt, dipoles, at, now, rate, j, out, ydst, Tdst, sign):
    """Add ``sign`` × the wrench of dipole ``dipoles[at]`` (A m², material) to n, m of
    ``ydst`` and its variations to the first nt tangent columns of ``Tdst`` (rows 6:12), or
    with ``ydst`` the residual r (6) and ``Tdst`` the Jacobian J (6, nt) (see callers); the
    field and its rates are piece j's (``now``, ``rate[:, j]``)."""
    m0, m1, m2 = dipoles[at, 0], dipoles[at, 1], dipoles[at, 2]
    if m0 == 0.0 and m1 == 0.0 and m2 == 0.0:
        return
    off = _N if ydst.size >= 18 else 0
    for d in range(nt):
        _dipole(y, T, d + 1, m0, m1, m2, now, rate[max(d - LAM, 0), j], out)
        for i in range(6):
            if off:
                Tdst[d, _TN + i] += sign * out[i]
            else:
                Tdst[i, d] += sign * out[i]
    _dipole(y, T, np.int64(0), m0, m1, m2, now, rate[0, j], out)
    for i in range(6):
        ydst[off + i] += sign * out[i]


@_jit
def _start(y, T, nt, base, x):
    """The state at the clamp from the base reaction x, and the tangents' initial values."""
    for i in range(3):
        y[_P + i] = base[i, 3]
        for k in range(3):
            y[_R + 3 * i + k] = base[i, k]
        y[_N + i] = x[i]
        y[_M + i] = x[3 + i]
    for i in range(18, y.size):
        y[i] = 0.0  # the tendons' lengths
    for d in range(nt):
        for i in range(T.shape[1]):  # with the tendons' lengths' (0 at the base)
            T[d, i] = 0.0
        if d < 6:
            T[d, _TN + d] = 1.0  # δ(n(0); m(0)) = e_d


@_jit
def _tip_residual(y, T, nt, tip_now, tip_rate, r, J, arm, act, now, rate, law):
    """The boundary residual r at the tip and its Jacobian columns J[:, :nt]: the total
    wrench n(L), m(L) minus the tip loads (and the tip dipole's wrench)."""
    for half in range(2):
        at = 3 * half
        F0, F1, F2 = tip_now[_TF + at], tip_now[_TF + at + 1], tip_now[_TF + at + 2]
        for i in range(3):
            r[at + i] = y[_N + at + i] - tip_now[_TD + at + i] - (
                y[_R + 3 * i] * F0 + y[_R + 3 * i + 1] * F1 + y[_R + 3 * i + 2] * F2)
        for d in range(nt):
            th0, th1, th2 = T[d, _TT], T[d, _TT + 1], T[d, _TT + 2]
            c0 = th1 * F2 - th2 * F1
            c1 = th2 * F0 - th0 * F2
            c2 = th0 * F1 - th1 * F0
            if d >= LAM:
                c0 += tip_rate[d - LAM, _TF + at]
                c1 += tip_rate[d - LAM, _TF + at + 1]
                c2 += tip_rate[d - LAM, _TF + at + 2]
            for i in range(3):
                J[at + i, d] = T[d, _TN + at + i] - (
                    y[_R + 3 * i] * c0 + y[_R + 3 * i + 1] * c1 + y[_R + 3 * i + 2] * c2)
                if d >= LAM:
                    J[at + i, d] -= tip_rate[d - LAM, _TD + at + i]
    if act is not None:
        last = now.shape[0] - 1
        _dipole_jump(y, T, nt, act[4], last + 1, now[last], rate, last, law[2][5], r, J, -1.0)


@_jit
def _set_loads(lam, case, now, tip_now):
    """The loads at load factor λ: start + λ (end - start), per piece and at the tip."""
    start, rate, tip_start, tip_rate = case
    for j in range(start.shape[0]):
        for i in range(start.shape[1]):
            now[j, i] = start[j, i] + lam * rate[0, j, i]
    for i in range(TIP_LOADS):
        tip_now[i] = tip_start[i] + lam * tip_rate[0, i]


@_inline
def _integrate(x, lam, nt, steps, base, arm, act, case, scratch, r, J):
    """Integrate base → tip from the base reaction x at load factor λ: the residual r (6) and
    the first nt Jacobian columns J[:, :nt] (6 by x, the 7th by λ). The tip state is left in
    scratch's y and its tangents in T (for the tip motion per unit x)."""
    y, T, work, twork, now, tip_now = scratch[0], scratch[1], scratch[2], scratch[3], \
        scratch[4], scratch[5]
    law = scratch[8]
    rate, tip_rate = case[1], case[3]
    _set_loads(lam, case, now, tip_now)
    piece_start, piece_len = arm[0], arm[1]
    _start(y, T, nt, base, x)
    for j in range(piece_len.size):
        _jump(y, T, nt, now, rate, j, arm, act, law)
        _steps(y, T, nt, piece_len[j] / steps[j], piece_start[j], steps[j], arm, act, j, now, rate,
               work, twork, law)
    _tip_residual(y, T, nt, tip_now, tip_rate, r, J, arm, act, now, rate, law)
