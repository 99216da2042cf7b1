"""Compiled closed forms for one load (numba): the elastica and the screw poses.

The one compiled module of ``softarm.analytic`` (numba's cache does not see changes in
callees defined in other files, so every compiled function of the package lives here).
``softarm.analytic`` imports it on first use (``import softarm`` does not import numba); it
never imports ``softarm.statics``.

:func:`solve` and :func:`fields` evaluate the elastica for one load: the same algorithm
as ``_elastica_math._batch`` (see that module's docstring for the derivation and the
notation), written for one load with scalar loops over the stations:
the tip condition and every station are solved by the same safeguarded Newton iteration in
ρ = log tan χ with the same stopping rules, the stations from the same starts (Jacobi's
amplitude, or its asymptotic form near χ = π/2). Two fields take product forms that need no
inverse trigonometric function: p² − w² = (sin(δ_L/2) cos(δ_L/2) sin χ_s/h)², h² =
sin²(δ_L/2) + cos²(δ_L/2) cos²χ_s (from tan(d/2) = tan(δ_L/2)/cos χ_s), so the curvature is
θ' = 2 √k sin(δ_L/2) cos(δ_L/2) (sin χ_s/h) √f; and, for χ_0 < 1, cos χ_s − cos χ_0 =
(sin χ_0 − sin χ_s)(sin χ_0 + sin χ_s)/(cos χ_s + cos χ_0). Carlson's R_F and R_D and
Jacobi's sn, cn are written out here (numba has no scipy.special).

:func:`screw` writes the poses H(s) = exp_SE3(s (u; ω)) · exp_SE3(s (0; τ e1)) of one arm and
fields linear in (1, 1 − cos τs, sin τs): the helix and the constant-strain closed forms of
``moment.py``, as ``_common.screw_poses`` does for batches.

References
----------
B. C. Carlson, "Numerical computation of real or complex elliptic integrals", Numer.
Algorithms 10 (1995) 13-26: the duplication algorithms for R_F and R_D, with their stopping
rules; DLMF §19.36 (the series after the duplications). Jacobi's sn, cn by the
arithmetic-geometric mean and the descending Landen transformation: DLMF §22.20, Abramowitz &
Stegun 16.4; their derivatives: DLMF §22.13.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import jit

__all__ = ["carlson_rd", "carlson_rf", "fields", "jacobi_sn_cn", "screw", "solve"]

_EPS = 2.220446049250313e-16
#: ``_elastica_math``'s bracket of ρ = log tan χ and Newton step limit, restated here: numba
#: caches compiled code by this file alone, so a constant imported from another file could
#: go stale in the cache (tests/analytic/test_compiled.py checks that they agree).
_RHO_MAX = 700.0
_MAX_STEPS = 100
#: Carlson's stopping constants (3r)^(-1/6) for R_F and (r/4)^(-1/6) for R_D, r = 2^-53: the
#: truncated series then errs by less than r relative.
_Q_RF = (3.0 * 2.0**-53) ** (-1.0 / 6.0)
_Q_RD = (0.25 * 2.0**-53) ** (-1.0 / 6.0)
#: Largest step in u = F(χ | m') from the last station solved for which the next one starts
#: from the Taylor series of am (error ~ h⁵ m'/120: a Newton step or two), else from am.
_STEP = 0.25

_jit = jit(what="softarm's compiled closed forms", error_model="numpy", fastmath=False)
#: The entry points (called from Python), announced when they compile (softarm._jit)
_entry = jit(what="softarm's compiled closed forms", error_model="numpy", fastmath=False,
             capability=lambda args: ("closed forms", "the closed forms' kernels"))


@_jit
def carlson_rf(x, y, z):
    """Carlson's R_F(x, y, z) for x, y, z ≥ 0, at most one of them zero (DLMF §19.36); +inf
    where two are zero (its limit there; the duplication below would never stop: the two
    zeros stay zero while the mean and the spread shrink alike)."""
    if x + y == 0.0 or x + z == 0.0 or y + z == 0.0:
        return math.inf
    a0 = (x + y + z) / 3.0
    q = _Q_RF * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    a, scale = a0, 1.0  # scale = 4^-n
    xn, yn, zn = x, y, z
    while q * scale >= abs(a):
        rx, ry, rz = math.sqrt(xn), math.sqrt(yn), math.sqrt(zn)
        lam = rx * (ry + rz) + ry * rz
        xn, yn, zn = 0.25 * (xn + lam), 0.25 * (yn + lam), 0.25 * (zn + lam)
        a = 0.25 * (a + lam)
        scale *= 0.25
    big_x = (a0 - x) * scale / a
    big_y = (a0 - y) * scale / a
    big_z = -(big_x + big_y)
    e2 = big_x * big_y - big_z * big_z
    e3 = big_x * big_y * big_z
    series = (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0
              - 5.0 * e2 * e2 * e2 / 208.0 + 3.0 * e3 * e3 / 104.0 + e2 * e2 * e3 / 16.0)
    return series / math.sqrt(a)


@_jit
def carlson_rd(x, y, z):
    """Carlson's R_D(x, y, z) for x, y ≥ 0 (at most one zero), z > 0 (DLMF §19.36); +inf
    where x and y are both zero or z is (its limit there, as for :func:`carlson_rf`)."""
    if x + y == 0.0 or z == 0.0:
        return math.inf
    a0 = (x + y + 3.0 * z) / 5.0
    q = _Q_RD * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    a, scale, total = a0, 1.0, 0.0
    xn, yn, zn = x, y, z
    while q * scale >= abs(a):
        rx, ry, rz = math.sqrt(xn), math.sqrt(yn), math.sqrt(zn)
        lam = rx * (ry + rz) + ry * rz
        total += scale / (rz * (zn + lam))
        xn, yn, zn = 0.25 * (xn + lam), 0.25 * (yn + lam), 0.25 * (zn + lam)
        a = 0.25 * (a + lam)
        scale *= 0.25
    big_x = (a0 - x) * scale / a
    big_y = (a0 - y) * scale / a
    big_z = -(big_x + big_y) / 3.0
    xy, zz = big_x * big_y, big_z * big_z
    e2 = xy - 6.0 * zz
    e3 = (3.0 * xy - 8.0 * zz) * big_z
    e4 = 3.0 * (xy - zz) * zz
    e5 = xy * zz * big_z
    series = (1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
              - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0)
    return scale * series / (a * math.sqrt(a)) + 3.0 * total


@_jit
def jacobi_sn_cn(u, mc, ratios):
    """Jacobi's sn(u | m) and cn(u | m) from the complementary parameter mc = 1 − m ∈ [0, 1].

    The arithmetic-geometric mean of 1 and √mc, then the descending Landen recursion
    φ_{n−1} = (φ_n + asin((c_n/a_n) sin φ_n))/2 from φ_N = 2^N a_N u (A&S 16.4); mc = 0 is
    the limit sn = tanh u, cn = sech u. ``ratios`` is scratch for c_n/a_n (at least 17
    entries). A start for Newton's method: sn, cn to about 1e-12 for u ≤ 12.
    """
    if mc <= 0.0:
        return math.tanh(u), 1.0 / math.cosh(u)
    a, b, c = 1.0, math.sqrt(mc), math.sqrt(1.0 - mc)
    n = 0
    while abs(c) > _EPS * a and n < 16:
        a, b, c = 0.5 * (a + b), math.sqrt(a * b), 0.5 * (a - b)
        n += 1
        ratios[n] = c / a
    phi = 2.0**n * a * u
    for i in range(n, 0, -1):
        phi = 0.5 * (phi + math.asin(ratios[i] * math.sin(phi)))
    return math.sin(phi), math.cos(phi)


@_jit
def _sin_cos_from_rho(rho):
    """(sin χ, cos χ) for tan χ = exp(ρ), both with full relative precision."""
    t = math.exp(-abs(rho))
    big = 1.0 / math.sqrt(1.0 + t * t)
    if rho >= 0.0:
        return big, t * big
    return t * big, big


@_jit
def _tip_residual(rho, ca, sa, sqrt_k, e):
    """Residual F/√f_L − √k of the tip condition and its slope in ρ (``_solve_tip``)."""
    s_ch, c_ch = _sin_cos_from_rho(rho)
    h = math.hypot(ca, sa * c_ch)
    s_dl, c_dl = sa * c_ch / h, ca / h
    m1 = s_dl * s_dl
    f_l = 1.0 + e * (c_dl - s_dl) * (c_dl + s_dl)
    mc = m1 * (1.0 - e * m1) / f_l
    cc, ss = c_ch * c_ch, s_ch * s_ch
    delta2 = cc + mc * ss
    arc = s_ch * carlson_rf(cc, delta2, 1.0)
    mm1 = (s_dl * c_dl) * (s_dl * c_dl)
    dm_f = 2.0 * mm1 * ss / f_l
    half_j = s_ch * ss * carlson_rd(cc, 1.0, delta2) / 6.0
    slope = s_ch * c_ch / math.sqrt(delta2) + dm_f * (
        half_j * (1.0 - 2.0 * e * e * mm1 / f_l) - e * arc)
    root_f = math.sqrt(f_l)
    return arc / root_f - sqrt_k, slope / root_f


@_jit
def _newton_step(residual, slope):
    """residual / slope, or inf (a bisection step, never a converged one) where the slope is
    not a positive finite number: at ρ near ±700 an underflowed cos χ can make it inf, and
    the step then came out 0 (taken as converged, far from the root)."""
    if slope > 0.0 and math.isfinite(slope):
        return residual / slope
    return math.inf


@_jit
def _solve_tip(ca, sa, sqrt_k, e):
    """ρ_0 of the tip condition by ``_elastica_math._newton``'s safeguarded iteration."""
    tol = 4.0 * _EPS
    x = math.log(math.sinh(sqrt_k * math.sqrt(1.0 - abs(e))))
    lo, hi = -_RHO_MAX, _RHO_MAX
    for _ in range(_MAX_STEPS):
        residual, slope = _tip_residual(x, ca, sa, sqrt_k, e)
        if residual < 0.0:
            lo = x
        else:
            hi = x
        step = _newton_step(residual, slope)
        newton = x - step
        size, scale = abs(step), tol * max(1.0, abs(x))
        last = size <= scale
        x = newton if last or (lo < newton < hi) else 0.5 * (lo + hi)
        if last or hi - lo <= scale:
            break
    return x


