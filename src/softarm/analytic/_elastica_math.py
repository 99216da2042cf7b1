"""Exact planar cantilever under a dead tip force: elliptic-integral closed form.

Pure mathematics, non-dimensional, no softarm imports (but its compiled twin for one load,
``_compiled``, imported on first use). A straight cantilever of length L and
bending stiffness EI is clamped at s = 0 with its tangent along +x and carries at s = L a dead
force P (cos φ, sin φ) in the (x, z) plane. ``planar_elastica`` returns the large-deflection
equilibrium on the fundamental (stable, no interior inflection point) branch:

* inextensible and unshearable (Euler elastica): fully closed form;
* extensible and shearable (planar Reissner rod, linear law N = EA ε, Q = GA γ, M = EI θ'):
  closed form for the angle, the curvature and the position across the force line, one
  Clenshaw-Curtis (Chebyshev) cumulative quadrature in arc length for the position along the
  force line.

Derivation (the notation of the code)
-------------------------------------
Lengths are in units of L, ``k = P L²/EI``, ``a_r = EI/(EA L²)``, ``g_r = EI/(GA L²)``. θ(s) is the
rotation of the cross-section (the tangent angle when unshearable), positive from +x towards +z.
The internal force is the dead load n = P (cos φ, sin φ) everywhere, so its material components
are N = P cos(φ − θ) (axial) and Q = P sin(φ − θ) (shear), and with r' = (1 + N/EA) d1 + (Q/GA) d3
the moment balance M' + r' × n = 0 reads

    θ'' = −k sin(φ − θ) [1 + e cos(φ − θ)],      e = k (a_r − g_r),

with θ(0) = 0 and θ'(1) = 0 (no tip moment). A positive transverse force (φ = π/2) turns the
tangent towards +z (θ' > 0), as it must. The mirror image (φ → −φ, θ → −θ, z → −z) reduces every
load to a ∈ [0, π], a = |φ| the angle from the clamp tangent to the force; the code solves that
problem and restores the sign σ = sign(φ). Let δ(s) = a − θ(s) be the angle still left between the
section and the force (δ(1) = δ_L at the tip) and w = cos(δ/2). The first integral (the
Hamiltonian, conserved because the load is dead) is

    θ'² = 4 k (p² − w²) f(w²),   p = cos(δ_L/2),   f(y) = 1 − e (sin²(δ_L/2) − y),

a quartic in w: s(θ) is an elliptic integral of the first kind. Parametrise every station by
χ through tan(d/2) = tan(δ_L/2)/cos χ (χ = 0 at the tip). Then cos²(d/2) = m cos²χ/(1 − m sin²χ)
with m = p², f(w²) (1 − m sin²χ) = f_L (1 − m' sin²χ) and ds = −dχ/(√(k f_L) (1 − m' sin²χ)^½),

    m' = m (1 + e m)/f_L,   1 − m' = m1 (1 − e m1)/f_L,   m1 = sin²(δ_L/2) = 1 − m,
    f_L = f(p²) = 1 + e cos δ_L,

so that the arc length from a station to the tip is Legendre's integral of the first kind

    √(k f_L) (1 − s) = F(χ_s | m') = sin χ_s R_F(cos²χ_s, 1 − m' sin²χ_s, 1)   (DLMF §19.25),

(0 ≤ m' ≤ 1 because |e| < 1): χ_s = am(√(k f_L)(1 − s) | m'), Jacobi's amplitude. This is the
Carlson form of DLMF 19.29.4 for the four linear factors y, 1 − y, p² − y, f(y) of y = w². The
tip condition is this relation at the clamp (d = a, s = 0, χ = χ_0 with tan(δ_L/2) = tan(a/2)
cos χ_0); it fixes δ_L. For e = 0 it is F(χ_0 | m) = √k with m = p², the classical form of
Frisch-Fay (1962) ch. 2 and Bisshopp & Drucker (1945): for φ = π/2, sqrt(k) = K(p) − F(ψ0, p)
with sin ψ0 = 1/(√2 p).

Positions, in the force frame e_F = (cos a, sin a), e_⊥ = (−sin a, cos a):

* across the force line, exactly for any e: the moment balance is θ'' = k (r' · e_⊥), hence
  η(s) = (θ'(s) − θ'(0))/k (the bending moment is the load times its lever arm);
* along the force line, r' · e_F = cos δ + k a_r − e sin² δ. For e = 0 the first integral gives
  cos δ = cos δ_L − θ'²/(2k), and ∫ θ'² ds = 4 √k m m1 [J(χ) − J(χ_s)] with
  J(χ) = ∫_0^χ sin²t (1 − m sin²t)^(−3/2) dt = (1/3) sin³χ R_D(cos²χ, 1, 1 − m sin²χ)
  (m m1 ∫ sd² du, Byrd & Friedman 316.02 in Carlson form); so
  ξ(s) = s (cos δ_L + k a_r) − (2/√k) m m1 [J(χ) − J(χ_s)]. For e ≠ 0 the same integrand needs
  elliptic integrals of the third kind whose reduction divides by m' − m ∝ e (cancellation for
  the common e ≪ 1); it is instead integrated in s by the Chebyshev (Clenshaw-Curtis) cumulative
  rule at Chebyshev points of [0, 1], where δ is known in closed form.

The unknowns are solved in ρ = log tan χ (sin χ and cos χ both keep full relative precision, for
loads from k ~ 1e-300 to strongly aligned tension) by Newton's method with the analytic slope,
safeguarded by a bracket (a bisection step whenever Newton would leave it), to a step of a few
ulps of ρ. The slope of the station relation is dF/dρ = sin χ cos χ/(1 − m' sin²χ)^½; the tip
condition also moves m' with χ_0, with ∂F/∂m' = J(χ | m')/2 and dm/dρ = 2 m m1 sin²χ_0. The
stations start from scipy's am(u | m') (``ellipj``), and converge in one or two steps; the tip
starts from the lower bound tan χ_0 ≥ sinh(√(k (1 − |e|))) (from F(χ | m') ≤ F(χ | 1) =
asinh tan χ), exact for strongly aligned loads and for small ones. All half-angle differences
are written as products of sines so that small loads keep full relative precision (no 1 − cos
cancellation).

Two routes evaluate this. A batch of loads (``_batch``) runs every step on arrays of shape
(B..., N). One load (``lone_rows``, what ``softarm.solve`` meets most) runs the same steps in
compiled scalar code (``_compiled``, numba, imported on first use): the tip condition
and every station by the same safeguarded Newton iteration with the same stopping rules, the
stations from the same starts, with Carlson's R_F, R_D and Jacobi's sn, cn written out there.
The two routes agree to a few units of 1e-15 of each field's scale
(tests/analytic/test_elastica_math.py).

References
----------
R. Frisch-Fay, *Flexible Bars*, Butterworths (1962), ch. 2 (cantilever with an inclined end load).
K. E. Bisshopp, D. C. Drucker, "Large deflection of cantilever beams", Q. Appl. Math. 3 (1945)
272-275, eqs. (6)-(9).
K. Mattiasson, Int. J. Numer. Meth. Engng 17 (1981) 145-153, Table 1 (the reference values).
M. Batista, "Large deflections of shear-deformable cantilever beam subject to a tip follower
force", Int. J. Mech. Sci. 75 (2013), and "A closed-form solution for Reissner planar
finite-strain beam using Jacobi elliptic functions", Int. J. Solids Struct. 87 (2016) 153-166:
the extensible/shearable moment equation and its first integral.
B. C. Carlson, "Numerical computation of real or complex elliptic integrals", Numer. Algorithms 10
(1995); DLMF §19.25 (Legendre forms as R_F, R_D) and eq. 19.29.4 (quartic integrands).
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numpy as np
from scipy.fft import dct
from scipy.special import ellipj, elliprd, elliprf

__all__ = ["ElasticaSolution", "planar_elastica"]

#: Bracket of ρ = log tan χ: sin χ, cos χ ≥ e^-700 stay normal doubles.
_RHO_MAX = 700.0
#: Largest supported load parameter k = P L²/EI (boundary layer of width L/√k ≈ 3e-3 L).
K_MAX = 1.0e5
#: Below this angle from axial tension (rad) the linearised tension solution is exact to 1e-17.
_A_LINEAR = 1.0e-8
#: Chebyshev points on [0, 1] for the shearable position quadrature, before √k scaling.
_N_CHEB = 64
#: Extra points per unit of √k (the clamp boundary layer has width ~ L/√k).
_N_CHEB_PER_ROOT_K = 4
#: Newton steps before giving up (bisection alone needs ~60 to resolve ρ ∈ ±700 to an ulp).
_MAX_STEPS = 100


class ElasticaSolution(NamedTuple):
    """Planar cantilever equilibrium at the requested stations (all non-dimensional).

    Shapes: ``(B..., N)`` for the station fields, ``(B...)`` for ``tip_angle``.
    """

    theta: np.ndarray  #: cross-section rotation θ(s) from +x towards +z, rad
    x: np.ndarray  #: centreline x(s)/L
    z: np.ndarray  #: centreline z(s)/L
    curvature: np.ndarray  #: θ'(s) in 1/L; the bending moment is EI θ'/L
    axial_strain: np.ndarray  #: N/EA = k a_r cos(φ − θ)
    shear_strain: np.ndarray  #: Q/GA = k g_r sin(φ − θ)
    tip_angle: np.ndarray  #: θ(L), rad


# --------------------------------------------------------------------------------------------
# Parametrisation and the closed-form arc length
# --------------------------------------------------------------------------------------------
def _sin_cos_from_rho(rho):
    """(sin χ, cos χ) for tan χ = exp(ρ), both with full relative precision."""
    t = np.exp(-np.abs(rho))
    big = 1.0 / np.sqrt(1.0 + t * t)
    small = t * big
    positive = rho >= 0.0
    return np.where(positive, big, small), np.where(positive, small, big)


def _tip_half_angle(ca, sa, c_chi):
    """sin and cos of δ_L/2 from tan(δ_L/2) = tan(a/2) cos χ."""
    h = np.hypot(ca, sa * c_chi)
    return sa * c_chi / h, ca / h


def _tip_geometry(ca, sa, s_chi, c_chi):
    """Half-angles of the tip misalignment δ_L and the tip rotation θ_L from χ.

    tan(δ_L/2) = tan(a/2) cos χ; θ_L = a − δ_L written without cancellation.
    """
    s_dl, c_dl = _tip_half_angle(ca, sa, c_chi)
    # tan(θ_L/2) = sa ca (1 − cos χ) / (ca² + sa² cos χ), 1 − cos χ = sin²χ/(1 + cos χ)
    half_tip = np.arctan2(sa * ca * s_chi * s_chi / (1.0 + c_chi), ca * ca + sa * sa * c_chi)
    return s_dl, c_dl, half_tip


def _station_half_angle(s_dl, c_dl, c_chs):
    """sin and cos of d/2 at a station, tan(d/2) = tan(δ_L/2)/cos χ_s."""
    h = np.hypot(s_dl, c_dl * c_chs)
    return s_dl / h, c_dl * c_chs / h


def _station_geometry(s_dl, c_dl, s_chs, c_chs):
    """Half-angles at a station: tan(d/2) = tan(δ_L/2)/cos χ_s.

    Returns sin(d/2), cos(d/2) and the product sin((d−δ_L)/2) sin((d+δ_L)/2) = p² − cos²(d/2).
    """
    s_d, c_d = _station_half_angle(s_dl, c_dl, c_chs)
    half_diff = np.arctan2(
        s_dl * c_dl * s_chs * s_chs / (1.0 + c_chs), c_dl * c_dl * c_chs + s_dl * s_dl
    )
    half_sum = np.arctan2(s_d, c_d) + np.arctan2(s_dl, c_dl)
    return s_d, c_d, np.sin(half_diff) * np.sin(half_sum)


def _modulus(s_dl, c_dl, e):
    """f_L = 1 + e cos δ_L and the complementary parameter 1 − m' = m1 (1 − e m1)/f_L."""
    m1 = s_dl * s_dl
    f_l = 1.0 + e * (c_dl - s_dl) * (c_dl + s_dl)
    return f_l, m1 * (1.0 - e * m1) / f_l


