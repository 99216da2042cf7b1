"""Peer implementations that softarm's benchmarks compare against (issue 7).

Three independent ways a user would compute the static equilibrium of a cantilevered
Cosserat rod without softarm:

* :func:`solve_bvp_cosserat` -- the Simo-Reissner rod as a two-point boundary-value problem
  for :func:`scipy.integrate.solve_bvp` (collocation), straight-rod initial guess and load
  continuation when the direct solve fails;
* :func:`shooting_cosserat` -- Rucker-style shooting: :func:`scipy.integrate.solve_ivp` from the
  clamped base with the unknown base wrench, :func:`scipy.optimize.root` on the tip-wrench
  residual, load stepping when the direct solve fails;
* :func:`pyelastica_static` -- PyElastica (``import elastica``) relaxed to rest by damped
  dynamics.

The module does not import softarm: it is the independent side of the comparison.

Conventions (the same as softarm's): SI units; 6-vectors linear part first, strain (gamma; kappa),
wrench (n; m); the arm axis is the material e1 (x); the base is clamped at the origin with
R(0) = I; the stiffness is K = diag(EA, GAy, GAz, GJ, EIy, EIz) in material components.

The equations solved by the two scipy peers (arc length s in [0, L], spatial n and m)::

    p' = R v,   R' = R hat(u),   n' = -f,   m' = -p' x n - l,
    v  = v0 + Kuu^-1 R^T n,      u  = u0 + Kww^-1 R^T m,      v0 = (1, 0, 0),

with f the distributed dead force per unit length (N/m, spatial) and l = 0 (no distributed
moment). Boundary conditions: p(0) = 0, R(0) = I, n(L) = tip force, m(L) = tip moment.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
from scipy.integrate import solve_bvp, solve_ivp
from scipy.optimize import root

__all__ = [
    "PeerResult",
    "RodProblem",
    "pyelastica_problem",
    "pyelastica_static",
    "pyelastica_warmup",
    "shooting_cosserat",
    "solve_bvp_cosserat",
]

_E1 = np.array([1.0, 0.0, 0.0])


# --------------------------------------------------------------------------------------------
# Problem and result types
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RodProblem:
    """A uniform cantilevered Cosserat rod with a tip load and a distributed dead force.

    Parameters
    ----------
    length : float
        Rod length L in m.
    EA, GAy, GAz : float
        Axial and shear stiffnesses in N (material e1, e2, e3).
    GJ, EIy, EIz : float
        Torsional and bending stiffnesses in N m^2 (about material e1, e2, e3).
    curvature : (3,) floats
        Intrinsic (stress-free) curvature u0 in 1/m, material components.
    tip_force : (3,) floats
        Tip force in N. Spatial components (dead load) unless ``follower`` is true, in which
        case these are the components in the tip's material frame (a follower load).
    tip_moment : (3,) floats
        Dead tip moment in N m, spatial components.
    follower : bool
        Whether ``tip_force`` follows the tip's material frame.
    gravity_per_length : (3,) floats
        Distributed dead force per unit length in N/m, spatial frame (e.g. rho A g).
    radius, density : float or None
        Circular radius in m and density in kg/m^3, used only by :func:`pyelastica_static`
        (PyElastica needs a mass and a cross-section; statics does not).
    """

    length: float
    EA: float
    GAy: float
    GAz: float
    GJ: float
    EIy: float
    EIz: float
    curvature: tuple = (0.0, 0.0, 0.0)
    tip_force: tuple = (0.0, 0.0, 0.0)
    tip_moment: tuple = (0.0, 0.0, 0.0)
    follower: bool = False
    gravity_per_length: tuple = (0.0, 0.0, 0.0)
    radius: float | None = None
    density: float | None = None

    def __post_init__(self):
        for name in ("length", "EA", "GAy", "GAz", "GJ", "EIy", "EIz"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"RodProblem.{name} must be positive and finite, got {value!r}")
        for name in ("curvature", "tip_force", "tip_moment", "gravity_per_length"):
            value = np.asarray(getattr(self, name), dtype=np.float64)
            if value.shape != (3,) or not np.all(np.isfinite(value)):
                raise ValueError(
                    f"RodProblem.{name} must be 3 finite numbers, got {getattr(self, name)!r}"
                )
            object.__setattr__(self, name, tuple(float(x) for x in value))

    @property
    def k_uu(self) -> np.ndarray:
        """Diagonal of the shear/stretch stiffness (EA, GAy, GAz) in N."""
        return np.array([self.EA, self.GAy, self.GAz])

    @property
    def k_ww(self) -> np.ndarray:
        """Diagonal of the twist/bending stiffness (GJ, EIy, EIz) in N m^2."""
        return np.array([self.GJ, self.EIy, self.EIz])

    def scaled(self, fraction: float) -> RodProblem:
        """The same rod with every applied load multiplied by ``fraction`` (continuation)."""
        return replace(
            self,
            tip_force=tuple(fraction * np.asarray(self.tip_force)),
            tip_moment=tuple(fraction * np.asarray(self.tip_moment)),
            gravity_per_length=tuple(fraction * np.asarray(self.gravity_per_length)),
        )


class PeerResult(NamedTuple):
    """What every peer returns.

    Attributes
    ----------
    tip_position : (3,) ndarray
        Tip position p(L) in m, spatial frame.
    seconds : float
        Wall time of the solve (``time.perf_counter``), set-up included, in s. ``info`` also
        has ``cpu_seconds`` (``time.process_time``), steadier on a shared machine.
    n_steps : int
        Load steps used (scipy peers; 1 = direct solve succeeded) or time steps (PyElastica).
    info : dict
        Peer-specific details (mesh size, function evaluations, settings, ...).
    """

    tip_position: np.ndarray
    seconds: float
    n_steps: int
    info: dict


# --------------------------------------------------------------------------------------------
# Shared Cosserat right-hand side (spatial n, m; R stored row-major in 9 entries)
# --------------------------------------------------------------------------------------------
def _rhs(problem: RodProblem, f_dist: np.ndarray, y: np.ndarray) -> np.ndarray:
    """d/ds of the state y = (p, R.ravel(), n, m), shape (18,) or (18, m)."""
    scalar = y.ndim == 1
    if scalar:
        y = y[:, None]
    R = y[3:12].reshape(3, 3, -1)
    n = y[12:15]
    m = y[15:18]
    v = _E1[:, None] + np.einsum("jik,jk->ik", R, n) / problem.k_uu[:, None]
    u = (
        np.asarray(problem.curvature)[:, None]
        + np.einsum("jik,jk->ik", R, m) / problem.k_ww[:, None]
    )
    dp = np.einsum("ijk,jk->ik", R, v)
    # R' = R hat(u), hat(u) the skew (cross-product) matrix of u, built per node.
    zero = np.zeros_like(u[0])
    u_hat = np.array([[zero, -u[2], u[1]], [u[2], zero, -u[0]], [-u[1], u[0], zero]])
    dR = np.einsum("ijk,jlk->ilk", R, u_hat)
    dn = -np.broadcast_to(f_dist[:, None], n.shape)
    dm = -np.cross(dp, n, axis=0)
    out = np.concatenate([dp, dR.reshape(9, -1), dn, dm], axis=0)
    return out[:, 0] if scalar else out


def _tip_wrench(problem: RodProblem, R_tip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Spatial tip force and moment; a follower force is rotated by the tip orientation."""
    force = np.asarray(problem.tip_force)
    if problem.follower:
        force = R_tip @ force
    return force, np.asarray(problem.tip_moment)