@_jit
def _station(target, mc, rho_tip, start):
    """(sin χ_s, cos χ_s) with F(χ_s | m') = target, by ``_solve_stations``' iteration from
    ``start`` (ρ), bracketed by [−700, ρ_tip], with |R''/R'| ≤ 2 in the stopping rule."""
    tol = 4.0 * _EPS
    lo, hi = -_RHO_MAX, rho_tip
    x = start if start > lo else lo  # NaN goes to a bracket end as well
    x = x if x < hi else hi
    for _ in range(_MAX_STEPS):
        s_ch, c_ch = _sin_cos_from_rho(x)
        cc = c_ch * c_ch
        delta2 = cc + mc * s_ch * s_ch
        residual = s_ch * carlson_rf(cc, delta2, 1.0) - target
        slope = s_ch * c_ch / math.sqrt(delta2)
        if residual < 0.0:
            lo = x
        else:
            hi = x
        step = _newton_step(residual, slope)
        newton = x - step
        size, scale = abs(step), tol * max(1.0, abs(x))
        last = size <= scale or size * size <= scale
        x = newton if last or (lo < newton < hi) else 0.5 * (lo + hi)
        if last or hi - lo <= scale:
            break
    return _sin_cos_from_rho(x)


@_entry
def solve(k, a, sign, a_r, g_r, s, cheb, weights, out):
    """The planar elastica for one load with 0 < a < π (rad) from the force to +x, k > 0.

    Writes θ, x, z, θ', N/EA, Q/GA (rows of ``out``, shape (6, N), the fields of
    ``ElasticaSolution`` in order) at the stations ``s`` (N,) in [0, 1], and returns the tip
    angle θ(1); ``sign`` = ±1 mirrors the solution (φ = sign · a). With e = k (a_r − g_r) ≠ 0
    the position along the force line is the Clenshaw-Curtis rule ``integrand(cheb) @
    weights`` (``cheb`` the Chebyshev points, ``weights`` (len(cheb), N)); otherwise both
    are unused and the closed form in R_D is used.
    """
    n = s.shape[0]
    e = k * (a_r - g_r)
    ka, kg = k * a_r, k * g_r
    sqrt_k = math.sqrt(k)
    ca, sa = math.cos(0.5 * a), math.sin(0.5 * a)
    rho_tip = _solve_tip(ca, sa, sqrt_k, e)
    s_chi, c_chi = _sin_cos_from_rho(rho_tip)
    h0 = math.hypot(ca, sa * c_chi)
    s_dl, c_dl = sa * c_chi / h0, ca / h0
    half_tip = math.atan2(sa * ca * s_chi * s_chi / (1.0 + c_chi), ca * ca + sa * sa * c_chi)
    tip = 2.0 * half_tip
    m, m1 = c_dl * c_dl, s_dl * s_dl
    f_l = 1.0 + e * (c_dl - s_dl) * (c_dl + s_dl)
    mc = m1 * (1.0 - e * m1) / f_l
    u0 = sqrt_k * math.sqrt(f_l)
    quadrature = e != 0.0
    ratios = np.empty(17)
    last = np.empty(3)  # (u, sin χ, cos χ) of the last station solved: the clamp at first
    last[0], last[1], last[2] = u0, s_chi, c_chi

    theta, x, z, kappa, axial, shear = out[0], out[1], out[2], out[3], out[4], out[5]
    xi = out[1]  # the position along the force line, before the rotation into x and z
    if quadrature:
        for j in range(n):
            xi[j] = 0.0
        for i in range(cheb.shape[0]):
            sn, cn = _station_angles(cheb[i], u0, mc, rho_tip, s_chi, c_chi, ratios, last)
            hd = math.hypot(s_dl, c_dl * cn)
            s_dn, c_dn = s_dl / hd, c_dl * cn / hd
            value = (c_dn - s_dn) * (c_dn + s_dn) + ka - e * (2.0 * s_dn * c_dn) ** 2
            for j in range(n):
                xi[j] += value * weights[i, j]

    kappa0 = 2.0 * sqrt_k * s_dl * c_dl * s_chi / math.hypot(s_dl, c_dl * c_chi)
    if quadrature:
        kappa0 *= math.sqrt(1.0 - e * (m1 - ca * ca))
    small_chi = math.atan2(s_chi, c_chi) < 1.0
    cos_a, sin_a = math.cos(a), math.sin(a)
    j_tip, cos_dl = 0.0, 0.0
    if not quadrature:
        cc = c_chi * c_chi
        j_tip = s_chi * s_chi * s_chi * carlson_rd(cc, 1.0, cc + m1 * s_chi * s_chi) / 3.0
        cos_dl = cos_a * math.cos(tip) + sin_a * math.sin(tip)  # cos(a − θ_L)
    for j in range(n):
        sn, cn = _station_angles(s[j], u0, mc, rho_tip, s_chi, c_chi, ratios, last)
        cd = c_dl * cn
        h = math.hypot(s_dl, cd)
        s_d, c_d = s_dl / h, cd / h  # sin and cos of δ(s)/2
        kap = (2.0 * sqrt_k * s_dl * c_dl) * sn / h
        if quadrature:  # θ' carries √f(w²), f = 1 − e (sin²(δ_L/2) − cos²(d/2))
            kap *= math.sqrt(1.0 - e * (m1 - c_d * c_d))
        if small_chi:
            dcos = (s_chi - sn) * (s_chi + sn) / (cn + c_chi)
        else:
            dcos = cn - c_chi
        th = 2.0 * math.atan2((sa * ca) * dcos, (ca * ca) * cn + sa * sa * c_chi)
        if s[j] == 1.0:
            th = tip  # the same rounding as the tip angle
        eta = 0.0 if s[j] == 0.0 else (kap - kappa0) / k
        if not quadrature:
            cc = cn * cn
            j_s = sn * sn * sn * carlson_rd(cc, 1.0, cc + m1 * sn * sn) / 3.0
            xi_j = s[j] * (cos_dl + ka) - (2.0 / sqrt_k * m * m1) * (j_tip - j_s)
        else:
            xi_j = xi[j]
        x[j] = xi_j * cos_a - eta * sin_a
        z[j] = sign * (xi_j * sin_a + eta * cos_a)
        theta[j] = sign * th
        kappa[j] = sign * kap
        axial[j] = ka * ((c_d - s_d) * (c_d + s_d))
        shear[j] = (sign * kg) * (2.0 * s_d * c_d)
    return sign * tip


