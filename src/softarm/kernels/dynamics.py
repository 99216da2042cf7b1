"""Dynamics: one implicit time step of the Cosserat rod (a boundary value problem in s,
BDF-α in time) and the loop over steps (entry point ``dynamic_steps``; docs/dynamics.md)."""

from __future__ import annotations

import math

import numpy as np

from ._compile import _entry, _given, _inline, _jit
from .layout import _CT, _FD, _FF, _JD, _JF, _LD, _LF, _P, _R, _TD, _TF, TENDON
from .linear import _band_factor, _band_solve, _copy
from .rod import _actuated, _dipole, _law, _nearest, _pressure, _rotated

# ==================================================================== dynamics (begin)
# One implicit time step of Cosserat rod dynamics is a boundary value problem in s (Till,
# Aloi & Rucker 2019). Node state (DYN = 24): centreline p (spatial), frame R (row-major),
# internal force n and moment m (material), velocity q and angular velocity ω (material).
# p and R sit where the statics' state has them (_P, _R), so _rotated and _dipole apply.
_DP, _DR, _DN, _DM, _DQ, _DW = _P, _R, 12, 15, 18, 21
DYN = 24
# Unknowns and rates per node (DUNK = 18): δp, δθ (material), δn, δm, δq, δω; a node's rate
# vector holds p', u, n', m', q', ω' in the same order.
DUNK = 18
_DYN_HALVINGS = 12  # the most halvings of a damped Newton step (contact, _dyn_newton)
_DKL = 29  # the band's lower width: rows of interval k meet node k's columns 29 back
# History per node (DHIST = 72): x = (ε (6), q, ω) at t - Δt, at t - 2Δt, and ẋ at t - Δt;
# then the same of x's slope in s (Hermite's rule needs the history terms' slopes; from the
# steps' own slopes, so that a settled state's ε̇ = c0 ε + ε_h has the slope zero too: a
# slope of ε_h by differences on the nodes, O(h²) but multiplied by c0 ~ 1/Δt, made a
# settled arm creep at 9 µm/s).
DHIST = 72
# Per-piece properties (DPROPS): K (36), B (36), (K + c0 B)⁻¹ (36), f⁰ (6), μ (1), ρJ (3).
# The loads are the statics' channels (PIECE_LOADS + actuators per piece, TIP_LOADS).
_PK, _PB, _PKD, _PF0, _PMU, _PRJ = 0, 36, 72, 108, 114, 115
DPROPS = 118
# BDF-α coefficients (DCOEF): c0, c1, c2, d1, Δt, α.
DCOEF = 6
# Statuses
DYN_OK, DYN_NEWTON, DYN_NOT_FINITE, DYN_INADMISSIBLE = 0, 1, 2, 3
# A step that took this many chord iterations asks for new factors at the next one: a
# factorisation costs about ten iterations, an aged factor one more iteration a step for
# tens of steps (measured: 3.0 -> 2.x iterations a step).
_DYN_REFRESH = 4
# The step in s is Hermite's rule, fourth order (issue 40): on an interval of length h,
#   y_b - y_a = h/2 (f_a + f_b) + h²/12 (f'_a - f'_b)
# for p, n, m, q, ω (their stored components), and for the frame
#   log(R_aᵀ R_b) = h/2 (u_a + u_b) + h²/12 (u'_a - u'_b + u_a × u_b)
# (Magnus' second term, R' = R û; the local error O(h⁵) measured on a frame with quadratic
# u). f' = df/ds along the solution is a difference of the node's rates at the node moved
# along them, its history terms moved by their own slopes (_node_slopes; forward, or
# central for a tol below 1e-9). Those slopes are the history's own (DHIST, below): the
# slopes of x = (ε, q, ω) found at the steps before. For f' = λ y the rule is the (2, 2)
# Padé approximant of e^{λh}: A-stable as the trapezoidal rule was, so any Δt and any kL
# still solve. Newton keeps the trapezoidal rule's band (a node meets only its intervals'
# rows): the rule's Jacobian is the trapezoidal one plus ∓h²/12 G² per node (G the node's
# rates' Jacobian), the change of G along the state left out (a chord iteration anyway).
# The settled state is softarm.solve's to O(h⁴) instead of the trapezoidal O(h²). A step
# in which the arm touches an obstacle takes the trapezoidal rule (_hermite).
_SLOPE_STEP = 1e-3  # the central difference's step in s, in mean spacings
_SLOPE_STEP_FORWARD = 1e-4  # the forward difference's (_node_slopes)
_CENTRAL_BELOW = 1e-9  # Newton's tol below which the slopes take central differences
# The step's flag for the trapezoidal rule (_hermite): slopes[0, _TRAPEZOID], 1.0 once an
# iterate of the step touched an obstacle, cleared at each step's start
_TRAPEZOID = DUNK + 6


@_inline
def _mat_t_vec(R, o, x0, x1, x2, out, k):
    """out[k:k+3] = Rᵀ x with R row-major at R[o:o+9]."""
    out[k] = R[o] * x0 + R[o + 3] * x1 + R[o + 6] * x2
    out[k + 1] = R[o + 1] * x0 + R[o + 4] * x1 + R[o + 7] * x2
    out[k + 2] = R[o + 2] * x0 + R[o + 5] * x1 + R[o + 8] * x2


@_inline
def _log_relative(za, zb, out):
    """out = log(R_aᵀ R_b) (material components of a); returns its angle θ."""
    ra, rb = _DR, _DR
    m00 = za[ra] * zb[rb] + za[ra + 3] * zb[rb + 3] + za[ra + 6] * zb[rb + 6]
    m11 = za[ra + 1] * zb[rb + 1] + za[ra + 4] * zb[rb + 4] + za[ra + 7] * zb[rb + 7]
    m22 = za[ra + 2] * zb[rb + 2] + za[ra + 5] * zb[rb + 5] + za[ra + 8] * zb[rb + 8]
    m01 = za[ra] * zb[rb + 1] + za[ra + 3] * zb[rb + 4] + za[ra + 6] * zb[rb + 7]
    m10 = za[ra + 1] * zb[rb] + za[ra + 4] * zb[rb + 3] + za[ra + 7] * zb[rb + 6]
    m02 = za[ra] * zb[rb + 2] + za[ra + 3] * zb[rb + 5] + za[ra + 6] * zb[rb + 8]
    m20 = za[ra + 2] * zb[rb] + za[ra + 5] * zb[rb + 3] + za[ra + 8] * zb[rb + 6]
    m12 = za[ra + 1] * zb[rb + 2] + za[ra + 4] * zb[rb + 5] + za[ra + 7] * zb[rb + 8]
    m21 = za[ra + 2] * zb[rb + 1] + za[ra + 5] * zb[rb + 4] + za[ra + 8] * zb[rb + 7]
    c = min(1.0, max(-1.0, 0.5 * (m00 + m11 + m22 - 1.0)))
    x0, x1, x2 = 0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01)  # sin θ · axis
    sn = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    th = math.atan2(sn, c)
    f = 1.0 + th * th / 6.0 if sn < 1e-4 else th / sn
    out[0] = f * x0
    out[1] = f * x1
    out[2] = f * x2
    return th


