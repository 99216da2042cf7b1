"""An upright soft arm under its own weight, before and after its critical length (issue 15).

Run it from anywhere: ``python examples/upright_arm.py [OUTPUT_FOLDER]`` (pictures need
matplotlib). docs/stability.md walks through it.
"""

import sys
import warnings
from pathlib import Path

import numpy as np

import softarm
from softarm.stability import plot_branch

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path.cwd()

# A silicone rod of 4 mm radius clamped pointing straight up: the base frame turns the
# arm's axis e1 to +z, gravity pulls along -z.
silicone = softarm.Material(youngs_modulus=2.0e6, poisson_ratio=0.49, density=1070.0)
up = np.array([[0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0],
               [0.0, 0.0, 0.0, 1.0]])
weight = softarm.Gravity()

# Greenhill (1881): the upright column stands while q L³/EI < 7.8373 (q = ρ g A)
arm = softarm.Arm(0.15, softarm.Circle(0.004), silicone)
q = 1070.0 * 9.81 * np.pi * 0.004**2
EI = 2.0e6 * np.pi * 0.004**4 / 4
print(f"Greenhill's critical length (inextensible): {(7.837347438943 * EI / q) ** (1 / 3):.5f} m")

# The model's own critical length: the weight scaled by λ buckles the 0.15 m arm at λc, and
# q L³ is what counts, so L_c = L λc^(1/3)
point = softarm.critical_load(arm, weight, base=up)
print(f"critical_load: λc = {point.factor:.8f} ({point.kind}, nullity {point.nullity}); "
      f"L_c = {0.15 * point.factor ** (1 / 3):.5f} m")

short = softarm.solve(arm, weight, base=up)
print(f"L = 0.15 m: {short.stability}, tip {np.round(short.tip_position, 5)} m")

long_arm = softarm.Arm(0.25, softarm.Circle(0.004), silicone)
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always", softarm.StabilityWarning)
    straight = softarm.solve(long_arm, weight, base=up)
print(f"L = 0.25 m, connected branch: {straight.stability}, tip "
      f"{np.round(straight.tip_position, 5)} m; warned: {bool(caught)}")
fallen = softarm.solve(long_arm, weight, base=up, branch="stable", imperfection=[1.0, 0, 0])
print(f"L = 0.25 m, branch='stable': {fallen.stability}, tip "
      f"{np.round(fallen.tip_position, 5)} m")

# The branches: the straight one from λ = 0 to 1 (the 0.25 m arm's weight scaled by λ), and
# the one that bifurcates from it at the critical point
straight_branch = softarm.continuation(long_arm, weight, lam=(0.0, 1.0), base=up)
bent_branch = straight_branch.switch(0, imperfection=[1.0, 0.0, 0.0], max_step=0.02)
print("critical points:", [(round(c.factor, 6), c.kind, c.nullity)
                           for c in straight_branch.critical])

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:  # pragma: no cover
    sys.exit(0)

fig, (left, right) = plt.subplots(1, 2, figsize=(10.0, 4.4), layout="constrained")
for eq, style, label in ((short, "-", "L = 0.15 m: straight, stable (drawn wide)"),
                         (straight, "--", "L = 0.25 m: straight, UNSTABLE (index 2)"),
                         (fallen, "-", "L = 0.25 m: branch='stable' (index 0)")):
    left.plot(eq.positions[:, 0], eq.positions[:, 2], style, lw=6 if eq is short else 2,
              alpha=0.5 if eq is short else 1.0, label=label)
left.plot([0], [0], "ks")
left.set_aspect("equal")
left.set_xlabel("x (m)")
left.set_ylabel("z (m), up")
left.grid(alpha=0.3)
left.legend(fontsize=8, loc="lower left")
left.set_title("upright silicone arm, r = 4 mm, own weight")
plot_branch(straight_branch, bent_branch, coordinate=0, ax=right,
            labels=["straight", "bent (switched at the bifurcation)"])
right.set_title("load factor (weight × λ) against tip x")
picture = out / "stability_upright.png"
fig.savefig(picture, dpi=120)
print("wrote", picture)
