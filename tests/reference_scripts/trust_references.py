"""Recompute the independent reference numbers of tests/statics/test_trust_regressions.py.

Run from the repository root:

    PYTHONPATH=tests python tests/reference_scripts/trust_references.py

Every number comes from scipy.integrate.solve_bvp (tests/_reference_rod.py: the static
Cosserat rod with extension and shear, clamped base, tip-wrench boundary conditions) continued
from the unloaded arm in load steps of at most 0.02 (secant predictor, step halved when
solve_bvp fails or the shape moves more than 5 % of L in a step), collocation tolerance 1e-6
during the continuation and 1e-9 for the final solve at λ = 1. It reads from softarm only the
arms' stiffness matrices, reference strains and linear densities, and the loads' fields.
"""

from __future__ import annotations

import json
import time

import numpy as np
from _reference_rod import describe, reference_energy, solve_reference

import softarm


def silicone_arm(length=1.0, nu=0.49):
    return softarm.Arm(length, softarm.Circle(0.01),
                       softarm.Material(youngs_modulus=1.5e6, poisson_ratio=nu, density=1070.0))


def demo_cases():
    """The random demo-arm batch of the batched-vs-looped regression (seed 2, 200 cases)."""
    rng = np.random.default_rng(2)
    F = rng.normal(size=(200, 3))
    F *= (rng.uniform(0.0, 4.0, size=200) / np.linalg.norm(F, axis=1))[:, None]
    return F


def cases():
    arm = silicone_arm()
    EI = float(arm.stiffness[4, 4])
    demo = softarm.load_case(
        __import__("pathlib").Path(softarm.__file__).parent / "data" / "demo.toml").arm
    F = demo_cases()
    return {
        "gravity_1m_nu049": (arm, [softarm.Gravity()]),
        "gravity_1m_nu05": (silicone_arm(nu=0.5), [softarm.Gravity()]),
        "gravity_0.6m": (silicone_arm(0.6), [softarm.Gravity()]),
        "gravity_0.8m": (silicone_arm(0.8), [softarm.Gravity()]),
        "tip_k25": (arm, [softarm.TipLoad(force=(0.0, 0.0, -25.0 * EI))]),
        "oblique_compressive": (arm, [softarm.TipLoad(force=np.array([-4.0, 0.0, -1.5]) * EI)]),
        "demo_case_1": (demo, [softarm.Gravity(), softarm.TipLoad(force=F[1])]),
        "demo_case_17": (demo, [softarm.Gravity(), softarm.TipLoad(force=F[17])]),
        "point_tol": (arm, [softarm.PointLoad(0.88, force=[0.1639, -0.1041, -0.2518])]),
        "tip_station": (silicone_arm(0.45), [softarm.Gravity(),
                                              softarm.PointLoad(0.09, force=[0.0, 0.0, -0.05]),
                                              softarm.TipLoad(force=[0.0, 0.02, -0.03])]),
    }


def main(names=()):
    out = {}
    for name, (arm, loads) in cases().items():
        if names and name not in names:
            continue
        t0 = time.perf_counter()
        ref = solve_reference(arm, loads, lam_step=0.02, tol=1e-6, final_tol=1e-9)
        entry = {"complete": ref.complete, "lam": ref.lam,
                 "tip": [float(x) for x in ref.tip_position()],
                 "seconds": round(time.perf_counter() - t0, 1)}
        rl = describe(loads)
        conservative = not (np.any(rl.tip_moment) or any(np.any(m) for _, _, m in rl.points))
        if conservative and ref.complete:
            entry["energy"] = reference_energy(ref, rl)
        _p, _R, n, m = ref.state([0.0])
        entry["base_force"] = [float(x) for x in n[0]]
        entry["base_moment"] = [float(x) for x in m[0]]
        out[name] = entry
        print(name, json.dumps(entry), flush=True)
    return out


if __name__ == "__main__":
    import sys

    main(sys.argv[1:])
