"""An independent reference for a free tip held on a plane or a round obstacle: scipy
``solve_bvp`` on the planar Reissner rod (extension and shear), the obstacle's reaction and
the tip's position unknown parameters.

Written for the tests from the equations alone, sharing no code with softarm. The arm bends
in the x-z plane from a clamp at the origin along x; θ(s) turns the section about y, so that
e1 = (cos θ, 0, -sin θ), e3 = (sin θ, 0, cos θ). With w the weight per length (gravity along
-z), F the applied dead tip force and R n̂ the obstacle's reaction, n̂ its outward normal at
the tip (in the x-z plane):

    n(s) = F + R n̂ + w (s - L) ẑ          (n' = w ẑ: the weight)
    N = n · e1,  Q = n · e3,               x' = (1 + N/EA) cos θ + (Q/GA) sin θ,
    θ' = m / EI,                           z' = -(1 + N/EA) sin θ + (Q/GA) cos θ,
    m' = x' n_z - z' n_x                   (m' = -(p' × n)_y),

with x = z = θ = 0 at the clamp, m(L) = 0, the tip (x(L), z(L)) = (p_x, p_z) (parameters,
so that n̂ is known along the arm) and the tip's surface on the obstacle: its distance
from the obstacle is r. A plane: (p - a) · n̂ = r; a circle (a capsule across the bending
plane, or a ball's section through its centre) of centre c and radius ρ: |p - c| = ρ + r,
n̂ = (p - c)/|p - c|. The obstacle is moved from where the unloaded tip touches it to its
place while the loads grow (continuation in μ from 0 to 1), each step from the last
solution.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_bvp


@dataclass
class TipHeld:
    s: np.ndarray
    x: np.ndarray
    z: np.ndarray
    theta: np.ndarray
    reaction: np.ndarray  # (x, z) components of the obstacle's force on the tip, N

    def positions(self, s) -> np.ndarray:
        """(S, 3) centreline positions at stations s (the collocation's own interpolant)."""
        return np.stack([np.interp(s, self.s, self.x), np.zeros_like(s),
                         np.interp(s, self.s, self.z)], axis=-1)


def _held(L, EA, GA, EI, r, w, force, surface, steps, tol) -> TipHeld:
    """``surface(μ, p)`` -> (the gap of the tip's surface, n̂) of the obstacle at
    continuation step μ, for the tip's centreline point p = (x, z)."""
    force = np.asarray(force, float)

    def rates(mu):
        def fun(s, y, p):
            th, m = y[2], y[3]
            _, normal = surface(mu, p[1:])
            nx = mu * force[0] + p[0] * normal[0] + 0.0 * s
            nz = mu * force[1] + p[0] * normal[1] + mu * w * (s - L)
            c, sn = np.cos(th), np.sin(th)
            N, Q = nx * c - nz * sn, nx * sn + nz * c
            dx = (1 + N / EA) * c + (Q / GA) * sn
            dz = -(1 + N / EA) * sn + (Q / GA) * c
            return np.vstack([dx, dz, m / EI, dx * nz - dz * nx])

        def bc(ya, yb, p):
            gap, _ = surface(mu, p[1:])
            return np.array([ya[0], ya[1], ya[2], yb[3], yb[0] - p[1], yb[1] - p[2], gap])

        return fun, bc

    s = np.linspace(0.0, L, 201)
    y = np.vstack([s, 0 * s, 0 * s, 0 * s])
    p = np.array([0.0, L, 0.0])
    for mu in np.linspace(0.0, 1.0, steps + 1)[1:]:
        fun, bc = rates(mu)
        sol = solve_bvp(fun, bc, s, y, p, tol=tol, max_nodes=100_000)
        if not sol.success:
            raise RuntimeError(f"_tip_reference: solve_bvp failed at μ = {mu}: {sol.message}")
        s, y, p = sol.x, sol.y, sol.p
    _, normal = surface(1.0, p[1:])
    return TipHeld(s, y[0], y[1], y[2], p[0] * np.asarray(normal))


def tip_on_plane(L, EA, GA, EI, r, w, force, point, normal, *, steps=40,
                 tol=1e-10) -> TipHeld:
    """The arm with its tip held on the plane through ``point`` with outward ``normal``
    (both (x, z)); ``force`` (F_x, F_z) the applied dead tip force (N)."""
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    point = np.asarray(point, float)
    start = np.array([L, 0.0]) - r * normal  # the plane that the unloaded tip touches

    def surface(mu, p):
        return (p - (start + mu * (point - start))) @ normal - r, normal

    return _held(L, EA, GA, EI, r, w, force, surface, steps, tol)


def tip_on_circle(L, EA, GA, EI, r, w, force, centre, radius, *, steps=40,
                  tol=1e-10) -> TipHeld:
    """The arm with its tip held on the circle of ``centre`` (x, z) and ``radius``."""
    centre = np.asarray(centre, float)
    tip = np.array([L, 0.0])
    start = tip + (radius + r) * (centre - tip) / np.linalg.norm(centre - tip)

    def surface(mu, p):
        offset = p - (start + mu * (centre - start))
        distance = np.linalg.norm(offset)
        return distance - radius - r, offset / distance

    return _held(L, EA, GA, EI, r, w, force, surface, steps, tol)
