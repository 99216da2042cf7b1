"""An independent reference for the static Cosserat rod: scipy ``solve_bvp`` with continuation.

Written for the tests from the equations alone, sharing no code with ``softarm.statics``:

    p' = R v,   R' = R û,   n' = -f,   m' = -p' × n - l,
    (v; u) = f⁰ + K⁻¹ (Rᵀ n; Rᵀ m),

with p, n, m spatial, R the material frame, f⁰ = (1, 0, 0, κ⁰) and K the section's 6×6
stiffness (read from the softarm arm: it is an input, not a computation under test). The base is
clamped at the origin with R(0) = I; at the tip n(L) = F, m(L) = M (a follower tip wrench is
R(L) times its material components). Segment joints and point loads cut the arm into pieces;
each piece is mapped to τ ∈ [0, 1] and all pieces are solved together (a multipoint BVP):
p and R continuous at a cut, n(s⁻) = n(s⁺) + F_point, m(s⁻) = m(s⁺) + M_point.

A global collocation method continued from the previous shape in small load steps stays on the
branch connected to the unloaded arm (issue 12): :func:`continuation` follows λ·loads from
λ = 0 with a secant predictor and step control (a step is rejected and halved when solve_bvp
fails or the shape moves more than ``max_move``·L in one step); if the step falls below
``min_step`` it reports the λ reached (a fold, or a path it cannot follow).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_bvp
from scipy.interpolate import make_interp_spline

# ---------------------------------------------------------------------------------------------
# load description, independent of softarm.loads (built from the softarm objects by `describe`)


@dataclass
class RefLoads:
    """Loads as plain arrays (SI, spatial unless said): the reference's own description."""

    tip_force: np.ndarray = field(default_factory=lambda: np.zeros(3))        # dead, spatial
    tip_moment: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tip_force_mat: np.ndarray = field(default_factory=lambda: np.zeros(3))    # follower
    tip_moment_mat: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))          # m/s², spatial
    dist_force: np.ndarray = field(default_factory=lambda: np.zeros(3))       # N/m, spatial
    dist_force_mat: np.ndarray = field(default_factory=lambda: np.zeros(3))   # N/m, material
    points: list = field(default_factory=list)   # [(s, force, moment)], dead, spatial

    def scaled(self, lam: float) -> RefLoads:
        return RefLoads(lam * self.tip_force, lam * self.tip_moment, lam * self.tip_force_mat,
                        lam * self.tip_moment_mat, lam * self.gravity, lam * self.dist_force,
                        lam * self.dist_force_mat,
                        [(s, lam * np.asarray(f), lam * np.asarray(m)) for s, f, m in self.points])


def describe(loads) -> RefLoads:
    """RefLoads from a list of unbatched softarm loads (reads only their public fields)."""
    out = RefLoads()
    for load in loads:
        kind = type(load).__name__
        if kind == "TipLoad":
            if load.follower:
                out.tip_force_mat = out.tip_force_mat + load.force
                out.tip_moment_mat = out.tip_moment_mat + load.moment
            else:
                out.tip_force = out.tip_force + load.force
                out.tip_moment = out.tip_moment + load.moment
        elif kind == "Gravity":
            out.gravity = out.gravity + load.acceleration
        elif kind == "DistributedForce":
            if (getattr(load, "span", None) is not None
                    or getattr(load, "segment", None) is not None):
                raise NotImplementedError("reference: span/segment restricted loads")
            if getattr(load, "follower", False):
                out.dist_force_mat = out.dist_force_mat + load.force
            else:
                out.dist_force = out.dist_force + load.force
        elif kind == "PointLoad":
            out.points.append((float(load.s), np.array(load.force, float),
                               np.array(load.moment, float)))
        else:
            raise NotImplementedError(kind)
    return out


@dataclass
class RefArm:
    """Segments as plain arrays: lengths, K, f⁰ and μ per segment."""

    lengths: np.ndarray
    K: np.ndarray          # (nseg, 6, 6)
    f0: np.ndarray         # (nseg, 6)
    mu: np.ndarray         # (nseg,) kg/m (0 if unknown)

    @property
    def length(self) -> float:
        return float(np.sum(self.lengths))

    @property
    def bounds(self) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(self.lengths)])


