"""Contact (issue 33): what a solve in contact costs, against the issue's targets and the
alternatives.

- the heavy soft arm lying on a table (tol 1e-6 L), against the hard-contact free-boundary
  ``solve_bvp`` reference of tests/_table_reference.py (the alternative: a free-boundary
  solve written for this one geometry) and against the same arm without the table;
- the free tip pressed onto a plane and onto a pin: held exactly (statics/tip_contact.py),
  against the penalty at the default δ, the free arm, and the Reissner-rod ``solve_bvp``
  references of tests/_tip_reference.py;
- a heavy arm's tip on a floor with Coulomb friction (statics/tip_friction.py): stuck and
  sliding, against the Reissner-rod ``solve_bvp`` references rolling and sliding on the
  floor (tests/_tip_reference.py) and the same tip held without friction; and a slide
  turned by a pull across the bending plane;
- the arm pressed onto a pin (a Capsule) by gravity and a tip force;
- a tendon finger closing on a cylinder, tracked over 100 tension steps (a prepared
  ForwardSolver, as a control loop calls it);
- the live app's redraw on examples/gripper_finger.toml: a chained Solver (the app's, its
  stations and tol) moved by 0.5 N of tension in contact, against the same move solved from
  the unloaded arm with the same law (what every move cost before the Solver kept its
  multiple-shooting solution);
- a dynamic drop onto the table at Δt = 1 ms: the cost of a step against the same step
  without the table.

Wall time (``perf_counter``) and CPU time (``process_time``), best of ``--repeats`` after a
warm-up call. Times are printed, never asserted. Run::

    python benchmarks/contact.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from _table_reference import table_reference
from _tip_reference import tip_on_circle, tip_on_plane, tip_sliding_on_plane, tip_stuck_on_plane

import softarm
from softarm.case import load_case
from softarm.statics import Solver

L, RADIUS, DROP = 0.5, 0.01, 0.02


def _soft_arm(length=L):
    return softarm.Arm(length, softarm.Circle(RADIUS),
                       softarm.Material(youngs_modulus=1e6, poisson_ratio=0.5, density=1000.0))


def _timed(call, repeats):
    """(result, best wall s, best CPU s) after one warm-up call."""
    result = call()
    walls, cpus = [], []
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        result = call()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return result, min(walls), min(cpus)


def table(repeats):
    arm = _soft_arm()
    loads = [softarm.Gravity(),
             softarm.Contact(softarm.Plane((0.0, 0.0, -DROP - RADIUS), (0.0, 0.0, 1.0)))]
    rows = []
    eq, wall, cpu = _timed(lambda: softarm.solve(arm, loads, tol=1e-6, s=201), repeats)
    k = arm.rigidities
    ref, rwall, rcpu = _timed(lambda: table_reference(L, k.EA, k.GAy, k.EIy, RADIUS,
                                                      arm.linear_density * 9.81, DROP), 1)
    error = np.abs(eq.positions - ref.positions(eq.s)).max() / L
    rows.append(("table, softarm (tol 1e-6 L)", wall, cpu, f"{error:.1e} L", "5 ms"))
    rows.append(("table, solve_bvp free boundary (hard contact)", rwall, rcpu, "reference",
                 ""))
    for distance in (1e-4, 1e-3):
        wide = [loads[0], loads[1].replace(distance=distance * L)]
        eq, wall, cpu = _timed(lambda wide=wide: softarm.solve(arm, wide, tol=1e-6, s=201),
                               repeats)
        error = np.abs(eq.positions - ref.positions(eq.s)).max() / L
        rows.append((f"table, softarm, contact distance {distance:g} L", wall, cpu,
                     f"{error:.1e} L", ""))
    _, wall, cpu = _timed(lambda: softarm.solve(arm, loads[:1], tol=1e-6, s=201,
                                                method="numeric"), repeats)
    rows.append(("the same arm without the table", wall, cpu, "", ""))
    return rows


def tip(repeats):
    """The free tip pressed by 0.05 N onto a plane 0.1 m below the clamp (it lands at about
    60°): held exactly (the default), with the penalty at the default δ given explicitly, the
    free arm, and the Reissner-rod ``solve_bvp`` reference (tests/_tip_reference.py)."""
    arm = _soft_arm()
    plane = softarm.Plane((0.0, 0.0, -0.1 - RADIUS), (0.0, 0.0, 1.0))
    force = softarm.TipLoad(force=(0.0, 0.0, -0.05))
    k = arm.rigidities
    ref, rwall, rcpu = _timed(lambda: tip_on_plane(
        L, k.EA, k.GAy, k.EIy, RADIUS, 0.0, (0.0, -0.05), (0.0, -0.1 - RADIUS), (0.0, 1.0)), 1)
    rows = []
    for name, contact, tol in (("tip on a plane, held (tol 1e-6 L)", softarm.Contact(plane),
                                1e-6),
                               ("tip on a plane, held (tol 1e-8 L)", softarm.Contact(plane),
                                1e-8),
                               ("tip on a plane, penalty at δ = 1e-5 L (tol 1e-6 L)",
                                softarm.Contact(plane, distance=1e-5 * L), 1e-6)):
        eq, wall, cpu = _timed(lambda c=contact, tol=tol: softarm.solve(
            arm, [force, c], tol=tol, s=201), repeats)
        shape = np.abs(eq.positions - ref.positions(eq.s)).max() / L
        error = abs(eq.contact_wrench[2] / ref.reaction[1] - 1.0)
        rows.append((f"{name} ({eq.method})", wall, cpu,
                     f"{shape:.1e} L; force {error:.1e}", ""))
    rows.append(("tip on a plane, solve_bvp reference (hard contact)", rwall, rcpu,
                 "reference", ""))
    # a pin (a capsule across the bending plane) under the tip: the reaction turns with the
    # contact point, followed along the load path from the first touch
    centre, radius = (0.5, -0.25), 0.1
    pin = softarm.Capsule((centre[0], -0.1, centre[1]), (centre[0], 0.1, centre[1]), radius)
    ref = tip_on_circle(L, k.EA, k.GAy, k.EIy, RADIUS, 0.0, (0.0, -0.05), centre, radius)
    for name, contact in (("tip on a pin, held (tol 1e-6 L)", softarm.Contact(pin)),
                          ("tip on a pin, penalty at δ = 1e-5 L (tol 1e-6 L)",
                           softarm.Contact(pin, distance=1e-5 * L))):
        eq, wall, cpu = _timed(lambda c=contact: softarm.solve(arm, [force, c], tol=1e-6,
                                                               s=201), repeats)
        shape = np.abs(eq.positions - ref.positions(eq.s)).max() / L
        error = np.abs(eq.contact_wrench[[0, 2]] - ref.reaction).max() / np.hypot(
            *ref.reaction)
        rows.append((f"{name} ({eq.method})", wall, cpu, f"{shape:.1e} L; force {error:.1e}",
                     ""))
    _, wall, cpu = _timed(lambda: softarm.solve(arm, [force], tol=1e-6, s=201,
                                                method="numeric"), repeats)
    rows.append(("the same arm without the plane", wall, cpu, "", ""))
    return rows


def friction(repeats):
    """The heavy arm of tests/test_tip_friction.py (E = 20 MPa) under its weight, its tip on
    a floor 40 mm below the clamp: with μ above the stuck force's lean on the whole path
    (it sticks, the cap rolling), below it (it slides), without friction, and sliding with
    a pull of 0.05 N across the bending plane (the slide's way turns on the path)."""
    arm = softarm.Arm(L, softarm.Circle(RADIUS), softarm.Material(
        youngs_modulus=2e7, poisson_ratio=0.5, density=1000.0))
    k, w = arm.rigidities, arm.linear_density * 9.81
    floor = softarm.Plane((0.0, 0.0, -0.04), (0.0, 0.0, 1.0))
    stuck, rwall, rcpu = _timed(lambda: tip_stuck_on_plane(
        L, k.EA, k.GAy, k.EIy, RADIUS, w, (0.0, 0.0), (0.0, -0.04), (0.0, 1.0)), 1)
    mu_stick, mu_slide = stuck.ratios.max() / 0.9, stuck.ratios.min() / 1.1
    sliding = tip_sliding_on_plane(L, k.EA, k.GAy, k.EIy, RADIUS, w, (0.0, 0.0),
                                   (0.0, -0.04), (0.0, 1.0), mu_slide,
                                   np.sign(stuck.reaction[0]))
    rows = []
    for name, mu, ref in ((f"floor, stuck (μ = {mu_stick:.2f})", mu_stick, stuck),
                          (f"floor, sliding (μ = {mu_slide:.2f})", mu_slide, sliding),
                          ("floor, frictionless (held)", 0.0, None)):
        eq, wall, cpu = _timed(lambda mu=mu: softarm.solve(
            arm, [softarm.Gravity(), softarm.Contact(floor, friction=mu)], s=201, tol=1e-6),
            repeats)
        error = "" if ref is None else (
            f"{np.abs(eq.positions - ref.positions(eq.s)).max() / L:.1e} L; force "
            f"{np.abs(eq.contact_wrench[[0, 2]] - ref.reaction).max() / np.hypot(*ref.reaction):.1e}"  # noqa: E501
        )
        rows.append((f"{name} ({eq.method})", wall, cpu, error, ""))
    rows.append(("floor, stuck: solve_bvp reference (rolling, from the first touch)", rwall,
                 rcpu, "reference", ""))
    pull = [softarm.Gravity(), softarm.TipLoad(force=(0.0, 0.05, 0.0)),
            softarm.Contact(floor, friction=0.3)]
    eq, wall, cpu = _timed(lambda: softarm.solve(arm, pull, s=201, tol=1e-6), repeats)
    rows.append((f"floor, sliding, pulled across the bending plane ({eq.method})", wall, cpu,
                 "", ""))
    return rows


def pin(repeats):
    arm = _soft_arm()
    pin_radius = 0.005
    obstacle = softarm.Capsule((0.3, -0.1, -RADIUS - pin_radius - 0.002),
                               (0.3, 0.1, -RADIUS - pin_radius - 0.002), pin_radius)
    loads = [softarm.Gravity(), softarm.TipLoad(force=(0.0, 0.0, -0.05)),
             softarm.Contact(obstacle)]
    eq, wall, cpu = _timed(lambda: softarm.solve(arm, loads, tol=1e-6, s=201), repeats)
    force = np.linalg.norm(eq.contact_wrench[:3])
    return [(f"pin (contact force {force:.3f} N)", wall, cpu, "", "3 ms")]


def finger(repeats):
    arm = softarm.Arm(0.12, softarm.Circle(0.01),
                      softarm.Material(youngs_modulus=1e6, poisson_ratio=0.49, density=1070.0))
    tendon = softarm.Tendon(1.0, softarm.routing.Straight(0.0, -0.007))
    cylinder = softarm.Contact(softarm.Capsule((0.06, -0.05, -0.045), (0.06, 0.05, -0.045),
                                               0.03))
    tensions = np.linspace(0.15, 15.0, 100)
    model = softarm.ForwardSolver(arm, [tendon], [cylinder])

    def track():
        return [model.solve([q]) for q in tensions]

    _, wall, cpu = _timed(track, max(1, repeats // 2))
    last = softarm.solve(arm, [tendon.with_tension(tensions[-1]), cylinder])
    force = float(np.linalg.norm(last.contact_wrench[:3]))
    return [(f"finger: 100 tension steps to 15 N (contact force at the end {force:.2f} N)",
             wall, cpu, "", "0.5 s")]


def slider(repeats):
    case = load_case(Path(__file__).resolve().parents[1] / "examples" / "gripper_finger.toml")
    tendon, cylinder = case.loads
    solver = Solver(case.arm, s=int(case.solve.stations), tol=float(case.solve.tol))
    solver.solve([tendon.replace(tension=15.0), cylinder])  # (its law raised, then kept)
    tensions = itertools.cycle([14.5, 15.0])

    def move():
        return solver.solve([tendon.replace(tension=next(tensions)), cylinder])

    moved, wall, cpu = _timed(move, repeats)
    law = moved.loads[-1]  # (the law the moves ended with)
    given = cylinder.replace(stiffness=law.stiffness, distance=law.distance)
    _, cold_wall, cold_cpu = _timed(lambda: solver.solve_from_unloaded(
        [tendon.replace(tension=14.5), given]), max(1, repeats // 2))
    where = f"{case.solve.stations} stations, tol {case.solve.tol:g}"
    return [(f"app redraw: a 0.5 N move of the gripper finger, chained ({where})", wall, cpu,
             "", "0.1 s"),
            ("the same move from the unloaded arm, the same law", cold_wall, cold_cpu, "", "")]


def drop(repeats):
    arm = _soft_arm()
    table_ = softarm.Contact(softarm.Plane((0.0, 0.0, -0.05), (0.0, 0.0, 1.0)))
    damping = softarm.Damping(retardation=0.02)
    steps = 300
    rows = []
    for name, loads in (("dynamic drop onto the table", [softarm.Gravity(), table_]),
                        ("the same drop without the table", [softarm.Gravity()])):
        _, wall, cpu = _timed(lambda loads=loads: softarm.simulate(
            arm, loads, duration=steps * 1e-3, dt=1e-3, damping=damping), 1)
        rows.append((f"{name}: a step (Δt = 1 ms, 101 stations, {steps} steps)",
                     wall / steps, cpu / steps, "", "2× without" if "onto" in name else ""))
    return rows


def measure(repeats: int) -> list[str]:
    """The markdown lines of docs/performance.md's "Contact" section (benchmarks/run.py)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (stability and approximation notes)
        rows = [*table(repeats), *tip(repeats), *friction(repeats), *pin(repeats),
                *finger(repeats),
                *slider(repeats), *drop(repeats)]
    lines = ["## Contact", "",
             f"`python benchmarks/contact.py --repeats {repeats}` "
             f"({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}): best of {repeats} after "
             "a warm-up, CPU time beside wall time; shape errors against the hard-contact "
             "references of tests/. The issue's targets are in the last column "
             "(docs/contact.md, \"Limits\": the statics' are missed).", "",
             "| case | wall | CPU | shape error | target |", "|---|---|---|---|---|"]
    for name, wall, cpu, error, target in rows:
        unit, scale = ("ms", 1e3) if wall < 1.0 else ("s", 1.0)
        lines.append(f"| {name} | {wall * scale:.3g} {unit} | {cpu * scale:.3g} {unit} | "
                     f"{error} | {target} |")
    lines += ["", f"A contact step costs {rows[-2][1] / rows[-1][1]:.2f}× the plain step "
              f"(wall; {rows[-2][2] / rows[-1][2]:.2f}× CPU)."]
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    print("\n".join(measure(args.repeats)))


if __name__ == "__main__":
    main()