@_jit
def _station_angles(s, u0, mc, rho_tip, s_chi, c_chi, ratios, last):
    """(sin χ_s, cos χ_s) at the station s ∈ [0, 1]: exact at the clamp and the tip, else
    polished by :func:`_station` from a start: once cos³χ < ε the asymptotic form 2 e^(−u) −
    m' e^u/8 of Jacobi's amplitude (as ``_solve_stations``); within ``_STEP`` in u of the
    last station solved, ``last`` = (u, sin χ, cos χ), the Taylor series of am about it;
    else am(u0 (1 − s) | m') itself. The start only sets how many Newton steps the root
    takes. Updates ``last`` to this station."""
    target = u0 * (1.0 - s)
    if s == 0.0:
        sn, cn = s_chi, c_chi
    elif s == 1.0:
        sn, cn = 0.0, 1.0
    else:
        start = math.nan
        if target > 12.0:  # below, 2 e^(-u) >= 1.2e-5: the asymptotic form is never used
            asymptotic = 2.0 * math.exp(-target) - mc * math.exp(target) / 8.0
            if asymptotic > 0.0 and asymptotic**3 < _EPS:
                start = -math.log(asymptotic)
        if start != start and abs(target - last[0]) <= _STEP:
            start = _taylor_start(target - last[0], last[1], last[2], mc)
        if start != start:
            sn, cn = jacobi_sn_cn(target, mc, ratios)
            if sn > 0.0 and cn > 0.0:
                start = math.log(sn) - math.log(cn)
            elif cn > 0.0:  # sn = 0: ρ = −∞
                start = -_RHO_MAX
            else:
                start = rho_tip
        sn, cn = _station(target, mc, rho_tip, start)
    last[0], last[1], last[2] = target, sn, cn
    return sn, cn