@_jit
def _inverse_jacobian(a0, a1, a2, sign, out):
    """out (3×3) = J_r⁻¹(sign · a) = I + sign a~/2 + β a~², β = 1/θ² - (1 + cos θ)/(2θ sin θ)."""
    th2 = a0 * a0 + a1 * a1 + a2 * a2
    th = math.sqrt(th2)
    if th < 1e-3:
        beta = 1.0 / 12.0 + th2 / 720.0
    else:
        beta = 1.0 / th2 - (1.0 + math.cos(th)) / (2.0 * th * math.sin(th))
    h = 0.5 * sign
    # a~ = [[0, -a2, a1], [a2, 0, -a0], [-a1, a0, 0]]; a~² = a aᵀ - θ² I
    out[0, 0] = 1.0 + beta * (a0 * a0 - th2)
    out[1, 1] = 1.0 + beta * (a1 * a1 - th2)
    out[2, 2] = 1.0 + beta * (a2 * a2 - th2)
    out[0, 1] = -h * a2 + beta * a0 * a1
    out[1, 0] = h * a2 + beta * a0 * a1
    out[0, 2] = h * a1 + beta * a0 * a2
    out[2, 0] = -h * a1 + beta * a0 * a2
    out[1, 2] = -h * a0 + beta * a1 * a2
    out[2, 1] = h * a0 + beta * a1 * a2


@_inline
def _node_rates(z, s, j, props, now, hist_h, coef, out, eps, act, actuation, lengths, tmp):
    """The node's rates (p', u, n', m', q', ω') on piece j (arc length s) with the step's
    history terms ``hist_h`` (ε_h, q_h, ω_h) and loads ``now`` (the statics' channels per
    piece); ``eps`` gets the strain f = (v; u). With actuators (``act``; ``actuation`` =
    the constitutive law's arm and scratch), (n, m) is the total wrench of rod, tendons and
    fluid and the strain solves the actuated law with the damping folded into its
    stiffness (:func:`_law`: K(ε - f⁰) + B ε̇ = (K + c0 B) ε - K f⁰ + B ε_h); ``lengths``
    gets each tendon's |w| = dℓ/ds. ``tmp`` (12,): scratch (no allocation in the step's
    inner loops: a node's rates are evaluated about 700 times a step with a new Jacobian)."""
    c0 = coef[0]
    pr = props[j]
    n0, n1, n2 = z[_DN], z[_DN + 1], z[_DN + 2]
    m0, m1, m2 = z[_DN + 3], z[_DN + 4], z[_DN + 5]
    actuated = act is not None and _actuated(act, j)
    if act is not None and actuated:
        law_arm, law = actuation[0], actuation[1]
        K, f0s = pr[_PK:_PK + 36], law_arm[3]
        Kd = law_arm[2]
        for i in range(6):  # f⁰' = (K + c0 B)⁻¹ (K f⁰ - B ε_h)
            acc = 0.0
            for k in range(6):
                acc += K[6 * i + k] * pr[_PF0 + k] - pr[_PB + 6 * i + k] * hist_h[k]
            eps[i] = acc
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += Kd[j, i, k] * eps[k]
            f0s[j, i] = acc
        e0, e1, e2, e3, e4, e5, _ = _law(law_arm, act, j, s, now, law, np.int64(0), n0, n1,
                                         n2, m0, m1, m2)
        eps[0], eps[1], eps[2], eps[3], eps[4], eps[5] = e0, e1, e2, e3, e4, e5
        for a in range(lengths.size):
            lengths[a] = law[1][a, 3] if act[2][j, a] != 0.0 and act[1][a] == TENDON else 0.0
    else:
        rhs = tmp  # (K + c0 B) ε = σ + K f⁰ - B ε_h
        for i in range(6):
            acc = z[_DN + i]
            for k in range(6):
                acc += (pr[_PK + 6 * i + k] * pr[_PF0 + k]
                        - pr[_PB + 6 * i + k] * hist_h[k])
            rhs[i] = acc
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += pr[_PKD + 6 * i + k] * rhs[k]
            eps[i] = acc
    v0, v1, v2 = eps[0], eps[1], eps[2]
    u0, u1, u2 = eps[3], eps[4], eps[5]
    vt0 = c0 * v0 + hist_h[0]
    vt1 = c0 * v1 + hist_h[1]
    vt2 = c0 * v2 + hist_h[2]
    ut0 = c0 * u0 + hist_h[3]
    ut1 = c0 * u1 + hist_h[4]
    ut2 = c0 * u2 + hist_h[5]
    q0, q1, q2 = z[_DQ], z[_DQ + 1], z[_DQ + 2]
    w0, w1, w2 = z[_DW], z[_DW + 1], z[_DW + 2]
    qt0 = c0 * q0 + hist_h[6]
    qt1 = c0 * q1 + hist_h[7]
    qt2 = c0 * q2 + hist_h[8]
    wt0 = c0 * w0 + hist_h[9]
    wt1 = c0 * w1 + hist_h[10]
    wt2 = c0 * w2 + hist_h[11]
    # p' = R v
    for i in range(3):
        out[i] = z[_DR + 3 * i] * v0 + z[_DR + 3 * i + 1] * v1 + z[_DR + 3 * i + 2] * v2
    out[3] = u0
    out[4] = u1
    out[5] = u2
    # the loads per length, material: Rᵀ f_d + f_f, Rᵀ l_d + l_f (+ a magnetisation's)
    fd, fl = tmp[0:6], tmp[6:12]
    for k in range(3):
        fd[k] = now[j, _FD + k]
        fd[3 + k] = now[j, _LD + k]
    ma0 = ma1 = ma2 = 0.0
    if act is not None:
        ma0, ma1, ma2 = act[3][j, 0], act[3][j, 1], act[3][j, 2]
    if act is not None and (ma0 != 0.0 or ma1 != 0.0 or ma2 != 0.0):
        law = actuation[1]
        _dipole(z, law[2], np.int64(0), ma0, ma1, ma2, now[j], now[j], law[2][3])
        for k in range(6):
            fd[k] += law[2][3, k]
    touching = False
    if act is not None and act[5].shape[0] > 0 and now[j, _CT] != 0.0:
        touching = _moving_contact(z, act[5], act[6][j], now[j, _CT], fd)
    _mat_t_vec(z, _DR, fd[0], fd[1], fd[2], fl, 0)
    _mat_t_vec(z, _DR, fd[3], fd[4], fd[5], fl, 3)
    for k in range(3):
        fl[k] += now[j, _FF + k]
        fl[3 + k] += now[j, _LF + k]
    mu = pr[_PMU]
    # n' = -u × n + μ (ω × q + q_t) - f
    out[6] = -(u1 * n2 - u2 * n1) + mu * (w1 * q2 - w2 * q1 + qt0) - fl[0]
    out[7] = -(u2 * n0 - u0 * n2) + mu * (w2 * q0 - w0 * q2 + qt1) - fl[1]
    out[8] = -(u0 * n1 - u1 * n0) + mu * (w0 * q1 - w1 * q0 + qt2) - fl[2]
    # m' = -u × m - v × n + ρJ ω_t + ω × ρJ ω - l
    j0, j1, j2 = pr[_PRJ], pr[_PRJ + 1], pr[_PRJ + 2]
    h0, h1, h2 = j0 * w0, j1 * w1, j2 * w2
    out[9] = (-(u1 * m2 - u2 * m1) - (v1 * n2 - v2 * n1) + j0 * wt0 + (w1 * h2 - w2 * h1)
              - fl[3])
    out[10] = (-(u2 * m0 - u0 * m2) - (v2 * n0 - v0 * n2) + j1 * wt1 + (w2 * h0 - w0 * h2)
               - fl[4])
    out[11] = (-(u0 * m1 - u1 * m0) - (v0 * n1 - v1 * n0) + j2 * wt2 + (w0 * h1 - w1 * h0)
               - fl[5])
    # q' = v_t - u × q + ω × v
    out[12] = vt0 - (u1 * q2 - u2 * q1) + (w1 * v2 - w2 * v1)
    out[13] = vt1 - (u2 * q0 - u0 * q2) + (w2 * v0 - w0 * v2)
    out[14] = vt2 - (u0 * q1 - u1 * q0) + (w0 * v1 - w1 * v0)
    # ω' = u_t - u × ω
    out[15] = ut0 - (u1 * w2 - u2 * w1)
    out[16] = ut1 - (u2 * w0 - u0 * w2)
    out[17] = ut2 - (u0 * w1 - u1 * w0)
    return touching