def _legendre_f(s_ch, c_ch, mc):
    """F(χ | m) = sin χ R_F(cos²χ, Δ², 1), Δ² = 1 − m sin²χ, from mc = 1 − m (DLMF §19.25).

    Returns F and Δ² (written as cos²χ + mc sin²χ, without cancellation).
    """
    delta2 = c_ch * c_ch + mc * s_ch * s_ch
    return s_ch * elliprf(c_ch * c_ch, delta2, 1.0), delta2


def _curvature(prod, c_d, s_dl, sqrt_k, e):
    """θ' = 2 √k sqrt((p² − w²) f(w²)) at a station (first integral), in 1/L."""
    f_d = 1.0 - e * (s_dl * s_dl - c_d * c_d)
    return 2.0 * sqrt_k * np.sqrt(np.maximum(prod, 0.0) * f_d)


def _newton(residual_and_slope, x, lo, hi, curvature=None):
    """Root of an increasing function in [lo, hi], elementwise, to a few ulps of x.

    Newton's method safeguarded by the bracket: every evaluation shrinks [lo, hi], and a Newton
    step that would leave it (non-positive or non-finite slope included) becomes a bisection
    step. An element stops after a Newton step δ below 4 ulps of max(1, |x|), or, given
    ``curvature`` ≥ |R''/R'| on the bracket, after one whose quadratic error bound
    (curvature/2) δ² is that small; or once its bracket is that narrow. Returns the root and
    the number of evaluations (the batch runs in lock step; converged elements stay put).
    """
    tol = 4.0 * np.finfo(np.float64).eps
    done = np.zeros(np.shape(x), dtype=bool)
    count = 0
    # Guarded below: an overflowing residual or a 0/0 slope (cos²χ underflows near ρ = ±700)
    # only turns its Newton step into a bisection step.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        while count < _MAX_STEPS and not done.all():
            count += 1
            residual, slope = residual_and_slope(x)
            below = residual < 0.0
            lo = np.where(below, x, lo)
            hi = np.where(below, hi, x)
            # (a slope that is not a positive finite number, e.g. inf from an underflowed
            # cos χ, gives an infinite step: a bisection, never a converged step of 0)
            usable = (slope > 0.0) & np.isfinite(slope)
            step = np.where(usable, residual / np.where(usable, slope, 1.0), np.inf)
            newton = x - step
            size, scale = np.abs(step), tol * np.maximum(1.0, np.abs(x))
            last = size <= scale
            if curvature is not None:
                last |= 0.5 * curvature * size * size <= scale
            take = last | (newton > lo) & (newton < hi)
            x = np.where(done, x, np.where(take, newton, 0.5 * (lo + hi)))
            done |= last | (hi - lo <= scale)
    return x, count