def ref_arm(arm) -> RefArm:
    segs = arm.segments
    return RefArm(np.array([a.length for a in segs], float),
                  np.array([a.stiffness for a in segs], float),
                  np.array([a.reference_strain for a in segs], float),
                  np.array([a.linear_density or 0.0 for a in segs], float))


def _hat(u):
    """(3, N) -> (3, 3, N) skew matrices."""
    z = np.zeros_like(u[0])
    return np.array([[z, -u[2], u[1]], [u[2], z, -u[0]], [-u[1], u[0], z]])


# ---------------------------------------------------------------------------------------------
# the multipoint BVP


class _Problem:
    def __init__(self, rarm: RefArm, loads: RefLoads):
        self.rarm, self.loads = rarm, loads
        L = rarm.length
        point_s = sorted({s for s, _, _ in loads.points if 0.0 < s < L})
        cuts = np.unique(np.concatenate([rarm.bounds, point_s]))
        self.cuts = cuts
        self.starts, self.lengths = cuts[:-1], np.diff(cuts)
        mid = self.starts + 0.5 * self.lengths
        self.seg = np.clip(np.searchsorted(rarm.bounds, mid) - 1, 0, len(rarm.lengths) - 1)
        self.P = len(self.lengths)
        self.C = np.linalg.inv(rarm.K)

    def jumps(self, loads: RefLoads):
        """(P-1, 6) wrench jumps at interior cuts; tip-located point loads go to the tip."""
        J = np.zeros((self.P, 6))
        tip = np.zeros(6)
        L = self.rarm.length
        for s, f, m in loads.points:
            if s >= L:
                tip += np.concatenate([f, m])
            elif s <= 0.0:
                continue  # at the clamp: taken by the support
            else:
                k = int(np.argmin(np.abs(self.cuts - s)))
                J[k - 1] += np.concatenate([f, m])   # between piece k-1 and piece k
        return J[:-1], tip

    def rhs(self, loads: RefLoads):
        P, C, f0 = self.P, self.C, self.rarm.f0

        def fun(tau, Y):
            out = np.empty_like(Y)
            for k in range(P):
                y = Y[18 * k:18 * (k + 1)]
                R = y[3:12].reshape(3, 3, -1)
                n, m = y[12:15], y[15:18]
                seg = self.seg[k]
                nm = np.einsum("jin,jn->in", R, n)       # Rᵀ n
                mm = np.einsum("jin,jn->in", R, m)
                eps = C[seg] @ np.vstack([nm, mm])
                v = f0[seg][:3, None] + eps[:3]
                u = f0[seg][3:, None] + eps[3:]
                dp = np.einsum("ijn,jn->in", R, v)
                dR = np.einsum("ijn,jkn->ikn", R, _hat(u))
                f = (self.rarm.mu[seg] * loads.gravity + loads.dist_force)[:, None] \
                    + np.einsum("ijn,j->in", R, loads.dist_force_mat)
                dn = -f
                dm = -np.cross(dp, n, axis=0)
                ell = self.lengths[k]
                out[18 * k:18 * k + 3] = ell * dp
                out[18 * k + 3:18 * k + 12] = ell * dR.reshape(9, -1)
                out[18 * k + 12:18 * k + 15] = ell * dn
                out[18 * k + 15:18 * k + 18] = ell * dm
            return out

        return fun

    def bc(self, loads: RefLoads):
        P = self.P
        J, tip_extra = self.jumps(loads)
        eye = np.eye(3).ravel()

        def bc(Ya, Yb):
            res = [Ya[0:3], Ya[3:12] - eye]
            for k in range(P - 1):
                a, b = Yb[18 * k:18 * (k + 1)], Ya[18 * (k + 1):18 * (k + 2)]
                res += [b[0:12] - a[0:12], a[12:18] - b[12:18] - J[k]]
            y = Yb[18 * (P - 1):]
            R = y[3:12].reshape(3, 3)
            res += [y[12:15] - loads.tip_force - R @ loads.tip_force_mat - tip_extra[:3],
                    y[15:18] - loads.tip_moment - R @ loads.tip_moment_mat - tip_extra[3:]]
            return np.concatenate(res)

        return bc

    def unloaded_guess(self, tau):
        """Unloaded shape (n = m = 0), integrated piece by piece with many small exact steps."""
        Y = np.zeros((18 * self.P, tau.size))
        p, R = np.zeros(3), np.eye(3)
        for k in range(self.P):
            seg = self.seg[k]
            u = self.rarm.f0[seg][3:]
            v = self.rarm.f0[seg][:3]
            ell = self.lengths[k]
            ps, Rs = [], []
            t_prev = 0.0
            for t in tau:
                h = (t - t_prev) * ell
                # exact rigid motion for constant (v, u) over h: subdivide (simple, accurate)
                for _ in range(20):
                    dh = h / 20
                    Rm = R @ _expm3(0.5 * dh * u)
                    p = p + Rm @ v * dh
                    R = R @ _expm3(dh * u)
                t_prev = t
                ps.append(p.copy())
                Rs.append(R.copy())
            Y[18 * k:18 * k + 3] = np.array(ps).T
            Y[18 * k + 3:18 * k + 12] = np.array(Rs).reshape(-1, 9).T
        return Y


