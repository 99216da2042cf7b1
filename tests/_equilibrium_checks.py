"""Checks of a returned Equilibrium that use only the equations of statics (no solver code).

* :func:`balance_errors`: global force and moment balance of the part [s, L] at every station,
  rebuilt from the returned stresses and the loads;
* :func:`potential_energy`: the potential energy of conservative loads at the returned shape;
* :func:`fine_stations`: output stations that resolve every smooth piece of the arm (segment
  joints and point loads are cuts) for both.

Stresses are the material (n; m) of the Equilibrium docs: the wrench exerted on [0, s] by
[s, L], so R n = (sum of the forces applied to [s, L]) and R m = (their moment about p(s)).
"""

from __future__ import annotations

import itertools

import numpy as np
from _reference_rod import describe, ref_arm

GAUSS_ORDER = 12   # Gauss-Legendre nodes per cell
CELLS = 8          # cells per smooth piece (between two cuts)


def cuts_of(arm, loads) -> np.ndarray:
    """Segment joints and interior point-load stations, base and tip included (m)."""
    L = float(arm.length)
    rl = describe(loads)
    inner = [s for s, _, _ in rl.points if 0.0 < s < L]
    return np.unique(np.concatenate([np.array(arm.boundaries, float), inner]))


def cells_of(arm, loads, cells=CELLS) -> np.ndarray:
    """Each smooth piece between cuts split into ``cells`` equal cells: their edges (m)."""
    cuts = cuts_of(arm, loads)
    edges = [np.linspace(a, b, cells + 1) for a, b in itertools.pairwise(cuts)]
    out = np.unique(np.concatenate(edges))
    return out


def fine_stations(arm, loads, order=GAUSS_ORDER, cells=CELLS) -> np.ndarray:
    """Every cell edge (cuts included) plus ``order`` Gauss-Legendre nodes inside each cell."""
    x, _ = np.polynomial.legendre.leggauss(order)
    edges = cells_of(arm, loads, cells)
    inner = [a + (b - a) * (x + 1.0) / 2.0 for a, b in itertools.pairwise(edges)]
    return np.unique(np.concatenate([edges, *inner]))


def _antiderivative(x, values, a, b):
    """t ↦ ∫_a^t g for g interpolated by the Legendre polynomial through (nodes x, values).

    Interpolation at the Gauss-Legendre nodes converges spectrally for a smooth piece.
    """
    coef = np.linalg.solve(np.polynomial.legendre.legvander(x, x.size - 1), values)
    integral = np.polynomial.legendre.legint(coef, lbnd=-1.0) * (0.5 * (b - a))

    def at(t):
        return np.polynomial.legendre.legval(2.0 * (np.asarray(t) - a) / (b - a) - 1.0,
                                             integral).T

    return at