def _solve_stations(s, sqrt_k, rho_tip, s_dl, c_dl, e):
    """(sin χ_s, cos χ_s) with F(χ_s | m') = √(k f_L) (1 − s); exact at s = 0 and s = 1.

    Starts from Jacobi's amplitude am(√(k f_L)(1 − s) | m') (scipy ``ellipj``, accurate to a few
    ulps) and polishes it by Newton in ρ = log tan χ_s, bracketed by [−700, ρ_tip]: usually one
    step. In ρ the residual R = F − √(k f_L)(1 − s) has R' = sin χ cos χ/Δ' > 0 and
    d log R'/dρ = cos 2χ + m' sin²χ cos²χ/Δ'² ∈ [−1, 2] (Δ'² ≥ cos²χ), so |R''/R'| ≤ 2 bounds
    the error a Newton step leaves. Returns the number of evaluations too.
    """
    shape = np.broadcast_shapes(np.shape(s), np.shape(rho_tip))
    f_l, mc = _modulus(s_dl, c_dl, e)
    target = np.broadcast_to(sqrt_k * np.sqrt(f_l) * (1.0 - s), shape)

    def residual_and_slope(rho):
        s_ch, c_ch = _sin_cos_from_rho(rho)
        arc, delta2 = _legendre_f(s_ch, c_ch, mc)
        return arc - target, s_ch * c_ch / np.sqrt(delta2)

    lo, hi = np.full(shape, -_RHO_MAX), np.broadcast_to(rho_tip, shape)
    sn, cn, _, _ = ellipj(target, np.broadcast_to(1.0 - mc, shape))
    # cn = cos χ_s is only accurate to ~1e-16 absolute. Near χ = π/2 (there mc ≪ 1 too), the
    # leading term of R_F(x, y, z) for x, y ≪ z, F = log(4/(c + (c² + mc)^½)) + O(c² log c),
    # inverts to c = 2 e^(−u) − mc e^u/8: the better start once c³ < ulp (errors c² vs ulp/c).
    asymptotic = 2.0 * np.exp(-target) - mc * np.exp(target) / 8.0
    use_asymptotic = (asymptotic > 0.0) & (asymptotic**3 < np.finfo(np.float64).eps)
    with np.errstate(divide="ignore", invalid="ignore"):  # sn = 0 at the tip, cn ≤ 0 by rounding
        start = np.where(use_asymptotic, -np.log(asymptotic), np.log(sn) - np.log(cn))
    start = np.where(start > lo, start, lo)  # NaN goes to a bracket end as well
    start = np.where((start < hi) & (s > 0.0), start, hi)  # s = 0: the clamp, χ_s = χ_0
    rho, count = _newton(residual_and_slope, start, lo, hi, curvature=2.0)
    rho = np.where(s == 0.0, rho_tip, rho)
    s_ch, c_ch = _sin_cos_from_rho(rho)
    at_tip = s == 1.0
    return np.where(at_tip, 0.0, s_ch), np.where(at_tip, 1.0, c_ch), count


