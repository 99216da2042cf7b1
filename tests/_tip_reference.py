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


# --- with Coulomb friction (tests/test_tip_friction.py) ----------------------------------
#
# The tip's cap (the disc of radius r about the tip's centre p in the bending plane) touches
# the plane at q = p - r n̂, where the obstacle's force f acts: its moment about the centre
# is ((q - p) × f)_y = -r (n̂ × f)_y, the tip's boundary moment. Sticking, the cap rolls on
# the plane without sliding: with t̂ = ŷ × n̂ the tangent (a turn dθ about y moves the
# contact point of a rolling disc by r dθ along t̂), (p - p₀) · t̂ = r (θ(L) - θ₀) from the
# first touch (p₀, θ₀), exactly. Sliding one way, f = N (n̂ + σ μ t̂), σ = ±1 the side the
# friction pushes to.


def _rates(L, EA, GA, EI, w, force, reaction):
    """solve_bvp's right-hand side for the dead tip force ``force`` (scaled by the
    continuation's μ) plus ``reaction(p)`` (the parameters), the weight w (N/m)."""

    def fun(s, y, p):
        th, m = y[2], y[3]
        rx, rz = reaction(p)
        nx = force[0] + rx + 0.0 * s
        nz = force[1] + rz + w * (s - L)
        c, sn = np.cos(th), np.sin(th)
        N, Q = nx * c - nz * sn, nx * sn + nz * c
        dx = (1 + N / EA) * c + (Q / GA) * sn
        dz = -(1 + N / EA) * sn + (Q / GA) * c
        return np.vstack([dx, dz, m / EI, dx * nz - dz * nx])

    return fun


def _tip_moment(r, normal, f):
    """((q - p) × f)_y with q - p = -r n̂ (x-z components)."""
    arm = -r * np.asarray(normal)
    return arm[1] * f[0] - arm[0] * f[1]


def first_touch(L, EA, GA, EI, r, w, force, point, normal, *, tol=1e-10):
    """(t₀, p₀ (x, z), θ₀): the load factor where the free arm's tip first touches the
    plane through ``point`` with outward ``normal``, and its tip there."""
    from scipy.optimize import brentq

    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    point = np.asarray(point, float)
    s = np.linspace(0.0, L, 201)
    guess = [np.vstack([s, 0 * s, 0 * s, 0 * s])]

    def free(t):
        fun = _rates(L, EA, GA, EI, t * w, t * np.asarray(force, float), lambda p: (0.0, 0.0))
        sol = solve_bvp(lambda s, y: fun(s, y, None),
                        lambda ya, yb: np.array([ya[0], ya[1], ya[2], yb[3]]),
                        s, guess[0], tol=tol, max_nodes=100_000)
        if not sol.success:
            raise RuntimeError(f"first_touch: solve_bvp failed at t = {t}: {sol.message}")
        guess[0] = sol.sol(s)
        return sol

    def gap(t):
        sol = free(t)
        return (np.array([sol.y[0, -1], sol.y[1, -1]]) - point) @ normal - r

    ts = np.linspace(0.0, 1.0, 41)
    gaps = [gap(t) for t in ts]
    k = next(i for i, g in enumerate(gaps) if g < 0.0)
    t0 = brentq(gap, ts[k - 1], ts[k], xtol=1e-14)
    sol = free(t0)
    return t0, np.array([sol.y[0, -1], sol.y[1, -1]]), sol.y[2, -1]


def tip_stuck_on_plane(L, EA, GA, EI, r, w, force, point, normal, *, steps=40, tol=1e-10):
    """The arm whose tip's cap touched the plane (``point``, ``normal``: (x, z)) first at
    t₀ and rolled on it without sliding as the loads grew to their full value (the weight
    w and the tip force ``force`` scaled by t): the reaction (x, z) is the parameters. Also
    the ratio |f_t|/f_n at every continuation step (``.ratios``), to choose μ: the tip
    sticks on the whole path where μ exceeds them."""
    t0 = first_touch(L, EA, GA, EI, r, w, force, point, normal, tol=tol)[0]
    s = np.linspace(0.0, L, 201)
    fun = _rates(L, EA, GA, EI, t0 * w, t0 * np.asarray(force, float), lambda p: (0.0, 0.0))
    sol = solve_bvp(lambda s_, y_: fun(s_, y_, None),
                    lambda ya, yb: np.array([ya[0], ya[1], ya[2], yb[3]]),
                    s, np.vstack([s, 0 * s, 0 * s, 0 * s]), tol=tol, max_nodes=100_000)
    touched = TipHeld(sol.x, sol.y[0], sol.y[1], sol.y[2], np.zeros(2))
    touched.m = sol.y[3]
    return tip_stuck_from(L, EA, GA, EI, r, w, force, point, normal, touched, t0, 1.0,
                          steps=steps, tol=tol)


