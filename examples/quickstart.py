"""softarm in a few lines: build an arm, load it, solve, export and plot.

Run it from anywhere: ``python examples/quickstart.py [OUTPUT_FOLDER]``.
"""

import sys
from pathlib import Path

import numpy as np

import softarm
from softarm.case import load_case
from softarm.io import save_result

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path.cwd()

# 1. An arm in code: a 0.3 m silicone rod of 10 mm radius, clamped at the origin along x.
silicone = softarm.Material(youngs_modulus=1.5e6, poisson_ratio=0.49, density=1070.0)
arm = softarm.Arm(0.3, softarm.Circle(0.01), silicone)

# 2. Loads: its own weight and a 20 g payload at the tip (dead loads, base frame, SI units).
loads = [softarm.Gravity(), softarm.TipLoad(force=[0.0, 0.0, -0.02 * 9.81])]

# 3. Solve: a closed form where one is exact, else the geometrically exact solver.
result = softarm.solve(arm, loads, s=51)
print(f"tip at {np.round(result.tip_position, 4)} m ({result.method})")

# 4. A batch of payloads in one call: leading axes of the load arrays are batch axes.
payloads = np.linspace(0.0, 0.05, 6)  # kg
batch = softarm.solve(arm, [softarm.Gravity(),
                            softarm.TipLoad(force=payloads[:, None] * [0.0, 0.0, -9.81])], s=51)
print("tip drop per payload (m):", np.round(batch.tip_position[:, 2], 4))

# 5. The same case from a file (as the `softarm` command reads it), exported to CSV.
case = load_case(Path(__file__).with_name("fig2_pure_bending.toml"))
circle = softarm.solve(case.arm, case.loads)
print("written:", save_result(circle, out / "fig2.csv", case))

# 6. Pictures need matplotlib (pip install "softarm[plot]").
try:
    from softarm.plot import plot_equilibrium
except ImportError:
    pass
else:
    plot_equilibrium(result, name="quickstart", path=out / "quickstart.png")
    print("written:", out / "quickstart.png")
