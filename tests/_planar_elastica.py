"""Independent references for stiff planar rods: scipy ``solve_bvp`` and two closed forms.

Written for tests/test_stiff_hanging.py, tests/test_stiff_tension.py and benchmarks/stiff.py
from the equations alone; it imports nothing from softarm (benchmarks/stiff.py puts tests/ on
``sys.path`` to import it, the tests find it through pytest's ``pythonpath``).

The planar Cosserat rod in the x-z plane, clamped at the origin with its axis along +x
(θ the tangent angle from +x towards +z, dead loads, SI units, spatial components)::

    x' = cos θ (1 + n₁/EA) − sin θ n₃/GA,     n₁ =  n_x cos θ + n_z sin θ   (material, axial)
    z' = sin θ (1 + n₁/EA) + cos θ n₃/GA,     n₃ = −n_x sin θ + n_z cos θ   (material, shear)
    θ' = m/EI,   m' = −(x' n_z − z' n_x),   n_x' = −q_x,   n_z' = −q_z,

x(0) = z(0) = θ(0) = 0, n(L) = tip force, m(L) = 0: the constitutive law of softarm's model,
v = e₁ + (n₁/EA, 0, n₃/GA), κ = m/EI, restricted to the plane.

:func:`solve_planar` solves it nondimensionally (s/L, p/L, n L²/EI, m L/EI) with load
continuation from a straight arm at a small load, λ growing geometrically, each step starting
from the previous solution and its mesh; the clamp's boundary layer (width ~ √(EI/F)) is left
to solve_bvp's mesh refinement, started from a mesh graded towards the clamp.

Two closed forms for a tip force alone (where EA = GA they are exact for the extensible,
shearable rod: then v = e₁ + Rᵀn/C gives p' = R e₁ + n/C, so n/C only adds n s/C to p and
leaves the moment balance, m' = −(R e₁) × n, that of the inextensible elastica):

* :func:`linear_tension_deflection`: tip force (F, P), P ≪ F: the lateral tip deflection
  w = (P/F)(L − tanh(kL)/k) + P L/GA, k = √(F/EI), with error O((P/F)³ L);
* :func:`separatrix_tip`: a tip force of magnitude T at angle ψ to the clamp's axis, kL ≫ 1:
  the tip position up to terms of order e^{−kL}/k (derivation in its docstring).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_bvp

__all__ = ["PlanarSolution", "linear_tension_deflection", "separatrix_tip", "solve_planar"]


@dataclass(frozen=True)
class PlanarSolution:
    """A converged reference: ``state(s)`` (6, N) = x, z, θ, n_x, n_z, m (m, rad, N, N m)."""

    length: float
    EI: float
    sol: object  # scipy's solution (nondimensional)
    steps: int  # continuation steps taken
    nodes: int  # mesh nodes of the last solve

    def state(self, s) -> np.ndarray:
        y = self.sol.sol(np.asarray(s, dtype=np.float64) / self.length)
        scale = np.array([self.length, self.length, 1.0, self.EI / self.length**2,
                          self.EI / self.length**2, self.EI / self.length])
        return y * scale[:, None] if y.ndim == 2 else y * scale

    def positions(self, s) -> np.ndarray:
        """(N, 3) centreline positions (x, 0, z) in m at the stations s."""
        y = self.state(np.atleast_1d(s))
        return np.stack([y[0], np.zeros_like(y[0]), y[1]], axis=-1)

    @property
    def tip(self) -> np.ndarray:
        return self.positions(self.length)[0]

    @property
    def tip_angle(self) -> float:
        return float(self.state(np.array([self.length]))[2, 0])


def _rhs(q, eps_a, eps_g):
    """The nondimensional right-hand side for loads q (q̃_x, q̃_z) = q L³/EI and compliances
    ε = EI/(EA L²), EI/(GA L²)."""

    def fun(t, y):
        _, _, th, nx, nz, m = y
        c, s = np.cos(th), np.sin(th)
        n1 = nx * c + nz * s
        n3 = -nx * s + nz * c
        stretch = 1.0 + eps_a * n1
        dx = c * stretch - s * eps_g * n3
        dz = s * stretch + c * eps_g * n3
        dm = -(dx * nz - dz * nx)
        return np.vstack([dx, dz, m, np.full_like(th, -q[0]), np.full_like(th, -q[1]), dm])

    return fun


def _bc(tip):
    def bc(ya, yb):
        return np.array([ya[0], ya[1], ya[2], yb[3] - tip[0], yb[4] - tip[1], yb[5]])

    return bc


def solve_planar(length, EI, EA, GA, *, distributed=(0.0, 0.0), tip=(0.0, 0.0), tol=1e-8,
                 path_tol=1e-6, start=1.0, growth=4.0, max_turn=0.5, max_nodes=400_000,
                 previous=None) -> PlanarSolution:
    """The planar rod under a dead distributed force (q_x, q_z) N/m and tip force (F_x, F_z) N.

    ``tol`` is solve_bvp's: on the relative collocation residual, which converges more
    slowly with the mesh than the solution does (the tip's error is far below it; estimate
    it by a second solve at a tighter ``tol`` from ``previous``).

    Continuation: the loads are scaled by λ from the λ whose largest nondimensional load
    (q L³/EI or F L²/EI) is ``start`` (λ = 1 if that is already small), λ multiplied by
    ``growth`` per step, each step started from the previous solution and its mesh, solved
    to ``path_tol``; the full load is then solved again to ``tol``. A step that fails or
    turns a section by more than ``max_turn`` rad (a jump to another branch: a hard pull
    at 150° can otherwise wind the arm the wrong way round) is retried with the square root
    of the factor, which is squared back after a success. ``previous`` (a PlanarSolution of
    the same arm and loads) skips the continuation.

    Raises RuntimeError if a step fails with the growth factor below 1.01.
    """
    L, EI = float(length), float(EI)
    q = np.asarray(distributed, dtype=np.float64) * L**3 / EI
    f = np.asarray(tip, dtype=np.float64) * L**2 / EI
    eps_a, eps_g = EI / (EA * L**2), EI / (GA * L**2)
    size = max(float(np.max(np.abs(q))), float(np.max(np.abs(f))))
    if previous is not None:
        sol = previous.sol
        lam, steps = 1.0, 0
    else:
        lam = min(1.0, start / size) if size > 0 else 1.0
        t = np.linspace(0.0, 1.0, 41) ** 2  # graded towards the clamp
        sol = None
        y = np.zeros((6, t.size))
        y[0] = t
        steps = 0
    factor = growth
    while True:
        if sol is not None:
            t, y = sol.x, sol.y
        last = lam == 1.0 and (previous is not None or path_tol <= tol)
        trial = solve_bvp(_rhs(lam * q, eps_a, eps_g), _bc(lam * f), t, y,
                          tol=tol if last else max(tol, path_tol), max_nodes=max_nodes)
        steps += 1
        turn = (np.max(np.abs(trial.sol(sol.x)[2] - sol.y[2]))
                if trial.success and sol is not None else 0.0)
        if trial.success and turn <= max_turn:
            sol, reached = trial, lam
            if last:
                break
            if lam == 1.0:
                path_tol = tol  # once more, to tol
                continue
            factor = min(growth, factor**2)
        else:
            if previous is not None or sol is None or factor < 1.01:
                raise RuntimeError(f"solve_bvp failed at load factor {lam:.6g}: "
                                   f"{trial.message} (turn {turn:.3g} rad)")
            factor = math.sqrt(factor)
        lam = min(1.0, reached * factor)
    return PlanarSolution(L, EI, sol, steps, sol.x.size)


def linear_tension_deflection(F, P, EI, L, GA):
    """Lateral tip deflection (m) of a clamped rod under a tip force (F, P), F > 0 along the
    clamp's axis, P ≪ F across it: w = (P/F)(L − tanh(kL)/k) + P L/GA, k = √(F/EI).

    Linearising the planar equations above in θ ~ P/F with EA = GA (or EA, GA → ∞):
    EI θ'' − F θ = −P, θ(0) = 0, θ'(L) = 0, so θ = (P/F)(1 − cosh k(L−s)/cosh kL), and
    z' = θ + P/GA. Dropped: terms O((P/F)³ L) and O((P/F)² F L/EA).
    """
    k = math.sqrt(F / EI)
    return (P / F) * (L - math.tanh(k * L) / k) + P * L / GA


def separatrix_tip(T, psi, EI, L, C):
    """Tip position (x, z) in m of a clamped rod of length L, axis +x, pulled at its tip by a
    dead force of magnitude T at angle ψ (rad, in (−π, π)) from +x towards +z, with
    EA = GA = C, up to terms of order e^{−kL}/k, k = √(T/EI).

    With α = ψ − θ the angle from the tangent to the force, the moment balance of the
    inextensible elastica is EI α'' = T sin α: a pendulum whose hyperbolic point α = 0 is
    the arm lined up with the force. Far from the clamp (kL ≫ 1) the arm lies on the
    separatrix into it, α'² = 4k² sin²(α/2), α(0) = ψ, i.e. tan(α/4) = tan(ψ/4) e^{−ks}
    (the free end's θ'(L) = 0 holds to O(e^{−kL})). With ds = −dα / (2k sin(α/2)):

        ∫₀^∞ (1 − cos α) ds = ∫₀^ψ sin(α/2)/k dα = (2/k)(1 − cos(ψ/2)),
        ∫₀^∞ sin α ds       = ∫₀^ψ cos(α/2)/k dα = (2/k) sin(ψ/2).

    The tangent is t = cos α d − sin α d⊥ (d = (cos ψ, sin ψ) the force's direction,
    d⊥ = (−sin ψ, cos ψ)), so p(L) = [L − (2/k)(1 − cos(ψ/2))] d − (2/k) sin(ψ/2) d⊥,
    plus T L/C d for the stretch and shear (module docstring).
    """
    k = math.sqrt(T / EI)
    d = np.array([math.cos(psi), math.sin(psi)])
    d_perp = np.array([-math.sin(psi), math.cos(psi)])
    along = L - (2.0 / k) * (1.0 - math.cos(psi / 2.0)) + T * L / C
    return along * d - (2.0 / k) * math.sin(psi / 2.0) * d_perp
