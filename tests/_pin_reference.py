"""Hard-contact reference: a planar arm pressed onto a frictionless cylindrical pin.

Written for tests/test_pin_reference.py from the equations alone; it imports nothing from
softarm. Same planar model and conventions as tests/_planar_elastica.py: the arm is clamped
at the origin along +x in the x-z plane, θ is the angle of the SECTION's axis e₁ from +x
towards +z, scalar moments are about −y (counter-clockwise in the x-z plane seen with +x to
the right and +z up), SI units, spatial components::

    x' = cos θ (1 + n₁/EA) − sin θ n₃/GA,    n₁ =  n_x cos θ + n_z sin θ  (material, axial)
    z' = sin θ (1 + n₁/EA) + cos θ n₃/GA,    n₃ = −n_x sin θ + n_z cos θ  (material, shear)
    θ' = m/EI,   m' = −(x' n_z − z' n_x),   n' = −q − c,

x(0) = z(0) = θ(0) = 0, n(L) = (0, −P) (a dead downward tip force), m(L) = 0, the weight
q = (0, −w) per unit reference length. n(s) is the force that the part (s, L] exerts on
[0, s]; the clamp's reaction on the arm is −n(0), its moment −m(0).

The pin is a rigid cylinder, axis along y through (x_p, z_p), radius R_pin, below the arm.
The arm's surface is a tube of radius r, so the gap is g = |p − p_pin| − ρ with ρ = R_pin + r,
and the contact force per unit reference length is c = c ν, ν = (cos φ, sin φ) the outward
normal at the centreline's polar angle φ around the pin axis; c ≥ 0, c g = 0.

Equations on the wrap (s_a ≤ s ≤ s_b)
-------------------------------------
The constraint is g = 0: the centreline lies on the circle of radius ρ, p = p_pin + ρ ν(φ),
and the arm runs clockwise over the top (φ decreasing). Write a = 1 + n₁/EA, γ = n₃/GA,
t = (cos θ, sin θ), d = (−sin θ, cos θ): the centreline's tangent is p' = a t + γ d, of length
√D, D = a² + γ², at the angle ψ = θ + β, β = atan2(γ, a) (the shear angle). On the circle

    φ' = −√D/ρ     and    ψ = φ − π/2,   i.e.   a cos(θ − φ) − γ sin(θ − φ) = 0.       (C)

With shear, the section (θ) is NOT the circle's tangent: they differ by the shear angle β,
and β changes along the wrap with n₃, which the pressure changes. Differentiating (C),
θ' + β' = φ', with β' = (a γ' − γ a')/D and, from n' = −q − c ν,

    n₁' = A₁ − c (ν·t),  A₁ = −q·t + θ' n₃,     n₃' = A₃ − c (ν·d),  A₃ = −q·d − θ' n₁,

is linear in c; solved for the multiplier,

    c = D [θ' + √D/ρ + (a A₃/GA − γ A₁/EA)/D] / [a (ν·d)/GA − γ (ν·t)/EA].           (P)

The denominator is ≈ 1/GA > 0 (ν ≈ d on the wrap), so c ≈ GA (1/ρ + m/EI) + O(q, n/EA): the
pressure is the shear stiffness times the mismatch between the circle's curvature and the
section's. On the wrap the state is (φ, θ, n_x, n_z, m) with x, z from φ, c from (P).

Edge zones, and why there is no point reaction
----------------------------------------------
A concentrated reaction F at an interior point would make n jump by −F ν, hence n₃ by ≈ −F
and the shear angle by ≈ −F/GA: a corner in the centreline, whose two sides leave the
contact point at a finite angle below the circle's tangent, i.e. into the pin. So for the
shearable rod hard contact has no point reaction; all of (x, z, θ, n, m) are continuous at
s_a and s_b, and the free arms are tangent to the circle there (their tangent p' is continuous
and equals the circle's on the wrap). The pressure does jump at the edges, from 0 to the
value (P): with c = 0 the same algebra gives the free arm's turning rate ψ' = θ' + β', so
(P) reads c = D (ψ'_free − φ') / [a (ν·d)/GA − γ (ν·t)/EA] at the edge, and c ≥ 0 there is
the condition that the free arm beside the wrap turns clockwise no faster than the circle,
i.e. curves away from the pin rather than into it.

Linearised on the wrap (n₁/EA, q small against c): n₃' ≈ −c, m' ≈ −n₃, β ≈ n₃/GA,
β' = φ' − θ' ≈ −1/ρ − m/EI, so

    m'' = (GA/EI) (m + EI/ρ):

the table problem's edge-zone equation (ρ → ∞ there) with the pin's curvature added. Its
solutions relax to the conforming moment m = −EI/ρ over λ = √(EI/GA). So the wrap has the same
kind of edge zones as the table: on a LONG wrap (when |m| would exceed EI/ρ, the unshearable
rod's wrap with point reactions at its ends) an interior with m ≈ −EI/ρ and c ≈ tension/ρ,
and two edge zones of width ~λ carrying the unshearable rod's end reactions as pressure.
Where the moment at the pin is far below EI/ρ (the soft arm here: EI/ρ = 0.52 N m against
~0.1 N m) the two edge zones merge into the whole wrap: its length is ≈ ρ F/GA (the
section turns by the shear jump F/GA while the centreline follows the circle), ≪ λ, with an
almost uniform pressure ≈ GA (1/ρ + m/EI); the unshearable limit GA → ∞ is the point
reaction F. The solver below uses equation (P) on the whole wrap and does not assume either
regime.

Free-boundary problem
---------------------
Three zones, [0, s_a] free, [s_a, s_b] on the pin, [s_b, L] free, each mapped to τ ∈ [0, 1]
and solved together by scipy's solve_bvp (17 states: 6 + 5 + 6) with s_a, s_b as unknown
parameters: 19 conditions = clamp (3) + tip (3) + at s_a continuity of x, z, θ, n, m (6) and
(C) (1) + at s_b continuity (6). (C) then holds on the whole wrap because (P) keeps its
derivative zero, so the free arm leaves the pin tangentially at s_b too. Nondimensional
variables: s/L, lengths/L, n L²/EI, m L/EI, c L³/EI. The starting guess is the penalty
solution (:func:`pin_penalty`) at a moderate stiffness.

:func:`pin_penalty` is the independent second method: the whole arm without zones, contact
force per length ≈ k max(0, −g) ν (smoothed at the contact's edges), for the tests to drive
k towards the hard limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_bvp

__all__ = ["PinPenalty", "PinReference", "pin_penalty", "pin_reference", "soft_arm"]


def soft_arm():
    """The default soft silicone arm of the contact references (issue 33): a dict of
    L (m), EA, GA (N), EI (N m²), r (m), w (N/m, its weight per length)."""
    r, E = 0.01, 1.0e6
    area, inertia = math.pi * r**2, math.pi * r**4 / 4.0
    return dict(L=0.5, EA=E * area, GA=E / 3.0 * area, EI=E * inertia, r=r,
                w=1000.0 * area * 9.81)


@dataclass(frozen=True)
class _Scaled:
    """The problem in nondimensional form (lengths / L, forces L²/EI)."""

    L: float
    EI: float
    eps_a: float  # EI / (EA L²)
    eps_g: float  # EI / (GA L²)
    q: tuple  # (q̃_x, q̃_z) = q L³/EI, the applied load per length
    tip: tuple  # (F̃_x, F̃_z) = F L²/EI
    rho: float  # (R_pin + r) / L
    centre: tuple  # pin axis / L

    @classmethod
    def of(cls, L, EA, GA, EI, r, w, P, R_pin, x_p, z_p):
        for name, value in dict(L=L, EA=EA, GA=GA, EI=EI, r=r, R_pin=R_pin).items():
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive finite number, got {value!r}")
        return cls(L, EI, EI / (EA * L**2), EI / (GA * L**2), (0.0, -w * L**3 / EI),
                   (0.0, -P * L**2 / EI), (R_pin + r) / L, (x_p / L, z_p / L))

    def scaled(self, lam):
        """The same problem with the loads multiplied by lam."""
        return _Scaled(self.L, self.EI, self.eps_a, self.eps_g,
                       (lam * self.q[0], lam * self.q[1]),
                       (lam * self.tip[0], lam * self.tip[1]), self.rho, self.centre)


def _free(y, pr, cx=0.0, cz=0.0):
    """d/ds of (x, z, θ, n_x, n_z, m), nondimensional, with a contact load (c_x, c_z)."""
    _, _, th, nx, nz, m = y
    c, s = np.cos(th), np.sin(th)
    n1 = nx * c + nz * s
    n3 = -nx * s + nz * c
    stretch = 1.0 + pr.eps_a * n1
    dx = c * stretch - s * pr.eps_g * n3
    dz = s * stretch + c * pr.eps_g * n3
    dm = -(dx * nz - dz * nx)
    return np.vstack([dx, dz, m, -pr.q[0] - cx + 0.0 * th, -pr.q[1] - cz + 0.0 * th, dm])


def _wrap_pressure(y, pr):
    """Equation (P): the pressure c̃ = c L³/EI on the wrap, for wrap states (φ, θ, n_x, n_z, m)."""
    phi, th, nx, nz, m = y
    ct, st = np.cos(th), np.sin(th)
    n1 = nx * ct + nz * st
    n3 = -nx * st + nz * ct
    a = 1.0 + pr.eps_a * n1
    g = pr.eps_g * n3
    D = a * a + g * g
    A1 = -(pr.q[0] * ct + pr.q[1] * st) + m * n3
    A3 = -(-pr.q[0] * st + pr.q[1] * ct) - m * n1
    nu_t, nu_d = np.cos(phi - th), np.sin(phi - th)
    den = a * nu_d * pr.eps_g - g * nu_t * pr.eps_a
    return D * (m + np.sqrt(D) / pr.rho + (a * A3 * pr.eps_g - g * A1 * pr.eps_a) / D) / den


def _wrap(y, pr):
    """d/ds of the wrap states (φ, θ, n_x, n_z, m), nondimensional."""
    phi, th, nx, nz, m = y
    c = _wrap_pressure(y, pr)
    ct, st = np.cos(th), np.sin(th)
    n1 = nx * ct + nz * st
    n3 = -nx * st + nz * ct
    a = 1.0 + pr.eps_a * n1
    g = pr.eps_g * n3
    dx, dz = ct * a - st * g, st * a + ct * g
    dm = -(dx * nz - dz * nx)
    return np.vstack([-np.sqrt(a * a + g * g) / pr.rho, m, -pr.q[0] - c * np.cos(phi),
                      -pr.q[1] - c * np.sin(phi), dm])


def _constraint(y, pr):
    """(C): the normal component of the constitutive tangent, zero on the circle."""
    phi, th, nx, nz, _ = y
    n1 = nx * np.cos(th) + nz * np.sin(th)
    n3 = -nx * np.sin(th) + nz * np.cos(th)
    return (1.0 + pr.eps_a * n1) * np.cos(th - phi) - pr.eps_g * n3 * np.sin(th - phi)


def _on_circle(phi, pr):
    return pr.centre[0] + pr.rho * np.cos(phi), pr.centre[1] + pr.rho * np.sin(phi)


# ---------------------------------------------------------------------------------------------
# The independent second method: a penalty on the whole arm


def _penalty_law(depth, k, beta):
    """Contact force per length (N/m, or nondimensional alike) for a penetration depth d, and
    its derivative in d: β H(k d/β), H(u) = 0 below 0, u − ½ above 1 and the C³ blend
    u⁴ (5/2 − 3u + u²) between (H' = 10u³ − 15u⁴ + 6u⁵ there): k max(0, d) − β/2 once deeper
    than β/k. (scipy's solve_bvp refines a plain kink k max(0, d) without end.)"""
    u = np.maximum(0.0, k * np.asarray(depth) / beta)
    v = np.minimum(u, 1.0)
    blend = u < 1.0
    force = beta * np.where(blend, v**4 * (2.5 - 3.0 * v + v * v), u - 0.5)
    slope = k * np.where(blend, v**3 * (10.0 - 15.0 * v + 6.0 * v * v), 1.0)
    return force, slope


@dataclass(frozen=True)
class PinPenalty:
    """A converged penalty solution; ``state(s)`` (6, N) = x, z, θ, n_x, n_z, m (SI units)."""

    length: float
    EI: float
    stiffness: float  # k, N/m² (force per length per metre of penetration)
    pressure_scale: float  # β, N/m: the law's smoothing
    sol: object  # scipy's solution (nondimensional)
    problem: _Scaled

    def state(self, s) -> np.ndarray:
        y = self.sol.sol(np.atleast_1d(np.asarray(s, dtype=np.float64)) / self.length)
        L, EI = self.length, self.EI
        return y * np.array([L, L, 1.0, EI / L**2, EI / L**2, EI / L])[:, None]

    def positions(self, s) -> np.ndarray:
        """(N, 3) centreline positions (x, 0, z) in m."""
        y = self.state(s)
        return np.stack([y[0], np.zeros_like(y[0]), y[1]], axis=-1)

    def gap(self, s) -> np.ndarray:
        """Surface-to-pin gap (m), negative where the arm penetrates."""
        y = self.state(s)
        cx, cz = np.asarray(self.problem.centre) * self.length
        return np.hypot(y[0] - cx, y[1] - cz) - self.problem.rho * self.length

    def pressure(self, s) -> np.ndarray:
        """Contact force per unit reference length (N/m) along the outward normal."""
        return _penalty_law(-self.gap(s), self.stiffness, self.pressure_scale)[0]


def _penalty_fun(pr, kt, bt):
    def fun(t, y):
        X, Z = y[0] - pr.centre[0], y[1] - pr.centre[1]
        dist = np.hypot(X, Z)
        c = _penalty_law(pr.rho - dist, kt, bt)[0] / dist
        return _free(y, pr, c * X, c * Z)

    return fun


def _penalty_jac(pr, kt, bt):
    """The exact Jacobian of :func:`_penalty_fun` (6, 6, N): solve_bvp's finite differences
    (steps ~1e-8 L) are far too coarse for the law's variation at large k and stall Newton."""

    def jac(t, y):
        x, z, th, nx, nz, _ = y
        c, s = np.cos(th), np.sin(th)
        ea, eg = pr.eps_a, pr.eps_g
        n1, n3 = nx * c + nz * s, -nx * s + nz * c
        a, g = 1.0 + ea * n1, eg * n3
        dx, dz = c * a - s * g, s * a + c * g
        dx_th, dz_th = -dz + ea * c * n3 + eg * s * n1, dx + ea * s * n3 - eg * c * n1
        dx_nx, dx_nz = ea * c * c + eg * s * s, (ea - eg) * s * c
        dz_nx, dz_nz = dx_nz, ea * s * s + eg * c * c
        X, Z = x - pr.centre[0], z - pr.centre[1]
        dist = np.hypot(X, Z)
        f, df = _penalty_law(pr.rho - dist, kt, bt)
        ex, ez = X / dist, Z / dist
        J = np.zeros((6, 6, t.size))
        J[0, 2], J[0, 3], J[0, 4] = dx_th, dx_nx, dx_nz
        J[1, 2], J[1, 3], J[1, 4] = dz_th, dz_nx, dz_nz
        J[2, 5] = 1.0
        # n' = −q − f(ρ − |X|) e: ∂(f e)/∂X = −f' e eᵀ + f (I − e eᵀ)/|X|
        for i, ei in enumerate((ex, ez)):
            for j, ej in enumerate((ex, ez)):
                J[3 + i, j] = df * ei * ej - f * ((i == j) - ei * ej) / dist
        J[5, 2] = -(dx_th * nz - dz_th * nx)
        J[5, 3] = -(dx_nx * nz - dz_nx * nx - dz)
        J[5, 4] = -(dx_nz * nz + dx - dz_nz * nx)
        return J

    return jac


def _penalty_bc(pr):
    def bc(ya, yb):
        return np.array([ya[0], ya[1], ya[2], yb[3] - pr.tip[0], yb[4] - pr.tip[1], yb[5]])

    return bc


def _mesh_around_contact(sol, pr, dense=401):
    """A fresh mesh on [0, 1] for the next solve from ``sol``: 201 nodes uniform, ``dense`` more
    on its contact zone widened twice its length each way (solve_bvp only ever adds nodes, and
    those piled up at a previous zone's edges slow every later solve)."""
    inside = np.flatnonzero(np.hypot(sol.y[0] - pr.centre[0], sol.y[1] - pr.centre[1]) < pr.rho)
    if inside.size == 0:
        return sol.x
    lo, hi = sol.x[inside[0]], sol.x[inside[-1]]
    lo, hi = max(0.0, lo - 2.0 * (hi - lo)), min(1.0, hi + 2.0 * (hi - lo))
    t = np.unique(np.concatenate([np.linspace(0.0, 1.0, 201), np.linspace(lo, hi, dense)]))
    return t[np.concatenate([[True], np.diff(t) > 1e-9])]


def pin_penalty(L, EA, GA, EI, r, w, P, R_pin, x_p, z_p, k, *, pressure_scale=None, tol=1e-6,
                softer=None, max_nodes=200_000) -> PinPenalty:
    """The arm on the pin with a penalty contact law, solved on the whole arm without zones.

    The contact force per length along the outward normal is β H(−k g/β) (N/m; g the gap in
    m, k in N/m², H in :func:`_penalty_law`): the plain penalty k max(0, −g), less β/2, beyond
    a penetration β/k, rounded to C³ above it. It is a function of k g, so every difference
    from the hard limit is O(1/k). ``pressure_scale`` β defaults to GA/(R_pin + r), the wrap's
    pressure scale (module docstring), so that the smoothing spans about the penetration.

    ``softer``: a :class:`PinPenalty` of the same arm and loads at a smaller k to start from
    (it must penetrate: the law's slope is zero at zero penetration, so a start on the pin's
    surface does not feel it). Without it the loads are raised from 1e-3 of their value by
    continuation (factor 2 per step, its square root after a failure). Each solve starts on
    a fresh mesh dense around the previous contact. ``tol`` is solve_bvp's, on the residual of
    each equation relative to 1 + |its right-hand side|: at the contact's edges, where the
    pressure fades, that is the absolute residual of n', whose round-off ~ 1e-16 |n|/h stalls
    the mesh refinement below about tol = 5e-7 for k ≥ 1e10 N/m² (on some machines already
    at 5e-7: their rounding differs; the solution's own error at tol = 1e-6 is ~2e-10 m,
    against tol = 7e-7 .. 2e-7). Raises RuntimeError if solve_bvp fails.
    """
    pr = _Scaled.of(L, EA, GA, EI, r, w, P, R_pin, x_p, z_p)
    beta = GA / (R_pin + r) if pressure_scale is None else float(pressure_scale)
    kt, bt = k * L**4 / EI, beta * L**3 / EI

    def solve(p, t, y, tol):
        return solve_bvp(_penalty_fun(p, kt, bt), _penalty_bc(p), t, y, tol=tol,
                         fun_jac=_penalty_jac(p, kt, bt), max_nodes=max_nodes)

    if softer is not None:
        t = _mesh_around_contact(softer.sol, pr)
        sol = solve(pr, t, softer.sol.sol(t), tol)
        if not sol.success:
            raise RuntimeError(f"pin_penalty (k = {k:.3g}): solve_bvp failed: {sol.message}")
        return PinPenalty(L, EI, k, beta, sol, pr)
    lo, hi = max(0.0, pr.centre[0] - 0.1), min(1.0, pr.centre[0] + 0.1)
    t = np.concatenate([np.linspace(0.0, lo, 101)[:-1], np.linspace(lo, hi, 801),
                        np.linspace(hi, 1.0, 101)[1:]])
    y = np.zeros((6, t.size))
    y[0] = t
    reached, lam, factor, sol = 0.0, 1e-3, 2.0, None
    while True:
        trial = solve(pr.scaled(lam), t, y, max(tol, 1e-6))
        if trial.success:
            sol, reached = trial, lam
            factor = min(2.0, factor**2)
            t = _mesh_around_contact(sol, pr)
            y = sol.sol(t)
            if lam == 1.0:
                break
        else:
            factor = math.sqrt(factor)
            if sol is None or factor < 1.01:
                raise RuntimeError(f"pin_penalty (k = {k:.3g}): solve_bvp failed at load "
                                   f"factor {lam:.4g}: {trial.message}")
        lam = min(1.0, reached * factor)
    if tol < 1e-6:
        sol = solve(pr, t, y, tol)
        if not sol.success:
            raise RuntimeError(f"pin_penalty (k = {k:.3g}): solve_bvp failed at tol {tol:.3g}: "
                               f"{sol.message}")
    return PinPenalty(L, EI, k, beta, sol, pr)


# ---------------------------------------------------------------------------------------------
# The hard-contact reference: three zones, the wrap's ends as unknown parameters


@dataclass(frozen=True)
class PinReference:
    """The converged hard-contact solution (SI units; moments about −y, see the module).

    ``sol`` is scipy's solution on τ ∈ [0, 1] of the 17 stacked zone states (nondimensional),
    ``wrap`` = (s_a, s_b) in m, ``nodes`` the mesh size of the last solve.
    """

    length: float
    EI: float
    problem: _Scaled
    sol: object
    wrap: tuple
    nodes: int

    # -- the states --------------------------------------------------------------------------
    def _zones(self, s):
        s = np.atleast_1d(np.asarray(s, dtype=np.float64)) / self.length
        a, b = np.asarray(self.wrap) / self.length
        if np.any((s < -1e-12) | (s > 1.0 + 1e-12)):
            raise ValueError(f"s must lie in [0, {self.length}] m, got {s * self.length}")
        return s, a, b

    def state(self, s) -> np.ndarray:
        """(6, N) = x, z (m), θ (rad), n_x, n_z (N), m (N m) at the stations s (m)."""
        s, a, b = self._zones(s)
        out = np.empty((6, s.size))
        first, on = s <= a, (s > a) & (s < b)
        last = ~(first | on)
        if first.any():
            out[:, first] = self.sol.sol(s[first] / a)[0:6]
        if on.any():
            y = self.sol.sol((s[on] - a) / (b - a))[6:11]
            out[0, on], out[1, on] = _on_circle(y[0], self.problem)
            out[2:, on] = y[1:]
        if last.any():
            out[:, last] = self.sol.sol((s[last] - b) / (1.0 - b))[11:17]
        L, EI = self.length, self.EI
        return out * np.array([L, L, 1.0, EI / L**2, EI / L**2, EI / L])[:, None]

    def positions(self, s) -> np.ndarray:
        """(N, 3) centreline positions (x, 0, z) in m."""
        y = self.state(s)
        return np.stack([y[0], np.zeros_like(y[0]), y[1]], axis=-1)

    def theta(self, s) -> np.ndarray:
        """(N,) the section's angle θ (rad) from +x towards +z."""
        return self.state(s)[2]

    def internal_force(self, s) -> np.ndarray:
        """(N, 3) spatial internal force (n_x, 0, n_z) in N that (s, L] exerts on [0, s]."""
        y = self.state(s)
        return np.stack([y[3], np.zeros_like(y[3]), y[4]], axis=-1)

    def internal_moment(self, s) -> np.ndarray:
        """(N,) internal moment m = EI θ' (N m, about −y)."""
        return self.state(s)[5]

    def tangent(self, s) -> np.ndarray:
        """(N, 2) the centreline's tangent (x', z') from the constitutive law (strain)."""
        _, _, th, nx, nz, _ = self.state(s)
        n1 = nx * np.cos(th) + nz * np.sin(th)
        n3 = -nx * np.sin(th) + nz * np.cos(th)
        a = 1.0 + n1 * self.problem.eps_a * self.length**2 / self.EI
        g = n3 * self.problem.eps_g * self.length**2 / self.EI
        return np.stack([np.cos(th) * a - np.sin(th) * g, np.sin(th) * a + np.cos(th) * g], -1)

    def gap(self, s) -> np.ndarray:
        """(N,) surface-to-pin gap (m): distance of the centreline from the pin axis − ρ."""
        y = self.state(s)
        cx, cz = np.asarray(self.problem.centre) * self.length
        return np.hypot(y[0] - cx, y[1] - cz) - self.problem.rho * self.length

    def normal(self, s) -> np.ndarray:
        """(N, 3) the pin's outward normal (cos φ, 0, sin φ) at the centreline's polar angle."""
        y = self.state(s)
        cx, cz = np.asarray(self.problem.centre) * self.length
        d = np.stack([y[0] - cx, np.zeros_like(y[0]), y[1] - cz], axis=-1)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def pressure(self, s) -> np.ndarray:
        """(N,) contact force per unit reference length (N/m) along the outward normal: equation
        (P) on the wrap, 0 off it."""
        s, a, b = self._zones(s)
        out = np.zeros(s.size)
        on = (s >= a) & (s <= b)
        if on.any():
            y = self.sol.sol((s[on] - a) / (b - a))[6:11]
            out[on] = _wrap_pressure(y, self.problem) * self.EI / self.length**3
        return out

    # -- resultants ----------------------------------------------------------------------------
    def _wrap_quadrature(self, points=64):
        """Gauss-Legendre stations (m) and weights on the wrap (the pressure is smooth there)."""
        x, wts = np.polynomial.legendre.leggauss(points)
        a, b = self.wrap
        return a + (b - a) * (x + 1.0) / 2.0, wts * (b - a) / 2.0

    @property
    def contact_force(self) -> np.ndarray:
        """(3,) the pin's total force on the arm (N, spatial), ∫ c ν ds over the wrap."""
        s, wts = self._wrap_quadrature()
        return np.sum((wts * self.pressure(s))[:, None] * self.normal(s), axis=0)

    @property
    def contact_moment(self) -> float:
        """The pin's total moment on the arm about the origin, ∫ (x c_z − z c_x) ds (N m, −y)."""
        s, wts = self._wrap_quadrature()
        c = self.pressure(s)[:, None] * self.normal(s)
        p = self.positions(s)
        return float(np.sum(wts * (p[:, 0] * c[:, 2] - p[:, 2] * c[:, 0])))

    @property
    def tip(self) -> np.ndarray:
        """(3,) the tip's position (x, 0, z) in m."""
        return self.positions(self.length)[0]


def _stacked_fun(pr):
    def fun(t, y, p):
        a, b = p
        return np.vstack([a * _free(y[0:6], pr), (b - a) * _wrap(y[6:11], pr),
                          (1.0 - b) * _free(y[11:17], pr)])

    return fun


def _stacked_bc(pr):
    def bc(ya, yb, p):
        end1, wrap_a, wrap_b, start3 = yb[0:6], ya[6:11], yb[6:11], ya[11:17]
        xa, za = _on_circle(wrap_a[0], pr)
        xb, zb = _on_circle(wrap_b[0], pr)
        return np.concatenate([
            ya[0:3],  # the clamp
            [yb[14] - pr.tip[0], yb[15] - pr.tip[1], yb[16]],  # the tip
            [end1[0] - xa, end1[1] - za], end1[2:6] - wrap_a[1:5],  # s_a: continuity
            [_constraint(wrap_a, pr)],  # s_a: on the circle's tangent
            [start3[0] - xb, start3[1] - zb], start3[2:6] - wrap_b[1:5],  # s_b: continuity
        ])

    return bc


def _guess_from(penalty, GA, nodes=201):
    """Zones, states and parameters (nondimensional) for the hard solve from a penalty solution:
    the wrap centred on the penalty's pressure centroid, its length ρ F/GA (the short-wrap
    estimate of the module docstring) but no longer than the penalty's contact."""
    pr, L = penalty.problem, penalty.length
    s = penalty.sol.x * L
    c = penalty.pressure(s)
    if not np.any(c > 0.0):
        raise ValueError("the loaded arm does not touch the pin (no contact in the penalty "
                         "solution): nothing for the hard-contact reference to solve")
    force = np.trapezoid(c, s)
    centre = np.trapezoid(c * s, s) / force
    touching = s[c > 1e-6 * c.max()]
    length = min(pr.rho * L * force / GA, touching[-1] - touching[0])
    a, b = (centre - length / 2.0) / L, (centre + length / 2.0) / L
    tau = np.linspace(0.0, 1.0, nodes)
    scale = np.array([L, L, 1.0, penalty.EI / L**2, penalty.EI / L**2, penalty.EI / L])[:, None]
    y1 = penalty.state(tau * a * L) / scale
    y2 = penalty.state((a + (b - a) * tau) * L) / scale
    y3 = penalty.state((b + (1.0 - b) * tau) * L) / scale
    phi = np.unwrap(np.arctan2(y2[1] - pr.centre[1], y2[0] - pr.centre[0]))
    return tau, np.vstack([y1, phi, y2[2:], y3]), np.array([a, b])


def pin_reference(L, EA, GA, EI, r, w, P, R_pin, x_p, z_p, *, tol=1e-8,
                  max_nodes=200_000) -> PinReference:
    """The hard-contact equilibrium of the arm pressed onto the pin (module docstring).

    Parameters
    ----------
    L : arm length (m); EA, GA : axial and shear stiffness (N); EI : bending stiffness (N m²);
    r : the arm's radius (m); w : its weight per length (N/m, along −z);
    P : the dead tip force (N, along −z); R_pin : the pin's radius (m);
    x_p, z_p : the pin axis (m), below the arm: z_p ≤ −(R_pin + r) lets the straight arm clear
    it; tol : scipy solve_bvp's tolerance (relative collocation residual) of the hard solve.

    The starting guess is a penalty solution (:func:`pin_penalty`, penetration scale 1e-4 L,
    then ten times stiffer). Raises ValueError if the arm does not touch the pin, RuntimeError
    if solve_bvp fails.
    """
    pr = _Scaled.of(L, EA, GA, EI, r, w, P, R_pin, x_p, z_p)
    beta = GA / (R_pin + r)
    penalty = pin_penalty(L, EA, GA, EI, r, w, P, R_pin, x_p, z_p, beta / (1e-4 * L),
                          tol=1e-6)
    penalty = pin_penalty(L, EA, GA, EI, r, w, P, R_pin, x_p, z_p, beta / (1e-5 * L),
                          tol=1e-6, softer=penalty)
    tau, y, p = _guess_from(penalty, GA)
    sol = solve_bvp(_stacked_fun(pr), _stacked_bc(pr), tau, y, p, tol=tol,
                    max_nodes=max_nodes)
    if not sol.success:
        raise RuntimeError(f"pin_reference: solve_bvp failed: {sol.message} "
                           f"(max residual {np.max(sol.rms_residuals):.3g})")
    a, b = sol.p
    if not 0.0 < a < b < 1.0:
        raise RuntimeError(f"pin_reference: the wrap came out as [{a * L}, {b * L}] m")
    return PinReference(L, EI, pr, sol, (a * L, b * L), sol.x.size)
