"""Hard-contact reference: a heavy arm clamped horizontally above a frictionless table.

Written for tests/test_table_reference.py from the equations alone; it imports nothing from
softarm. Same planar model and conventions as tests/_planar_elastica.py: the x-z plane, clamp at
the origin with the axis along +x, θ the section's angle from +x towards +z, spatial components,
SI units::

    x' = cos θ (1 + n₁/EA) − sin θ n₃/GA,    n₁ =  n_x cos θ + n_z sin θ   (material, axial)
    z' = sin θ (1 + n₁/EA) + cos θ n₃/GA,    n₃ = −n_x sin θ + n_z cos θ   (material, shear)
    θ' = m/EI,   m' = −(x' n_z − z' n_x),   n_x' = −q_x − c_x,   n_z' = −q_z − c_z,

x(0) = z(0) = θ(0) = 0, n(L) = 0, m(L) = 0 (no tip force). The only load is the weight,
q = (0, −w) N/m. The table is the plane z = −h (outward normal +z); the arm's surface (radius r)
touches it when the centreline is at z = −h + r = −d, so the gap is z + d (d = h − r, the drop).
The contact force per reference length c = (0, c_z), c_z ≥ 0, c_z (z + d) = 0; a concentrated
force may act only at the free end (see below).

Derivation
----------
*n_x ≡ 0.* Frictionless flat table: c_x = 0; with q_x = 0 and no tip force, n_x' = 0 and
n_x(L) = 0, so n_x = 0 on the whole arm. Then n₁ = n_z sin θ, n₃ = n_z cos θ and::

    z' = sin θ + n_z D(θ),   D(θ) = sin²θ/EA + cos²θ/GA,
    x' = cos θ + n_z sin θ cos θ (1/EA − 1/GA),   m' = −x' n_z.

*The constrained zone.* Where the centreline lies on the table, z = −d and z' = 0, which fixes
the shear force by the section angle::

    n_z = N(θ) = −sin θ / D(θ),   hence  x' = cos θ / (GA D),   m' = sin θ cos θ / (GA D²),

so the zone is the autonomous second-order system EI θ'' = sin θ cos θ / (GA D²) and the
pressure is the constraint's multiplier, read off the force balance::

    c_z = w − n_z' = w − N'(θ) m/EI,   N'(θ) = −cos θ [(1 + sin²θ)/GA − sin²θ/EA] / D².

Linearised, EI θ'' = GA θ: a saddle with rates ±1/ℓ, ℓ = √(EI/GA). Its first integral
(d/dθ of sin²θ/(2D) is sin θ cos θ/(GA D²)) is m²/(2 EI) = sin²θ/(2D) + const.

*The zone is semi-infinite (it never ends on the arm).* The unloaded flat state θ = m = n_z = 0
(pressure = w) is the saddle's equilibrium: a zone reaching it at a finite s would need
θ = m = 0 there, and the zone's initial-value problem then gives θ ≡ 0. Nor can an interior
point reaction end it: on the table n_z = N(θ) is continuous with θ. So the constraint holds
from the lift-off point s_c to the tip, and the section angle decays like e^{−(s − s_c)/ℓ}
(the stable manifold, const = 0: m = −√(EI/D) sin θ = √(EI D) n_z, i.e. the lift-off moment is
the lift-off shear force times ≈ ℓ). At the tip m(L) = 0 calls for the growing mode with a
weight e^{−(L − s_c)/ℓ} (≈ e^{−29} for the default arm), and n_z(L) = N(θ(L)) is then a
concentrated reaction at the free end, upward (θ(L) has the sign of θ(s_c) < 0) and of order
GA |θ(s_c)| e^{−(L − s_c)/ℓ}: admissible and negligible. This module solves the zone on its
exact finite interval [s_c, L] with m(L) = 0 and reports that end reaction; the first integral
above is checked by the tests, not used.

*Lift-off.* No concentrated force acts at s_c, so θ, m and n_z are continuous there: the
section's curvature θ' = m/EI is continuous (C¹ θ, and θ'' too since m' = −x' n_z is), but the
pressure jumps from 0 to c_z(s_c⁺) > 0, so n_z' jumps and so does the centreline's curvature,
z''(s_c⁻) = D(θ_c) c_z(s_c⁺) against 0 on the table. Conditions at s_c, with s_c unknown::

    z(s_c) = −d,   n_z(s_c) = N(θ(s_c))   (z' = 0: the arm arrives tangent to the table),
    θ, m, x continuous into the zone.

*The free arc* [0, s_c] has c = 0. Counting: the arc (x, z, θ, n_z, m) and the zone (x, θ, m)
give 8 unknown functions plus s_c; the clamp gives 3 conditions, s_c gives 5, the tip m(L) = 0
one: 9. Both segments are mapped to t ∈ [0, 1] and solved together by scipy's solve_bvp,
nondimensionally (s/L, p/L, n L²/EI, m L/EI), from the small-deflection (Euler–Bernoulli)
solution with a point reaction at lift-off, s_c = (72 EI d / w)^{1/4}.

*Point-reaction model* (:func:`point_reaction_reference`, a sanity comparison only): the same
rod with the unshearable-style lift-off θ(s_c) = 0, m(s_c) = 0, z(s_c) = −d and a concentrated
reaction R = n_z(s_c⁻) there, the rest flat and unstressed. Its centreline arrives with slope
z' = R/GA > 0, i.e. from below the table: it penetrates by ≈ R ℓ/GA.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad, solve_bvp

__all__ = ["TableSolution", "point_reaction_reference", "table_reference"]


def _D(th, eps_a, eps_g):
    """D̃ = sin²θ ε_a + cos²θ ε_g = D EI/L², ε_a = EI/(EA L²), ε_g = EI/(GA L²)."""
    return np.sin(th) ** 2 * eps_a + np.cos(th) ** 2 * eps_g


def _slopes(th, nz, eps_a, eps_g):
    """(x', z') of the centreline for n_x = 0 (nondimensional)."""
    c, s = np.cos(th), np.sin(th)
    n1, n3 = nz * s, nz * c
    return c * (1.0 + eps_a * n1) - s * eps_g * n3, s * (1.0 + eps_a * n1) + c * eps_g * n3


def _zone_shear(th, eps_a, eps_g):
    """N(θ) = −sin θ / D̃: the shear force that keeps the centreline flat (nondimensional)."""
    return -np.sin(th) / _D(th, eps_a, eps_g)


def _zone_shear_slope(th, eps_a, eps_g):
    """N'(θ) = −cos θ [(1 + sin²θ) ε_g − sin²θ ε_a] / D̃² (nondimensional)."""
    s2 = np.sin(th) ** 2
    return -np.cos(th) * ((1.0 + s2) * eps_g - s2 * eps_a) / _D(th, eps_a, eps_g) ** 2