def _load_scales(problem: RodProblem) -> tuple[float, float]:
    """Force (N) and moment (N m) scales used to non-dimensionalise residuals."""
    L = problem.length
    force = (
        np.linalg.norm(problem.tip_force)
        + np.linalg.norm(problem.gravity_per_length) * L
        + np.linalg.norm(problem.tip_moment) / L
    )
    force = max(force, min(problem.EIy, problem.EIz) / L**2 * 1e-3)
    return force, force * L


# --------------------------------------------------------------------------------------------
# 1. scipy.integrate.solve_bvp
# --------------------------------------------------------------------------------------------
def _bvp_attempt(problem, tol, s, y_guess, max_nodes):
    f_dist = np.asarray(problem.gravity_per_length)
    force_scale, moment_scale = _load_scales(problem)

    def fun(_s, y):
        return _rhs(problem, f_dist, y)

    def bc(ya, yb):
        force, moment = _tip_wrench(problem, yb[3:12].reshape(3, 3))
        return np.concatenate(
            [
                ya[0:3] / problem.length,
                ya[3:12] - np.eye(3).ravel(),
                (yb[12:15] - force) / force_scale,
                (yb[15:18] - moment) / moment_scale,
            ]
        )

    return solve_bvp(fun, bc, s, y_guess, tol=tol, max_nodes=max_nodes, bc_tol=tol)