def _solve_tip(ca, sa, sqrt_k, e):
    """ρ_0 = log tan χ_0 of the tip condition F(χ_0 | m'(χ_0)) = √(k f_L(χ_0)), and the count.

    The residual F/√f_L − √k increases with ρ_0; its slope carries the motion of m' and f_L
    through m = cos²(δ_L/2): dm/dρ = 2 m m1 sin²χ, df_L/dm = 2e, dm'/dm = (1 − 2e² m m1/f_L)/f_L
    and ∂F/∂m' = J(χ | m')/2 = sin³χ R_D(cos²χ, 1, Δ'²)/6, J as in ``_j_integral``.
    """

    def residual_and_slope(rho):
        s_ch, c_ch = _sin_cos_from_rho(rho)
        s_dl, c_dl = _tip_half_angle(ca, sa, c_ch)
        f_l, mc = _modulus(s_dl, c_dl, e)
        arc, delta2 = _legendre_f(s_ch, c_ch, mc)
        mm1 = (s_dl * c_dl) ** 2  # m m1
        dm_f = 2.0 * mm1 * s_ch * s_ch / f_l  # (dm/dρ)/f_L; dm'/dρ = dm_f (1 − 2 e² m m1/f_L)
        half_j = s_ch**3 * elliprd(c_ch * c_ch, 1.0, delta2) / 6.0
        slope = s_ch * c_ch / np.sqrt(delta2) + dm_f * (
            half_j * (1.0 - 2.0 * e * e * mm1 / f_l) - e * arc
        )
        root_f = np.sqrt(f_l)
        return arc / root_f - sqrt_k, slope / root_f

    shape = np.shape(sqrt_k)
    start = np.log(np.sinh(sqrt_k * np.sqrt(1.0 - np.abs(e))))
    return _newton(residual_and_slope, start, np.full(shape, -_RHO_MAX), np.full(shape, _RHO_MAX))


def _j_integral(s_ch, c_ch, m1):
    """J(χ) = ∫_0^χ sin²t (1 − m sin²t)^(−3/2) dt = (1/3) sin³χ R_D(cos²χ, 1, Δ²) (DLMF 19.25)."""
    delta2 = c_ch * c_ch + m1 * s_ch * s_ch
    return s_ch**3 * elliprd(c_ch * c_ch, 1.0, delta2) / 3.0


def _cos_difference(s_a, c_a, s_b, c_b):
    """cos χ_b − cos χ_a for χ_b ≤ χ_a, accurate both for small angles and near π/2."""
    chi_a, chi_b = np.arctan2(s_a, c_a), np.arctan2(s_b, c_b)
    product = 2.0 * np.sin(0.5 * (chi_a + chi_b)) * np.sin(0.5 * (chi_a - chi_b))
    return np.where(chi_a < 1.0, product, c_b - c_a)


