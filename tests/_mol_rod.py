"""Method-of-lines reference for planar Reissner rod dynamics (the swinging arm).

Written from the equations alone for softarm's rod dynamics; its model imports nothing from
softarm (only :func:`load_reference` reads the stored file with the package's reader). Run it
as a script (``python tests/_mol_rod.py``) to regenerate
``src/softarm/validation/data/swinging_arm_mol.csv`` (shipped: ``softarm reproduce`` reads
it; see :func:`main`; add ``--cache DIR`` to reuse runs).

The continuum. A planar Cosserat rod in the x-z plane, clamped at the origin with its axis
along +x, free at s = L; arc length s, position r(s, t) = (x, z), section angle θ(s, t) from
+x towards +z, material directors d₁ = (cos θ, sin θ), d₂ = (−sin θ, cos θ). Material strains
and stresses (softarm's model restricted to the plane, K = diag(EA, kGA, EI))::

    ν₁ = r'·d₁ − 1,   ν₂ = r'·d₂,   κ = θ',
    N = EA (ν₁ + τ ν̇₁),   Q = kGA (ν₂ + τ ν̇₂),   M = EI (κ + τ κ̇),   n = N d₁ + Q d₂,
    ρA r̈ = n' − ρA g e_z,        ρI θ̈ = M' + r' × n,    (a × b = a_x b_z − a_z b_x),

with r(0) = 0, θ(0) = 0, n(L) = 0, M(L) = 0; τ is the Kelvin-Voigt retardation time (0:
undamped).

The discretisation (staggered, second order). N cells of width h = L/N; nodes s_i = i h carry
the position r_i and the angle θ_i; edges (cells) carry the strains, evaluated at the edge
midpoint with the mean angle θ_{i+½} = (θ_i + θ_{i+1})/2::

    r'_{i+½} = (r_{i+1} − r_i)/h,   ν_{i+½} = R(θ_{i+½})ᵀ r'_{i+½} − e₁,
    κ_{i+½} = (θ_{i+1} − θ_i)/h.

Node i (1 ≤ i ≤ N; node 0 is the clamp) gets the lumped mass m_i = ρA h and rotary inertia
J_i = ρI h (half of each at the tip node N, whose cell ends at s = L)::

    m_i r̈_i = n_{i+½} − n_{i−½} − m_i g e_z,
    J_i θ̈_i = M_{i+½} − M_{i−½} + (h/2) [(r' × n)_{i+½} + (r' × n)_{i−½}],

with n_{N+½} = 0, M_{N+½} = 0 (free tip). For τ = 0 these are exactly Lagrange's equations of
the discrete energy V = Σ_edges h ½ (EA ν₁² + kGA ν₂² + EI κ²) + Σ_i m_i g z_i with the kinetic
energy T = Σ_i ½ (m_i |ṙ_i|² + J_i θ̇_i²), so the semi-discrete system conserves T + V exactly:
any drift in :func:`energy` measures the time integration alone.

Time integration: scipy's ``solve_ivp`` (Radau by default) with the block-tridiagonal sparsity
of the Jacobian (each node couples to its two neighbours), the state interleaved per node as
(x, z, θ, ẋ, ż, θ̇).
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.sparse import csr_matrix

__all__ = [
    "PlanarRod",
    "energy",
    "linear_frequencies",
    "richardson",
    "simulate",
    "swing",
    "swinging_arm",
]

_DATA = (Path(__file__).resolve().parents[1] / "src" / "softarm" / "validation" / "data"
         / "swinging_arm_mol.csv")


@dataclass(frozen=True)
class PlanarRod:
    """A uniform planar Reissner rod (SI units: m, N, N m², kg/m, kg m, m/s², s)."""

    length: float
    EA: float  # axial stiffness (N)
    GA: float  # shear stiffness k G A, shear factor included (N)
    EI: float  # bending stiffness (N m²)
    rhoA: float  # mass per unit length (kg/m)
    rhoI: float  # rotary inertia per unit length about the bending axis (kg m)
    gravity: float = 9.81  # along −z (m/s²)
    tau: float = 0.0  # Kelvin-Voigt retardation time (s)


def swinging_arm(tau: float = 0.0) -> PlanarRod:
    """The swinging arm of the shared problem definition (helpers/swing.md).

    L = 0.5 m, solid circle r = 0.02 m, E = 1e6 Pa, ν = 0.5 (G = E/3), ρ = 1100 kg/m³,
    Cowper's shear factor k = 6(1+ν)/(7+6ν) = 0.9, g = 9.81 m/s².
    """
    radius, youngs, poisson, density = 0.02, 1.0e6, 0.5, 1100.0
    shear_modulus = youngs / (2 * (1 + poisson))
    k = 6 * (1 + poisson) / (7 + 6 * poisson)
    area, inertia = math.pi * radius**2, math.pi * radius**4 / 4
    return PlanarRod(
        length=0.5,
        EA=youngs * area,
        GA=k * shear_modulus * area,
        EI=youngs * inertia,
        rhoA=density * area,
        rhoI=density * inertia,
        tau=tau,
    )


class _Discrete:
    """The semi-discrete system of one rod on ``n_cells`` cells (see the module docstring)."""

    def __init__(self, rod: PlanarRod, n_cells: int):
        if n_cells < 1:
            raise ValueError(f"n_cells must be a positive integer, got {n_cells!r}")
        self.rod, self.n = rod, n_cells
        self.h = rod.length / n_cells
        weight = np.ones(n_cells)
        weight[-1] = 0.5  # the tip node's cell is half a cell
        self.mass = rod.rhoA * self.h * weight
        self.rot_inertia = rod.rhoI * self.h * weight

    def initial_state(self) -> np.ndarray:
        """Straight along +x, stress-free, at rest."""
        q = np.zeros((self.n, 6))
        q[:, 0] = self.h * np.arange(1, self.n + 1)
        return q.ravel()

    def _with_clamp(self, q):
        # prepend node 0 (the clamp: r = 0, θ = 0, at rest) to the per-node columns
        return np.vstack([np.zeros((1, 6)), q])

    def strains(self, y):
        """Edge quantities: r' (2 arrays), cos, sin of the mid-edge angle, ν₁, ν₂, κ."""
        q = self._with_clamp(y.reshape(self.n, 6))
        dx, dz = np.diff(q[:, 0]) / self.h, np.diff(q[:, 1]) / self.h
        theta_mid = 0.5 * (q[1:, 2] + q[:-1, 2])
        c, s = np.cos(theta_mid), np.sin(theta_mid)
        a = c * dx + s * dz  # r'·d₁
        b = -s * dx + c * dz  # r'·d₂
        return q, dx, dz, c, s, a - 1.0, b, np.diff(q[:, 2]) / self.h

    def rhs(self, t, y):
        rod, h = self.rod, self.h
        q, dx, dz, c, s, nu1, nu2, kappa = self.strains(y)
        axial, shear, moment = rod.EA * nu1, rod.GA * nu2, rod.EI * kappa
        if rod.tau:
            dvx, dvz = np.diff(q[:, 3]) / h, np.diff(q[:, 4]) / h
            omega_mid = 0.5 * (q[1:, 5] + q[:-1, 5])
            a, b = nu1 + 1.0, nu2
            axial = axial + rod.tau * rod.EA * (c * dvx + s * dvz + omega_mid * b)
            shear = shear + rod.tau * rod.GA * (-s * dvx + c * dvz - omega_mid * a)
            moment = moment + rod.tau * rod.EI * np.diff(q[:, 5]) / h
        nx, nz = axial * c - shear * s, axial * s + shear * c
        cross = dx * nz - dz * nx  # (r' × n) on the edges
        # close the free tip: edge N+½ carries no stress
        nx, nz, moment, cross = (np.append(v, 0.0) for v in (nx, nz, moment, cross))
        out = np.empty((self.n, 6))
        out[:, :3] = q[1:, 3:]
        out[:, 3] = np.diff(nx) / self.mass
        out[:, 4] = np.diff(nz) / self.mass - rod.gravity
        out[:, 5] = (np.diff(moment) + 0.5 * h * (cross[1:] + cross[:-1])) / self.rot_inertia
        return out.ravel()

    def sparsity(self):
        """Block-tridiagonal pattern of ∂rhs/∂y (6 × 6 blocks, one per node)."""
        rows, cols = [], []
        for i in range(self.n):
            for j in range(max(0, i - 1), min(self.n, i + 2)):
                r, cc = np.meshgrid(np.arange(6 * i, 6 * i + 6), np.arange(6 * j, 6 * j + 6))
                rows.append(r.ravel())
                cols.append(cc.ravel())
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        return csr_matrix((np.ones(rows.size), (rows, cols)), shape=(6 * self.n, 6 * self.n))

    def energy(self, y):
        """Kinetic + elastic + gravitational energy (J) of the state(s) y (..., 6N)."""
        y = np.asarray(y)
        rod = self.rod
        q = y.reshape((*y.shape[:-1], self.n, 6))
        kinetic = 0.5 * (
            self.mass * (q[..., 3] ** 2 + q[..., 4] ** 2) + self.rot_inertia * q[..., 5] ** 2
        ).sum(-1)
        potential = (self.mass * rod.gravity * q[..., 1]).sum(-1)
        flat = y.reshape(-1, y.shape[-1])
        elastic = np.empty(flat.shape[0])
        for k, yk in enumerate(flat):
            _, _, _, _, _, nu1, nu2, kappa = self.strains(yk)
            density = rod.EA * nu1**2 + rod.GA * nu2**2 + rod.EI * kappa**2
            elastic[k] = 0.5 * self.h * density.sum()
        return kinetic + potential + elastic.reshape(y.shape[:-1])