@_jit
def _taylor_start(h, sn, cn, mc):
    """ρ = log tan χ at u + h from χ = am(u | m') (its sine and cosine given), by the Taylor
    series of am to order 4: the derivatives of χ are dn, −m' sn cn, −m' cos 2χ dn and
    2 m' sin 2χ dn² + m'² cos 2χ sn cn (sn' = cn dn, cn' = −sn dn, dn' = −m' sn cn, DLMF
    §22.13). NaN if the prediction leaves (0, π/2)."""
    m = 1.0 - mc
    dn = math.sqrt(cn * cn + mc * sn * sn)
    sc = sn * cn
    c2 = (cn - sn) * (cn + sn)
    d4 = 4.0 * m * sc * dn * dn + m * m * c2 * sc
    chi = math.atan2(sn, cn) + h * (dn + h / 2.0 * (-m * sc + h / 3.0 * (
        -m * c2 * dn + h / 4.0 * d4)))
    if 0.0 < chi < 0.5 * math.pi:
        return math.log(math.tan(chi))
    return math.nan


@_entry
def fields(by, bz, length, stiffness, solution, out):
    """Poses (flattened, 16 columns), strains (6) and stresses (6) of a planar solution.

    ``solution`` (6, N) holds θ, x/L, z/L, θ' L, N/EA, Q/GA; the plane has the in-plane unit
    normal b = (0, by, bz) and the section turns about a = e1 × b = (0, −bz, by):
    R = I + sin θ a~ + 2 sin²(θ/2) (a aᵀ − I), p = L (x e1 + z b), γ = (N/EA) e1 + (Q/GA) b,
    κ = (θ'/L) a and σ = K ε with ``stiffness`` = diag K (6,). ``out`` has shape (N, 28).
    """
    ea, ga_y, ga_z, _, ei_y, ei_z = (stiffness[0], stiffness[1], stiffness[2], stiffness[3],
                                     stiffness[4], stiffness[5])
    for j in range(out.shape[0]):
        th = solution[0, j]
        half = math.sin(0.5 * th)
        sin, vers = math.sin(th), 2.0 * half * half
        x, z = solution[1, j], solution[2, j]
        axial, shear, curvature = solution[4, j], solution[5, j], solution[3, j]
        row = out[j]
        row[0] = 1.0 - vers
        row[1] = -by * sin
        row[2] = -bz * sin
        row[3] = length * x
        row[4] = by * sin
        row[5] = 1.0 - (by * by) * vers
        row[6] = -(by * bz) * vers
        row[7] = (length * by) * z
        row[8] = bz * sin
        row[9] = -(by * bz) * vers
        row[10] = 1.0 - (bz * bz) * vers
        row[11] = (length * bz) * z
        row[12] = 0.0
        row[13] = 0.0
        row[14] = 0.0
        row[15] = 1.0
        row[16] = axial
        row[17] = by * shear
        row[18] = bz * shear
        row[19] = 0.0
        row[20] = (-bz / length) * curvature
        row[21] = (by / length) * curvature
        row[22] = ea * axial
        row[23] = (ga_y * by) * shear
        row[24] = (ga_z * bz) * shear
        row[25] = 0.0
        row[26] = (-bz / length * ei_y) * curvature
        row[27] = (by / length * ei_z) * curvature