@_jit
def _moving_contact(z, obstacles, params, scale, out):
    """Add the contact's force and moment per unit length (spatial) on the moving node z to
    out[0:6]: the statics' normal force (:func:`_contact`) and Coulomb friction at the
    surface point p - r n, regularised, f_t = -μ φ w / √(|w|² + w_ε²) with w the surface
    point's sliding velocity (its velocity R q + (R ω) × (-r n), less the normal part) and
    w_ε = ``params[4]`` (m/s): sliding where |w| >> w_ε, sticking as a creep of speed
    about w_ε |f_t| / (μ φ) below the friction cone (contact.md). ``params`` = the piece's
    (r, δ, k, μ, w_ε); ``scale`` the penalty's (the channel CT). Returns whether an
    obstacle pushes."""
    px, py, pz = z[_DP], z[_DP + 1], z[_DP + 2]
    r, mu, slip = params[0], params[3], params[4]
    # the section's velocity and spin, spatial
    vx = z[_DR] * z[_DQ] + z[_DR + 1] * z[_DQ + 1] + z[_DR + 2] * z[_DQ + 2]
    vy = z[_DR + 3] * z[_DQ] + z[_DR + 4] * z[_DQ + 1] + z[_DR + 5] * z[_DQ + 2]
    vz = z[_DR + 6] * z[_DQ] + z[_DR + 7] * z[_DQ + 1] + z[_DR + 8] * z[_DQ + 2]
    wx = z[_DR] * z[_DW] + z[_DR + 1] * z[_DW + 1] + z[_DR + 2] * z[_DW + 2]
    wy = z[_DR + 3] * z[_DW] + z[_DR + 4] * z[_DW + 1] + z[_DR + 5] * z[_DW + 2]
    wz = z[_DR + 6] * z[_DW] + z[_DR + 7] * z[_DW + 1] + z[_DR + 8] * z[_DW + 2]
    touching = False
    for k in range(obstacles.shape[0]):
        d, n0, n1, n2, _, _, _, _ = _nearest(px, py, pz, obstacles[k])
        phi, _ = _pressure(d - r, params[1], params[2])
        phi *= scale
        if phi == 0.0:
            continue
        touching = True
        out[0] += phi * n0
        out[1] += phi * n1
        out[2] += phi * n2
        if mu == 0.0:
            continue
        a0, a1, a2 = -r * n0, -r * n1, -r * n2  # the surface point from the centreline
        s0 = vx + wy * a2 - wz * a1
        s1 = vy + wz * a0 - wx * a2
        s2 = vz + wx * a1 - wy * a0
        normal = s0 * n0 + s1 * n1 + s2 * n2
        s0, s1, s2 = s0 - normal * n0, s1 - normal * n1, s2 - normal * n2
        # (its own name: ``scale``, the penalty's, holds for the next obstacles)
        slide = -mu * phi / math.sqrt(s0 * s0 + s1 * s1 + s2 * s2 + slip * slip)
        t0, t1, t2 = slide * s0, slide * s1, slide * s2
        out[0] += t0
        out[1] += t1
        out[2] += t2
        out[3] += a1 * t2 - a2 * t1
        out[4] += a2 * t0 - a0 * t2
        out[5] += a0 * t1 - a1 * t0
    return touching


@_jit
def _point_wrench(z, now, tip_now, j, act, actuation, out):
    """out = the point wrench (material) on the node z at the start of piece j, or with
    j = -1 at the tip: the dead (spatial) and follower channels, and a segment's dipole
    there (at its distal end), in the field of the piece channels ``now``."""
    d = np.empty(6)
    for k in range(6):
        d[k] = tip_now[_TD + k] if j < 0 else now[j, _JD + k]
    if act is not None:
        row = act[4].shape[0] - 1 if j < 0 else j
        m0, m1, m2 = act[4][row, 0], act[4][row, 1], act[4][row, 2]
        if m0 != 0.0 or m1 != 0.0 or m2 != 0.0:
            law = actuation[1]
            field = now[now.shape[0] - 1] if j < 0 else now[j]
            _dipole(z, law[2], np.int64(0), m0, m1, m2, field, field, law[2][3])
            for k in range(6):
                d[k] += law[2][3, k]
    _mat_t_vec(z, _DR, d[0], d[1], d[2], out, 0)
    _mat_t_vec(z, _DR, d[3], d[4], d[5], out, 3)
    for k in range(6):
        out[k] += tip_now[_TF + k] if j < 0 else now[j, _JF + k]


@_jit
def _dyn_column(k, c):
    """The unknown's column of node k's component c (node 0: only n, m are unknown)."""
    if k == 0:
        return c - 6
    return 6 + DUNK * (k - 1) + c