@dataclass(frozen=True)
class Trajectory:
    """A MOL run: times (s), tip positions (len(t), 2) as (x, z) in m, states, cost."""

    t: np.ndarray
    tip_xz: np.ndarray
    y: np.ndarray  # (len(t), 6 n_cells) states, interleaved per node
    n_cells: int
    rtol: float
    nfev: int
    wall_s: float


def simulate(
    rod: PlanarRod,
    n_cells: int,
    duration: float = 1.5,
    rtol: float = 1e-8,
    t_eval=None,
    method: str = "Radau",
    atol: float | None = None,
) -> Trajectory:
    """Integrate the semi-discrete rod from the straight state at rest over [0, duration].

    ``atol`` defaults to ``rtol`` times the length scale L (positions, m) for every component
    (the velocities are of order L/s, the angles of order 1, so the same number suits all).
    """
    disc = _Discrete(rod, n_cells)
    if t_eval is None:
        t_eval = np.linspace(0.0, duration, round(duration / 0.01) + 1)
    t_eval = np.asarray(t_eval, dtype=np.float64)
    if atol is None:
        atol = rtol * rod.length
    kwargs = {"jac_sparsity": disc.sparsity()} if method in ("Radau", "BDF", "LSODA") else {}
    t0 = time.perf_counter()
    sol = solve_ivp(
        disc.rhs,
        (0.0, duration),
        disc.initial_state(),
        method=method,
        t_eval=t_eval,
        rtol=rtol,
        atol=atol,
        **kwargs,
    )
    wall = time.perf_counter() - t0
    if not sol.success:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    y = sol.y.T
    tip = y[:, 6 * (n_cells - 1) : 6 * (n_cells - 1) + 2]
    return Trajectory(sol.t, tip, y, n_cells, rtol, sol.nfev, wall)


