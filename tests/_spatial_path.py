"""An independent reference for "the equilibrium connected to the unloaded arm" in 3-D: the
Cosserat rod under dead forces, followed along its loading path by pseudo-arclength
continuation on the base moment.

Written for tests/statics/test_branch_guard.py from the equations alone; it imports nothing from
softarm. The arm is clamped at the origin with R(0) = I (axis +x), stress-free curvature κ⁰
(material), stiffnesses K = diag(EA, GAy, GAz, GJ, EIy, EIz). Under dead forces only (a tip
force F and a uniform distributed force q, e.g. gravity μ g; spatial components) the internal
force is known everywhere, n(s) = λ (F + q (L − s)), and the unknown of the shooting problem is
the base moment m(0) (3 components)::

    p' = R v,  R' = R û,  m' = −p' × n,
    u = κ⁰ + K_b⁻¹ Rᵀ m,  v = e₁ + K_s⁻¹ Rᵀ n,

with the residual r(m₀, λ) = m(L) − λ M (a dead tip moment M). The variational equations
(δR = R δθ~, δθ material; δu = K_b⁻¹ (Rᵀ δm + Rᵀm × δθ), δθ' = −u × δθ + δu,
δv = K_s⁻¹ (Rᵀ δn + Rᵀn × δθ), δp' = R (δθ × v + δv), δm' = −δp' × n − p' × δn) give
∂r/∂m₀ and ∂r/∂λ (scipy's DOP853, rtol 1e-11).

The solution set is a curve in (m₀, λ). The continuation refuses a step whose corrector ends
farther than a tenth of the step from its prediction, whose tangent turns by more than 10°,
or across which a singular point lies: the orientation det [A; t] (A = [∂r/∂m₀ ∂r/∂λ]) changes
sign, or A_aug,before⁻¹ A_aug,after (A_aug = [A; t]) has an eigenvalue with a negative real part
(a double root: the two bending planes of a round section together). A step shorter than 1e-9
that still crosses is an error: the cases this serves have no singular point on their path.
Single shooting: for loads with kL = L √(|F|/EI) up to about 10.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

__all__ = ["SpatialEnd", "follow"]


@dataclass(frozen=True)
class SpatialEnd:
    """The end of the path: ``tip`` (3,) m and ``tip_rotation`` (3, 3) at λ = 1, the base
    moment (3,) N m, the steps accepted."""

    tip: np.ndarray
    tip_rotation: np.ndarray
    base_moment: np.ndarray
    steps: int


_E1 = np.array([1.0, 0.0, 0.0])


def _cross(a, b):
    """a × b over the last axis (3,) or (4, 3), broadcast: numpy's cross costs more than the
    products at this size."""
    a, b = np.asarray(a), np.asarray(b)
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def _hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


class _Rod:
    def __init__(self, length, stiffness, curvature, tip_force, tip_moment, distributed):
        self.L = float(length)
        k = np.asarray(stiffness, dtype=float)
        self.ks, self.kb = k[:3], k[3:]
        self.k0 = np.asarray(curvature, dtype=float)
        self.F = np.asarray(tip_force, dtype=float)
        self.M = np.asarray(tip_moment, dtype=float)
        self.q = np.asarray(distributed, dtype=float)

    def rhs(self, s, y, lam):
        """y: R (9, row-major), p (3), m (3), then per column (m₀ x, y, z; λ) δθ, δp, δm
        (the four columns' variations as the rows of a (4, 9) block)."""
        R = y[:9].reshape(3, 3)
        m = y[12:15]
        unit = self.F + self.q * (self.L - s)
        n = lam * unit
        mm, nm = R.T @ m, R.T @ n  # material components
        u = self.k0 + mm / self.kb
        v = _E1 + nm / self.ks
        dp = R @ v
        out = np.empty_like(y)
        out[:9] = (R @ _hat(u)).ravel()
        out[9:12] = dp
        out[12:15] = -_cross(dp, n)
        variation = y[15:].reshape(4, 9)
        dth, dm = variation[:, :3], variation[:, 6:]
        dn = np.zeros((4, 3))
        dn[3] = unit  # ∂n/∂λ; n does not depend on m₀
        du = (dm @ R + _cross(mm, dth)) / self.kb  # rows: Rᵀ δm + Rᵀm × δθ, per column
        dv = (dn @ R + _cross(nm, dth)) / self.ks
        ddp = (_cross(dth, v) + dv) @ R.T
        rates = out[15:].reshape(4, 9)
        rates[:, :3] = -_cross(u, dth) + du
        rates[:, 3:6] = ddp
        rates[:, 6:] = -_cross(ddp, n) - _cross(dp, dn)
        return out

    def shoot(self, m0, lam):
        """(r (3,), ∂r/∂m₀ (3, 3), ∂r/∂λ (3,), tip (3,), R(L))."""
        y0 = np.zeros(15 + 36)
        y0[:9] = np.eye(3).ravel()
        y0[12:15] = m0
        for c in range(3):
            y0[15 + 9 * c + 6 + c] = 1.0
        sol = solve_ivp(self.rhs, (0.0, self.L), y0, method="DOP853", rtol=1e-11,
                        atol=1e-13 * max(1.0, float(np.max(np.abs(m0)))), args=(lam,))
        y = sol.y[:, -1]
        r = y[12:15] - lam * self.M
        r_m = np.column_stack([y[15 + 9 * c + 6:15 + 9 * c + 9] for c in range(3)])
        r_l = y[15 + 27 + 6:15 + 27 + 9] - self.M
        return r, r_m, r_l, y[9:12], y[:9].reshape(3, 3)


def follow(length, stiffness, *, tip_force=(0.0, 0.0, 0.0), tip_moment=(0.0, 0.0, 0.0),
           distributed=(0.0, 0.0, 0.0), curvature=(0.0, 0.0, 0.0), step=0.01,
           max_steps=100000) -> SpatialEnd:
    """Follow λ·loads from the unloaded arm (λ = 0) to λ = 1 (see the module docstring);
    ``stiffness`` = (EA, GAy, GAz, GJ, EIy, EIz). RuntimeError where a fold or a singular
    point stops it."""
    rod = _Rod(length, stiffness, curvature, tip_force, tip_moment, distributed)
    m_scale = (np.linalg.norm(rod.F) * length + np.linalg.norm(rod.q) * length**2 / 2
               + np.linalg.norm(rod.M) + min(rod.kb) / length)

    def matrix(r_m, r_l):
        return np.column_stack([r_m * m_scale, r_l])  # (3, 4), z = (m₀ / m_scale, λ)

    def tangent(A, previous):
        t = np.linalg.svd(A)[2][-1]
        return t if t @ previous > 0 else -t

    z = np.zeros(4)
    r, r_m, r_l, tip, R = rod.shoot(np.zeros(3), 0.0)
    A = matrix(r_m, r_l)
    t = tangent(A, np.array([0.0, 0.0, 0.0, 1.0]))
    augmented = np.vstack([A, t])
    orientation = np.sign(np.linalg.det(augmented))
    ds, accepted = step, 0
    while accepted < max_steps:
        last = t[3] > 0 and z[3] + ds * t[3] >= 1.0
        predicted = z + ((1.0 - z[3]) / t[3] if last else ds) * t
        w = predicted.copy()
        ok = False
        for _ in range(8):
            r, r_m, r_l, tip, R = rod.shoot(w[:3] * m_scale, w[3])
            A_new = matrix(r_m, r_l)
            if last:
                dw = np.append(np.linalg.solve(A_new[:, :3], -r), 0.0)
            else:
                dw = np.linalg.solve(np.vstack([A_new, t]), -np.append(r, t @ (w - predicted)))
            w += dw
            if np.abs(dw).sum() < 1e-12:
                r, r_m, r_l, tip, R = rod.shoot(w[:3] * m_scale, w[3])
                A_new = matrix(r_m, r_l)
                ok = np.abs(r).max() <= 1e-9 * m_scale
                break
        if ok:
            t_new = tangent(A_new, t)
            aug_new = np.vstack([A_new, t_new])
            ratio = np.linalg.eigvals(np.linalg.solve(augmented, aug_new))
            ok = (t_new @ t >= math.cos(math.radians(10.0))
                  and np.linalg.norm(w - predicted) <= 0.1 * max(ds, np.linalg.norm(w - z))
                  and np.sign(np.linalg.det(aug_new)) == orientation
                  and np.all(ratio.real > 0.0))
        if not ok:
            ds *= 0.5
            if ds < 1e-9:
                raise RuntimeError(f"reference path stopped at λ = {z[3]}: a fold or a "
                                   "singular point")
            continue
        if t_new[3] <= 0.0:
            raise RuntimeError(f"reference path folds at λ = {w[3]}")
        z, t, augmented = w, t_new, aug_new
        accepted += 1
        if last:
            return SpatialEnd(tip, R, z[:3] * m_scale, accepted)
        ds = min(step, 1.5 * ds)
    raise RuntimeError("reference path: too many steps")
