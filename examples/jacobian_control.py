"""A 1 kHz resolved-rate control loop on a 3-tendon continuum robot under gravity.

Each control period the loop calls ``ForwardSolver.solve`` once, with the tensions it
commands: the arm's equilibrium, reached quasi-statically from the last one, and its exact
actuation Jacobian (tip motion per newton of each tendon). The controller steps the tensions
by the damped least-squares solution of J δτ = (target - tip), kept >= 0, towards a target
that goes round a circle of reachable tip positions in one second. Writes
jacobian_control.png: the targets and the tips, the tracking error and the solve time per
period.

    python examples/jacobian_control.py [OUT.png]
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
tendons = [softarm.Tendon(0.0, Straight(*o)) for o in offsets]

# the target: tips under a tension pattern turning once around the arm, 1000 periods of 1 ms
periods = 1000
phase = np.linspace(0.0, 2.0 * np.pi, periods, endpoint=False)
pattern = 1.5 + 1.2 * np.cos(phase[:, None] - 2.0 * np.pi * np.arange(3) / 3.0)
targets = softarm.solve(arm, [gravity] + [softarm.Tendon(pattern[:, i], Straight(*o))
                                          for i, o in enumerate(offsets)]).tip_position

model = softarm.ForwardSolver(arm, tendons, [gravity], tol=1e-6)
tension = pattern[0] + [0.8, 0.0, 0.0]   # a start off the first target
state = model.solve(tension)
damping = 1e-3                      # m per N, the damped least squares' λ
tips, commanded, seconds = [], [], []
for target in targets:
    J = state.actuation_jacobian[:3]             # m/N: the tip's motion per tension
    error = target - state.tip_position
    step = J.T @ np.linalg.solve(J @ J.T + damping ** 2 * np.eye(3), error)
    tension = np.maximum(tension + step, 0.0)
    start = time.perf_counter()
    state = model.solve(tension)
    seconds.append(time.perf_counter() - start)
    tips.append(state.tip_position)
    commanded.append(tension)
tips, commanded, seconds = np.array(tips), np.array(commanded), np.array(seconds)
# the error of period k: the tip reached with its command against the target it aimed at
error = np.linalg.norm(tips - targets, axis=1)
print(f"{periods} periods: tracking error {1e3 * np.median(error[10:]):.3f} mm median after "
      f"the first 10 ({1e3 * error.max():.2f} mm at most, the start); ForwardSolver.solve "
      f"{1e3 * np.median(seconds):.2f} ms median, {1e3 * seconds.max():.2f} ms at most")

import matplotlib  # noqa: E402

matplotlib.use("Agg")
from matplotlib import pyplot as plt  # noqa: E402

fig, (left, middle, right) = plt.subplots(1, 3, figsize=(14, 4.4))
left.plot(1e3 * targets[:, 1], 1e3 * targets[:, 2], "-", color="tab:blue", lw=3, alpha=0.4,
          label="target")
left.plot(1e3 * tips[:, 1], 1e3 * tips[:, 2], "-", color="tab:red", lw=1, label="tip")
left.set(xlabel="y (mm)", ylabel="z (mm)", title="tip seen along the arm (x axis)")
left.set_aspect("equal")
left.legend()
middle.semilogy(np.arange(periods), 1e3 * error)
middle.set(xlabel="period (1 ms)", ylabel="|tip - target| (mm)", title="tracking error")
right.plot(np.arange(periods), 1e3 * seconds, ".", ms=2)
right.axhline(1.0, color="grey", lw=0.8)
right.set(xlabel="period (1 ms)", ylabel="ms", ylim=(0.0, 1.2),
          title="ForwardSolver.solve per period (1 ms budget)")
fig.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "jacobian_control.png"
fig.savefig(out, dpi=110)
print(f"wrote {out}")