@dataclass(frozen=True)
class TableSolution:
    """The hard-contact solution: lift-off at ``s_c``, the table under [s_c, L].

    Forces are spatial (N), moments the planar m of the module docstring (N m, positive
    turning +x towards +z), the pressure per reference length (N/m).
    """

    length: float  # m
    EA: float  # N
    GA: float  # N
    EI: float  # N m²
    radius: float  # m
    weight: float  # w, N/m
    drop: float  # d = h − r, m: the centreline's height above the table is z + d
    s_c: float  # lift-off arc length, m
    tip_reaction: float  # concentrated upward force at the free end, N (≈ 0, see docstring)
    sol: object  # scipy's solution of both segments (nondimensional)

    @property
    def table_height(self) -> float:
        """h: the table is the plane z = −h (m)."""
        return self.drop + self.radius

    @property
    def zone(self) -> tuple[float, float]:
        """[s_a, s_b] (m) on which the centreline lies on the table: [s_c, L]."""
        return (self.s_c, self.length)

    @property
    def boundary_layer(self) -> float:
        """ℓ = √(EI/GA) (m): the decay length of the section angle and of the extra pressure."""
        return float(np.sqrt(self.EI / self.GA))

    @property
    def _eps(self):
        L2 = self.length**2
        return self.EI / (self.EA * L2), self.EI / (self.GA * L2)

    def state(self, s) -> np.ndarray:
        """(6, N): x, z, θ, n_x, n_z, m (m, m, rad, N, N, N m) at stations s (m)."""
        L, EI = self.length, self.EI
        s = np.atleast_1d(np.asarray(s, dtype=np.float64)) / L
        sig = self.s_c / L
        air = s <= sig
        y = np.empty((6, s.size))
        ya = self.sol.sol(np.clip(s / sig, 0.0, 1.0))
        yz = self.sol.sol(np.clip((s - sig) / (1.0 - sig), 0.0, 1.0))
        eps_a, eps_g = self._eps
        y[0] = np.where(air, ya[0], yz[5])
        y[1] = np.where(air, ya[1], 0.0)
        y[2] = np.where(air, ya[2], yz[6])
        y[3] = 0.0
        y[4] = np.where(air, ya[3], _zone_shear(yz[6], eps_a, eps_g))
        y[5] = np.where(air, ya[4], yz[7])
        y *= np.array([L, L, 1.0, EI / L**2, EI / L**2, EI / L])[:, None]
        y[1] = np.where(air, y[1], -self.drop)  # on the table exactly
        return y

    def positions(self, s) -> np.ndarray:
        """(N, 3) centreline positions (x, 0, z) in m."""
        y = self.state(s)
        return np.stack([y[0], np.zeros_like(y[0]), y[1]], axis=-1)

    def theta(self, s) -> np.ndarray:
        """(N,) section angles θ (rad)."""
        return self.state(s)[2]

    def forces(self, s) -> np.ndarray:
        """(N, 3) internal force and moment (n_x, n_z, m) in N, N, N m."""
        return self.state(s)[3:].T

    def pressure(self, s) -> np.ndarray:
        """(N,) contact force per reference length c_z (N/m) from the zone's θ and m:
        c_z = w − N'(θ) m/EI on [s_c, L], 0 in the air (the tip reaction not included)."""
        y = self.state(s)
        eps_a, eps_g = self._eps
        # dimensional N'(θ) = (EI/L²) Ñ'(θ), θ' = m/EI
        c = self.weight - _zone_shear_slope(y[2], eps_a, eps_g) * y[5] / self.length**2
        s = np.atleast_1d(np.asarray(s, dtype=np.float64))
        return np.where(s < self.s_c, 0.0, c)

    def _integrals(self):
        """(∫ c_z ds, ∫ x c_z ds) over the zone by adaptive quadrature, split at s_c + kℓ."""
        ell = self.boundary_layer
        cuts = [self.s_c + k * ell for k in (0, 1, 3, 10, 30) if self.s_c + k * ell < self.length]
        cuts.append(self.length)
        force = moment = 0.0
        for a, b in itertools.pairwise(cuts):
            force += quad(lambda s: self.pressure(s)[0], a, b, epsabs=0.0, epsrel=1e-12,
                          limit=200)[0]
            moment += quad(lambda s: self.state(s)[0, 0] * self.pressure(s)[0], a, b,
                           epsabs=0.0, epsrel=1e-12, limit=200)[0]
        return force, moment

    @property
    def contact_force(self) -> np.ndarray:
        """(2,) total contact force on the arm (F_x, F_z) in N, tip reaction included."""
        return np.array([0.0, self._integrals()[0] + self.tip_reaction])

    @property
    def contact_moment(self) -> float:
        """Moment of the contact forces about the origin (N m, planar sign of m: x f_z − z f_x)."""
        x_tip = self.state(self.length)[0, 0]
        return self._integrals()[1] + x_tip * self.tip_reaction