# --------------------------------------------------------------------------------------------
# Public function
# --------------------------------------------------------------------------------------------
def _as_finite(value, name):
    array = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return array


def planar_elastica(k, phi, s_over_L, *, axial_ratio=None, shear_ratio=None):
    """Large-deflection planar cantilever under a dead tip force, on its fundamental branch.

    Clamped at s = 0 with tangent +x, free at s = L, tip force P (cos φ, sin φ) fixed in space.
    Exact (geometrically non-linear) for the inextensible, unshearable rod (Euler elastica) and
    for the extensible, shearable planar Reissner rod with a linear constitutive law.

    Parameters
    ----------
    k : array_like
        Load parameter P L²/EI ≥ 0, at most ``K_MAX`` = 1e5. Broadcasts with ``phi`` and the
        ratios to the batch shape B.
    phi : array_like
        Force direction in rad from +x towards +z; any finite value (taken modulo 2π). φ = π/2
        is the transverse load of Mattiasson's table, φ = 0 pure tension, φ = ±π compression.
    s_over_L : array_like, shape (N,)
        Stations s/L in [0, 1].
    axial_ratio, shear_ratio : array_like or None, optional
        a_r = EI/(EA L²) and g_r = EI/(GA L²), ≥ 0; None or 0 for an inextensible or
        unshearable rod. Supported while P/EA = k a_r < 1 and |P/EA − P/GA| = |k (a_r − g_r)| < 1
        (beyond, the tension-aligned state loses stability and the fundamental branch changes
        character); ValueError otherwise.

    Returns
    -------
    ElasticaSolution
        ``theta`` (rad, cross-section rotation = tangent angle if unshearable), ``x``, ``z``
        (centreline / L), ``curvature`` θ' (1/L; moment = EI θ'/L), ``axial_strain`` N/EA,
        ``shear_strain`` Q/GA, each of shape (B..., N); ``tip_angle`` θ(L) of shape (B...).

    Notes
    -----
    Branch: the equilibrium continuously connected to the small-load solution, along which θ
    rotates monotonically from 0 towards φ (no inflection point inside the rod): the stable one.
    For axial compression (|φ| = π) the rod stays straight up to the Euler load k = π²/4 and
    then follows the buckled branch; the side is sign(sin φ) of the float given, so
    ``phi=np.pi`` (sin = 1.2e-16 > 0) buckles towards +z and ``phi=-np.pi`` towards −z. That float
    carries an imperfection of 1.2e-16 rad, which within ~1e-5 of k = π²/4 shows as a deflection
    of order (1e-16)^(1/3) L, as it physically should.

    Accuracy: the unknowns are solved by safeguarded Newton steps to a few ulps; angles and
    positions are accurate to a few units of 1e-15 (absolute, in rad and L), angles keep full
    relative precision for small loads. The inextensible case is closed form throughout; with
    shear or extension the position along the force line is a Clenshaw-Curtis cumulative
    quadrature (64 + 4 ⌈√k⌉ Chebyshev points on [0, L]) of a smooth integrand, the rest closed
    form. Beyond k f_L ≈ 1.2e5 cos²χ_0 ~ e^(−2√(k f_L)) would underflow and the boundary layer at
    the clamp lose accuracy, so k (1 + |e|) ≤ ``K_MAX`` is required (ValueError). Within 1e-8
    rad of axial tension the problem is linear in that angle to relative 1e-17 and the
    beam-column closed form is used instead (the elliptic route would underflow there).

    References
    ----------
    Frisch-Fay, *Flexible Bars* (1962), ch. 2; Bisshopp & Drucker, Q. Appl. Math. 3 (1945),
    eqs. (6)-(9); Mattiasson, IJNME 17 (1981), Table 1; Batista, IJSS 87 (2016) (shearable
    first integral); DLMF 19.25, 19.29.4 (Carlson forms). See the module docstring.

    Examples
    --------
    >>> import numpy as np
    >>> sol = planar_elastica(1.0, np.pi / 2, np.array([0.0, 1.0]))
    >>> print(f"{sol.z[-1]:.5f} {1 - sol.x[-1]:.5f} {sol.tip_angle:.5f}")
    0.30172 0.05643 0.46135
    """
    k = _as_finite(k, "k")
    phi = _as_finite(phi, "phi")
    a_r = _as_finite(0.0 if axial_ratio is None else axial_ratio, "axial_ratio")
    g_r = _as_finite(0.0 if shear_ratio is None else shear_ratio, "shear_ratio")
    s = _as_finite(s_over_L, "s_over_L")
    if s.ndim != 1:
        raise ValueError(f"s_over_L must be a 1-D array of stations, got shape {s.shape}")
    if np.any((s < 0.0) | (s > 1.0)):
        raise ValueError(f"s_over_L must lie in [0, 1], got {s_over_L!r}")
    if np.any(k < 0.0) or np.any(k > K_MAX):
        raise ValueError(f"k must lie in [0, {K_MAX:g}], got {k!r}")
    if np.any(a_r < 0.0) or np.any(g_r < 0.0):
        raise ValueError(
            f"axial_ratio and shear_ratio must be >= 0, got {axial_ratio!r}, {shear_ratio!r}"
        )
    k, phi, a_r, g_r = np.broadcast_arrays(k, phi, a_r, g_r)
    e = k * (a_r - g_r)
    if np.any(k * (1.0 + np.abs(e)) > K_MAX):
        # beyond k f_L ≈ 1.2e5, cos²χ_0 ~ exp(-2√(k f_L)) underflows and the clamp's boundary
        # layer loses accuracy (checked against mpmath): refuse rather than be silently wrong
        raise ValueError(
            f"need k (1 + |k (axial_ratio - shear_ratio)|) <= {K_MAX:g}, got k up to "
            f"{float(np.max(k))!r} with k (axial_ratio - shear_ratio) up to "
            f"{float(np.max(np.abs(e)))!r}"
        )
    if np.any(k * a_r >= 1.0) or np.any(np.abs(e) >= 1.0):
        raise ValueError(
            "need P/EA = k*axial_ratio < 1 and |k*(axial_ratio - shear_ratio)| < 1, got "
            f"k*axial_ratio = {k * a_r!r}, k*(axial_ratio - shear_ratio) = {e!r}"
        )

    if k.ndim == 0:  # one load: scalar arithmetic for its unknowns, numpy along the stations
        return _lone(float(k), float(phi), s, float(a_r), float(g_r))
    return _batch(k, phi, s, a_r, g_r, e)