@_entry
def screw(u, omega, twist, s, extra, out):
    """Poses of H(s) = exp_SE3(s (u; ω)) · exp_SE3(s (0; τ e1)) and fields linear in ψ = τ s.

    One arm: u, ω (3,) in 1 and 1/m (material frame), τ = ``twist`` in 1/m, stations s (N,)
    in m. Writes row j of ``out`` (N, 16 + C): the pose (flattened 4×4) and Σ_y b_y(ψ)
    extra[y] with b = (1, 1 − cos ψ, sin ψ) (``extra`` (3, C)). With θ = |ω|, a = ω/θ (a = e1
    for θ = 0) and φ = θ s: R = exp(φ a~) exp(ψ e1~), exp(φ a~) = I + sin φ a~ + (1 − cos φ)
    (a aᵀ − I), and p = s (a·u) a + (sin φ/θ) u⊥ + ((1 − cos φ)/θ) a × u, u⊥ = u − (a·u) a
    (p = s u for θ = 0); 1 − cos x is written 2 sin²(x/2) (no cancellation). The same closed
    form as ``_common.screw_poses``.
    """
    theta = math.sqrt(omega[0] * omega[0] + omega[1] * omega[1] + omega[2] * omega[2])
    if theta == 0.0:
        a0, a1, a2 = 1.0, 0.0, 0.0
    else:
        a0, a1, a2 = omega[0] / theta, omega[1] / theta, omega[2] / theta
    dot = a0 * u[0] + a1 * u[1] + a2 * u[2]
    along = (dot * a0, dot * a1, dot * a2)
    perp = (u[0] - along[0], u[1] - along[1], u[2] - along[2])
    cross = (a1 * u[2] - a2 * u[1], a2 * u[0] - a0 * u[2], a0 * u[1] - a1 * u[0])
    columns = extra.shape[1]
    for j in range(s.shape[0]):
        row = out[j]
        sj = s[j]
        phi = theta * sj
        half = math.sin(0.5 * phi)
        sin_phi, vers_phi = math.sin(phi), 2.0 * half * half
        # exp(φ a~), row-major
        r00 = 1.0 + vers_phi * (a0 * a0 - 1.0)
        r01 = -sin_phi * a2 + vers_phi * a0 * a1
        r02 = sin_phi * a1 + vers_phi * a0 * a2
        r10 = sin_phi * a2 + vers_phi * a1 * a0
        r11 = 1.0 + vers_phi * (a1 * a1 - 1.0)
        r12 = -sin_phi * a0 + vers_phi * a1 * a2
        r20 = -sin_phi * a1 + vers_phi * a2 * a0
        r21 = sin_phi * a0 + vers_phi * a2 * a1
        r22 = 1.0 + vers_phi * (a2 * a2 - 1.0)
        psi = twist * sj
        half = math.sin(0.5 * psi)
        sin_psi, vers_psi = math.sin(psi), 2.0 * half * half
        cos_psi = 1.0 - vers_psi
        # times exp(ψ e1~) = [[1, 0, 0], [0, cos ψ, -sin ψ], [0, sin ψ, cos ψ]]
        row[0], row[1], row[2] = r00, cos_psi * r01 + sin_psi * r02, cos_psi * r02 - sin_psi * r01
        row[4], row[5], row[6] = r10, cos_psi * r11 + sin_psi * r12, cos_psi * r12 - sin_psi * r11
        row[8], row[9], row[10] = r20, cos_psi * r21 + sin_psi * r22, cos_psi * r22 - sin_psi * r21
        if theta == 0.0:
            row[3], row[7], row[11] = sj * u[0], sj * u[1], sj * u[2]
        else:
            f_sin, f_vers = sin_phi / theta, vers_phi / theta
            for i in range(3):
                row[4 * i + 3] = sj * along[i] + f_sin * perp[i] + f_vers * cross[i]
        row[12], row[13], row[14], row[15] = 0.0, 0.0, 0.0, 1.0
        for c in range(columns):
            row[16 + c] = extra[0, c] + vers_psi * extra[1, c] + sin_psi * extra[2, c]
