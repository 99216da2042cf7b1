"""Every capability of softarm, each on a small problem (tests/test_compile_all.py runs this
after ``softarm compile --all`` in the same numba cache: every kernel version used here must
be one that ``compile --all`` used, so that nothing compiles here in a user's fresh cache).

``python tests/_every_capability.py [NAME ...]``: prints ``NAME: ok SECONDS`` per capability, or
the error, and exits 1 if any failed. Chosen by what a user calls, not by softarm's kernels:
the library's and the case files' routes to the statics (passive, actuated, magnets, contact,
single and multiple shooting with and without Jacobians and the verdict, closed forms and
their verdicts, in tension too, chained solves, the control loop, inverse statics,
displacement control, critical loads and continuation) and the dynamics (passive, actuated,
magnets, contact with and without friction, from an equilibrium, step by step, a moving base,
input schedules).
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import softarm as sa
from softarm.case import load_case, simulation_parts, solve_case
from softarm.routing import Straight
from softarm.statics import Solver

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SILICONE = sa.Material(youngs_modulus=1.5e6, poisson_ratio=0.49, density=1070.0)


def arm():
    return sa.Arm(0.2, sa.Circle(0.01), SILICONE)


def tendons():
    return [sa.Tendon(0.2, Straight(0.0, 0.006)), sa.Tendon(0.1, Straight(0.006, 0.0))]


def taut():
    """An arm that a 1 kN pull puts in strong tension (kL = 32: multiple shooting)."""
    return sa.Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)


PULL = [sa.TipLoad(force=[1e3, 0.0, 1.0]), sa.DistributedForce([0.0, 0.0, 0.0])]


def soft_beam():
    return sa.Arm.from_stiffness(1.0, EA=1e4, GAy=1e4, GAz=1e4, GJ=1.0, EIy=1.0, EIz=1.0)


def pressed():
    return [sa.TipLoad(force=[0.0, 0.0, -10.0]),
            sa.Contact(sa.Plane((0.0, 0.0, -0.1), (0.0, 0.0, 1.0)), radius=0.01)]


def magnetic():
    return sa.Arm.from_stiffness(0.2, EA=50.0, GAy=30.0, GAz=30.0, GJ=0.015, EIy=0.02,
                                 EIz=0.02, magnetization=(0.5, 0.0, 0.0))


def moving():
    return sa.Arm(0.2, sa.Circle(0.01), sa.Material(1e6, poisson_ratio=0.5, density=1100.0))


def table(friction=0.0):
    return sa.Contact(sa.Plane((0.0, 0.0, -0.0102), (0.0, 0.0, 1.0)), friction=friction)


def brief(arm, loads=(), **options):
    """Three implicit steps on 5 stations."""
    return sa.simulate(arm, loads, duration=3e-3, dt=1e-3, stations=5, **options)


BUCKLING = sa.Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0)
UNLOADED_GRAVITY = [sa.Gravity(), sa.TipLoad(force=[0.0, 0.01, 0.0])]

CASES = {
    # statics, single shooting
    "passive": lambda: sa.solve(arm(), UNLOADED_GRAVITY, method="numeric"),
    "passive without the verdict": lambda: Solver(arm(), stability=False).solve(
        [sa.Gravity()]),
    "passive with Jacobians": lambda: sa.solve(arm(), [sa.Gravity()], method="numeric",
                                               jacobians=True),
    "passive, chained": lambda: [Solver(arm()).solve(
        [sa.Gravity(), sa.TipLoad(force=[0.0, f, 0.0])]) for f in (0.005, 0.01)],
    "passive, chained, with Jacobians": lambda: [Solver(arm()).solve(
        [sa.Gravity(), sa.TipLoad(force=[0.0, f, 0.0])], jacobians=True) for f in (0.005, 0.01)],
    "closed forms and their verdict": lambda: (
        sa.analytic.tip_moment(arm(), moment=[0.0, 1e-3, 0.0]),
        sa.solve(arm(), [sa.TipLoad(force=[0.0, 0.0, -0.05])])),
    "a closed form in strong tension and its verdict": lambda: sa.solve(
        taut(), [sa.TipLoad(force=[1e3, 0.0, 1.0])]),
    "actuated": lambda: sa.solve(arm(), [sa.Gravity(), *tendons(), sa.Chamber(
        1e3, area=1e-5, routing=Straight(0.0, -0.005))], method="numeric"),
    "magnets": lambda: sa.solve(magnetic(), [sa.MagneticField([0.0, 0.0, 0.05])],
                                method="numeric"),
    "actuated with Jacobians": lambda: sa.solve(arm(), [sa.Gravity(), *tendons()],
                                                method="numeric", jacobians=True),
    "actuated, chained": lambda: [Solver(arm()).solve(
        [sa.Gravity(), sa.Tendon(t, Straight(0.0, 0.006))]) for t in (0.1, 0.2)],
    "the control loop": lambda: [sa.ForwardSolver(arm(), tendons(), [sa.Gravity()]).solve(u)
                                 for u in ([0.2, 0.1], [0.25, 0.1])],
    "inverse statics": lambda: sa.inverse(arm(), tendons(), sa.solve(
        arm(), [sa.Gravity(), *tendons()]).tip_position, loads=[sa.Gravity()]),
    "displacement control": lambda: sa.solve(arm(), [sa.Gravity(), sa.Tendon(
        routing=Straight(0.0, 0.006), displacement=-1e-4)]),
    "critical load": lambda: sa.critical_load(BUCKLING, [sa.TipLoad(force=[-1.0, 0.0, 0.0]),
                                                         sa.DistributedForce([0.0, 0.0, 0.0])],
                                              max_factor=4.0),
    "continuation": lambda: sa.continuation(BUCKLING, [sa.TipLoad(force=[-3.0, 0.0, 0.0]),
                                                       sa.DistributedForce([0.0, 1e-3, 0.0])]),
    "critical load of an actuated arm": lambda: sa.critical_load(
        arm(), [sa.Gravity(), sa.Tendon(0.1, Straight(0.0, 0.006))], max_factor=2.0),
    # a free tip held with friction (single shooting from the base, tip_friction.py), stuck
    # with its Jacobians, then sliding along a chained Solver's path
    "a tip held with friction": lambda: (
        sa.solve(arm(), [sa.Gravity(), sa.Contact(sa.Plane((0.0, 0.0, -0.03), (0.0, 0.0, 1.0)),
                                                  friction=5.0)], jacobians=True),
        [Solver(arm()).solve([sa.Gravity().scaled(g), sa.Contact(sa.Plane(
            (0.0, 0.0, -0.03), (0.0, 0.0, 1.0)), friction=0.1)]) for g in (0.8, 1.0)]),
    # statics, multiple shooting: passive, actuated, touching; verdict and Jacobians or not
    **{f"multiple shooting, {who}{', verdict' * verdict}{', Jacobians' * jacobians}":
       (lambda make=make, verdict=verdict, jacobians=jacobians:
        Solver(make[0](), stability=verdict, shooting=make[2]).solve(make[1](),
                                                                    jacobians=jacobians))
       for who, make in {"passive": (taut, lambda: PULL, "auto"),
                         "actuated": (arm, lambda: [sa.Gravity(), *tendons()], "multiple"),
                         "touching": (soft_beam, pressed, "auto")}.items()
       for verdict in (True, False) for jacobians in (False, True)},
    # dynamics
    "dynamics": lambda: brief(moving(), [sa.Gravity()]),
    "dynamics, actuated": lambda: brief(moving(), actuators=[
        sa.Tendon(tension=0.1, routing=Straight(0.0, 0.005))]),
    "dynamics, magnets": lambda: brief(sa.Arm(0.2, sa.Circle(0.01), sa.Material(
        1e6, poisson_ratio=0.5, density=1100.0), magnetization=(0.5, 0.0, 0.0)),
        [sa.MagneticField([0.0, 0.0, 0.01])]),
    "dynamics, contact": lambda: brief(moving(), [sa.Gravity(), table()]),
    "dynamics, contact with friction": lambda: brief(moving(), [sa.Gravity(), table(0.4)]),
    "dynamics, contact, actuated": lambda: brief(moving(), [sa.Gravity(), table()], actuators=[
        sa.Tendon(tension=0.1, routing=Straight(0.0, 0.005))]),
    "dynamics from an equilibrium": lambda: brief(moving(), [sa.Gravity()], initial=sa.solve(
        moving(), [sa.Gravity(), sa.TipLoad(force=[0.0, 0.0, -0.01])], s=5)),
    "dynamics, actuated, from an equilibrium": lambda: brief(
        moving(), [sa.Gravity()], actuators=[sa.Tendon(tension=0.1, routing=Straight(0.0, 0.005))],
        initial=sa.solve(moving(), [sa.Gravity(), sa.Tendon(0.05, Straight(0.0, 0.005))], s=5)),
    "Simulator.step": lambda: [sim.step() for sim in [sa.Simulator(
        moving(), [], [sa.Gravity()], dt=1e-3, stations=5)] for _ in range(2)],
    "Simulator.step, actuated": lambda: [sim.step([0.1]) for sim in [sa.Simulator(
        moving(), [sa.Tendon(0.0, Straight(0.0, 0.005))], [sa.Gravity()], dt=1e-3,
        stations=5)] for _ in range(2)],
    # case files: what the command line runs
    **{f"case {name}": (lambda name=name: solve_case(load_case(EXAMPLES / f"{name}.toml")))
       for name in ("demo", "fig2_sweep", "tendon_robot", "magnetic_catheter", "catheter_bend",
                    "gripper_finger")},
    **{f"case {name} (its first steps)": (lambda name=name: next(simulation_parts(
        load_case(EXAMPLES / f"{name}.toml"), seconds=0.0)))
       for name in ("whip", "tendon_fast_move", "pneumatic_step")},
}


def main(names) -> int:
    warnings.simplefilter("ignore")  # (StabilityWarning and the like: not what is tested)
    np.seterr(all="ignore")
    failed = 0
    for name in names or CASES:
        start = time.perf_counter()
        try:
            CASES[name]()
            status = "ok"
        except Exception as error:  # (reported, and the exit status says it)
            status, failed = f"{type(error).__name__}: {error}", failed + 1
        print(f"{name}: {status} {time.perf_counter() - start:.1f} s", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