def tip_stuck_from(L, EA, GA, EI, r, w, force, point, normal, held, start, end, *,
                   steps=40, tol=1e-10):
    """The arm whose tip's cap, held on the plane in ``held`` (a TipHeld with ``.m``, the
    internal moment, at the load factor ``start``), rolls on it without sliding while the
    loads go from ``start`` to ``end`` (scaled, as tip_stuck_on_plane's). ``.ratios``: the
    lean |f_t|/f_n at every continuation step."""
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    tangent = np.array([normal[1], -normal[0]])  # ŷ × n̂ in (x, z)
    point, force = np.asarray(point, float), np.asarray(force, float)
    p0, th0 = np.array([held.x[-1], held.z[-1]]), held.theta[-1]
    xs, y = held.s, np.vstack([held.x, held.z, held.theta, held.m])
    p = np.asarray(held.reaction, float)
    ratios = []
    for mu in np.linspace(start, end, steps + 1)[1:]:
        fun = _rates(L, EA, GA, EI, mu * w, mu * force, lambda p: (p[0], p[1]))

        def bc(ya, yb, p):
            return np.array([ya[0], ya[1], ya[2], yb[3] - _tip_moment(r, normal, p),
                             (np.array([yb[0], yb[1]]) - point) @ normal - r,
                             (np.array([yb[0], yb[1]]) - p0) @ tangent - r * (yb[2] - th0)])

        sol = solve_bvp(fun, bc, xs, y, p, tol=tol, max_nodes=100_000)
        if not sol.success:
            raise RuntimeError(f"tip_stuck_from: solve_bvp failed at μ = {mu}")
        xs, y, p = sol.x, sol.y, sol.p
        ratios.append(abs(p @ tangent) / (p @ normal))
    out = TipHeld(xs, y[0], y[1], y[2], np.asarray(p))
    out.m, out.ratios = y[3], np.array(ratios)
    return out


def tip_sliding_on_plane(L, EA, GA, EI, r, w, force, point, normal, mu, side, *, steps=40,
                         tol=1e-10) -> TipHeld:
    """The arm whose tip slides on the plane (``point``, ``normal``: (x, z)) with Coulomb's
    ``mu``, the friction pushing the tip along ``side`` × t̂ (t̂ = ŷ × n̂): the reaction
    N (n̂ + side μ t̂) at the contact point, N the parameter (the plane moved into place
    from where the unloaded tip touches it, as tip_on_plane)."""
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    tangent = np.array([normal[1], -normal[0]])
    lean = normal + side * mu * tangent
    point, force = np.asarray(point, float), np.asarray(force, float)
    start = np.array([L, 0.0]) - r * normal
    s = np.linspace(0.0, L, 201)
    y, p = np.vstack([s, 0 * s, 0 * s, 0 * s]), np.array([0.0])
    for c in np.linspace(0.0, 1.0, steps + 1)[1:]:
        fun = _rates(L, EA, GA, EI, c * w, c * force, lambda p: p[0] * lean)
        where = start + c * (point - start)

        def bc(ya, yb, p, where=where):
            return np.array([ya[0], ya[1], ya[2],
                             yb[3] - _tip_moment(r, normal, p[0] * lean),
                             (np.array([yb[0], yb[1]]) - where) @ normal - r])

        sol = solve_bvp(fun, bc, s, y, p, tol=tol, max_nodes=100_000)
        if not sol.success:
            raise RuntimeError(f"tip_sliding_on_plane: solve_bvp failed at c = {c}")
        s, y, p = sol.x, sol.y, sol.p
    out = TipHeld(s, y[0], y[1], y[2], p[0] * lean)
    out.m = y[3]
    return out