@_jit
def _dyn_residual(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, r, rates, eps,
                  lengths, slopes, central):
    """The scaled residual r (18 (G - 1) + 6) of the step's discrete equations: Hermite's
    rule in s on every interval (the trapezoidal rule corrected with the rates' slopes,
    fourth order; above) (a joint of zero length: continuity, n and m jumping by the point
    wrench at the next piece's start), then the tip's boundary condition. ``grid`` =
    (interval lengths, piece of each node, s of each node). ``rates`` (G, 18), ``eps`` (G,
    6) and ``lengths`` ((G, tendons) twice) get each node's rates, strains, dℓ/ds and its
    slope, ``slopes`` (G, 25) the rates' and the strain's slopes in s, and 1.0 where the
    trapezoidal rule holds instead (``slopes[0, _TRAPEZOID]``, set by this or an earlier
    iterate of the step: _hermite). Returns the largest |r|."""
    h, node_piece, node_s = grid
    G = Z.shape[0]
    tmp = np.empty(12)
    for k in range(G):
        if _node_rates(Z[k], node_s[k], node_piece[k], props, now, hh[k], coef, rates[k],
                       eps[k], act, actuation, lengths[0][k], tmp):
            slopes[0, _TRAPEZOID] = 1.0  # the trapezoidal rule for the rest of the step
    # (the slopes even where the trapezoidal rule holds: the history keeps them, and a
    # history without them after a contact leaves ε̇' wrong by c0 ε' for the steps after)
    _node_slopes(Z, grid, props, coef, now, hh, act, actuation, rates, eps, lengths[0],
                 slopes, lengths[1], central, tmp)
    lg = np.empty(3)
    jw = np.empty(6)
    worst = 0.0
    for k in range(G - 1):
        za, zb = Z[k], Z[k + 1]
        o = DUNK * k
        hk = h[k]
        c12 = _hermite(hk, slopes)
        fa, fb, ga, gb = rates[k], rates[k + 1], slopes[k], slopes[k + 1]
        _log_relative(za, zb, lg)
        # the rotation's Magnus term h²/12 u_a × u_b (R' = R û)
        x0 = fa[4] * fb[5] - fa[5] * fb[4]
        x1 = fa[5] * fb[3] - fa[3] * fb[5]
        x2 = fa[3] * fb[4] - fa[4] * fb[3]
        for i in range(3):
            r[o + i] = (zb[_DP + i] - za[_DP + i] - 0.5 * hk * (fa[i] + fb[i])
                        - c12 * (ga[i] - gb[i]))
        r[o + 3] = lg[0] - 0.5 * hk * (fa[3] + fb[3]) - c12 * (ga[3] - gb[3] + x0)
        r[o + 4] = lg[1] - 0.5 * hk * (fa[4] + fb[4]) - c12 * (ga[4] - gb[4] + x1)
        r[o + 5] = lg[2] - 0.5 * hk * (fa[5] + fb[5]) - c12 * (ga[5] - gb[5] + x2)
        for i in range(12):
            r[o + 6 + i] = (zb[_DN + i] - za[_DN + i] - 0.5 * hk * (fa[6 + i] + fb[6 + i])
                            - c12 * (ga[6 + i] - gb[6 + i]))
        if hk == 0.0:  # a joint: n and m jump by the point wrench at the next piece's start
            _point_wrench(za, now, tip_now, node_piece[k + 1], act, actuation, jw)
            for i in range(6):
                r[o + 6 + i] += jw[i]
        for i in range(DUNK):
            r[o + i] /= S[i]
            worst = max(worst, abs(r[o + i]))
    zt = Z[G - 1]
    o = DUNK * (G - 1)
    _point_wrench(zt, now, tip_now, np.int64(-1), act, actuation, jw)
    for i in range(6):
        r[o + i] = (zt[_DN + i] - jw[i]) / S[6 + i]
        worst = max(worst, abs(r[o + i]))
    return worst


@_jit
def _hermite(hk, slopes):
    """Hermite's coefficient h²/12 of an interval of length hk, or 0 (the trapezoidal rule)
    in a step where the arm touches an obstacle (at any iterate: the step's flag). The
    penalty's rates are not smooth (their slope jumps at the band's edge, and friction's
    with the sliding); Hermite's rule taken only between nodes that do not touch, switching
    node by node as the contact spreads, failed Newton at a touchdown with friction and
    lost the balance of an undamped impact's energy (11 % at Δt = 0.5 ms, 4.6 % with the
    trapezoidal rule). In contact, the static limit is the penalty's, which its band δ
    limits anyway; an arm that does not touch its obstacles moves as without them."""
    if slopes[0, _TRAPEZOID] != 0.0:
        return 0.0
    return hk * hk / 12.0


@_jit
def _node_slopes(Z, grid, props, coef, now, hh, act, actuation, rates, eps, lengths0, slopes,
                 lslopes, central, tmp):
    """slopes[k] = the derivative in s of node k's rates (18) and strain (6, ``eps``), and
    lslopes[k] that of its tendons' dℓ/ds, along the solution: a difference of
    :func:`_node_rates` at the node's state moved by ε times its own rates (R by exp(ε u)),
    its arc length by ε and its history terms by ε times their slopes (``hh[:, 12:]``):
    central (±ε, ε = _SLOPE_STEP mean spacings) if ``central``, else forward (ε =
    _SLOPE_STEP_FORWARD mean spacings, one evaluation fewer: 1/3 of the residual's cost,
    2/3 of the slopes', but a floor of about 1e-11 in Newton's scaled residual, the
    rounding of terms such as c0 q over that step: _dyn_newton asks for central
    differences below a tol of _CENTRAL_BELOW)."""
    _, node_piece, node_s = grid
    G = Z.shape[0]
    zp = np.empty(DYN)
    fm = np.empty(DUNK)
    e1 = np.empty(6)
    em = np.empty(6)
    A = 1 if act is None else max(1, act[0].shape[0])
    l1 = np.zeros(A)
    lm = np.zeros(A)
    hp = np.empty(12)
    spacing = (node_s[G - 1] - node_s[0]) / max(G - 1, 1)
    step = (_SLOPE_STEP if central else _SLOPE_STEP_FORWARD) * spacing
    for k in range(G):
        z, f, g = Z[k], rates[k], slopes[k]
        for side in range(2 if central else 1):
            e = step if side == 0 else -step
            for i in range(DYN):
                zp[i] = z[i]
            for i in range(3):
                zp[_DP + i] += e * f[i]
            for i in range(12):
                zp[_DN + i] += e * f[6 + i]
            _rotated(zp, e * f[3], e * f[4], e * f[5], zp)
            for i in range(12):
                hp[i] = hh[k, i] + e * hh[k, 12 + i]
            _node_rates(zp, node_s[k] + e, node_piece[k], props, now, hp, coef,
                        g if side == 0 else fm, e1 if side == 0 else em, act, actuation,
                        l1 if side == 0 else lm, tmp)
        if not central:  # (the other end of the difference: the node itself)
            for i in range(DUNK):
                fm[i] = f[i]
            for i in range(6):
                em[i] = eps[k, i]
            for a in range(lm.size):
                lm[a] = lengths0[k, a]
        width = 2.0 * step if central else step
        for i in range(DUNK):
            g[i] = (g[i] - fm[i]) / width
        for i in range(6):
            g[DUNK + i] = (e1[i] - em[i]) / width
        for a in range(lslopes.shape[1]):
            lslopes[k, a] = (l1[a] - lm[a]) / width


@_jit
def _dyn_put(Bm, kl, row, col, value):
    Bm[row, col - row + kl] += value