def _straight_guess(problem: RodProblem, s: np.ndarray) -> np.ndarray:
    """Undeformed straight rod carrying the rigid-body (statically determinate) wrench."""
    y = np.zeros((18, s.size))
    y[0] = s
    y[3:12] = np.eye(3).ravel()[:, None]
    f = np.asarray(problem.gravity_per_length)
    force, moment = _tip_wrench(problem, np.eye(3))
    L = problem.length
    # n(s) = F + f (L - s); m(s) = M + (p_L - p(s)) x F + integral_s^L (p(t) - p(s)) x f dt.
    y[12:15] = force[:, None] + f[:, None] * (L - s)
    arm_tip = np.stack([L - s, 0 * s, 0 * s])
    arm_dist = 0.5 * np.stack([(L - s) ** 2, 0 * s, 0 * s])
    y[15:18] = (
        moment[:, None]
        + np.cross(arm_tip, force[:, None], axis=0)
        + np.cross(arm_dist, f[:, None], axis=0)
    )
    return y


def solve_bvp_cosserat(
    problem: RodProblem,
    tol: float = 1e-6,
    n_nodes: int = 21,
    max_nodes: int = 100_000,
    max_load_steps: int = 64,
) -> PeerResult:
    """Static equilibrium with :func:`scipy.integrate.solve_bvp` (4th-order collocation).

    The state is y = (p (3), R row-major (9), n (3), m (3)), all spatial; 18 equations and
    18 boundary conditions (p(0) = 0, R(0) = I, n(L), m(L) = tip wrench). R is integrated as
    nine free entries, as a user would; collocation keeps it orthogonal to the solver's
    tolerance. The initial guess is the undeformed straight rod on ``n_nodes`` uniform nodes
    carrying the statically determinate wrench. If the direct solve fails, the loads are
    applied in growing fractions, each solve warm-started from the previous mesh and solution;
    a failed step halves the increment.

    Parameters
    ----------
    problem : RodProblem
    tol : float
        ``solve_bvp`` relative residual tolerance (also used as ``bc_tol``).
    n_nodes : int
        Initial uniform mesh size (solve_bvp refines it adaptively up to ``max_nodes``).
    max_nodes : int
        Mesh-size cap passed to ``solve_bvp``.
    max_load_steps : int
        Cap on the number of continuation steps.

    Returns
    -------
    PeerResult
        ``n_steps`` is the number of solve_bvp calls that succeeded (1 = direct solve);
        ``info`` holds the final mesh size and the failed attempts.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    s = np.linspace(0.0, problem.length, n_nodes)
    sol = _bvp_attempt(problem, tol, s, _straight_guess(problem, s), max_nodes)
    steps, failures = 1, 0
    if not sol.success:
        failures += 1
        steps = 0
        lam, dlam = 0.0, 0.25
        s_prev = s
        y_prev = _straight_guess(problem.scaled(0.0), s)
        while lam < 1.0:
            if steps + failures > max_load_steps:
                raise RuntimeError(f"solve_bvp_cosserat: continuation stalled at load {lam:.3g}")
            target = min(1.0, lam + dlam)
            trial = _bvp_attempt(problem.scaled(target), tol, s_prev, y_prev, max_nodes)
            if trial.success:
                lam, s_prev, y_prev, sol = target, trial.x, trial.y, trial
                steps += 1
                dlam = min(2 * dlam, 0.5)
            else:
                failures += 1
                dlam /= 2
                if dlam < 1e-4:
                    raise RuntimeError(
                        "solve_bvp_cosserat: continuation failed at load "
                        f"{lam:.3g}: {trial.message}"
                    )
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    return PeerResult(
        sol.y[0:3, -1].copy(),
        seconds,
        steps,
        {
            "mesh_nodes": sol.x.size,
            "failed_attempts": failures,
            "message": sol.message,
            "cpu_seconds": cpu,
        },
    )


# --------------------------------------------------------------------------------------------
# 2. Shooting (Rucker-style)
# --------------------------------------------------------------------------------------------
def _shoot(problem, base_wrench, rtol, atol, method):
    f_dist = np.asarray(problem.gravity_per_length)
    y0 = np.concatenate([np.zeros(3), np.eye(3).ravel(), base_wrench])
    return solve_ivp(
        lambda _s, y: _rhs(problem, f_dist, y),
        (0.0, problem.length),
        y0,
        method=method,
        rtol=rtol,
        atol=atol,
    )


def _shooting_attempt(problem, guess, rtol, atol, method, root_method, root_tol):
    force_scale, moment_scale = _load_scales(problem)
    scale = np.array([force_scale] * 3 + [moment_scale] * 3)
    nfev = [0]

    def residual(x):
        nfev[0] += 1
        ivp = _shoot(problem, x * scale, rtol, atol, method)
        if not ivp.success:
            return np.full(6, 1e3)
        yb = ivp.y[:, -1]
        force, moment = _tip_wrench(problem, yb[3:12].reshape(3, 3))
        return np.concatenate([yb[12:15] - force, yb[15:18] - moment]) / scale

    sol = root(residual, guess / scale, method=root_method, tol=root_tol)
    ok = sol.success and np.max(np.abs(residual(sol.x))) < max(100 * root_tol, 1e-9)
    return ok, sol.x * scale, nfev[0]


def shooting_cosserat(
    problem: RodProblem,
    tol: float = 1e-8,
    method: str = "DOP853",
    root_method: str = "hybr",
    max_load_steps: int = 64,
) -> PeerResult:
    """Static equilibrium by shooting on the base wrench (Rucker & Webster style).

    Unknowns: the spatial base wrench (n(0), m(0)). Each residual evaluation integrates the
    18-state Cosserat ODE from the clamped base with :func:`scipy.integrate.solve_ivp`
    (``rtol = tol``, ``atol = tol * 1e-2`` on the state, whose entries are O(L), O(1) and
    O(load)), and compares the tip wrench with the applied one; :func:`scipy.optimize.root`
    drives the non-dimensional residual to zero. The first guess is the statically
    determinate wrench of the straight rod. If the direct solve fails, the load is stepped
    up (quarters, halving after a failure), each step warm-started.

    Parameters
    ----------
    problem : RodProblem
    tol : float
        Integrator relative tolerance; root tolerance ``tol`` on the scaled residual.
    method : str
        ``solve_ivp`` method (``"DOP853"`` or ``"RK45"``).
    root_method : str
        ``scipy.optimize.root`` method (``"hybr"`` or ``"lm"``).
    max_load_steps : int
        Cap on the number of continuation steps.

    Returns
    -------
    PeerResult
        ``n_steps`` counts the successful root solves; ``info`` has the number of ODE
        integrations (``nfev``) and the base wrench.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    rtol, atol = tol, tol * 1e-2
    root_tol = tol

    def guess_for(prob):
        y = _straight_guess(prob, np.array([0.0]))
        return y[12:18, 0]

    total_nfev = 0
    ok, x, nfev = _shooting_attempt(
        problem, guess_for(problem), rtol, atol, method, root_method, root_tol
    )
    total_nfev += nfev
    steps, failures = 1, 0
    if not ok:
        failures, steps = 1, 0
        lam, dlam = 0.0, 0.25
        x = guess_for(problem.scaled(0.0))
        while lam < 1.0:
            if steps + failures > max_load_steps:
                raise RuntimeError(f"shooting_cosserat: continuation stalled at load {lam:.3g}")
            target = min(1.0, lam + dlam)
            prob = problem.scaled(target)
            # Warm start: previous base wrench plus the rigid-body increment of the load.
            guess = x + guess_for(prob) - guess_for(problem.scaled(lam))
            ok, x_new, nfev = _shooting_attempt(
                prob, guess, rtol, atol, method, root_method, root_tol
            )
            total_nfev += nfev
            if ok:
                lam, x = target, x_new
                steps += 1
                dlam = min(2 * dlam, 0.5)
            else:
                failures += 1
                dlam /= 2
                if dlam < 1e-4:
                    raise RuntimeError(f"shooting_cosserat: continuation failed at load {lam:.3g}")
    tip = _shoot(problem, x, rtol, atol, method).y[0:3, -1].copy()
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    return PeerResult(
        tip,
        seconds,
        steps,
        {"nfev": total_nfev, "failed_attempts": failures, "base_wrench": x, "cpu_seconds": cpu},
    )