def _batch(k, phi, s, a_r, g_r, e):
    """:func:`planar_elastica` for validated arrays broadcast to the batch shape B."""
    # Mirror to a = |φ| ∈ [0, π]; trivial cases (k = 0, pure tension) get safe values.
    wrapped = phi - 2.0 * np.pi * np.round(phi / (2.0 * np.pi))
    sign = np.where(wrapped < 0.0, -1.0, 1.0)
    a = np.abs(wrapped)
    straight = (k == 0.0) | (a == 0.0)
    # Nearly axial tension: the problem is linear in a to relative O(a²) (below 1e-16 here),
    # and the elliptic route would underflow (sin²(a/2) < 1e-308 for a < 1e-154).
    near_tension = a < _A_LINEAR
    a_safe = np.where(straight | near_tension, 0.5 * np.pi, a)
    k_safe = np.where(straight, 1.0, k)
    sqrt_k = np.sqrt(k_safe)
    ca, sa = np.cos(0.5 * a_safe), np.sin(0.5 * a_safe)

    # Tip condition: arc length from the clamp (d = a) to the tip equals √k.
    rho_tip, _ = _solve_tip(ca, sa, sqrt_k, e)
    s_chi, c_chi = _sin_cos_from_rho(rho_tip)
    s_dl, c_dl, half_tip = _tip_geometry(ca, sa, s_chi, c_chi)
    prod0 = np.sin(half_tip) * np.sin(a_safe - half_tip)

    # Stations (batch axis B..., station axis last), with the Chebyshev points of the position
    # quadrature when it is needed (one solve for both).
    ex = (..., None)
    quadrature = not np.all(e == 0.0)
    n_cheb = _N_CHEB + _N_CHEB_PER_ROOT_K * int(np.ceil(np.max(sqrt_k))) if quadrature else 0
    s_all = np.concatenate([s, _chebyshev_points(n_cheb)]) if quadrature else s
    s_chs, c_chs, _ = _solve_stations(s_all, sqrt_k[ex], rho_tip[ex], s_dl[ex], c_dl[ex], e[ex])
    if quadrature:
        ka = (k * a_r)[ex]
        s_dn, c_dn = _station_half_angle(s_dl[ex], c_dl[ex], c_chs[..., s.size :])
        integrand = (c_dn - s_dn) * (c_dn + s_dn) + ka - e[ex] * (2.0 * s_dn * c_dn) ** 2
        xi = _cumulative_chebyshev(integrand, s)
        s_chs, c_chs = s_chs[..., : s.size], c_chs[..., : s.size]
    s_d, c_d, prod = _station_geometry(s_dl[ex], c_dl[ex], s_chs, c_chs)
    dcos = _cos_difference(s_chi[ex], c_chi[ex], s_chs, c_chs)
    ca_, sa_ = ca[ex], sa[ex]
    theta_a = 2.0 * np.arctan2(sa_ * ca_ * dcos, ca_ * ca_ * c_chs + sa_ * sa_ * c_chi[ex])
    theta_a = np.where(s == 1.0, 2.0 * half_tip[ex], theta_a)  # the same rounding as tip_angle
    kappa = _curvature(prod, c_d, s_dl[ex], sqrt_k[ex], e[ex])
    kappa0 = _curvature(prod0, ca, s_dl, sqrt_k, e)
    eta = np.where(s == 0.0, 0.0, (kappa - kappa0[ex]) / k_safe[ex])

    m, m1 = c_dl * c_dl, s_dl * s_dl
    tip = 2.0 * half_tip
    cos_dl = np.cos(a_safe) * np.cos(tip) + np.sin(a_safe) * np.sin(tip)  # cos(a − θ_L)
    if not quadrature:
        j_diff = _j_integral(s_chi, c_chi, m1)[ex] - _j_integral(s_chs, c_chs, m1[ex])
        xi = s * (cos_dl + k * a_r)[ex] - (2.0 / sqrt_k * m * m1)[ex] * j_diff

    cos_d = (c_d - s_d) * (c_d + s_d)  # cos δ(s) and sin δ(s) = 2 sin(d/2) cos(d/2)
    sin_d = 2.0 * s_d * c_d
    cos_a, sin_a = np.cos(a_safe)[ex], np.sin(a_safe)[ex]
    x_a = xi * cos_a - eta * sin_a
    z_a = xi * sin_a + eta * cos_a

    sg, st = sign[ex], straight[ex]
    ka, kg = (k * a_r)[ex], (k * g_r)[ex]
    if np.any(near_tension):  # it only replaces values: skipped when no load needs it
        lin = _tension_linear(s, k_safe[ex], np.where(near_tension, a, 0.0)[ex], e[ex], ka, kg)
        lin_tip = _tension_linear(1.0, k_safe, np.where(near_tension, a, 0.0), e, k * a_r, k * g_r)
        nt = near_tension[ex]
        theta_a, x_a, z_a = (
            np.where(nt, u, v) for u, v in zip(lin[:3], (theta_a, x_a, z_a), strict=True)
        )
        kappa, cos_d = np.where(nt, lin[3], kappa), np.where(nt, 1.0, cos_d)
        sin_d = np.where(nt, lin[4], sin_d)
        tip = np.where(near_tension, lin_tip[0], tip)
    theta = np.where(st, 0.0, sg * theta_a)
    x = np.where(st, s * (1.0 + ka), x_a)
    z = np.where(st, 0.0, sg * z_a)
    curvature = np.where(st, 0.0, sg * kappa)
    axial = np.where(st, ka, ka * cos_d)  # straight: pure tension N = P (or k = 0)
    shear = np.where(st, 0.0, sg * kg * sin_d)
    tip = np.where(straight, 0.0, sign * tip)
    return ElasticaSolution(theta, x, z, curvature, axial, shear, tip)


