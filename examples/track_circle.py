"""Track a circle with the tip of a 3-tendon continuum robot under gravity (inverse statics).

The circle is made of reachable tip positions (each from a rotating tension pattern); an
InverseSolver then finds the tensions for every target in turn, each from the last answer, as
a control loop would. Writes track_circle.png: the targets and the tips reached, and the
tensions along the way.

    python examples/track_circle.py [OUT.png]
"""

import sys
import time

import numpy as np

import softarm
from softarm.routing import Straight

nitinol = softarm.Material(6.0e10, poisson_ratio=0.33, density=6450.0)
arm = softarm.Arm(0.25, softarm.Circle(0.0006), nitinol, mass_per_length=0.02)
offsets = [(0.0, 0.008), (0.006928, -0.004), (-0.006928, -0.004)]   # (y, z) in m
gravity = softarm.Gravity([0.0, 0.0, -9.81])

# 60 reachable targets: the tips under a tension pattern turning once around the arm
phase = np.linspace(0.0, 2.0 * np.pi, 60, endpoint=False)
pattern = 1.5 + 1.2 * np.cos(phase[:, None] - 2.0 * np.pi * np.arange(3) / 3.0)
made = softarm.solve(arm, [gravity] + [softarm.Tendon(pattern[:, i], Straight(*o))
                                       for i, o in enumerate(offsets)])
targets = made.tip_position

tracker = softarm.InverseSolver(arm, [softarm.Tendon(0.0, Straight(*o)) for o in offsets],
                                [gravity])
start = time.perf_counter()
result = tracker.track(targets)
seconds = time.perf_counter() - start
reached = result.equilibrium.tip_position
print(f"{int(result.reached.sum())}/{len(targets)} targets reached, largest error "
      f"{np.max(np.linalg.norm(reached - targets, axis=1)):.2e} m, "
      f"{1e3 * seconds / len(targets):.1f} ms a target")

import matplotlib  # noqa: E402

matplotlib.use("Agg")
from matplotlib import pyplot as plt  # noqa: E402

fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.6))
left.plot(targets[:, 1], targets[:, 2], "o", mfc="none", color="tab:blue", label="target")
left.plot(reached[:, 1], reached[:, 2], ".", color="tab:red", label="tip reached")
left.set(xlabel="y (m)", ylabel="z (m)", title="tip seen along the arm (x axis)")
left.set_aspect("equal")
left.legend()
for i in range(3):
    right.plot(np.degrees(phase), result.inputs[:, i], label=f"tendon {i + 1}")
right.set(xlabel="target phase (°)", ylabel="tension (N)", title="tensions found")
right.legend()
fig.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "track_circle.png"
fig.savefig(out, dpi=110)
print(f"wrote {out}")