def _expm3(w):
    th = np.linalg.norm(w)
    W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    if th == 0.0:
        return np.eye(3)
    return np.eye(3) + np.sin(th) / th * W + (1 - np.cos(th)) / th**2 * W @ W


@dataclass
class RefSolution:
    problem: _Problem
    sol: object          # scipy solve_bvp result at the final λ
    lam: float           # load factor reached (1.0 when complete)
    steps: int

    @property
    def complete(self) -> bool:
        return self.lam >= 1.0

    def state(self, s):
        """(p, R, n, m) at arc lengths s (array), spatial; right limit at a cut."""
        s = np.atleast_1d(np.asarray(s, float))
        pr = self.problem
        k = np.clip(np.searchsorted(pr.cuts, s, side="right") - 1, 0, pr.P - 1)
        tau = (s - pr.starts[k]) / pr.lengths[k]
        Yall = self.sol.sol(np.clip(tau, 0.0, 1.0))
        y = np.empty((18, s.size))
        for i in range(s.size):
            y[:, i] = Yall[18 * k[i]:18 * (k[i] + 1), i]
        p = y[0:3].T
        R = y[3:12].T.reshape(-1, 3, 3)
        return p, R, y[12:15].T, y[15:18].T

    def tip_position(self):
        return self.state([self.problem.rarm.length - 0.0])[0][0]


def solve_reference(arm, loads, *, lam_step=0.02, min_step=1e-4, max_move=0.05, tol=1e-8,
                    nodes=201, max_nodes=20000, final_tol=None) -> RefSolution:
    """Follow λ·loads from the unloaded arm (λ = 0 → 1) by solve_bvp continuation.

    Parameters
    ----------
    arm : softarm Arm or SegmentedArm (its K, f⁰, μ and lengths are read)
    loads : list of unbatched softarm loads
    lam_step : first and largest λ step; halved on failure or when the shape moves more than
        ``max_move``·L (infinity norm of positions) in one step, grown by 1.5 after success.
    min_step : smallest λ step before giving up (the λ reached is then returned).
    tol : solve_bvp collocation tolerance during continuation; ``final_tol`` (default tol)
        for one last solve at λ = 1.
    """
    rarm, rl = ref_arm(arm), describe(loads)
    pr = _Problem(rarm, rl)
    L = rarm.length
    tau = np.linspace(0.0, 1.0, nodes)
    Y = pr.unloaded_guess(tau)
    prev = None           # (tau, Y, lam) of the previous accepted point, for the secant
    lam, step, count = 0.0, lam_step, 0
    sol0 = solve_bvp(pr.rhs(rl.scaled(0.0)), pr.bc(rl.scaled(0.0)), tau, Y, tol=tol,
                     max_nodes=max_nodes)
    if sol0.status != 0:
        raise RuntimeError(f"reference: unloaded arm failed: {sol0.message}")
    cur = sol0
    while lam < 1.0:
        target = min(1.0, lam + step)
        x = cur.x
        guess = cur.sol(x)
        if prev is not None:
            ratio = (target - lam) / (lam - prev[1])
            guess = guess + ratio * (guess - prev[0].sol(x))
        sl = rl.scaled(target)
        new = solve_bvp(pr.rhs(sl), pr.bc(sl), x, guess, tol=tol, max_nodes=max_nodes)
        count += 1
        ok = new.status == 0
        if ok:
            xs = np.linspace(0, 1, 51)
            move = np.max(np.abs(new.sol(xs)[np.r_[[18 * k + i for k in range(pr.P)
                                                     for i in range(3)]]]
                                 - cur.sol(xs)[np.r_[[18 * k + i for k in range(pr.P)
                                                      for i in range(3)]]]))
            ok = move <= max_move * L
        if ok:
            prev = (cur, lam)
            cur, lam = new, target
            step = min(lam_step, 1.5 * step)
        else:
            step *= 0.5
            if step < min_step:
                return RefSolution(pr, cur, lam, count)
    if final_tol is not None and final_tol < tol:
        new = solve_bvp(pr.rhs(rl), pr.bc(rl), cur.x, cur.y, tol=final_tol,
                        max_nodes=max_nodes)
        if new.status == 0:
            cur = new
    return RefSolution(pr, cur, 1.0, count)