def swing(n_cells: int, duration: float = 1.5, tau: float = 0.0, rtol: float = 1e-8,
          t_eval=None, method: str = "Radau"):
    """Tip trajectory of the swinging arm: ``(t, tip_xz)``, tip_xz (len(t), 2) = (x, z) in m."""
    run = simulate(swinging_arm(tau), n_cells, duration, rtol, t_eval, method)
    return run.t, run.tip_xz


def energy(rod: PlanarRod, n_cells: int, y) -> np.ndarray:
    """Total discrete energy (J) of the states ``y`` (..., 6 n_cells) of :func:`simulate`."""
    return _Discrete(rod, n_cells).energy(y)


def linear_frequencies(rod: PlanarRod, n_cells: int, count: int = 2) -> np.ndarray:
    """The lowest ``count`` bending natural frequencies ω (rad/s) of the semi-discrete rod.

    Linearised about the straight, stress-free state without gravity: eigenvalues of
    −M⁻¹ ∂F/∂q restricted to the transverse (z, θ) degrees of freedom (the axial ones
    decouple in the linearisation). Converges to the Timoshenko cantilever's frequencies.
    """
    disc = _Discrete(replace(rod, gravity=0.0, tau=0.0), n_cells)
    y0 = disc.initial_state()
    eps = 1e-7 * rod.length
    size = 6 * n_cells
    transverse = [6 * i + k for i in range(n_cells) for k in (1, 2)]  # z_i, θ_i
    rows = [j + 3 for j in transverse]  # their accelerations
    stiffness = np.empty((len(transverse), len(transverse)))
    for col, j in enumerate(transverse):
        dy = np.zeros(size)
        dy[j] = eps
        acc = (disc.rhs(0.0, y0 + dy) - disc.rhs(0.0, y0 - dy)) / (2 * eps)
        stiffness[:, col] = -acc[rows]
    eig = np.linalg.eigvals(stiffness)
    omega = np.sort(np.sqrt(np.abs(eig.real)))
    return omega[:count]


