"""The swinging arm (helpers/swing.md, undamped) in PyElastica: the coarsest passing setting.

Usage: ``python benchmarks/dynamics_pyelastica.py`` (needs ``pip install ".[bench]"``).

For each n_elem in (10, 20, 40, 80, 160) and each clamp placement, PyElastica's
``PositionVerlet`` runs the 1.5-s swing at the time step ``cfl * 2 / omega_max`` (the explicit
stability limit of the fastest element mode, rounded down to divide 0.01 s) and the tip is
compared with the method-of-lines reference
``src/softarm/validation/data/swinging_arm_mol.csv`` at t = 0, 0.01, ..., 1.5 s. The table
prints the max tip error (in L), wall and CPU seconds
(``time.process_time``); the coarsest setting with error <= 1e-3 L is reported by
:func:`coarsest_passing`, whose result (a :class:`Run`) is the cost to set softarm's own run
beside (see :func:`main`).

PyElastica conventions matched to softarm's model (K = diag(EA, kGA, kGA, GJ, EI, EI)):

* shear: PyElastica builds ``alpha_c G A`` with its fixed alpha_c = 27/28, so its
  ``shear_modulus`` is set to k G / alpha_c (k = 0.9, G = E/3): then its shear stiffness is
  the problem's kGA. Its GJ changes with it, which a planar swing does not see.
* mass and rotary inertia: rho A dx per element lumped half to each node (ends get half),
  rho I dx per element: the problem's rho A and rho I.
* gravity: ``GravityForces`` (-9.81 m/s^2 along z); no damper is added (undamped case).
* constitutive law: PyElastica scales its internal stresses by the element dilatation
  (n = S sigma / e, bending couple B kappa / e^3); softarm's law is linear in the strains.
  The axial strain here is below rho g L / E = 5e-3, so the two laws differ by that relative
  amount in the stretched, curved parts of the arm.
* clamp: ``OneEndFixedBC`` (clamp="node") fixes node 0 and the director of element 0, i.e.
  the clamped section sits at s = dx/2, a first-order error in dx. clamp="centred" shifts the
  rod by dx/2 so that element 0 straddles the origin and fixes nodes 0 and 1 and element 0
  (``FixedConstraint``): the same library and elements, only the clamp placed at its centre.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from _mol_rod import load_reference

LENGTH, RADIUS, YOUNGS, DENSITY, GRAVITY = 0.5, 0.02, 1.0e6, 1100.0, 9.81
SHEAR_FACTOR, SHEAR_MODULUS = 0.9, 1.0e6 / 3.0
PYELASTICA_ALPHA_C = 27.0 / 28.0  # fixed in elastica.rod.factory_function
TOLERANCE = 1e-3  # max tip error, in L
SAMPLE = 0.01  # s, the reference's sampling


class Run(NamedTuple):
    n_elem: int
    clamp: str
    dt: float
    steps: int
    max_tip_error: float  # in L, over t = 0, 0.01, ..., 1.5 s
    wall_s: float
    cpu_s: float


def stable_dt(n_elem: int, clamp: str = "node", cfl: float = 0.8) -> float:
    """``cfl`` times 2 / omega_max, omega_max from the axial wave and the element's
    shear-rotation mode, rounded down so that a whole number of steps makes 0.01 s."""
    dx = LENGTH / n_elem if clamp == "node" else LENGTH / (n_elem - 0.5)
    area, inertia = math.pi * RADIUS**2, math.pi * RADIUS**4 / 4
    k_ga = SHEAR_FACTOR * SHEAR_MODULUS * area
    omega_max = max(
        2 * math.sqrt(YOUNGS / DENSITY) / dx,
        math.sqrt(4 * YOUNGS * inertia / (DENSITY * inertia * dx**2) + k_ga / (DENSITY * inertia)),
    )
    dt = cfl * 2.0 / omega_max
    return SAMPLE / math.ceil(SAMPLE / dt)


def simulate(n_elem: int, dt: float, clamp: str = "node", duration: float = 1.5):
    """PyElastica's swinging arm: ``(t, tip_xz, wall_s, cpu_s)`` sampled every 0.01 s."""
    import elastica as ea

    class _Sim(ea.BaseSystemCollection, ea.Constraints, ea.Forcing):
        pass

    dx = LENGTH / n_elem if clamp == "node" else LENGTH / (n_elem - 0.5)
    start = np.zeros(3) if clamp == "node" else np.array([-0.5 * dx, 0.0, 0.0])
    wall0, cpu0 = time.perf_counter(), time.process_time()
    sim = _Sim()
    rod = ea.CosseratRod.straight_rod(
        n_elem, start, np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), n_elem * dx,
        RADIUS, DENSITY, youngs_modulus=YOUNGS,
        shear_modulus=SHEAR_FACTOR * SHEAR_MODULUS / PYELASTICA_ALPHA_C,
    )
    sim.append(rod)
    if clamp == "node":
        sim.constrain(rod).using(
            ea.OneEndFixedBC, constrained_position_idx=(0,), constrained_director_idx=(0,)
        )
    else:
        sim.constrain(rod).using(
            ea.FixedConstraint, constrained_position_idx=(0, 1), constrained_director_idx=(0,)
        )
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, 0.0, -GRAVITY]))
    sim.finalize()
    stepper = ea.PositionVerlet()
    per_sample = round(SAMPLE / dt)
    samples = round(duration / SAMPLE)
    tips = [rod.position_collection[[0, 2], -1].copy()]
    t = 0.0
    for _ in range(samples):
        for _ in range(per_sample):
            t = stepper.step(sim, t, dt)
        tips.append(rod.position_collection[[0, 2], -1].copy())
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    return np.arange(samples + 1) * SAMPLE, np.array(tips), wall, cpu