# ---------------------------------------------------------------------------------------------
# potential energy of conservative loads (dead forces, gravity, dead distributed/point forces)


def potential_energy_from_states(rarm: RefArm, loads: RefLoads, s, p, R, n, m, cuts):
    """Π = ∫ ½ εᵀ K ε ds − F·p(L) − ∫ (μ g + q)·p ds − Σ F_i·p(s_i), in J.

    ``s`` must contain every cut (segment joints, point loads) and resolve each piece; ε is
    rebuilt from the material stresses (Rᵀ n; Rᵀ m). Each piece is integrated with a
    degree-5 spline (error ~h⁶). Dead moments are not conservative in 3D: refused.
    """
    if np.any(loads.tip_moment) or np.any(loads.tip_force_mat) or np.any(loads.tip_moment_mat) \
            or np.any(loads.dist_force_mat) or any(np.any(mm) for _, _, mm in loads.points):
        raise ValueError("potential energy: only dead forces and gravity are conservative")
    C = np.linalg.inv(rarm.K)
    total = 0.0
    for a, b in itertools.pairwise(cuts):
        sel = (s >= a - 1e-15) & (s <= b + 1e-15)
        t = s[sel]
        seg = int(np.clip(np.searchsorted(rarm.bounds, 0.5 * (a + b)) - 1, 0,
                          len(rarm.lengths) - 1))
        sig = np.concatenate([np.einsum("nji,nj->ni", R[sel], n[sel]),
                              np.einsum("nji,nj->ni", R[sel], m[sel])], axis=1)
        eps = sig @ C[seg].T
        dens = 0.5 * np.einsum("ni,ni->n", eps, sig)
        f = rarm.mu[seg] * loads.gravity + loads.dist_force
        dens = dens - p[sel] @ f
        spl = make_interp_spline(t, dens, k=5)
        total += float(spl.integrate(t[0], t[-1]))
    total -= float(loads.tip_force @ p[-1])
    for sp, fp, _ in loads.points:
        i = int(np.argmin(np.abs(s - sp)))
        total -= float(fp @ p[i])
    return total


def reference_energy(ref: RefSolution, loads: RefLoads, per_piece=200):
    pr = ref.problem
    s = np.unique(np.concatenate([np.linspace(a, b, per_piece + 1)
                                  for a, b in itertools.pairwise(pr.cuts)]))
    # evaluate each piece from its own side (stresses jump at point loads)
    total = 0.0
    for a, b in itertools.pairwise(pr.cuts):
        t = np.linspace(a, b, per_piece + 1)
        k = int(np.searchsorted(pr.cuts, 0.5 * (a + b)) - 1)
        Yk = ref.sol.sol((t - a) / (b - a))[18 * k:18 * (k + 1)]
        p, R = Yk[0:3].T, Yk[3:12].T.reshape(-1, 3, 3)
        n, m = Yk[12:15].T, Yk[15:18].T
        sub = RefLoads(gravity=loads.gravity, dist_force=loads.dist_force)
        total += potential_energy_from_states(ref.problem.rarm, sub, t, p, R, n, m,
                                              np.array([a, b]))
    p_all = ref.state(s)[0]
    total -= float(loads.tip_force @ ref.tip_position())
    for sp, fp, _ in loads.points:
        total -= float(fp @ ref.state([sp])[0][0])
    del p_all
    return total
