"""Displacement-controlled tendons (issue 16, item 4): the cost of a displacement-controlled
solve of examples/tendon_robot.toml against the tension-controlled one it reproduces.

The tendons' displacements are the length changes the tension-controlled solve reports, so
both solves give the same equilibrium (printed: the largest station distance / L). Wall time
(``perf_counter``) beside CPU time (``process_time``), median of ``--repeats`` warm solves
(the kernels compiled and cached by a first solve), with and without ``jacobians=True``; and
the number of bounded Newton iterations (tension-controlled solves) the displacement solve
took.

Run::

    python benchmarks/displacement.py [--repeats 30]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import softarm
from softarm.case import load_case
from softarm.statics import Solver

sys.path.insert(0, str(Path(__file__).resolve().parent))
from run import timed  # benchmarks/ is not a package

CASE = Path(__file__).resolve().parents[1] / "examples" / "tendon_robot.toml"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=30)
    args = parser.parse_args(argv)
    case = load_case(CASE)
    arm, loads = case.arm, case.loads
    by_tension = softarm.solve(arm, loads)  # compiles (or loads the cache)
    changes = iter(by_tension.tendon_length_changes)
    displaced = [softarm.Tendon(routing=load.routing, end=load.end, displacement=next(changes))
                 if load.kind == "tendon" else load for load in loads]
    calls = []
    inner = Solver.solve_from_unloaded

    def counted(self, loads, *, jacobians=False):
        calls.append(jacobians)
        return inner(self, loads, jacobians=jacobians)

    print(f"{CASE.name}: tensions {by_tension.tendon_tensions.tolist()} N, "
          f"displacements {np.round(1e3 * by_tension.tendon_length_changes, 6).tolist()} mm")
    print(f"{'':44} {'wall (ms)':>10} {'CPU (ms)':>10} {'ratio':>7}")
    for jacobians in (False, True):
        base, w0, c0 = timed(lambda j=jacobians: softarm.solve(
            arm, loads, method="numeric", jacobians=j), args.repeats)
        Solver.solve_from_unloaded = counted
        try:
            calls.clear()
            softarm.solve(arm, displaced, jacobians=jacobians)
            solves = len(calls) - 1  # the outer call itself
            result, w1, c1 = timed(lambda j=jacobians: softarm.solve(
                arm, displaced, jacobians=j), args.repeats)
        finally:
            Solver.solve_from_unloaded = inner
        tag = ", jacobians=True" if jacobians else ""
        distance = np.max(np.abs(result.positions - base.positions)) / arm.length
        print(f"{'tension-controlled' + tag:44} {1e3 * w0:10.2f} {1e3 * c0:10.2f} {1.0:7.2f}")
        print(f"{'displacement-controlled' + tag:44} {1e3 * w1:10.2f} {1e3 * c1:10.2f} "
              f"{c1 / c0:7.2f}")
        print(f"    {solves} tension-controlled solves inside; same equilibrium to "
              f"{distance:.2g} L")


if __name__ == "__main__":
    main()
