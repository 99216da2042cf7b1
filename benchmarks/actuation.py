"""Actuation benchmark (issue 14): a 3-tendon robot under gravity.

softarm's exact solver against a shooting implementation of Rucker & Webster's tendon model
written here with scipy (``solve_ivp`` + ``optimize.root``, the way users code it today), at
matched accuracy (tip within 1e-6 L of a tight reference), and a batch of 10⁴ random tension
triples in one call. Wall time (``perf_counter``) and CPU time (``process_time``) side by side;
medians over repeats. Run::

    python benchmarks/actuation.py [--cases 10000] [--repeats 15]

Targets (issue 14): ≤ 1 ms per exact solve at 1e-6 L, ≥ 50× faster than the scipy shooting,
10⁴ batched cases ≤ 5 s.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import root

import softarm
from softarm._threads import threads_for
from softarm.routing import Straight
from softarm.statics.solver import CASES_PER_THREAD

L = 0.25
RADIUS = 0.0006
E, NU = 6.0e10, 0.33
MU = 0.02  # kg/m: backbone and spacer disks
OFFSETS = np.array([[0.0, 0.008], [0.006928, -0.004], [-0.006928, -0.004]])  # (y, z), m
TENSIONS = np.array([3.0, 1.0, 0.0])  # N
GRAVITY = np.array([0.0, 0.0, -9.81])


def robot():
    material = softarm.Material(E, poisson_ratio=NU, density=6450.0)
    return softarm.Arm(L, softarm.Circle(RADIUS), material, mass_per_length=MU)


def loads(tensions):
    tensions = np.asarray(tensions, dtype=float)
    return [softarm.Gravity(GRAVITY)] + [
        softarm.Tendon(tensions[..., i], Straight(*OFFSETS[i])) for i in range(3)]


# --------------------------------------------------------------------------------------------
# A scipy shooting implementation of the Rucker–Webster model (total-wrench form)
# --------------------------------------------------------------------------------------------

def _hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def scipy_shooting(arm, tensions, rtol):
    """Tip position by shooting on the base wrench: per right-hand-side evaluation, the
    6 × 6 Newton solve of the constitutive law with tendons (numpy)."""
    K = arm.stiffness
    r = np.array([[0.0, y, z] for y, z in OFFSETS])
    f_dist = MU * GRAVITY

    def strain(sigma):
        eps = np.array([1.0, 0, 0, 0, 0, 0]) + np.linalg.solve(
            K, sigma - sum(t * np.r_[1.0, 0, 0, np.cross(ri, [1.0, 0, 0])]
                           for t, ri in zip(tensions, r, strict=True)))
        for _ in range(20):
            F = K @ (eps - np.r_[1.0, 0, 0, 0, 0, 0]) - sigma
            H = K.copy()
            for t, ri in zip(tensions, r, strict=True):
                w = eps[:3] + np.cross(eps[3:], ri)
                nw = np.linalg.norm(w)
                tt = w / nw
                F += t * np.r_[tt, np.cross(ri, tt)]
                J = np.hstack([np.eye(3), -_hat(ri)])
                H += t / nw * J.T @ (np.eye(3) - np.outer(tt, tt)) @ J
            step = np.linalg.solve(H, -F)
            eps += step
            if np.max(np.abs(step)) < 1e-14:
                break
        return eps

    def rhs(_s, y):
        R = y[3:12].reshape(3, 3)
        n, m = y[12:15], y[15:18]
        eps = strain(np.r_[R.T @ n, R.T @ m])
        dp = R @ eps[:3]
        dR = R @ _hat(eps[3:])
        return np.r_[dp, dR.ravel(), -f_dist, -np.cross(dp, n)]

    def shoot(x):
        y0 = np.r_[np.zeros(3), np.eye(3).ravel(), x]
        sol = solve_ivp(rhs, (0.0, L), y0, method="RK45", rtol=rtol, atol=rtol * 1e-3)
        return sol.y[:, -1]

    guess = np.r_[-f_dist * L, np.cross([L / 2, 0, 0], -f_dist * L)]
    sol = root(lambda x: shoot(x)[12:], guess, method="hybr", tol=1e-12)
    return shoot(sol.x)[:3]


def _median_time(fn, repeats):
    walls, cpus = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=10_000)
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args(argv)
    arm = robot()
    case = loads(TENSIONS)
    reference = softarm.solve(arm, case, tol=1e-12).tip_position
    print(f"3-tendon nitinol robot under gravity, L = {L} m, tensions {TENSIONS.tolist()} N")
    print(f"reference tip (softarm tol 1e-12): {reference}")

    # softarm at 1e-6 L (warm: compiled, a fresh Solver each call as softarm.solve does)
    softarm.solve(arm, case, tol=1e-6)
    tip = softarm.solve(arm, case, tol=1e-6).tip_position
    sa_wall, sa_cpu = _median_time(lambda: softarm.solve(arm, case, tol=1e-6), args.repeats)
    sa_err = np.linalg.norm(tip - reference) / L
    prepared = softarm.statics.Solver(arm, tol=1e-6)
    warm_wall, warm_cpu = _median_time(lambda: prepared.solve(case), args.repeats)
    print(f"softarm.solve tol=1e-6:          {1e3 * sa_wall:8.3f} ms wall, {1e3 * sa_cpu:8.3f} "
          f"ms CPU, tip error {sa_err:.1e} L")
    print(f"prepared Solver (warm re-solve): {1e3 * warm_wall:8.3f} ms wall, "
          f"{1e3 * warm_cpu:8.3f} ms CPU")
    # the same solve with the tip as the only output (s=2: base and tip; each of the default
    # 101 stations costs one RK4 sub-step, each solving the tendon law 4 times)
    tip_err = np.linalg.norm(softarm.solve(arm, case, tol=1e-6, s=2).tip_position
                             - reference) / L
    tip_wall, tip_cpu = _median_time(lambda: softarm.solve(arm, case, tol=1e-6, s=2),
                                     args.repeats)
    print(f"softarm.solve tol=1e-6, tip only: {1e3 * tip_wall:8.3f} ms wall, "
          f"{1e3 * tip_cpu:8.3f} ms CPU, tip error {tip_err:.1e} L (s=2)")

    # scipy: loosen rtol until the tip error exceeds 1e-6 L; time the loosest that meets it
    chosen = None
    for rtol in (1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7, 1e-8):
        err = np.linalg.norm(scipy_shooting(arm, TENSIONS, rtol) - reference) / L
        if err <= 1e-6:
            chosen = (rtol, err)
            break
    if chosen is None:
        print("scipy shooting: no rtol on the grid reached 1e-6 L")
    else:
        rtol, err = chosen
        sp_wall, sp_cpu = _median_time(lambda: scipy_shooting(arm, TENSIONS, rtol),
                                       max(3, args.repeats // 5))
        print(f"scipy shooting rtol={rtol:g}:      {1e3 * sp_wall:8.1f} ms wall, "
              f"{1e3 * sp_cpu:8.1f} ms CPU, tip error {err:.1e} L")
        print(f"ratio scipy / softarm: {sp_wall / sa_wall:.0f}× wall, {sp_cpu / sa_cpu:.0f}× CPU")

    rng = np.random.default_rng(1)
    tensions = rng.uniform(0.0, 3.0, size=(args.cases, 3))
    batch = loads(tensions)
    softarm.solve(arm, loads(tensions[:2]), tol=1e-6)
    t0, c0 = time.perf_counter(), time.process_time()
    eq = softarm.solve(arm, batch, tol=1e-6)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"{args.cases} batched tension triples, tol=1e-6: {wall:.2f} s wall, {cpu:.2f} s "
          f"CPU ({1e3 * wall / args.cases:.3f} ms a case); largest error estimate "
          f"{np.max(eq.error_estimate):.1e} m")
    t0, c0 = time.perf_counter(), time.process_time()
    eq = softarm.solve(arm, batch, tol=1e-6, s=2)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"the same batch, tip only (s=2): {wall:.2f} s wall, {cpu:.2f} s CPU "
          f"({1e3 * wall / args.cases:.3f} ms a case)")
    t0, c0 = time.perf_counter(), time.process_time()
    softarm.solve(arm, batch, tol=1e-6, threads=1)
    wall1, cpu1 = time.perf_counter() - t0, time.process_time() - c0
    print(f"the same batch, 101 stations, on one thread (threads=1): {wall1:.2f} s wall, "
          f"{cpu1:.2f} s CPU; the batches above ran on "
          f"{threads_for(args.cases, CASES_PER_THREAD)} thread(s)")


if __name__ == "__main__":
    main()
