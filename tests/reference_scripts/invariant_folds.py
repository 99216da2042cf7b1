"""How often the random cases of tests/statics/test_invariants.py meet a fold, and whether the
independent solve_bvp continuation (tests/_reference_rod.py) stops there too.

Run from the repository root (SOFTARM_INVARIANTS_LARGE=1 for the large run's cases):

    PYTHONPATH=tests python tests/reference_scripts/invariant_folds.py

Prints one line per ConvergenceError (the solver's load factor, the reference's λ reached) and
a count per family of cases.
"""

from __future__ import annotations

import sys
from pathlib import Path

import softarm


def main():
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "statics"))
    import test_invariants as inv

    groups = {
        "balance": [inv.case("balance", i) for i in range(inv.N_BALANCE)],
        "ladder": [inv.case("ladder", i) for i in range(inv.N_LADDER)],
        "energy": [inv.case("energy", i, conservative=True) for i in range(inv.N_ENERGY)],
        "batch": [(arm, inv.take(loads, row)) for arm, loads in
                  (inv.batch_group(g) for g in range(inv.N_BATCH_GROUPS))
                  for row in range(inv.BATCH)],
    }
    for name, cases in groups.items():
        errors = 0
        for i, (arm, loads) in enumerate(cases):
            try:
                softarm.solve(arm, loads, tol=inv.TOL)
            except softarm.ConvergenceError as error:
                errors += 1
                ref = inv.reference_of((name, i), arm, tuple(loads))
                print(f"{name}[{i}]: load_factor={getattr(error, 'load_factor', None)} "
                      f"reference λ={ref.lam:.4g} complete={ref.complete}: {error}", flush=True)
        print(f"{name}: {errors} of {len(cases)} cases raised ConvergenceError", flush=True)


if __name__ == "__main__":
    main()
