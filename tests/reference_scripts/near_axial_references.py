"""Recompute tests/data/near_axial_paths.json: where the loading path of a cantilever under a
near-axial compressive load ends (issue 42), by pseudo-arclength continuation from the unloaded
arm (tests/_planar_path.py and tests/_spatial_path.py, which import nothing from softarm).

Run from the repository root (about 6 min on one core):

    PYTHONPATH=tests python tests/reference_scripts/near_axial_references.py

"cases": the arm L = 1 m, EI = 1 N m², EA = GA = 1e12 N (practically inextensible); a dead tip
force of magnitude F L²/EI in 30 ... 1000 at 175 ... 179.99° from the arm's axis (+x), in the
x-y plane (planar reference).

"spatial": two silicone arms (L = 0.3 m, r = 5 mm, E = 1 MPa, ν = 0.5, ρ = 1000 kg/m³) whose
response leaves every plane (3-D reference): k times the Euler load π²EI/(4L²) at 179.9° in
the x-y plane with a weak gravity along −z (its weight 1 % of the force), and exactly along −x
on an arm precurved about y (κ⁰ L = 0.03) with a weak gravity along −y.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

from _planar_path import follow
from _spatial_path import follow as follow_spatial

ANGLES = (175.0, 176.0, 177.0, 178.0, 179.0, 179.5, 179.9, 179.95, 179.99)  # degrees
MAGNITUDES = (30.0, 50.0, 100.0, 200.0, 300.0, 500.0, 700.0, 1000.0)  # F L²/EI
OUT = Path(__file__).resolve().parents[1] / "data" / "near_axial_paths.json"


def silicone(curvature=(0.0, 0.0, 0.0)):
    """(length, stiffness (EA, GAy, GAz, GJ, EIy, EIz), μ, curvature) of the silicone arm:
    a round section r = 5 mm, E = 1 MPa, ν = 0.5 (G = E/3), shear coefficient 6 (1 + ν)/
    (7 + 6 ν) (Cowper's, for a solid circle), ρ = 1000 kg/m³."""
    r, E, nu, rho = 0.005, 1e6, 0.5, 1000.0
    area, second_moment = math.pi * r**2, math.pi * r**4 / 4
    G = E / (2 * (1 + nu))
    shear = 6 * (1 + nu) / (7 + 6 * nu)
    return (0.3, (E * area, shear * G * area, shear * G * area, G * 2 * second_moment,
                  E * second_moment, E * second_moment), rho * area, curvature)


def euler_load(length, stiffness):
    """π² EI / (4 L²), N."""
    return math.pi**2 * stiffness[4] / (4 * length**2)


def spatial_cases():
    """The 3-D cases: (name, k, length, stiffness, μ, curvature, tip force, distributed
    force), SI units."""
    out = []
    for k in (10.0, 30.0):
        L, K, mu, _ = silicone()
        euler = euler_load(L, K)
        a = math.radians(179.9)
        force = (k * euler * math.cos(a), k * euler * math.sin(a), 0.0)
        out.append(("off_axis_with_gravity_z", k, L, K, mu, (0.0, 0.0, 0.0), force,
                    (0.0, 0.0, -0.01 * k * euler / L)))
        out.append(("axial_precurved_with_gravity_y", k, L, K, mu, (0.0, 0.03 / L, 0.0),
                    (-k * euler, 0.0, 0.0), (0.0, -0.01 * k * euler / L, 0.0)))
    return out


def main():
    spatial = []
    for name, k, L, K, _, curvature, force, distributed in spatial_cases():
        start = time.process_time()
        end = follow_spatial(L, K, tip_force=force, distributed=distributed,
                             curvature=curvature)
        spatial.append({"name": name, "k": k, "tip": [float(v) for v in end.tip],
                        "steps": end.steps})
        print(f"{name} k = {k}: tip {end.tip} {end.steps} steps "
              f"{time.process_time() - start:.1f} s", flush=True)
    cases = []
    for angle in ANGLES:
        for magnitude in MAGNITUDES:
            a = math.radians(angle)
            force = (magnitude * math.cos(a), magnitude * math.sin(a))
            start = time.process_time()
            end = follow(1.0, 1.0, 1e12, 1e12, tip_force=force)
            cases.append({"angle_deg": angle, "magnitude": magnitude,
                          "tip": [float(end.tip[0]), float(end.tip[1])],
                          "tip_angle": float(end.theta), "reached": float(end.reached),
                          "folded": end.folded, "steps": end.steps})
            print(f"{angle:8.2f}° F L²/EI {magnitude:6.0f}: tip ({end.tip[0]:+.6f}, "
                  f"{end.tip[1]:+.6f}) λ {end.reached:.3f} {end.steps} steps "
                  f"{time.process_time() - start:.1f} s", flush=True)
    OUT.parent.mkdir(exist_ok=True)
    OUT.write_text(json.dumps({
        "source": "tests/reference_scripts/near_axial_references.py: pseudo-arclength "
                  "continuation of the planar rod from the unloaded arm (tests/_planar_path.py, "
                  "scipy DOP853 rtol 1e-11), independent of softarm",
        "arm": {"length": 1.0, "EI": 1.0, "EA": 1e12, "GA": 1e12},
        "cases": cases, "spatial": spatial}, indent=1) + "\n")


if __name__ == "__main__":
    main()