@_jit
def _magnetised(act):
    """Whether any piece of the arm carries a magnetisation (act[3])."""
    for j in range(act[3].shape[0]):
        for i in range(3):
            if act[3][j, i] != 0.0:
                return True
    return False


@_jit
def _dyn_jacobian(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, rates, slopes,
                  Gk, G2, Bm, kl):
    """The scaled Jacobian of :func:`_dyn_residual` in band storage (``rates`` and
    ``slopes`` as the residual left them). Each node's ∂(rates)/∂(unknowns) G by forward
    differences, and the slopes' G² (``G2``, Hermite's term); the rotation of the point
    wrenches at the joints and the tip is exact for the dead channels (a dipole's own
    turning and the change of G along the state are left out: the iteration is a chord
    iteration anyway)."""
    h, node_piece, node_s = grid
    G = Z.shape[0]
    Bm[:, :] = 0.0
    zp = np.empty(DYN)
    g1 = np.empty(DUNK)
    e1 = np.empty(6)
    l1 = np.empty(max(1, 0 if act is None else act[0].shape[0]))
    Ja = np.empty((3, 3))
    Jb = np.empty((3, 3))
    lg = np.empty(3)
    tmp = np.empty(12)
    # the rates depend on the position p only through loads that depend on where the
    # section is: contact (the penalty's stiffness ∂f/∂p, the largest term of a touching
    # node's Jacobian: without it Newton crept and failed on touchdown, friction or a
    # start at rest on an obstacle) and a magnetisation in a field with a gradient
    placed = act is not None and (act[5].shape[0] > 0 or _magnetised(act))
    first = 0 if placed else 3
    for k in range(G):
        for c in range(first, DUNK):
            for i in range(DYN):
                zp[i] = Z[k, i]
            d = 1e-7 * S[c]
            if c < 3:
                zp[_DP + c] += d
            elif c < 6:
                a0 = d if c == 3 else 0.0
                a1 = d if c == 4 else 0.0
                a2 = d if c == 5 else 0.0
                _rotated(zp, a0, a1, a2, zp)
            else:
                zp[_DN + c - 6] += d
            _node_rates(zp, node_s[k], node_piece[k], props, now, hh[k], coef, g1, e1, act,
                        actuation, l1, tmp)
            for i in range(DUNK):
                Gk[k, i, c] = (g1[i] - rates[k, i]) / d
        for i in range(DUNK):
            for c in range(first):
                Gk[k, i, c] = 0.0
        if slopes[0, _TRAPEZOID] != 0.0:
            continue  # (no G²: the trapezoidal rule, _hermite)
        for i in range(DUNK):  # G² (G is sparse: the products of its nonzeros)
            for c in range(DUNK):
                G2[k, i, c] = 0.0
            for m in range(DUNK):
                g = Gk[k, i, m]
                if g != 0.0:
                    for c in range(DUNK):
                        G2[k, i, c] += g * Gk[k, m, c]
    jw = np.empty(6)
    for k in range(G - 1):
        za, zb = Z[k], Z[k + 1]
        row0 = DUNK * k
        hk = h[k]
        c12 = _hermite(hk, slopes)
        _log_relative(za, zb, lg)
        _inverse_jacobian(lg[0], lg[1], lg[2], -1.0, Ja)
        _inverse_jacobian(lg[0], lg[1], lg[2], 1.0, Jb)
        for side in range(2):
            node = k + side
            sgn = 1.0 if side == 1 else -1.0
            for c in range(DUNK):
                if node == 0 and (c < 6 or c >= 12):
                    continue
                col = _dyn_column(node, c)
                for i in range(DUNK):
                    v = -0.5 * hk * Gk[node, i, c]
                    if c12 != 0.0:
                        v += sgn * c12 * G2[node, i, c]
                    if 3 <= i < 6 and 3 <= c < 6:
                        v += (Jb[i - 3, c - 3] if side == 1 else -Ja[i - 3, c - 3])
                    elif i == c and not (3 <= i < 6):
                        v += sgn
                    if v != 0.0:
                        _dyn_put(Bm, kl, row0 + i, col, v * S[c] / S[i])
        if hk == 0.0 and k > 0:  # the point wrench turns with the frame at the joint
            _point_wrench(za, now, tip_now, node_piece[k + 1], act, actuation, jw)
            for blk in range(2):  # (only the dead part turns: Rᵀ F_d)
                j1 = node_piece[k + 1]
                f0 = now[j1, _JF + 3 * blk]
                f1 = now[j1, _JF + 3 * blk + 1]
                f2 = now[j1, _JF + 3 * blk + 2]
                _dyn_skew_put(Bm, kl, row0 + 6 + 3 * blk, _dyn_column(k, 3),
                              jw[3 * blk] - f0, jw[3 * blk + 1] - f1, jw[3 * blk + 2] - f2,
                              1.0, S[6 + 3 * blk], S[3])
    zt = Z[G - 1]
    row0 = DUNK * (G - 1)
    _point_wrench(zt, now, tip_now, np.int64(-1), act, actuation, jw)
    for i in range(6):
        _dyn_put(Bm, kl, row0 + i, _dyn_column(G - 1, 6 + i), 1.0)
    if G - 1 > 0:
        for blk in range(2):
            _dyn_skew_put(Bm, kl, row0 + 3 * blk, _dyn_column(G - 1, 3),
                          jw[3 * blk] - tip_now[_TF + 3 * blk],
                          jw[3 * blk + 1] - tip_now[_TF + 3 * blk + 1],
                          jw[3 * blk + 2] - tip_now[_TF + 3 * blk + 2],
                          -1.0, S[6 + 3 * blk], S[3])


@_jit
def _dyn_skew_put(Bm, kl, row, col, w0, w1, w2, sign, srow, scol):
    """Bm[row:row+3, col:col+3] += sign · w~ (scaled)."""
    f = sign * scol / srow
    _dyn_put(Bm, kl, row, col + 1, -w2 * f)
    _dyn_put(Bm, kl, row, col + 2, w1 * f)
    _dyn_put(Bm, kl, row + 1, col, w2 * f)
    _dyn_put(Bm, kl, row + 1, col + 2, -w0 * f)
    _dyn_put(Bm, kl, row + 2, col, -w1 * f)
    _dyn_put(Bm, kl, row + 2, col + 1, w0 * f)


@_jit
def _dyn_apply(Z, dx, S):
    """Z -= the scaled correction dx (rotations R ← R exp(-δθ~))."""
    G = Z.shape[0]
    for k in range(G):
        for c in range(DUNK):
            if k == 0 and (c < 6 or c >= 12):
                continue
            if 3 <= c < 6:
                continue
            v = dx[_dyn_column(k, c)] * S[c]
            if c < 3:
                Z[k, _DP + c] -= v
            else:
                Z[k, _DN + c - 6] -= v
        if k > 0:
            o = _dyn_column(k, 3)
            _rotated(Z[k], -dx[o] * S[3], -dx[o + 1] * S[3], -dx[o + 2] * S[3], Z[k])


