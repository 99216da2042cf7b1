"""Stiff problems: rods in strong tension and long hanging hoses (multiple shooting).

Per case, at tol 1e-6 L: softarm's auto route (multiple shooting where kL >= 15), softarm
forced onto single shooting, and scipy's ``solve_bvp`` on the same planar problem (the
reference of tests/test_stiff_*.py, tests/_planar_elastica.py, imported from there: one
model, two users), with load continuation from a straight arm. Wall time (``perf_counter``)
and CPU time (``process_time``) per solve, best of several after a warm-up call; a route
that fails is timed once and reported as ``fails: <message>``. The tip error is against an
exact closed form (tension: the pendulum separatrix, exact to e^{−kL}) or solve_bvp at
tol 1e-9 (hoses). softarm runs without its stability verdict (``stability=False``: it is not
part of the solve; with it, add 5-40 %). Run::

    python benchmarks/stiff.py [--repeats 5]

Times are printed, never asserted. ``benchmarks/run.py`` puts the same table in
docs/performance.md ("Stiff problems", :func:`markdown`).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from _planar_elastica import separatrix_tip, solve_planar

import softarm
from softarm.statics.solver import Solver

TOL = 1e-6  # relative to L
LATERAL = 1e-3  # P / F of the tension cases


def tension_case(load):
    """EI = 1, L = 1, EA = GA = 1e12, tip force (F, 0, 1e-3 F) with F L²/EI = ``load``."""
    C = 1e12
    arm = softarm.Arm.from_stiffness(1.0, EA=C, GAy=C, GAz=C, GJ=1.0, EIy=1.0, EIz=1.0)
    F, P = load, LATERAL * load
    loads = [softarm.TipLoad(force=[F, 0.0, P]), softarm.DistributedForce([0.0, 0.0, 0.0])]
    planar = {"length": 1.0, "EI": 1.0, "EA": C, "GA": C, "tip": (F, P)}
    exact = separatrix_tip(math.hypot(F, P), math.atan2(P, F), 1.0, 1.0, C)
    return f"tension F L²/EI = {load:.0e}", arm, loads, planar, exact


def hose_case(length):
    """A silicone hose (E 1.5 MPa, ν 0.49, ρ 1070 kg/m³, radius 10 mm) hanging under its
    weight from a horizontal clamp."""
    arm = softarm.Arm(length, softarm.Circle(0.01),
                      softarm.Material(1.5e6, poisson_ratio=0.49, density=1070.0))
    k = arm.rigidities
    q = arm.linear_density * 9.81
    planar = {"length": length, "EI": k.EIy, "EA": k.EA, "GA": k.GAz, "distributed": (0.0, -q)}
    fine = solve_planar(**planar, tol=1e-9)
    name = f"hose L = {length:g} m (q L³/EI = {q * length**3 / k.EIy:.0f})"
    return name, arm, [softarm.Gravity([0.0, 0.0, -9.81])], planar, fine.tip[[0, 2]]


def best_time(fn, repeats):
    """(best wall s, best CPU s, result) over ``repeats`` calls after a warm-up call; a failure
    is timed once: (wall, CPU, the exception)."""
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        result = fn()
    except Exception as error:  # a route that fails is a result here
        return time.perf_counter() - t0, time.process_time() - c0, error
    walls, cpus = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        result = fn()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    return min(walls), min(cpus), result


def measure(repeats: int) -> list[tuple]:
    """Rows (case, route, wall s, CPU s, tip error / L or the failure's message, wall / the
    auto route's), every case on every route."""
    cases = [tension_case(load) for load in (1e2, 1e4, 1e6, 1e8)]
    cases += [hose_case(length) for length in (1.0, 2.0, 3.0)]
    rows = []
    for name, arm, loads, planar, exact in cases:
        length = planar["length"]
        routes = {
            "softarm auto": lambda arm=arm, loads=loads: softarm.solve(
                arm, loads, tol=TOL, stability=False).tip_position[[0, 2]],
            "softarm single": lambda arm=arm, loads=loads: Solver(
                arm, tol=TOL, shooting="single", stability=False).solve(loads)
            .tip_position[[0, 2]],
            "solve_bvp": lambda planar=planar: solve_planar(**planar, tol=TOL).tip[[0, 2]],
        }
        auto_wall = None
        for route, fn in routes.items():
            count = 1 if route == "solve_bvp" and "1e+08" in name else repeats
            wall, cpu, result = best_time(fn, count)
            if isinstance(result, Exception):
                rows.append((name, route, wall, cpu, f"fails: {str(result)[:60]}", None))
                continue
            error = float(np.max(np.abs(result - exact))) / length
            auto_wall = wall if route == "softarm auto" else auto_wall
            rows.append((name, route, wall, cpu, error, wall / auto_wall if auto_wall else None))
    return rows


def markdown(rows, repeats: int) -> list[str]:
    """The rows as the "Stiff problems" section of docs/performance.md."""
    lines = ["## Stiff problems (multiple shooting)", "",
             f"`python benchmarks/stiff.py`: tol {TOL:g} L, best of {repeats} after a warm-up "
             "(solve_bvp at F L²/EI = 1e8 timed once), without the stability verdict. The tip "
             "error is against the pendulum separatrix (tension, exact to e^{-kL}) or "
             "solve_bvp at tol 1e-9 (hoses, tests/_planar_elastica.py). softarm's auto route "
             "takes multiple shooting from kL = 15 (docs/solver.md).", "",
             "| case | route | wall ms | CPU ms | tip error / L | wall / auto |",
             "|---|---|---|---|---|---|"]
    for name, route, wall, cpu, error, ratio in rows:
        error = error if isinstance(error, str) else f"{error:.1e}"
        ratio = "" if ratio is None else f"{ratio:.1f}×"
        lines.append(f"| {name} | {route} | {1e3 * wall:.1f} | {1e3 * cpu:.1f} | {error} | "
                     f"{ratio} |")
    return [*lines, ""]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    print("\n".join(markdown(measure(args.repeats), args.repeats)))


if __name__ == "__main__":
    main()