def run(n_elem: int, clamp: str = "node", cfl: float = 0.8) -> Run:
    """One setting against the MOL reference (a non-finite tip counts as error inf)."""
    dt = stable_dt(n_elem, clamp, cfl)
    t, tip, wall, cpu = simulate(n_elem, dt, clamp)
    t_ref, tip_ref = load_reference("undamped")
    if not np.allclose(t, t_ref, atol=1e-9):
        raise ValueError("the reference's sampling is not t = 0, 0.01, ..., 1.5 s")
    err = np.max(np.linalg.norm(tip - tip_ref, axis=1)) / LENGTH
    err = err if np.isfinite(err) else math.inf
    return Run(n_elem, clamp, dt, round(1.5 / dt), float(err), wall, cpu)


def warmup() -> None:
    """Compile PyElastica's numba kernels once (not part of any timing)."""
    simulate(5, 1e-4, "node", duration=0.01)
    simulate(5, 1e-4, "centred", duration=0.01)


def coarsest_passing(clamp: str = "node", cells=(10, 20, 40, 80, 160), cfl: float = 0.8,
                     tolerance: float = TOLERANCE, runs: list | None = None) -> Run | None:
    """The first n_elem in ``cells`` whose tip stays within ``tolerance`` L (None: none)."""
    for n in cells:
        result = run(n, clamp, cfl)
        if runs is not None:
            runs.append(result)
        if result.max_tip_error <= tolerance:
            return result
    return None


def main(argv=None) -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tolerance", type=float, default=TOLERANCE, help="max tip error in L")
    args = parser.parse_args(argv)
    warmup()
    print(f"{'clamp':8s} {'n_elem':>6s} {'dt (s)':>10s} {'steps':>7s} "
          f"{'max tip err (L)':>16s} {'wall (s)':>9s} {'cpu (s)':>8s}")
    chosen = {}
    for clamp in ("node", "centred"):
        runs: list[Run] = []
        chosen[clamp] = coarsest_passing(clamp, tolerance=args.tolerance, runs=runs)
        for r in runs:
            print(f"{r.clamp:8s} {r.n_elem:6d} {r.dt:10.3e} {r.steps:7d} "
                  f"{r.max_tip_error:16.2e} {r.wall_s:9.2f} {r.cpu_s:8.2f}", flush=True)
    for clamp, r in chosen.items():
        verdict = "none passed" if r is None else (
            f"n_elem={r.n_elem}, dt={r.dt:.3e} s: {r.cpu_s:.2f} s CPU, {r.wall_s:.2f} s wall")
        print(f"coarsest within {args.tolerance:g} L, clamp={clamp}: {verdict}")
    # softarm's own run goes here beside it, e.g. (once softarm has dynamics):
    #   t0 = time.process_time(); <softarm swing at its coarsest passing setting>;
    #   print(f"softarm: ... {time.process_time() - t0:.2f} s CPU")


if __name__ == "__main__":
    main()
