"""Closed-form and transcendental natural frequencies of a uniform cantilever (clamped-free).

Written from the equations alone as an independent reference for softarm's rod dynamics; it
imports nothing from softarm. SI units; ω in rad/s.

Bending (Timoshenko beam: shear factor k, rotary inertia ρI). With ξ = x/L, the deflection
w = L W(ξ), the section rotation ψ(ξ), time-harmonic at ω, the beam equations
kGA (w'' − ψ') + ρA ω² w = 0 and EI ψ'' + kGA (w' − ψ) + ρI ω² ψ = 0 read::

    W'' − ψ' + b² s² W = 0,        s² ψ'' + W' − ψ + b² r² s² ψ = 0,
    b² = ρA ω² L⁴ / EI  (ω = b √(EI/ρA L⁴)),   r² = I / (A L²),   s² = EI / (kGA L²),

clamped at ξ = 0 (W = ψ = 0) and free at ξ = 1 (moment ψ' = 0, shear force W' − ψ = 0).
Below the second-spectrum cut-off b r s < 1 the general solution is (Huang 1961; the same
form in Han, Benaroya & Wei 1999, section 6)::

    W = C₁ cosh(bαξ) + C₂ sinh(bαξ) + C₃ cos(bβξ) + C₄ sin(bβξ),
    α, β = (1/√2) [ ∓(r² + s²) + √((r² − s²)² + 4/b²) ]^½,

with ψ following from the first equation (ψ' = W'' + b² s² W, no constant). The four end
conditions give a 4×4 homogeneous system whose determinant is the classical frequency
equation; :func:`cantilever_bending` brackets its sign changes on a grid in b and polishes
them with ``brentq``. Sources: T. C. Huang, "The effect of rotatory inertia and of shear
deformation on the frequency and normal mode equations of uniform beams with simple end
conditions", J. Appl. Mech. 28 (1961) 579-584; S. M. Han, H. Benaroya, T. Wei, "Dynamics of
transversely vibrating beams using four engineering theories", J. Sound Vib. 225 (1999)
935-988. As r, s → 0: cosh(bL)cos(bL) = −1, b = 1.8751², 4.6941² (Euler-Bernoulli).

Two independent checks live here too: :func:`cantilever_bending_transfer` (the same
boundary-value problem through the matrix exponential of the first-order system, no
closed-form solution used) and :func:`cantilever_bending_fem` (linear Timoshenko finite
elements with one-point shear integration, consistent mass, ``scipy.linalg.eigh``).

Torsion and axial (clamped-free rods, quarter-wave): ω = (π / 2L) √(GJ / ρJ) and
ω = (π / 2L) √(EA / ρA).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import eigh, expm
from scipy.optimize import brentq

__all__ = [
    "cantilever_axial",
    "cantilever_bending",
    "cantilever_bending_fem",
    "cantilever_bending_transfer",
    "cantilever_torsion",
]


def _params(length, EI, kGA, rhoA, rhoI):
    for name, value in (("length", length), ("EI", EI), ("kGA", kGA), ("rhoA", rhoA),
                        ("rhoI", rhoI)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive finite number, got {value!r}")
    r2 = rhoI / (rhoA * length**2)  # I / (A L²)
    s2 = EI / (kGA * length**2)
    scale = math.sqrt(EI / (rhoA * length**4))  # ω = b² scale
    return r2, s2, scale


def _huang_determinant(b, r2, s2):
    """The clamped-free frequency determinant, rows scaled to stay O(1) for large bα."""
    root = math.sqrt((r2 - s2) ** 2 + 4.0 / b**2)
    alpha = math.sqrt(0.5 * (-(r2 + s2) + root))
    beta = math.sqrt(0.5 * ((r2 + s2) + root))
    ba, bb = b * alpha, b * beta
    # ψ = p (C₁ sinh + C₂ cosh) + q (−C₃ sin + C₄ cos)
    p = b * (alpha**2 + s2) / alpha
    q = b * (beta**2 - s2) / beta
    ch, sh, c, s = math.cosh(ba), math.sinh(ba), math.cos(bb), math.sin(bb)
    e = math.exp(-ba)  # scale the hyperbolic columns
    rows = np.array([
        [1.0 * e, 0.0, 1.0, 0.0],  # W(0) = 0
        [0.0, p * e, 0.0, q],  # ψ(0) = 0
        [p * ba * ch * e, p * ba * sh * e, -q * bb * c, -q * bb * s],  # ψ'(1) = 0
        [ba * sh * e - p * sh * e, ba * ch * e - p * ch * e,  # W'(1) − ψ(1) = 0
         -bb * s + q * s, bb * c - q * c],
    ])
    return np.linalg.det(rows)


def _roots(func, upper, count, points=200):
    grid = np.linspace(upper * 1e-3, upper, points)
    values = np.array([func(b) for b in grid])
    roots = []
    for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:], strict=True):
        if fa == 0.0 or fa * fb < 0.0:
            roots.append(brentq(func, a, b, xtol=1e-14, rtol=1e-15))
            if len(roots) == count:
                return np.array(roots)
    raise ValueError(f"found only {len(roots)} of {count} roots below b = {upper}")


def cantilever_bending(length, EI, kGA, rhoA, rhoI, count=2):
    """The lowest ``count`` bending natural frequencies ω (rad/s) of a Timoshenko cantilever.

    Roots of Huang's clamped-free frequency equation (module docstring). Raises ValueError if
    a requested mode lies above the second-spectrum cut-off ω² = kGA/ρI (not handled here).
    """
    r2, s2, scale = _params(length, EI, kGA, rhoA, rhoI)
    cutoff_b = (r2 * s2) ** -0.5  # b r s = 1
    # Euler-Bernoulli b_n ≈ ((n − ½) π)² bounds the Timoshenko roots from above
    upper = min(((count + 0.5) * math.pi) ** 2, cutoff_b * (1 - 1e-9))
    b = _roots(lambda x: _huang_determinant(x, r2, s2), upper, count)
    return b * scale


def cantilever_bending_transfer(length, EI, kGA, rhoA, rhoI, count=2):
    """The same frequencies from the first-order system y' = A(b) y, y = (W, W', ψ, ψ').

    Clamped start y(0) = (0, W'(0), 0, ψ'(0)); the frequency condition is that the 2×2 map
    from (W'(0), ψ'(0)) to the free-end residuals (ψ'(1), W'(1) − ψ(1)), taken from
    ``expm(A)``, is singular. Valid above the cut-off too.
    """
    r2, s2, scale = _params(length, EI, kGA, rhoA, rhoI)

    def det(b):
        a = np.array([
            [0.0, 1.0, 0.0, 0.0],
            [-(b**2) * s2, 0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, -1.0 / s2, (1.0 - b**2 * r2 * s2) / s2, 0.0],
        ])
        phi = expm(a)[:, [1, 3]]  # responses to W'(0) and ψ'(0)
        return np.linalg.det(np.array([phi[3], phi[1] - phi[2]]))

    upper = ((count + 0.5) * math.pi) ** 2
    return _roots(det, upper, count) * scale


def cantilever_bending_fem(length, EI, kGA, rhoA, rhoI, n_elements=400, count=2):
    """Lowest bending frequencies from linear Timoshenko elements (one-point shear
    integration against locking, consistent mass), dense ``scipy.linalg.eigh``.

    Converges as O(h²) to :func:`cantilever_bending`; a second, discrete route.
    """
    h = length / n_elements
    ndof = 2 * (n_elements + 1)  # (w_i, ψ_i) per node
    k_glob, m_glob = np.zeros((ndof, ndof)), np.zeros((ndof, ndof))
    # bending: EI/h [[1, -1], [-1, 1]] on ψ; shear (at the midpoint): γ = (w₂−w₁)/h − (ψ₁+ψ₂)/2
    g = np.array([-1.0 / h, -0.5, 1.0 / h, -0.5])
    k_el = kGA * h * np.outer(g, g)
    k_el[np.ix_([1, 3], [1, 3])] += EI / h * np.array([[1.0, -1.0], [-1.0, 1.0]])
    consistent = h / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])
    m_el = np.zeros((4, 4))
    m_el[np.ix_([0, 2], [0, 2])] = rhoA * consistent
    m_el[np.ix_([1, 3], [1, 3])] = rhoI * consistent
    for e in range(n_elements):
        idx = np.arange(2 * e, 2 * e + 4)
        k_glob[np.ix_(idx, idx)] += k_el
        m_glob[np.ix_(idx, idx)] += m_el
    free = slice(2, ndof)  # clamp node 0: w = ψ = 0
    vals = eigh(k_glob[free, free], m_glob[free, free], eigvals_only=True,
                subset_by_index=[0, count - 1])
    return np.sqrt(vals)


def cantilever_torsion(length, GJ, rhoJ):
    """First torsional frequency ω = (π / 2L) √(GJ / ρJ) (rad/s) of a clamped-free rod."""
    return math.pi / (2 * length) * math.sqrt(GJ / rhoJ)


def cantilever_axial(length, EA, rhoA):
    """First axial frequency ω = (π / 2L) √(EA / ρA) (rad/s) of a clamped-free rod."""
    return math.pi / (2 * length) * math.sqrt(EA / rhoA)