def _tension_linear(s, k, a, e, ka, kg):
    """Closed form for a load within a ≪ 1 rad of axial tension, to relative O(a²).

    sin(a − θ) = (a − θ)(1 + O(a²)) turns the moment equation into θ'' = μ² (θ − a),
    μ² = k (1 + e): θ = a (1 − cosh μ(1 − s)/cosh μ). Returns θ, x, z, θ', sin δ = a − θ.
    """
    mu = np.sqrt(k * (1.0 + e))
    denominator = 1.0 + np.exp(-2.0 * mu)
    near, far = np.exp(-mu * s), np.exp(-mu * (2.0 - s))
    ratio_cosh = (near + far) / denominator  # cosh μ(1 − s) / cosh μ
    ratio_sinh = (near - far) / denominator  # sinh μ(1 − s) / cosh μ
    theta = a * (1.0 - ratio_cosh)
    integral = a * (
        s
        - 2.0
        * np.exp(-mu * s / 2.0)
        * np.sinh(mu * s / 2.0)
        * (1.0 + np.exp(-2.0 * mu * (1.0 - s / 2.0)))
        / (denominator * mu)
    )
    z = (1.0 + ka - kg) * integral + kg * a * s
    x = (1.0 + ka) * s * np.ones_like(theta)
    return theta, x, z, a * mu * ratio_sinh, a * ratio_cosh


def _chebyshev_points(n):
    """Chebyshev points of [0, 1], s_j = cos²(π j / (2(n − 1))), j = 0 … n − 1 (tip to clamp).

    Written as sin²(π (n − 1 − j) / (2(n − 1))) so that both ends are exact.
    """
    return np.sin(0.5 * np.pi * np.arange(n - 1, -1, -1) / (n - 1)) ** 2


#: Largest (Chebyshev points × stations) whose quadrature weights are kept (2 MiB each).
_CACHED_WEIGHTS = 2**18


def _cumulative_chebyshev(values, s):
    """∫_0^s f for f sampled at ``_chebyshev_points(n)`` on the last axis (Clenshaw-Curtis).

    The rule is linear in the samples: ``values @ W`` with the weights W (n, N) of
    :func:`_chebyshev_weights`, kept for the last few (n, s) (the same stations come back call
    after call); very large grids run :func:`_cumulative_chebyshev_direct` instead.
    """
    n = values.shape[-1]
    if n * s.size > _CACHED_WEIGHTS:
        return _cumulative_chebyshev_direct(values, s)
    return values @ _chebyshev_weights(n, s.tobytes())


@functools.lru_cache(maxsize=16)
def _chebyshev_weights(n, stations):
    """W with ``_cumulative_chebyshev_direct(values, s) = values @ W``, shape (n, N), read-only.

    Row i is the rule applied to the i-th unit sample; ``stations`` is ``s.tobytes()``.
    """
    weights = _cumulative_chebyshev_direct(np.eye(n), np.frombuffer(stations))
    weights.setflags(write=False)
    return weights