def _check(name, value, positive=True):
    value = float(value)
    if not (np.isfinite(value) and (value > 0 or not positive)):
        raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    return value


def table_reference(L, EA, GA, EI, r, w, d, *, tol=1e-8, max_nodes=200_000) -> TableSolution:
    """Hard contact of a clamped heavy arm with the table z = −(d + r) (module docstring).

    Parameters: length L (m), rigidities EA, GA (N), EI (N m²), radius r (m), weight per
    length w (N/m), drop d = h − r (m) of the centreline from the clamp to its height on the
    table; ``tol`` is solve_bvp's (relative collocation residual).

    Raises ValueError if the solution's structure is not admissible (s_c not in (0, L), the
    free arc through the table, or a pull at the end: the arm touches with its tip only or
    not at all) and RuntimeError if solve_bvp fails.
    """
    L, EA, GA, EI, r, w, d = (_check(n, v) for n, v in zip(
        ("L", "EA", "GA", "EI", "r", "w", "d"), (L, EA, GA, EI, r, w, d), strict=True))
    eps_a, eps_g = EI / (EA * L**2), EI / (GA * L**2)
    qt = w * L**3 / EI  # n_z' = w on the free arc
    dt = d / L

    def fun(t, y, p):
        sig = p[0]
        _, _, tha, nza, ma, _, thz, mz = y
        dxa, dza = _slopes(tha, nza, eps_a, eps_g)
        nzz = _zone_shear(thz, eps_a, eps_g)
        dxz, _ = _slopes(thz, nzz, eps_a, eps_g)  # z' = 0 by construction
        return np.vstack([sig * dxa, sig * dza, sig * ma, sig * np.full_like(t, qt),
                          -sig * dxa * nza, (1 - sig) * dxz, (1 - sig) * mz,
                          -(1 - sig) * dxz * nzz])

    def bc(ya, yb, p):
        return np.array([ya[0], ya[1], ya[2],
                         yb[1] + dt, yb[3] - _zone_shear(yb[2], eps_a, eps_g),
                         ya[5] - yb[0], ya[6] - yb[2], ya[7] - yb[4],
                         yb[7]])

    t = np.linspace(0.0, 1.0, 81)
    sig, air = _small_deflection_start(qt, dt, t)
    y = np.vstack([air, sig + (1 - sig) * t, 0 * t, 0 * t])
    sol = solve_bvp(fun, bc, t, y, p=[sig], tol=tol, max_nodes=max_nodes)
    if not sol.success:
        raise RuntimeError(f"solve_bvp failed: {sol.message}")
    s_c = float(sol.p[0]) * L
    tip_reaction = float(_zone_shear(sol.sol(1.0)[6], eps_a, eps_g)) * EI / L**2
    # The assumed structure must be admissible: s_c on the arm, the free arc above the table
    # (checked at the mesh nodes), no pull at the end (the pressure on the table exceeds w on
    # the stable manifold; the tests check it).
    gap = float(np.min(sol.y[1, :-1] + dt)) if 0.0 < s_c < L else -1.0
    if not (gap > 0.0 and tip_reaction >= 0.0):
        raise ValueError(f"d must let the arm's far part lie flat on the table, got d = {d!r} m "
                         f"(lift-off at s_c = {s_c!r} m for L = {L!r} m, tip reaction "
                         f"{tip_reaction!r} N): a larger d touches with the tip only or not at all")
    return TableSolution(L, EA, GA, EI, r, w, d, s_c, tip_reaction, sol)


