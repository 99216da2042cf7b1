"""Where one call's time goes: softarm's compiled kernels against the Python around them.

The calls the issues time one at a time: a solve of the Mattiasson cantilever (k = 5), the
3-tendon robot's solve (benchmarks/actuation.py) with 101 stations and with the tip only, a
warm solve with the tip compliance and three tendon columns (101 stations and the tip
only; then the same by the prepared ``ForwardSolver``), and a tracked target of inverse
statics. Each call is timed whole, and the time
inside the compiled kernels (``solve_cases``, ``stability_cases``, ``inverse_newton``) is
summed by wrappers around them (under a microsecond a call); the rest is Python: checking
the loads, filling the load channels, the stability verdict's and the Equilibrium's
arrays. The loads are built before each call, so the Python is softarm's own. Medians and
minima over the repeats, wall time (``perf_counter``) and CPU time (``process_time``) side
by side.

This is the measurement behind the Python trims of the round of 2026-11-30 (docs/solver.md):
a speed target of a single call is met or missed by this Python as much as by the kernels.

Run::

    python benchmarks/overhead.py [--repeats 400]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import softarm
from softarm import kernels
from softarm.routing import Straight

sys.path.insert(0, str(Path(__file__).resolve().parent))
from actuation import GRAVITY, OFFSETS, TENSIONS, L, loads, robot

KERNELS = ("solve_cases", "stability_cases", "inverse_newton")


class _KernelClock:
    """Wall and CPU time spent inside the compiled kernels since :meth:`reset`."""

    def __init__(self):
        self.wall = self.cpu = 0.0
        module = kernels
        for name in KERNELS:
            setattr(module, name, self._timed(getattr(module, name)))

    def _timed(self, kernel):
        def timed(*args):
            t0, c0 = time.perf_counter(), time.process_time()
            try:
                return kernel(*args)
            finally:
                self.wall += time.perf_counter() - t0
                self.cpu += time.process_time() - c0
        return timed

    def reset(self):
        self.wall = self.cpu = 0.0


def _measure(clock, call, prepare, repeats):
    """(total, kernels) wall and CPU seconds per call: lists over the repeats."""
    rows = []
    for i in range(repeats):
        args = prepare(i)
        clock.reset()
        t0, c0 = time.perf_counter(), time.process_time()
        call(*args)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        rows.append((wall, cpu, clock.wall, clock.cpu))
    return np.array(rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=400)
    args = parser.parse_args(argv)
    clock = _KernelClock()

    mattiasson = softarm.Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0,
                                            EIz=1.0)
    tip_force = softarm.TipLoad(force=[0.0, 0.0, 5.0])
    arm = robot()
    near = np.array([2.0, 1.0, 0.5])
    control = softarm.statics.Solver(arm, tol=1e-6)
    control_tip = softarm.statics.Solver(arm, tol=1e-6, s=[L])
    gravity = softarm.Gravity(GRAVITY)
    tendons = [softarm.Tendon(0.0, Straight(*o)) for o in OFFSETS]
    phase = np.linspace(0.0, 2 * np.pi, 1000, endpoint=False)
    pattern = 1.5 + 1.2 * np.cos(phase[:, None] - 2 * np.pi * np.arange(3) / 3)
    path = softarm.solve(arm, loads(pattern), tol=1e-10).tip_position
    model = softarm.ForwardSolver(arm, tendons, [gravity], tol=1e-6)
    model.solve(near)
    tracker = softarm.InverseSolver(arm, tendons, [gravity], s=[L])
    tracker.track(path[:20])

    cases = [
        ("Mattiasson k=5, method='numeric', tol 1e-6 L, 101 stations",
         lambda: softarm.solve(mattiasson, tip_force, method="numeric", tol=1e-6),
         lambda i: ()),
        ("3-tendon robot under gravity, tol 1e-6 L, 101 stations",
         lambda case: softarm.solve(arm, case, tol=1e-6), lambda i: (loads(TENSIONS),)),
        ("the same, the tip only (s=2)",
         lambda case: softarm.solve(arm, case, tol=1e-6, s=2), lambda i: (loads(TENSIONS),)),
        ("warm solve + tip compliance + 3 tendon columns, tol 1e-6 L (new tensions each)",
         lambda case: control.solve(case, jacobians=True),
         lambda i: (loads(near + 1e-3 * np.sin(0.1 * i + np.arange(3))),)),
        ("the same, the tip only",
         lambda case: control_tip.solve(case, jacobians=True),
         lambda i: (loads(near + 1e-3 * np.sin(0.1 * i + np.arange(3))),)),
        ("the same by ForwardSolver.solve (prepared once; the tip only)",
         model.solve, lambda i: (near + 1e-3 * np.sin(0.1 * i + np.arange(3)),)),
        ("a tracked target along a circle, the tip only (InverseSolver.solve, warm)",
         tracker.solve, lambda i: (path[(20 + i) % len(path)],)),
    ]
    print(f"{args.repeats} calls each, in ms (median / min); kernels: {', '.join(KERNELS)}")
    print(f"{'call':84s} {'whole':>13s} {'kernels':>13s} {'Python':>13s}   CPU: whole, "
          "Python (median)")
    for label, call, prepare in cases:
        call(*prepare(0))  # compiled, warm
        rows = _measure(clock, call, prepare, args.repeats)
        python = rows[:, 0] - rows[:, 2]
        python_cpu = rows[:, 1] - rows[:, 3]

        def both(values):
            return f"{1e3 * statistics.median(values):6.3f}/{1e3 * min(values):.3f}"

        print(f"{label:84s} {both(rows[:, 0]):>13s} {both(rows[:, 2]):>13s} "
              f"{both(python):>13s}   {1e3 * statistics.median(rows[:, 1]):.3f}, "
              f"{1e3 * statistics.median(python_cpu):.3f}")


if __name__ == "__main__":
    main()