@functools.lru_cache(maxsize=16)
def _chebyshev_rule(n, stations):
    """The points (n,) and the weights (n, N) of the cumulative rule, read-only (the same
    stations come back call after call); ``stations`` is ``s.tobytes()``."""
    points = _chebyshev_points(n)
    points.setflags(write=False)
    return points, _chebyshev_weights(n, stations)


def _cumulative_chebyshev_direct(values, s):
    """∫_0^s f for f sampled at ``_chebyshev_points(n)`` on the last axis (Clenshaw-Curtis).

    f ≈ Σ c_j T_j(2s − 1) with c from a DCT-I of the samples; the series is integrated term by
    term (∫T_0 = T_1, ∫T_j = T_{j+1}/(2(j+1)) − T_{j−1}/(2(j−1))) and evaluated at the stations s
    with T_j(cos ϑ) = cos jϑ, 2s − 1 = cos ϑ. Shapes: values (B..., n), s (N,) → (B..., N).
    """
    n = values.shape[-1]
    halve_ends = np.ones(n)
    halve_ends[[0, -1]] = 0.5
    c = dct(values, type=1, axis=-1) * (halve_ends / (n - 1))
    c = np.concatenate([c, np.zeros((*c.shape[:-1], 2))], axis=-1)  # c_0 … c_{n+1}
    j = np.arange(1, n + 1)
    below = c[..., :n] * np.where(j == 1, 2.0, 1.0)  # c_{j−1}, doubled for ∫T_0 = T_1
    b = (below - c[..., 2:]) / (2.0 * j)  # coefficients of T_1 … T_n in the antiderivative
    angle = 2.0 * np.arctan2(np.sqrt(1.0 - s), np.sqrt(s))
    t_minus_clamp = np.cos(angle[:, None] * j) - np.where(j % 2 == 0, 1.0, -1.0)
    return 0.5 * (b @ t_minus_clamp.T)


# --------------------------------------------------------------------------------------------
# One load: the compiled route (``_compiled``, numba, imported on first use), the same
# algorithm with scalar loops; _batch stays the route for batches
# (tests/analytic/test_elastica_math.py checks that the two agree).
# --------------------------------------------------------------------------------------------
def compiled():
    """The compiled module ``_compiled`` of this package, imported on first use (``import
    softarm`` does not import numba)."""
    global _COMPILED
    if _COMPILED is None:
        from . import _compiled as module

        _COMPILED = module
    return _COMPILED


_COMPILED = None
#: Placeholders of the quadrature's points and weights where it is not used (the kernel's
#: argument types stay the same, so numba compiles one version).
_NO_POINTS = np.zeros(0)
_NO_POINTS.setflags(write=False)
_NO_WEIGHTS = np.zeros((0, 0))
_NO_WEIGHTS.setflags(write=False)


def lone_rows(k, phi, s, a_r, g_r):
    """:func:`planar_elastica` for one validated load (floats) on the stations s (N,).

    Returns the fields θ, x, z, θ', N/EA, Q/GA as the rows of one fresh array (6, N) and the
    tip angle (a float), or None where the compiled route does not apply (a quadrature whose
    weights would be too large to keep: the caller then runs :func:`_batch`). The straight
    and the nearly tension-aligned loads take their closed forms here, every other load the
    compiled kernel, which agrees with :func:`_batch` to a few ulps.
    """
    n = s.shape[0]
    e = k * (a_r - g_r)
    ka, kg = k * a_r, k * g_r
    wrapped = phi - 2.0 * math.pi * round(phi / (2.0 * math.pi))
    sign = -1.0 if wrapped < 0.0 else 1.0
    a = abs(wrapped)
    if k == 0.0 or a == 0.0:  # straight: pure tension N = P (or no load)
        rows = np.zeros((6, n))
        rows[1] = s * (1.0 + ka)
        rows[4] = ka
        return rows, 0.0
    if a < _A_LINEAR:  # nearly axial tension: the linearised closed form (see _batch)
        theta, x, z, kappa, sin_d = _tension_linear(s, k, a, e, ka, kg)
        tip = _tension_linear(1.0, k, a, e, ka, kg)[0]
        rows = np.stack([sign * theta, x, sign * z, sign * kappa, np.full(n, ka),
                         sign * kg * sin_d])
        return rows, float(sign * tip)
    points, weights = _NO_POINTS, _NO_WEIGHTS
    if e != 0.0:
        n_cheb = _N_CHEB + _N_CHEB_PER_ROOT_K * math.ceil(math.sqrt(k))
        if n_cheb * n > _CACHED_WEIGHTS:
            return None
        points, weights = _chebyshev_rule(n_cheb, s.tobytes())
    rows = np.empty((6, n))
    tip = compiled().solve(k, a, sign, a_r, g_r, s, points, weights, rows)
    return rows, tip


def _lone(k, phi, s, a_r, g_r):
    """:func:`planar_elastica` for one validated load (floats) on the stations s (N,)."""
    s = np.array(s, dtype=np.float64)  # fresh and contiguous: one compiled version
    result = lone_rows(k, phi, s, a_r, g_r)
    if result is None:
        e = k * (a_r - g_r)
        return _batch(*(np.array(v) for v in (k, phi)), s, np.array(a_r), np.array(g_r),
                      np.array(e))
    rows, tip = result
    return ElasticaSolution(*rows, np.float64(tip))