def richardson(fine: np.ndarray, coarse: np.ndarray, order: float = 2.0, ratio: float = 2.0):
    """Richardson extrapolation of two results at mesh ratio ``ratio`` and known ``order``."""
    factor = ratio**order
    return fine + (fine - coarse) / (factor - 1.0)


# --------------------------------------------------------------------------------------------
# The convergence study and the reference file (python tests/_mol_rod.py)
# --------------------------------------------------------------------------------------------
CASES = {"undamped": 0.0, "damped": 0.01}  # Kelvin-Voigt τ (s) of helpers/swing.md
# Undamped: the explicit DOP853 (no numerical damping of the undamped high modes, and about
# five times cheaper than Radau here; the two agree to 1e-8 L, see the study); damped: τ K ε̇
# makes the high modes stiff (decay rate τ ω², ~1e5 1/s at 40 cells), so Radau.
METHODS = {"undamped": "DOP853", "damped": "Radau"}
T_EVAL = np.round(np.arange(151) * 0.01, 10)  # 0, 0.01, ..., 1.5 s


def _run_cached(case, n_cells, rtol, cache, method=None):
    method = method or METHODS[case]
    name = f"{case}_{method}_n{n_cells}_rtol{rtol:.0e}.npz"
    path = None if cache is None else cache / name
    if path is not None and path.exists():
        data = np.load(path)
        return data["tip"], float(data["wall"]), float(data["energy_drift"])
    rod = swinging_arm(CASES[case])
    run = simulate(rod, n_cells, 1.5, rtol, T_EVAL, method=method)
    e = energy(rod, n_cells, run.y)
    drift = float(np.max(np.abs(e - e[0])))
    if path is not None:
        cache.mkdir(parents=True, exist_ok=True)
        np.savez(path, tip=run.tip_xz, wall=run.wall_s, energy_drift=drift)
    return run.tip_xz, run.wall_s, drift


