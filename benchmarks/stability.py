"""What a stability verdict costs per solve, and what critical_load costs (issue 15).

    python benchmarks/stability.py

Each row times softarm.solve(method="numeric") with and without the verdict
(``stability=True`` / ``False``), median wall and CPU time over repeats, warm (numba
compiled first), and prints the verdict's share of the solve; then critical_load on the
classical cases. Times are printed, never asserted.
"""

from __future__ import annotations

import statistics
import time
import warnings

import numpy as np

import softarm
from softarm import Arm, Gravity, TipLoad


def timed(function, repeats):
    wall, cpu = [], []
    for _ in range(repeats):
        w0, c0 = time.perf_counter(), time.process_time()
        function()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return statistics.median(wall), statistics.median(cpu)


def paired(without, with_, repeats):
    """Median wall and CPU times of two functions timed in alternation (the machine's load
    drifts; alternating shares it between the two)."""
    a, b = [], []
    for _ in range(repeats):
        a.append(timed(without, 1))
        b.append(timed(with_, 1))
    return (statistics.median(x[0] for x in a), statistics.median(x[1] for x in a),
            statistics.median(x[0] for x in b), statistics.median(x[1] for x in b))


def solve_cases():
    round_arm = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0,
                                   mass_per_length=1.0)
    soft = Arm.from_stiffness(0.3, EA=30.0, GAy=12.0, GAz=12.0, GJ=0.01, EIy=0.013,
                              EIz=0.02, mass_per_length=0.05)
    rng = np.random.default_rng(1)
    forces = rng.normal(size=(1000, 3))
    return [
        ("3D tip force (k = 5)", round_arm, TipLoad(force=[0.0, 3.0, 4.0]), 200),
        ("upright heavy column, q = 0.9 q_c", round_arm, Gravity([-0.9 * 7.8373, 0, 0]), 200),
        ("soft arm: gravity + 3D tip force", soft,
         [Gravity(), TipLoad(force=[0.0, 0.02, -0.05])], 200),
        ("batch of 1000 random tip forces", round_arm, TipLoad(force=forces), 7),
    ]


def main():
    print("stability verdict per solve (softarm.solve, method='numeric', tol=1e-8)")
    print(f"{'case':40s} {'solve ms':>10s} {'+verdict ms':>12s} {'share':>7s} "
          f"{'cpu share':>9s}")
    for name, arm, loads, repeats in solve_cases():
        for stability in (True, False):  # compile both
            softarm.solve(arm, loads, method="numeric", stability=stability)
        w1, c1, w2, c2 = paired(
            lambda arm=arm, loads=loads: softarm.solve(arm, loads, method="numeric",
                                                       stability=False),
            lambda arm=arm, loads=loads: softarm.solve(arm, loads, method="numeric",
                                                       stability=True), repeats)
        print(f"{name:40s} {1e3 * w1:10.3f} {1e3 * w2:12.3f} {(w2 - w1) / w1:7.1%} "
              f"{(c2 - c1) / c1:9.1%}")
    print()
    print("closed forms, 10^4 cases, 11 stations (softarm.solve, method='auto')")
    arm = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0)
    rng = np.random.default_rng(0)
    axial = np.zeros((10000, 3))
    axial[:, 0] = rng.uniform(-5.0, 5.0, 10000)
    for name, loads in (("axial force (closed-form index)", TipLoad(force=axial)),
                        ("tip moment, helix (swept)", TipLoad(moment=rng.normal(size=(10000, 3))))):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for stability in (True, False):
                softarm.solve(arm, loads, s=11, stability=stability)
            w1, c1, w2, c2 = paired(
                lambda loads=loads: softarm.solve(arm, loads, s=11, stability=False),
                lambda loads=loads: softarm.solve(arm, loads, s=11, stability=True), 5)
        print(f"{name:40s} {1e3 * w1:10.1f} {1e3 * w2:12.1f} {(w2 - w1) / w1:7.1%} "
              f"{(c2 - c1) / c1:9.1%}")
    print()
    print("critical_load (default steps 256, refined until two grids agree to 1e-9)")
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0,
                             mass_per_length=1.0)
    rect = Arm.from_stiffness(1.0, EA=1e10, GAy=1e10, GAz=1e10, GJ=0.5, EIy=1.0, EIz=1e6)
    rows = [("Euler cantilever (round)", arm, TipLoad(force=[-1.0, 0, 0]),
             np.pi ** 2 / 4),
            ("Greenhill heavy column", arm, Gravity([-1.0, 0, 0]), 7.837347438943484),
            ("Prandtl lateral-torsional", rect, TipLoad(force=[0, 1.0, 0]),
             4.012599343578901 * np.sqrt(0.5))]
    print(f"{'case':30s} {'wall s':>8s} {'cpu s':>8s} {'lambda_c':>18s} {'rel. error':>11s}")
    for name, a, loads, reference in rows:
        softarm.critical_load(a, loads)
        w, c = timed(lambda a=a, loads=loads: softarm.critical_load(a, loads), 3)
        point = softarm.critical_load(a, loads)
        print(f"{name:30s} {w:8.3f} {c:8.3f} {point.factor:18.12f} "
              f"{abs(point.factor / reference - 1):11.1e}")
    print()
    print("solve(branch='stable') past the Euler load (P = 1.5 P_cr, round)")
    load = TipLoad(force=[-1.5 * np.pi ** 2 / 4, 0, 0])
    softarm.solve(arm, load, branch="stable")
    w, c = timed(lambda: softarm.solve(arm, load, branch="stable"), 3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        w0, _ = timed(lambda: softarm.solve(arm, load, method="numeric"), 10)
    print(f"branch='stable': {w:.3f} s wall, {c:.3f} s CPU (a plain solve: {1e3 * w0:.2f} ms)")


if __name__ == "__main__":
    main()