# --------------------------------------------------------------------------------------------
# 3. PyElastica: damped dynamics relaxed to rest
# --------------------------------------------------------------------------------------------
# PyElastica's CosseratRod (v1.0.0, elastica/rod/factory_function.py) builds its stiffness from a
# circular section of radius r: shear/stretch matrix diag(alpha_c G A, alpha_c G A, E A) with
# alpha_c = 27/28 (Kaneko/Hutchinson's circle value for nu = 0.5; some older docs and papers quote
# 4/3), bend/twist matrix diag(E I, E I, G 2I), I = pi r^4 / 4. Its material axes are
# (d1, d2, d3) with d3 the rod tangent; we pass direction = x and normal = y, so d1 = our e2,
# d2 = our e3, d3 = our e1, and our diag(EA, GAy, GAz) -> its diag(GAy, GAz, EA), our
# diag(GJ, EIy, EIz) -> its diag(EIy, EIz, GJ). Its arrays are component-first: position (3, n+1),
# directors (3, 3, n) with rows d_i (the transpose of our R), external torques in material frame.
_SHEAR_ALPHA_C = 27.0 / 28.0


def pyelastica_problem(problem: RodProblem, stiffness: str = "problem") -> RodProblem:
    """The rod that :func:`pyelastica_static` actually simulates, as a :class:`RodProblem`.

    ``stiffness="problem"``: PyElastica's matrices are overwritten with the problem's K, so it
    solves the same continuum problem (only its discretisation and its stopping rule differ).
    ``stiffness="material"``: the plain PyElastica user route, a circle of ``problem.radius``
    with E = EIy / I and G = GJ / (2 I): then EIz = EIy, EA = E pi r^2 and
    GA = (27/28) G pi r^2 follow from the section and generally differ from the problem's
    (e.g. an 'inextensible' reference). Use this to separate PyElastica's modelling error from
    its discretisation and convergence error.
    """
    if stiffness == "problem":
        return problem
    if stiffness != "material":
        raise ValueError(f"stiffness must be 'problem' or 'material', got {stiffness!r}")
    if problem.radius is None:
        raise ValueError("pyelastica_problem: problem.radius is required for stiffness='material'")
    r = problem.radius
    area, inertia = math.pi * r**2, math.pi * r**4 / 4
    youngs, shear = problem.EIy / inertia, problem.GJ / (2 * inertia)
    return replace(
        problem,
        EA=youngs * area,
        GAy=_SHEAR_ALPHA_C * shear * area,
        GAz=_SHEAR_ALPHA_C * shear * area,
        EIz=problem.EIy,
    )