def _study(case, cells, rtol, rtol_check, cache, length):
    """Refinement in cells and in rtol; returns (Richardson trajectory, provenance note)."""
    tips = {}
    for n in cells:
        tips[n], wall, drift = _run_cached(case, n, rtol, cache)
        print(f"{case:9s} n={n:4d} rtol={rtol:.0e} {METHODS[case]}: wall {wall:7.1f} s, "
              f"energy change {drift:.2e} J, tip(1.5 s) = {tips[n][-1]}", flush=True)
    finest, second, third = cells[-1], cells[-2], cells[-3]
    tight, _, _ = _run_cached(case, finest, rtol_check, cache)
    time_err = np.max(np.abs(tight - tips[finest])) / length
    print(f"{case}: max|tip(rtol {rtol_check:.0e}) - tip(rtol {rtol:.0e})| at n={finest}: "
          f"{time_err:.2e} L")
    pairs = list(itertools.pairwise(cells))
    diffs = [np.max(np.abs(tips[b] - tips[a])) for a, b in pairs]
    for (a, b), d in zip(pairs, diffs, strict=True):
        print(f"{case}: max|tip(n={b}) - tip(n={a})| = {d / length:.3e} L")
    orders = [math.log2(d0 / d1) for d0, d1 in itertools.pairwise(diffs)]
    print(f"{case}: observed orders " + ", ".join(f"{p:.2f}" for p in orders))
    extrap = richardson(tips[finest], tips[second])
    raw_err = np.max(np.abs(extrap - tips[finest])) / length
    extrap_err = np.max(np.abs(extrap - richardson(tips[second], tips[third]))) / length
    print(f"{case}: n={finest} differs from the Richardson value by {raw_err:.2e} L; "
          f"successive Richardson values differ by {extrap_err:.2e} L", flush=True)
    note = (f"# {case} (tau = {CASES[case]} s, {METHODS[case]}): estimated error "
            f"{max(extrap_err, time_err):.0e} L = max(Richardson n={second}/{finest} vs "
            f"n={third}/{second}: {extrap_err:.1e} L,\n#   rtol {rtol:.0e} vs {rtol_check:.0e} "
            f"at n={finest}: {time_err:.1e} L); n={finest} alone differs by {raw_err:.1e} L; "
            f"observed orders " + ", ".join(f"{p:.2f}" for p in orders))
    return extrap, note


def main(argv=None) -> None:
    """Convergence study in n_cells and rtol, then write the reference file (_DATA)."""
    import argparse

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("--cells", type=int, nargs="+", default=[20, 40, 80, 160])
    parser.add_argument("--rtol", type=float, default=1e-9)
    parser.add_argument("--rtol-check", type=float, default=1e-10,
                        help="a tighter tolerance at the finest mesh (time-error estimate)")
    parser.add_argument("--cache", type=Path, default=None, help="directory of cached runs")
    parser.add_argument("--write", action="store_true", help=f"write {_DATA}")
    args = parser.parse_args(argv)
    length = swinging_arm().length
    result, notes = {}, []
    for case in CASES:
        result[case], note = _study(case, args.cells, args.rtol, args.rtol_check, args.cache,
                                    length)
        notes.append(note)
    if not args.write:
        return
    cells = " ".join(map(str, args.cells))
    header = [
        "# Swinging arm (helpers/swing.md): tip position (x, z) in m of the planar Reissner",
        "# rod clamped at the origin along +x, released straight at rest, gravity 9.81 m/s^2",
        "# along -z. L = 0.5 m, r = 0.02 m, E = 1e6 Pa, G = E/3, k = 0.9, rho = 1100 kg/m^3;",
        "# damped: Kelvin-Voigt tau = 0.01 s. Method of lines (tests/_mol_rod.py: staggered",
        "# finite differences, lumped masses, scipy solve_ivp), Richardson extrapolation",
        f"# (order 2) of n = {args.cells[-2]} and {args.cells[-1]} cells, rtol {args.rtol:.0e},"
        " atol = rtol * L.",
        f"# Regenerate: python tests/_mol_rod.py --write --cells {cells} --rtol {args.rtol:.0e}"
        f" --rtol-check {args.rtol_check:.0e}",
        *notes,
        "t_s,x_undamped_m,z_undamped_m,x_damped_m,z_damped_m",
    ]
    rows = np.column_stack([T_EVAL, result["undamped"], result["damped"]])
    lines = [f"{r[0]:.2f}," + ",".join(f"{v:.10f}" for v in r[1:]) for r in rows]
    _DATA.parent.mkdir(exist_ok=True)
    _DATA.write_text("\n".join(header + lines) + "\n")
    print(f"wrote {_DATA}")


def load_reference(case: str = "undamped"):
    """(t, tip_xz) of ``case`` ('undamped' or 'damped') from the reference file (read by the
    package's reader: softarm reproduce uses it too)."""
    from softarm.validation._motion import swinging_arm_reference

    if case not in CASES:
        raise ValueError(f"case must be one of {sorted(CASES)}, got {case!r}")
    return swinging_arm_reference(case)


if __name__ == "__main__":
    main()