def _small_deflection_start(qt, dt, t):
    """Euler–Bernoulli start for the free arc: EI z⁗ = −w on [0, σ], z = z' = 0 at the clamp,
    z(σ) = −d, z'(σ) = z''(σ) = 0 (a point reaction at lift-off), so that d = w σ⁴/(72 EI).

    Nondimensional load qt = w L³/EI and drop dt = d/L; returns σ = s_c/L (at most 0.9) and
    the (5, t.size) rows x, z, θ, n_z, m at s/L = σ t.
    """
    sig = min((72.0 * dt / qt) ** 0.25, 0.9)
    s = sig * t
    z = -qt * s**4 / 24 + qt * sig * s**3 / 9 - qt * sig**2 * s**2 / 12
    th = -qt * s**3 / 6 + qt * sig * s**2 / 3 - qt * sig**2 * s / 6
    m = -qt * s**2 / 2 + 2 * qt * sig * s / 3 - qt * sig**2 / 6
    nz = qt * s - 2 * qt * sig / 3
    return sig, np.vstack([s, z, th, nz, m])


def point_reaction_reference(L, EA, GA, EI, r, w, d, *, tol=1e-8):
    """The point-reaction (unshearable-style) lift-off, for comparison only (module docstring).

    Returns (s_c, R, positions) with R the reaction at s_c (N) and positions(s) -> (N, 3).
    """
    eps_a, eps_g = EI / (EA * L**2), EI / (GA * L**2)
    qt = w * L**3 / EI
    dt = d / L

    def fun(t, y, p):
        sig = p[0]
        _, _, th, nz, m = y
        dx, dz = _slopes(th, nz, eps_a, eps_g)
        return np.vstack([sig * dx, sig * dz, sig * m, sig * np.full_like(t, qt), -sig * dx * nz])

    def bc(ya, yb, p):
        return np.array([ya[0], ya[1], ya[2], yb[1] + dt, yb[2], yb[4]])

    t = np.linspace(0.0, 1.0, 81)
    sig, y = _small_deflection_start(qt, dt, t)
    sol = solve_bvp(fun, bc, t, y, p=[sig], tol=tol, max_nodes=100_000)
    if not sol.success:
        raise RuntimeError(f"solve_bvp failed: {sol.message}")
    sig = float(sol.p[0])
    R = float(sol.sol(1.0)[3]) * EI / L**2

    def positions(s):
        s = np.atleast_1d(np.asarray(s, dtype=np.float64)) / L
        y = sol.sol(np.clip(s / sig, 0.0, 1.0))
        x = np.where(s <= sig, y[0], sol.sol(1.0)[0] + (s - sig)) * L
        z = np.where(s <= sig, y[1], -dt) * L
        return np.stack([x, np.zeros_like(x), z], axis=-1)

    return sig * L, R, positions