def _require_elastica():
    try:
        import elastica
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "pyelastica_static needs PyElastica, which is not installed "
            '(pip install ".[bench]" or pip install pyelastica)'
        ) from exc
    return elastica


def pyelastica_static(
    problem: RodProblem,
    n_elements: int = 50,
    stiffness: str = "problem",
    clamp: str = "node",
    damping_ratio: float = 1.0,
    cfl: float = 0.8,
    speed_tol: float | None = None,
    max_time: float | None = None,
    ramp_periods: float = 0.5,
    check_every: int = 200,
) -> PeerResult:
    """Static equilibrium by damped dynamics in PyElastica, run until the rod is at rest.

    Set-up as in PyElastica's own examples: ``CosseratRod.straight_rod`` along x (normal y),
    ``OneEndFixedBC`` at node/element 0 (``clamp="node"``), ``EndpointForces`` (dead tip
    force), ``GravityForces``
    (acceleration chosen so that the distributed force per unit length equals
    ``problem.gravity_per_length`` with PyElastica's mass rho pi r^2), a small custom forcing
    for a follower tip force or a dead tip moment (PyElastica has neither built in),
    ``AnalyticalLinearDamper`` and the ``PositionVerlet`` stepper.

    Tuning (documented, not per-case): with omega1 = 3.516 sqrt(EI_min / (rho A L^4)) the
    first cantilever bending frequency,

    * damping: ``uniform_damping_constant = 2 * damping_ratio * omega1`` (1/s), i.e. critical
      damping of the slowest mode at ``damping_ratio = 1``; all modes are damped alike, the
      stiffer ones under-critically but decaying at the same rate omega1;
    * time step: ``cfl`` times the explicit stability limit 2/omega_max of the fastest mode
      (0.8; 0.9 was still stable on every case, 1.2 blew up),
      estimated from the axial and shear waves (2 c / dx) and the shear-rotation mode
      sqrt(4 EI / (rho I dx^2) + GA / (rho I)) of one element;
    * loads: tip loads ramped linearly over ``ramp_periods`` first-mode periods (gravity is
      applied at once, as ``GravityForces`` does);
    * stop: the largest nodal speed is below ``speed_tol`` on three consecutive checks
      (every ``check_every`` steps) after the ramp; default ``speed_tol = 1e-5 L omega1``,
      i.e. a remaining creep distance of about speed / omega1 = 1e-5 L. Or at ``max_time``
      (default 20 first-mode periods). A blow-up (speed above 1e3 L omega1) raises.

    Clamp. PyElastica stores directors on elements, so ``OneEndFixedBC`` fixes the director
    of the first element, i.e. R = I at the element centre s = dx/2 rather than at s = 0: the
    whole rod lags by the rotation kappa(0) dx / 2 and the tip error is first order in dx
    (measured: 2e-2 L at 50 elements for pure bending kL = 3). ``clamp="centred"`` is the
    second-order alternative: the rod starts at x = -dx/2 with dx = L / (n - 1/2), so the first
    element straddles the clamp and its centre sits at the origin; nodes 0 and 1 and element 0
    are held by ``FixedConstraint``. Same library, same elements, only the clamp placement.

    Parameters
    ----------
    problem : RodProblem
        Must have ``radius`` and ``density`` (mass and rotational inertia of the dynamics).
    n_elements : int
        Number of PyElastica elements.
    stiffness : {"problem", "material"}
        See :func:`pyelastica_problem`.
    clamp : {"node", "centred"}
        PyElastica's standard clamp or the element-centred one, see above.
    damping_ratio, cfl, speed_tol, max_time, ramp_periods, check_every
        Tuning, see above.

    Returns
    -------
    PeerResult
        ``n_steps`` is the number of time steps; ``info`` has dt, the damping constant, the
        simulated time and whether the speed criterion was met.

    Raises
    ------
    ImportError
        If PyElastica is not installed.
    """
    ea = _require_elastica()
    if problem.radius is None or problem.density is None:
        raise ValueError("pyelastica_static: problem.radius and problem.density are required")
    if problem.curvature != (0.0, 0.0, 0.0):
        raise ValueError("pyelastica_static: only initially straight rods are set up here")
    model = pyelastica_problem(problem, stiffness)
    t0, c0 = time.perf_counter(), time.process_time()

    if clamp not in ("node", "centred"):
        raise ValueError(f"clamp must be 'node' or 'centred', got {clamp!r}")
    L, r, rho = model.length, model.radius, model.density
    area, inertia = math.pi * r**2, math.pi * r**4 / 4
    dx = L / n_elements if clamp == "node" else L / (n_elements - 0.5)
    start = np.zeros(3) if clamp == "node" else np.array([-0.5 * dx, 0.0, 0.0])
    ei_min = min(model.EIy, model.EIz)
    omega1 = 3.516 * math.sqrt(ei_min / (rho * area * L**4))
    period1 = 2 * math.pi / omega1
    ga_max = max(model.GAy, model.GAz)
    omega_max = max(
        2 * math.sqrt(model.EA / (rho * area)) / dx,
        2 * math.sqrt(ga_max / (rho * area)) / dx,
        math.sqrt(
            4 * max(model.EIy, model.EIz, model.GJ) / (rho * inertia * dx**2)
            + ga_max / (rho * inertia)
        ),
    )
    dt = cfl * 2.0 / omega_max
    nu = 2.0 * damping_ratio * omega1
    ramp = ramp_periods * period1
    if speed_tol is None:
        speed_tol = 1e-5 * L * omega1
    if max_time is None:
        max_time = 20 * period1

    class _Sim(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.Damping):
        pass

    sim = _Sim()
    rod = ea.CosseratRod.straight_rod(
        n_elements,
        start,
        np.array([1.0, 0.0, 0.0]),
        np.array([0.0, 1.0, 0.0]),
        n_elements * dx,
        r,
        rho,
        youngs_modulus=model.EIy / inertia,
        shear_modulus=model.GJ / (2 * inertia),
    )
    # Overwrite the section-derived matrices with the (possibly anisotropic) target stiffness.
    # The shear matrix lives on elements; the bend matrix on Voronoi regions (uniform rod: same).
    rod.shear_matrix[...] = np.diag([model.GAy, model.GAz, model.EA])[:, :, None]
    rod.bend_matrix[...] = np.diag([model.EIy, model.EIz, model.GJ])[:, :, None]
    sim.append(rod)
    if clamp == "node":
        sim.constrain(rod).using(
            ea.OneEndFixedBC, constrained_position_idx=(0,), constrained_director_idx=(0,)
        )
    else:
        sim.constrain(rod).using(
            ea.FixedConstraint, constrained_position_idx=(0, 1), constrained_director_idx=(0,)
        )

    tip_force = np.asarray(model.tip_force)
    tip_moment = np.asarray(model.tip_moment)
    if model.follower:
        sim.add_forcing_to(rod).using(
            _follower_tip_force_cls(ea), force_material=tip_force, ramp_up_time=ramp
        )
    elif np.any(tip_force):
        sim.add_forcing_to(rod).using(
            ea.EndpointForces, start_force=np.zeros(3), end_force=tip_force, ramp_up_time=ramp
        )
    if np.any(tip_moment):
        sim.add_forcing_to(rod).using(
            _dead_tip_moment_cls(ea), moment_spatial=tip_moment, ramp_up_time=ramp
        )
    gravity = np.asarray(model.gravity_per_length)
    if np.any(gravity):
        sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=gravity / (rho * area))
    sim.dampen(rod).using(ea.AnalyticalLinearDamper, uniform_damping_constant=nu, time_step=dt)
    sim.finalize()

    stepper = ea.PositionVerlet()
    t, steps, quiet, converged = 0.0, 0, 0, False
    while t < max_time:
        for _ in range(check_every):
            t = stepper.step(sim, t, dt)
        steps += check_every
        speed = float(np.max(np.linalg.norm(rod.velocity_collection, axis=0)))
        if not (np.isfinite(speed) and speed < 1e3 * L * omega1):
            raise RuntimeError(f"pyelastica_static: unstable at t = {t:.3g} s (dt = {dt:.3g} s)")
        quiet = quiet + 1 if (t > ramp and speed < speed_tol) else 0
        if quiet >= 3:
            converged = True
            break
    tip = rod.position_collection[:, -1].copy()
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    return PeerResult(
        tip,
        seconds,
        steps,
        {
            "dt": dt,
            "cpu_seconds": cpu,
            "damping_constant": nu,
            "simulated_time": t,
            "converged": converged,
            "final_speed": speed,
            "speed_tol": speed_tol,
            "n_elements": n_elements,
            "stiffness": stiffness,
            "clamp": clamp,
        },
    )