def balance_errors(eq, loads=None, order=GAUSS_ORDER, cells=CELLS):
    """Largest force and moment imbalance over all stations, and the case's own scales.

    For a single (unbatched) equilibrium whose stations include every cut and resolve each
    piece (:func:`fine_stations`). The integrals of the distributed loads over [s, L] and of
    their moments come from the returned positions and
    rotations on each cell: the Legendre interpolant through the cell's Gauss nodes,
    integrated exactly (composite Gauss accuracy, error ~ (h/2)^(2·order): far below the
    solver's tolerance). At a point load's
    own station the stress is a one-sided limit: either side is accepted.

    Returns
    -------
    (force_error, moment_error, force_scale, moment_scale)
        N, N m, N, N m. The scales are the sums of the magnitudes of all applied forces
        (tip, point, ∫|f| ds) and of the applied moments plus force scale × L.
    """
    loads = eq.loads if loads is None else loads
    arm = eq.arm
    rarm = ref_arm(arm)
    rl = describe(loads)
    L = float(arm.length)
    s = np.asarray(eq.s, float)
    p = np.asarray(eq.positions)
    R = np.asarray(eq.rotations)
    n_sp = np.einsum("nij,nj->ni", R, eq.stresses[:, :3])
    m_sp = np.einsum("nij,nj->ni", R, eq.stresses[:, 3:])
    cuts = cells_of(arm, loads, cells)
    if not np.all(np.isin(cuts, s)):
        raise ValueError("balance_errors needs the fine_stations (every cell edge)")
    seg_bounds = rarm.bounds
    # distributed force per length at each station, cell by cell (μ jumps at joints)
    F_int = np.zeros((s.size, 3))   # ∫_s^L f
    G_int = np.zeros((s.size, 3))   # ∫_s^L p × f
    tail_F = np.zeros(3)
    tail_G = np.zeros(3)
    for a, b in reversed(list(itertools.pairwise(cuts))):
        sel = np.flatnonzero((s >= a) & (s <= b))
        t = s[sel]
        seg = int(np.clip(np.searchsorted(seg_bounds, 0.5 * (a + b)) - 1, 0,
                          len(rarm.lengths) - 1))
        x, _ = np.polynomial.legendre.leggauss(order)
        nodes = a + (b - a) * (x + 1.0) / 2.0
        idx = np.array([int(np.argmin(np.abs(s - tn))) for tn in nodes])
        if np.max(np.abs(s[idx] - nodes)) > 1e-12 * max(1.0, L):
            raise ValueError("balance_errors needs the fine_stations of the same order")
        f = (rarm.mu[seg] * rl.gravity + rl.dist_force)[None, :] \
            + np.einsum("nij,j->ni", R[idx], rl.dist_force_mat)
        pf = np.cross(p[idx], f)
        Af = _antiderivative(x, f, a, b)
        Ag = _antiderivative(x, pf, a, b)
        # stations in this piece: ∫_t^b + tail (a station at a cut gets the same either way)
        F_int[sel] = Af(b) - Af(t) + tail_F
        G_int[sel] = Ag(b) - Ag(t) + tail_G
        tail_F = tail_F + Af(b) - Af(a)
        tail_G = tail_G + Ag(b) - Ag(a)
    F_tip = rl.tip_force + R[-1] @ rl.tip_force_mat
    M_tip = rl.tip_moment + R[-1] @ rl.tip_moment_mat
    force_err = 0.0
    moment_err = 0.0
    for i in range(s.size):
        base_n = F_tip + F_int[i]
        base_m = M_tip + np.cross(p[-1] - p[i], F_tip) + G_int[i] - np.cross(p[i], F_int[i])
        # point loads strictly beyond s_i (those at L act at the tip); at s_i: either side
        options_n, options_m = [base_n.copy()], [base_m.copy()]
        for sp, fp, mp in rl.points:
            if sp <= 0.0:
                continue
            j = int(np.argmin(np.abs(s - sp)))
            extra_n, extra_m = fp, mp + np.cross(p[j] - p[i], fp)
            if sp > s[i] or (sp >= L and s[i] >= L):
                options_n = [o + extra_n for o in options_n]
                options_m = [o + extra_m for o in options_m]
            elif sp == s[i]:
                options_n = options_n + [o + extra_n for o in options_n]
                options_m = options_m + [o + extra_m for o in options_m]
        errs = [(np.max(np.abs(n_sp[i] - on)), np.max(np.abs(m_sp[i] - om)))
                for on, om in zip(options_n, options_m, strict=True)]
        best = min(errs, key=lambda e: e[0] + e[1] / L)
        force_err = max(force_err, best[0])
        moment_err = max(moment_err, best[1])
    dist = np.sum(np.linalg.norm(rarm.mu[:, None] * rl.gravity + rl.dist_force, axis=1)
                  * rarm.lengths) + np.linalg.norm(rl.dist_force_mat) * L
    force_scale = (np.linalg.norm(rl.tip_force) + np.linalg.norm(rl.tip_force_mat) + dist
                   + sum(np.linalg.norm(f) for _, f, _ in rl.points))
    moment_scale = (np.linalg.norm(rl.tip_moment) + np.linalg.norm(rl.tip_moment_mat)
                    + sum(np.linalg.norm(m) for _, _, m in rl.points) + force_scale * L)
    return force_err, moment_err, force_scale, moment_scale


def potential_energy(eq, loads=None, order=GAUSS_ORDER, cells=CELLS):
    """Π = ∫ ½ εᵀ K ε ds − ∫ (μ g + q)·p ds − F_tip·p(L) − Σ F_i·p(s_i), in J.

    Only for conservative loads (dead forces, gravity): ValueError otherwise. ``eq`` must be
    solved at :func:`fine_stations` (same ``order``): each piece is integrated by Gauss-Legendre
    quadrature on its interior nodes (the strains there are unambiguous).
    """
    loads = eq.loads if loads is None else loads
    arm = eq.arm
    rarm = ref_arm(arm)
    rl = describe(loads)
    if (np.any(rl.tip_moment) or np.any(rl.tip_force_mat) or np.any(rl.tip_moment_mat)
            or np.any(rl.dist_force_mat) or any(np.any(m) for _, _, m in rl.points)):
        raise ValueError("potential energy: only dead forces and gravity are conservative")
    x, w = np.polynomial.legendre.leggauss(order)
    cuts = cells_of(arm, loads, cells)
    s = np.asarray(eq.s, float)
    total = 0.0
    for a, b in itertools.pairwise(cuts):
        nodes = a + (b - a) * (x + 1.0) / 2.0
        idx = np.array([int(np.argmin(np.abs(s - t))) for t in nodes])
        if np.max(np.abs(s[idx] - nodes)) > 1e-12 * max(1.0, arm.length):
            raise ValueError("potential_energy needs the fine_stations of the same order")
        seg = int(np.clip(np.searchsorted(rarm.bounds, 0.5 * (a + b)) - 1, 0,
                          len(rarm.lengths) - 1))
        eps = np.asarray(eq.strains)[idx]
        dens = 0.5 * np.einsum("ni,ij,nj->n", eps, rarm.K[seg], eps)
        dens -= np.asarray(eq.positions)[idx] @ (rarm.mu[seg] * rl.gravity + rl.dist_force)
        total += 0.5 * (b - a) * float(w @ dens)
    total -= float(rl.tip_force @ eq.positions[-1])
    for sp, fp, _ in rl.points:
        total -= float(fp @ eq.positions[int(np.argmin(np.abs(s - sp)))])
    return total