@_jit
def _set_base(Zw, row):
    """The base node of a step's guess: its pose and velocities from the base's row (18:
    p, R row-major, q, ω material)."""
    for i in range(3):
        Zw[0, _DP + i] = row[i]
        Zw[0, _DQ + i] = row[12 + i]
        Zw[0, _DW + i] = row[15 + i]
    for i in range(9):
        Zw[0, _DR + i] = row[3 + i]


@_jit
def _sum_squares(r):
    total = 0.0
    for i in range(r.size):
        total += r[i] * r[i]
    return total


# Friction's band on a step that does not solve (issue 39): Coulomb's law regularised with
# the speed w_ε (``slip_velocity``) has the slope μ φ / w_ε in the sliding velocity, steep at
# a touchdown (φ large, w from 0 to the arrival speed within a step), and Newton fails there
# from every guess (the docs' table drop, μ = 0.5, at the default 1e-4 m/s). The step is
# then solved along a continuation in w_ε: from the last state with the band widened 10×,
# 100×, ... (at most 10^_WIDENINGS) until it solves, then narrowed back towards the band
# given, each solve from the answer before, by a factor that is halved (in its logarithm)
# after a narrowing that fails and doubled again (up to 10) after one that solves. The
# step's answer is the law's own at the band given; it fails as before after _NARROWINGS
# failed narrowings.
_WIDENINGS = 4
_NARROWINGS = 12


@_jit
def _friction(params) -> bool:
    """Whether any piece has friction (μ > 0; ``params`` = act[6])."""
    for j in range(params.shape[0]):
        if params[j, 3] > 0.0:
            return True
    return False


@_jit
def _with_band(params, given, exponent):
    """act[6]'s w_ε column = the given bands × 10^exponent."""
    for j in range(params.shape[0]):
        params[j, 4] = given[j] if exponent == 0.0 else given[j] * 10.0 ** exponent


@_jit
def _dyn_widened(Zw, last, pose, grid, props, coef, S, now, tip_now, hh, act, actuation,
                 tol, max_iter, fac, kl, work):
    """A step with friction solved along a continuation in the friction's band (above):
    _dyn_newton's (code, residual, iterations, factorisations), the iterations summed.
    ``last`` the state before the step, ``pose`` the base's row. Writes act[6]'s w_ε column
    and restores it (``act`` is a thread's own where friction acts: _simulator)."""
    params = act[6]
    given = params[:, 4].copy()
    code, res, its, nf = DYN_NEWTON, np.inf, 0, 0
    exponent = 0.0  # the band is given × 10^exponent
    while code != DYN_OK and exponent < _WIDENINGS:
        exponent += 1.0
        _with_band(params, given, exponent)
        _copy(last, Zw)
        _set_base(Zw, pose)
        fac[3][0] = 0
        code, res, more, nf2 = _dyn_newton(Zw, grid, props, coef, S, now, tip_now, hh, act,
                                           actuation, tol, max_iter, fac, kl, work)
        its += more
        nf += nf2
    if code == DYN_OK:
        good = Zw.copy()  # the answer at the narrowest band solved so far
        step, failures = 1.0, 0
        while exponent > 0.0:
            trial = max(exponent - step, 0.0)
            _with_band(params, given, trial)
            fac[3][0] = 0
            code, res, more, nf2 = _dyn_newton(Zw, grid, props, coef, S, now, tip_now, hh,
                                               act, actuation, tol, max_iter, fac, kl, work)
            its += more
            nf += nf2
            if code == DYN_OK:
                _copy(Zw, good)
                exponent = trial
                step = min(2.0 * step, 1.0)
                continue
            failures += 1
            if failures > _NARROWINGS:
                break  # (code: the failure)
            _copy(good, Zw)
            step *= 0.5
    _with_band(params, given, 0.0)
    return code, res, its, nf


@_jit
def _dyn_newton(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, tol, max_iter,
                factors, kl, work):
    """Chord-Newton on one step's equations from the guess Z (the factors (Bm, Lm, piv,
    state) are reused while ``state[0]`` (1: valid) and the iteration contracts, refreshed
    otherwise). Returns (status, scaled residual, iterations, factorisations).

    Converged when the residual is below tol and so is the error left in the unknowns,
    estimated from the contraction ρ of the corrections: ρ/(1 - ρ) times the last one. A
    first correction has no ρ of its own: ``state[1]`` holds the last step's, measured on
    the same factors (1, none, when they are new), so that a step whose first correction
    already leaves less than tol ends there; each use doubles it until a step measures it
    again (one Newton solve and residual fewer a step: 2.2 -> 1.6 iterations on Till &
    Rucker's cantilever)."""
    Bm, Lm, piv, valid = factors
    r, dx, rates, eps, lengths, Gk, slopes, G2 = work
    central = tol < _CENTRAL_BELOW
    n = r.size
    last = math.inf
    factored = 0
    # with contact, a Newton step on a fresh Jacobian that does not lower the residual is
    # halved until it does (a contact that opens or closes within the step changes the
    # equations' slope by the penalty's k: the full step overshoots deep into the obstacle)
    damped = act is not None and act[5].shape[0] > 0
    before_step = np.empty((Z.shape[0], Z.shape[1]) if damped else (1, 1))
    merit_before = 0.0
    worst = _dyn_residual(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, r, rates,
                          eps, lengths, slopes, central)
    for it in range(max_iter):
        if not math.isfinite(worst):
            return DYN_NOT_FINITE, worst, it, factored
        fresh = valid[0] == 0
        if valid[0] == 0:
            _dyn_jacobian(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, rates,
                          slopes, Gk, G2, Bm, kl)
            if _band_factor(Bm, n, kl, piv, Lm) == 0.0:
                return DYN_NEWTON, worst, it, factored
            valid[0] = 1
            valid[1] = 1.0  # (no contraction measured on these factors yet)
            factored += 1
        for i in range(n):
            dx[i] = r[i]
        if not _band_solve(Bm, n, kl, piv, Lm, dx):
            valid[0] = 0
            continue
        step = 0.0
        for i in range(n):
            step = max(step, abs(dx[i]))
        if damped:
            _copy(Z, before_step)
            merit_before = _sum_squares(r)
        _dyn_apply(Z, dx, S)
        before = worst
        worst = _dyn_residual(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, r,
                              rates, eps, lengths, slopes, central)
        halvings = 0
        if damped and fresh:  # (merit: the residual's 2-norm; the max norm can stall)
            merit = _sum_squares(r)
            while not (merit < merit_before) and halvings < _DYN_HALVINGS:
                halvings += 1
                _copy(before_step, Z)
                for i in range(n):
                    dx[i] *= 0.5
                step *= 0.5
                _dyn_apply(Z, dx, S)
                worst = _dyn_residual(Z, grid, props, coef, S, now, tip_now, hh, act,
                                      actuation, r, rates, eps, lengths, slopes, central)
                merit = _sum_squares(r)
        # converged when the residual is below tol and so is the error left, estimated
        # from the contraction ρ of the last two corrections: ρ/(1 - ρ) × this one
        rho = step / last if last < math.inf else valid[1]
        if worst <= tol and (step <= tol or (rho < 0.5 and rho / (1.0 - rho) * step <= tol)):
            valid[1] = rho if last < math.inf else min(1.0, 2.0 * valid[1])
            return DYN_OK, worst, it + 1, factored
        if not (worst < 0.25 * before) or step > last:
            valid[0] = 0  # slow or growing: a fresh Jacobian at the current iterate
        last = step
    return DYN_NEWTON, worst, max_iter, factored


