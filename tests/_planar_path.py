"""An independent reference for "the equilibrium connected to the unloaded arm": the planar
Cosserat rod under dead loads, followed along its loading path by pseudo-arclength continuation.

Written for tests/statics/test_branch_guard.py from the equations alone; it imports nothing from
softarm. The rod lies in the x-y plane, clamped at the origin along +x (θ the tangent angle from
+x towards +y, SI units, spatial components). Under dead loads only, the internal force is known
everywhere, n(s) = λ (F + q (L − s)) (tip force F, uniform distributed force q, e.g. gravity
μ g), so the only unknown of the shooting problem is the base moment m(0)::

    θ' = κ⁰ + m/EI,
    m' = −(p' × n)_z,   p' = (1 + n₁/EA) t + (n₃/GA) ν,   n₁ = n·t,  n₃ = n·ν,

t = (cos θ, sin θ), ν = (−sin θ, cos θ) (the planar restriction of softarm's model: extension,
shear, bending, a uniform precurvature κ⁰ about z), θ(0) = 0, and the residual
r(m₀, λ) = m(L) − λ M (a dead tip moment M about z).

The solution set {r = 0} is a curve in the plane (m₀, λ). Pseudo-arclength continuation follows
it from (0, 0) through any turn, so it cannot jump to another branch: each step is a predictor
along the unit tangent and a Newton corrector on the hyperplane orthogonal to it, with the
step halved whenever the corrector does not converge, ends farther from the prediction than a
tenth of the step, or the tangent turns by more than 10°. Where λ turns back before 1 (a
fold), :func:`follow` says so. The variational
equations of θ and m in m₀ and λ are integrated with the state (scipy's DOP853, rtol 1e-11).

Single shooting loses its digits in strong tension (∂r/∂m₀ grows like e^{kL}, k = √(F/EI)).
So the arc-length path runs while the loads' kL = L √(|F|/EI) is at most ``shooting_kl``
(10), and from there on (where the arm is pulled straight and the path no longer turns) the
path is continued in λ by collocation (scipy's solve_bvp on x, y, θ, m, each step from the
last solution, a step refused when any section turns by more than 0.1 rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_bvp, solve_ivp

__all__ = ["PathEnd", "follow"]


@dataclass(frozen=True)
class PathEnd:
    """The end of a followed path: ``tip`` (x, y) in m and ``theta`` (rad) at λ = ``reached``
    (1 unless a fold stopped it), ``steps`` accepted, ``folded`` when λ turned back first."""

    tip: np.ndarray
    theta: float
    base_moment: float
    reached: float
    steps: int
    folded: bool


class _Rod:
    def __init__(self, length, EI, EA, GA, curvature, tip_force, tip_moment, distributed):
        self.L, self.EI, self.EA, self.GA, self.k0 = length, EI, EA, GA, curvature
        self.F = np.asarray(tip_force, dtype=float)
        self.M = float(tip_moment)
        self.q = np.asarray(distributed, dtype=float)

    def _force(self, s, lam):
        unit = self.F + self.q * (self.L - s)
        return lam * unit, unit

    def rhs(self, s, y, lam):
        """y = (x, y, θ, m, θ_m, m_m, θ_λ, m_λ): the state and its derivatives in m₀ and λ."""
        _, _, th, m, th_a, m_a, th_l, m_l = y
        (nx, ny), (ux, uy) = self._force(s, lam)
        c, sn = math.cos(th), math.sin(th)
        n1, n3 = nx * c + ny * sn, -nx * sn + ny * c  # material axial and shear force
        v1, v2 = 1.0 + n1 / self.EA, n3 / self.GA
        px, py = v1 * c - v2 * sn, v1 * sn + v2 * c
        # p' × n and its variations (δθ: t and ν turn; δλ: n grows along (ux, uy))
        cross = px * ny - py * nx

        def d_cross(dth, dn_x, dn_y):
            dn1 = n3 * dth + dn_x * c + dn_y * sn
            dn3 = -n1 * dth - dn_x * sn + dn_y * c
            dv1, dv2 = dn1 / self.EA, dn3 / self.GA
            dpx = dv1 * c - dv2 * sn + (-v1 * sn - v2 * c) * dth
            dpy = dv1 * sn + dv2 * c + (v1 * c - v2 * sn) * dth
            return dpx * ny - dpy * nx + px * dn_y - py * dn_x

        return [px, py, self.k0 + m / self.EI, -cross,
                m_a / self.EI, -d_cross(th_a, 0.0, 0.0),
                m_l / self.EI, -d_cross(th_l, ux, uy)]

    def state_rhs(self, s, y, lam):
        """The state alone, y = (x, y, θ, m), vectorised over s (for solve_bvp)."""
        th, m = y[2], y[3]
        unit = self.F[:, None] + self.q[:, None] * (self.L - s)
        nx, ny = lam * unit
        c, sn = np.cos(th), np.sin(th)
        n1, n3 = nx * c + ny * sn, -nx * sn + ny * c
        v1, v2 = 1.0 + n1 / self.EA, n3 / self.GA
        px, py = v1 * c - v2 * sn, v1 * sn + v2 * c
        return np.vstack([px, py, self.k0 + m / self.EI, -(px * ny - py * nx)])

    def profile(self, m0, lam, s):
        """The state (4, len(s)) integrated from the base moment m₀."""
        sol = solve_ivp(self.rhs, (0.0, self.L), [0.0, 0.0, 0.0, m0, 0.0, 1.0, 0.0, 0.0],
                        method="DOP853", rtol=1e-11, atol=1e-13 * max(1.0, abs(m0)),
                        args=(lam,), t_eval=s)
        return sol.y[:4]

    def collocate(self, lam_from, m0, lam_to):
        """The path from (λ, m₀) to λ = ``lam_to`` by solve_bvp continuation in λ:
        (tip, θ(L), m₀)."""
        s = self.L * np.linspace(0.0, 1.0, 401) ** 2  # graded towards the clamp
        y = self.profile(m0, lam_from, s)
        lam, step = lam_from, 0.05 * lam_from
        while lam < lam_to:
            target = min(lam_to, lam + step)
            trial = solve_bvp(lambda t, z, target=target: self.state_rhs(t, z, target),
                              lambda a, b, target=target: np.array(
                                  [a[0], a[1], a[2], b[3] - target * self.M]),
                              s, y, tol=1e-8, max_nodes=400_000)
            turn = np.max(np.abs(trial.sol(s)[2] - y[2])) if trial.success else np.inf
            if turn <= 0.1:
                s, y, lam = trial.x, trial.y, target
                step *= 1.5
            else:
                step *= 0.5
                if step < 1e-9 * lam:
                    raise RuntimeError(f"reference collocation stuck at λ = {lam}")
        return np.array([y[0, -1], y[1, -1]]), y[2, -1], y[3, 0]

    def shoot(self, m0, lam):
        """(r, ∂r/∂m₀, ∂r/∂λ, tip (x, y), θ(L))."""
        sol = solve_ivp(self.rhs, (0.0, self.L), [0.0, 0.0, 0.0, m0, 0.0, 1.0, 0.0, 0.0],
                        method="DOP853", rtol=1e-11, atol=1e-13 * max(1.0, abs(m0)),
                        args=(lam,))
        x, y, th, m, _, m_a, _, m_l = sol.y[:, -1]
        return m - lam * self.M, m_a, m_l - self.M, np.array([x, y]), th


def follow(length, EI, EA, GA, *, tip_force=(0.0, 0.0), tip_moment=0.0,
           distributed=(0.0, 0.0), curvature=0.0, step=0.01, max_steps=100000,
           shooting_kl=10.0) -> PathEnd:
    """Follow λ·loads from the unloaded arm (λ = 0) to λ = 1 by pseudo-arclength continuation.

    ``tip_force`` (N) and ``distributed`` (N/m, uniform) are dead forces in the x-y plane,
    ``tip_moment`` (N m) a dead moment about z, ``curvature`` (1/m) the stress-free curvature
    about z. ``step`` is the largest arclength step in the plane (m₀ / m_scale, λ), m_scale
    the largest moment the loads can apply about the base.
    """
    rod = _Rod(length, EI, EA, GA, curvature, tip_force, tip_moment, distributed)
    m_scale = (np.linalg.norm(rod.F) * length + np.linalg.norm(rod.q) * length**2 / 2
               + abs(rod.M) + EI / length)
    force = np.linalg.norm(rod.F) + np.linalg.norm(rod.q) * length
    kl = length * math.sqrt(force / EI)
    lam_end = 1.0 if kl <= shooting_kl else (shooting_kl / kl) ** 2  # the arc-length part
    z = np.array([0.0, 0.0])  # (m₀ / m_scale, λ)
    r, r_m, r_l, tip, th = rod.shoot(0.0, 0.0)

    def tangent(r_m, r_l):
        """The unit tangent: the gradient of r turned by 90°, oriented once at the start.
        Along a smooth branch it turns continuously; a corrector that lands on another
        branch across a bifurcation finds it reversed (the orientation is that of det
        [∇r; t], which changes sign there), and the step is refused."""
        t = np.array([-r_l, r_m * m_scale])
        return orientation * t / np.linalg.norm(t)

    orientation = 1.0
    t = tangent(r_m, r_l)
    orientation = 1.0 if t[1] > 0 else -1.0
    t = tangent(r_m, r_l)
    ds, accepted, folded = step, 0, False
    while accepted < max_steps:
        last = t[1] > 0 and z[1] + ds * t[1] >= lam_end
        if last:  # the step to λ_end itself: Newton in m₀ alone there
            predicted = z + (lam_end - z[1]) / t[1] * t
        else:
            predicted = z + ds * t
        w = predicted.copy()
        ok = False
        for _ in range(8):
            r, r_m, r_l, tip, th = rod.shoot(w[0] * m_scale, w[1])
            if last:
                dw = np.array([-r / (r_m * m_scale), 0.0])
            else:
                A = np.array([[r_m * m_scale, r_l], t])
                dw = np.linalg.solve(A, -np.array([r, t @ (w - predicted)]))
            w += dw
            if abs(dw[0]) + abs(dw[1]) < 1e-12:
                r, r_m, r_l, tip, th = rod.shoot(w[0] * m_scale, w[1])
                ok = abs(r) <= 1e-9 * m_scale
                break
        if ok:
            t_new = tangent(r_m, r_l)
            ok = (t_new @ t >= math.cos(math.radians(10.0))
                  and np.linalg.norm(w - predicted) <= 0.1 * ds
                  and (not last or np.linalg.norm(w - z) <= 1.5 * ds))
        if not ok:
            ds *= 0.5
            if ds < 1e-12:
                raise RuntimeError(f"reference path stuck at λ = {z[1]}")
            continue
        if t_new[1] < 0 < t[1]:  # λ turned back: a fold before λ = 1
            folded = True
            break
        z, t = w, t_new
        accepted += 1
        if last:
            break
        ds = min(step, 1.5 * ds)
    if not folded and lam_end < 1.0:
        tip, th, m0 = rod.collocate(z[1], z[0] * m_scale, 1.0)
        return PathEnd(tip, th, m0, 1.0, accepted, folded)
    return PathEnd(tip, th, z[0] * m_scale, z[1], accepted, folded)