def pyelastica_warmup() -> float:
    """Trigger PyElastica's numba compilation once (seconds taken); call before timing.

    PyElastica compiles its kernels on first use (about 30 s on a cold cache, about 1 s when
    numba's on-disk cache is warm); that one-off cost is not part of a static solve.
    """
    t0 = time.perf_counter()
    problem = RodProblem(
        1.0,
        1e3,
        1e3,
        1e3,
        1.0,
        1.0,
        1.0,
        tip_force=(0.0, 0.0, 0.1),
        tip_moment=(0.0, 0.01, 0.0),
        radius=0.05,
        density=1000.0,
    )
    pyelastica_static(problem, n_elements=5, max_time=1e-3, check_every=10)
    pyelastica_static(
        replace(problem, follower=True),
        n_elements=5,
        clamp="centred",
        max_time=1e-3,
        check_every=10,
    )
    return time.perf_counter() - t0


def _follower_tip_force_cls(ea):  # class factory: elastica is imported lazily
    class FollowerTipForce(ea.NoForces):
        """Tip force fixed in the last element's material frame, ramped up linearly."""

        def __init__(self, force_material, ramp_up_time):
            super().__init__()
            self.force_material = np.asarray(force_material, dtype=np.float64)
            self.ramp_up_time = ramp_up_time

        def apply_forces(self, system, time=0.0):
            factor = min(1.0, time / self.ramp_up_time)
            # PyElastica's directors map spatial to material (rows d_i), so spatial = Q^T f.
            # Its material axes are (d1, d2, d3) = (our e2, e3, e1): permute the components.
            f = self.force_material
            f_pyel = np.array([f[1], f[2], f[0]])
            system.external_forces[:, -1] += factor * system.director_collection[..., -1].T @ f_pyel

    return FollowerTipForce


def _dead_tip_moment_cls(ea):  # class factory: elastica is imported lazily
    class DeadTipMoment(ea.NoForces):
        """Tip moment fixed in space, applied to the last element, ramped up linearly."""

        def __init__(self, moment_spatial, ramp_up_time):
            super().__init__()
            self.moment_spatial = np.asarray(moment_spatial, dtype=np.float64)
            self.ramp_up_time = ramp_up_time

        def apply_torques(self, system, time=0.0):
            factor = min(1.0, time / self.ramp_up_time)
            # External torques are stored in material components.
            system.external_torques[:, -1] += (
                factor * system.director_collection[..., -1] @ self.moment_spatial
            )

    return DeadTipMoment