@_jit
def _dyn_history_terms(H, coef, hh):
    """x_h = c1 x(t-Δt) + c2 x(t-2Δt) + d1 ẋ(t-Δt) for x = (ε, q, ω) at every node
    (hh[:, :12]), and the same of their slopes in s (hh[:, 12:], from H[:, 36:])."""
    c1, c2, d1 = coef[1], coef[2], coef[3]
    for k in range(H.shape[0]):
        for i in range(24):
            o = 36 * (i // 12) + i % 12
            hh[k, i] = c1 * H[k, o] + c2 * H[k, o + 12] + d1 * H[k, o + 24]


@_jit
def _dyn_energies(Z, h, node_piece, props, eps, hh, coef, gravity, out):
    """out = kinetic, elastic, gravity energy (J) and dissipation power (W) of the state,
    by the trapezoidal rule on the grid."""
    c0 = coef[0]
    kin = 0.0
    ela = 0.0
    grav = 0.0
    power = 0.0
    G = Z.shape[0]
    for k in range(G):
        wl = 0.0
        if k > 0:
            wl += 0.5 * h[k - 1]
        if k < G - 1:
            wl += 0.5 * h[k]
        if wl == 0.0:
            continue
        pr = props[node_piece[k]]
        z = Z[k]
        mu = pr[_PMU]
        e = kin
        for i in range(3):
            e += 0.5 * wl * (mu * z[_DQ + i] ** 2 + pr[_PRJ + i] * z[_DW + i] ** 2)
            grav -= wl * mu * gravity[i] * z[_DP + i]
        kin = e
        for i in range(6):
            de_i = eps[k, i] - pr[_PF0 + i]
            et_i = c0 * eps[k, i] + hh[k, i]
            for j in range(6):
                de_j = eps[k, j] - pr[_PF0 + j]
                et_j = c0 * eps[k, j] + hh[k, j]
                ela += 0.5 * wl * de_i * pr[_PK + 6 * i + j] * de_j
                power += wl * et_i * pr[_PB + 6 * i + j] * et_j
    out[0] = kin
    out[1] = ela
    out[2] = grav
    out[3] = power


@_jit
def _dyn_predict(Z, Z1, Z2):
    """Z ← the quadratic extrapolation of the states at t - 2Δt (Z2), t - Δt (Z1) and t
    (Z): 3 Z - 3 Z1 + Z2, the rotations R exp(2 a - b) with a = log(R1ᵀ R), b =
    log(R2ᵀ R1) (the last two increments)."""
    a = np.empty(3)
    b = np.empty(3)
    for k in range(Z.shape[0]):
        _log_relative(Z1[k], Z[k], a)
        _log_relative(Z2[k], Z1[k], b)
        for i in range(DYN):
            if not (_DR <= i < _DR + 9):
                Z[k, i] = 3.0 * Z[k, i] - 3.0 * Z1[k, i] + Z2[k, i]
        _rotated(Z[k], 2.0 * a[0] - b[0], 2.0 * a[1] - b[1], 2.0 * a[2] - b[2], Z[k])


def _dynamics(args):
    """dynamic_steps' capability: passive, or with actuators or magnets (``act``)."""
    actuated = _given(args[26])
    return ("dynamics" + "+actuated" * actuated,
            "the dynamics (implicit time steps)"
            + " for actuated, magnetic or touching arms" * actuated)


@_entry(_dynamics, nogil=True)
def dynamic_steps(Z, Zold, H, aux, props, loads, tip, grid, coef, S, options, base, gravity,
                  stations, first, last, factors, positions, rotations, velocities, spins,
                  strains, stresses, energy, info, status, act, actuation, inputs, tendons):
    """Advance the cases [first, last) by base.shape[1] implicit time steps each.

    Z (B, G, DYN), Zold (B, 2, G, DYN): the state now and one and two steps before (for
    the predictor); H (B, G,
    DHIST) the BDF-α history; aux (B, 2): the dissipated energy so far (J) and the last
    dissipation power (W). props (P, DPROPS) the pieces' properties; loads (B, P, W) and
    tip (B, TIP_LOADS) the statics' load channels (at zero inputs when ``inputs`` is
    given); grid = (interval lengths (G - 1; 0 at a joint between pieces), piece of each
    node, s of each node); coef (DCOEF,), S (18,) scales, options = (tol, max_iter). base
    (B or 1, T, 18): the base's p, R (row-major), q, ω (material) at each new step;
    gravity (B, 3) (for the energy); stations (S,) the recorded nodes; factors = (Bm, Lm,
    piv, state, jacobian): per case (B) or one shared (1; reused only by the first case of
    the call), and a scratch (2, G, 18, 18) for the nodes' Jacobians;
    a case's state (2,) says whether its factors are valid (1.0) and holds the contraction
    last measured on them (_dyn_newton).
    Outputs per case and step: positions,
    rotations (9), velocities, spins (spatial), strains, stresses (material), energy
    (kinetic, elastic, gravity, dissipated), info (residual, iterations, factorisations,
    predictor - corrector distance / L); status (B,) is the number of steps done (= T on
    success): a failed step leaves Z, Zold, H and aux at the last solved step, and info's
    row at the failed step holds (residual, -1, ...); a case whose status is < 0 on entry
    is skipped (it failed before).

    Optional (None: compiled without): ``act`` the actuators and magnets (the statics'
    ``act``), with ``actuation`` = (the constitutive law's arm (the statics' arm with
    K + c0 B, its inverse and a scratch f⁰), the law's scratch); ``inputs``
    = (q (B or 1, T, n): the inputs at each step, unit piece channels (n, P, W), unit tip
    channels (n, TIP_LOADS)): the loads at step t are loads + Σᵢ qᵢ unitᵢ; ``tendons`` (B,
    T, A) the tendons' lengths (m) at each step.
    """
    tol = options[0]
    max_iter = int(options[1])
    length_scale = S[0]
    h, node_piece = grid[0], grid[1]
    G = Z.shape[1]
    T = base.shape[1]
    kl = np.int64(_DKL)
    n = DUNK * (G - 1) + 6
    A = 1 if act is None else max(1, act[0].shape[0])
    Bm_all, Lm_all, piv_all, valid_all, jacobian = factors
    # (the nodes' G and G², 2 × G × 18 × 18: the caller's scratch, kept with the factors, so
    # that the memory guard counts what a step holds; _node_bytes)
    work = (np.empty(n), np.empty(n), np.empty((G, DUNK)), np.empty((G, 6)),
            (np.zeros((G, A)), np.zeros((G, A))), jacobian[0],
            np.empty((G, DUNK + 7)), jacobian[1])
    eps, lengths, rates, slopes = work[3], work[4], work[2], work[6]
    hh = np.empty((G, 24))  # the history terms and their slopes in s
    Zw = np.empty((G, DYN))
    Zp = np.empty((G, DYN))
    en = np.empty(4)
    c0 = coef[0]
    now = np.empty((loads.shape[1], loads.shape[2]))
    tip_now = np.empty(tip.shape[1])
    for b in range(first, last):
        if status[b] < 0:
            continue  # a case that failed in an earlier call: left where it stopped
        f = b if Bm_all.shape[0] > 1 else 0
        if Bm_all.shape[0] == 1 and b > first:
            valid_all[0, 0] = 0.0  # (one shared factor storage: another case's factors)
        fac = (Bm_all[f], Lm_all[f], piv_all[f], valid_all[f])
        bb = b if base.shape[0] > 1 else 0
        status[b] = 0
        for i in range(now.shape[0]):
            for c in range(now.shape[1]):
                now[i, c] = loads[b, i, c]
        for c in range(tip_now.size):
            tip_now[c] = tip[b, c]
        for t in range(T):
            if inputs is not None:  # the loads at this step's inputs
                q, unit, unit_tip = inputs
                qb = b if q.shape[0] > 1 else 0
                for i in range(now.shape[0]):
                    for c in range(now.shape[1]):
                        acc = loads[b, i, c]
                        for e in range(q.shape[2]):
                            acc += q[qb, t, e] * unit[e, i, c]
                        now[i, c] = acc
                for c in range(tip_now.size):
                    acc = tip[b, c]
                    for e in range(q.shape[2]):
                        acc += q[qb, t, e] * unit_tip[e, c]
                    tip_now[c] = acc
            _dyn_history_terms(H[b], coef, hh)
            # guess: the extrapolated state, the base's pose and velocity set
            for k in range(G):
                for i in range(DYN):
                    Zw[k, i] = Z[b, k, i]
            _dyn_predict(Zw, Zold[b, 0], Zold[b, 1])
            for k in range(G):
                for i in range(3):
                    Zp[k, i] = Zw[k, _DP + i]  # (the predicted centreline)
            _set_base(Zw, base[bb, t])
            slopes[0, _TRAPEZOID] = 0.0  # (Hermite's rule until the arm touches)
            code, res, its, nf = _dyn_newton(Zw, grid, props, coef, S, now, tip_now, hh, act,
                                             actuation, tol, max_iter, fac, kl, work)
            if code != DYN_OK and act is not None and act[5].shape[0] > 0:
                # contact: a contact that closes within the step can put the extrapolated
                # guess deep in an obstacle, outside Newton's reach; again from the last
                # state, with fresh factors
                for k in range(G):
                    for i in range(DYN):
                        Zw[k, i] = Z[b, k, i]
                _set_base(Zw, base[bb, t])
                fac[3][0] = 0
                code, res, again, nf2 = _dyn_newton(Zw, grid, props, coef, S, now, tip_now, hh,
                                                    act, actuation, tol, max_iter, fac, kl,
                                                    work)
                its += again
                nf += nf2
                if code != DYN_OK and _friction(act[6]):
                    code, res, again, nf2 = _dyn_widened(Zw, Z[b], base[bb, t], grid, props,
                                                         coef, S, now, tip_now, hh, act,
                                                         actuation, tol, max_iter, fac, kl,
                                                         work)
                    its += again
                    nf += nf2
            info[b, t, 0] = res
            info[b, t, 2] = nf
            for k in range(G):  # the model's limit: a section turned inside out (v₁ <= 0)
                if code == DYN_OK and not eps[k, 0] > 0.0:
                    code = DYN_INADMISSIBLE
            if code != DYN_OK:
                info[b, t, 1] = -1.0
                fac[3][0] = 0
                break
            moved = 0.0
            for k in range(G):
                for i in range(3):
                    moved = max(moved, abs(Zw[k, _DP + i] - Zp[k, i]))
            info[b, t, 1] = its
            info[b, t, 3] = moved / length_scale
            if its >= _DYN_REFRESH:
                fac[3][0] = 0  # the factors have aged: new ones for the next step
            # accept: shift the history, x_t = c0 x + x_h
            for k in range(G):
                for i in range(DYN):
                    Zold[b, 1, k, i] = Zold[b, 0, k, i]
                    Zold[b, 0, k, i] = Z[b, k, i]
                    Z[b, k, i] = Zw[k, i]
                for i in range(24):  # x = (ε, q, ω), then its slope (ε', q', ω')
                    if i < 12:
                        x = eps[k, i] if i < 6 else Zw[k, _DQ + i - 6]
                    else:
                        x = slopes[k, DUNK + i - 12] if i < 18 else rates[k, i - 6]
                    o = 36 * (i // 12) + i % 12
                    H[b, k, o + 12] = H[b, k, o]
                    H[b, k, o] = x
                    H[b, k, o + 24] = c0 * x + hh[k, i]
            _dyn_energies(Zw, h, node_piece, props, eps, hh, coef, gravity[b], en)
            aux[b, 0] += 0.5 * (aux[b, 1] + en[3]) * coef[4]
            aux[b, 1] = en[3]
            energy[b, t, 0] = en[0]
            energy[b, t, 1] = en[1]
            energy[b, t, 2] = en[2]
            energy[b, t, 3] = aux[b, 0]
            if tendons is not None:  # ℓ = ∫ |w| ds, Hermite's rule as the state's
                w, dw = lengths
                for a in range(tendons.shape[2]):
                    acc = 0.0
                    for k in range(G - 1):
                        acc += (0.5 * h[k] * (w[k, a] + w[k + 1, a])
                                + _hermite(h[k], slopes) * (dw[k, a] - dw[k + 1, a]))
                    tendons[b, t, a] = acc
            for si in range(stations.size):
                k = stations[si]
                z = Zw[k]
                pr = props[node_piece[k]]
                for i in range(3):
                    positions[b, t, si, i] = z[_DP + i]
                    velocities[b, t, si, i] = (z[_DR + 3 * i] * z[_DQ] + z[_DR + 3 * i + 1]
                                               * z[_DQ + 1] + z[_DR + 3 * i + 2] * z[_DQ + 2])
                    spins[b, t, si, i] = (z[_DR + 3 * i] * z[_DW] + z[_DR + 3 * i + 1]
                                          * z[_DW + 1] + z[_DR + 3 * i + 2] * z[_DW + 2])
                for i in range(9):
                    rotations[b, t, si, i] = z[_DR + i]
                for i in range(6):
                    strains[b, t, si, i] = eps[k, i] - pr[_PF0 + i]
                    stresses[b, t, si, i] = z[_DN + i]
            status[b] = t + 1
