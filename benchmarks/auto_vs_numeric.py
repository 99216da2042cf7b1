"""``method="auto"`` against ``method="numeric"`` (tol 1e-6) on the closed-form benchmark cases.

The two are timed in alternation (``run.timed_pair``: blocks of calls taking turns, so both see
the same load on a shared machine); median wall and CPU time per call and their ratio. The
same measurement as the ``softarm auto`` rows of ``run.py``, alone and quick::

    python benchmarks/auto_vs_numeric.py                       # every closed-form case
    python benchmarks/auto_vs_numeric.py princeton_shear_P13.345 --repeats 400

Times are printed, never asserted.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import cases as bench_cases
from run import timed_pair


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="*", help="case names (default: every closed-form case)")
    parser.add_argument("--repeats", type=int, default=200, help="blocks per function")
    parser.add_argument("--block", type=int, default=5, help="calls per block")
    args = parser.parse_args(argv)
    import softarm

    known = {case.name: case for case in bench_cases.cases()}
    unknown = [name for name in args.case if name not in known]
    if unknown:
        parser.error(f"unknown case(s) {unknown}; known: {sorted(known)}")
    print(f"{'case':28s} {'closed form':28s} {'auto ms':>8s} {'(CPU)':>7s} "
          f"{'numeric ms':>10s} {'(CPU)':>7s} {'auto/numeric':>12s} {'(CPU)':>7s}")
    for name in args.case or list(known):
        arm, loads = bench_cases.to_softarm(known[name].problem)
        route = softarm.solve(arm, loads, method="auto").method
        if route.startswith("numeric"):
            if args.case:
                print(f"{name:28s} no closed form ({route})")
            continue
        softarm.solve(arm, loads, method="numeric", tol=1e-6)  # compiled before timing
        (wall, cpu), (n_wall, n_cpu) = timed_pair(
            lambda arm=arm, loads=loads: softarm.solve(arm, loads, method="auto"),
            lambda arm=arm, loads=loads: softarm.solve(arm, loads, method="numeric", tol=1e-6),
            args.repeats, args.block)
        print(f"{name:28s} {route:28s} {wall * 1e3:8.3f} {cpu * 1e3:7.3f} "
              f"{n_wall * 1e3:10.3f} {n_cpu * 1e3:7.3f} {wall / n_wall:11.2f}× "
              f"{cpu / n_cpu:6.2f}×", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
