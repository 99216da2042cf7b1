"""Write tests/data/till_rucker/ from runs of Till, Aloi & Rucker's dynamics examples.

The runs themselves (their C++ code, patched to write CSV) happen outside this repository; see
tests/data/till_rucker/README.md for the commit, the patch, the build and the run commands.
This script only reads their raw CSV output, subsamples it, and writes the files kept here,
together with params.json (the examples' parameters in SI units, derived values computed from
the same formulas as their code).

    python tests/reference_scripts/till_rucker_dynamics.py RAW_DIR

RAW_DIR holds cant_N40_tip.csv, cant_N40_centreline.csv, tend/tendon_N200_tip.csv,
tend/tendon_N200_centreline.csv and conv/<run>_tip.csv of the convergence runs.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parents[1] / "data" / "till_rucker"
UPSTREAM = "github.com/JohnDTill/ContinuumRobotExamples"
COMMIT = "064f593e1ceb5c725481e3a6669bdcbe90f1e43f"

# Their codes put the rod axis on e3; softarm puts it on material e1. A vector a = (ax, ay, az)
# in their frame is (az, ax, ay) in softarm's (the proper rotation P below); the same mapping
# as src/softarm/validation/data/actuation_benchmarks.json.
AXIS_MAP = {
    "their_frame": "rod axis = material e3; base at the origin with R(0) = I, so the "
                   "undeformed rod lies along world +z; gravity along world -x",
    "to_softarm": "a = (ax, ay, az) in their frame -> (az, ax, ay) in softarm's frame "
                  "(P = [[0,0,1],[1,0,0],[0,1,0]], proper); rotation matrices P R P^T; "
                  "Kse diag(GA, GA, EA) -> (EA, GA, GA); Kbt diag(EI, EI, GJ) -> (GJ, EI, EI)",
    "P": [[0, 0, 1], [1, 0, 0], [0, 1, 0]],
}


def to_softarm(a):
    """Map a 3-vector from their frame (axis e3) to softarm's (axis e1)."""
    return [a[2], a[0], a[1]]


def section(radius, E, G, rho):
    A = math.pi * radius**2
    second = math.pi * radius**4 / 4
    return {
        "area": A, "second_moment_I": second, "polar_moment_J": 2 * second,
        "Kse_their_order_GA_GA_EA": [G * A, G * A, E * A],
        "Kbt_their_order_EI_EI_GJ": [E * second, E * second, G * 2 * second],
        "Kse_softarm_order_EA_GA_GA": [E * A, G * A, G * A],
        "Kbt_softarm_order_GJ_EI_EI": [G * 2 * second, E * second, E * second],
        "rhoA": rho * A,
        "rhoJ_their_order": [rho * second, rho * second, rho * 2 * second],
        "rhoJ_softarm_order": [rho * 2 * second, rho * second, rho * second],
        "shear_coefficient": 1.0,
    }


def bdf_alpha(dt, alpha):
    return {
        "alpha": alpha, "dt": dt,
        "c0": (1.5 + alpha) / (dt * (1 + alpha)), "c1": -2.0 / dt,
        "c2": (0.5 + alpha) / (dt * (1 + alpha)), "d1": alpha / (1 + alpha),
        "formula": "x_t(i) = c0 x(i) + c1 x(i-1) + c2 x(i-2) + d1 x_t(i-1); "
                   "start from rest at the static solution: x(-1) = x(-2) = x(0), x_t(-1) = 0",
    }


def cantilever_params():
    E, G, radius, rho, L = 200e9, 80e9, 0.001, 8000.0, 0.5
    g = [-9.81, 0.0, 0.0]
    tip_mass = 0.02
    dt, alpha, N, T = 2e-3, -0.2, 40, 25.0
    return {
        "example": "02_Dynamics/00_Cosserat_Rod_PDE/Cpp/main.cpp",
        "what": "Steel cantilever (clamped at s = 0, free at s = L), horizontal, under its own "
                "weight. Initial condition: static equilibrium under gravity plus a dead tip "
                "force m_tip g; at t = 0+ the tip force is removed (gravity stays) and the rod "
                "oscillates about its self-weight equilibrium. No material damping (all B = 0), "
                "no drag, no other load. Only numerical damping from BDF-alpha (alpha = -0.2).",
        "length": L, "radius": radius, "youngs_modulus": E, "shear_modulus": G,
        "poisson_ratio_implied": E / (2 * G) - 1, "density": rho,
        "gravity_their_frame": g, "gravity_softarm_frame": to_softarm(g),
        "section": section(radius, E, G, rho),
        "reference_strains": "v* = e3 (their frame), u* = 0: straight, unstretched",
        "constitutive_law": "material frame: R^T n = Kse (v - v*) + Bse v_t, "
                            "R^T m = Kbt (u - u*) + Bbt u_t (Kelvin-Voigt)",
        "Bse_their_order": [0.0, 0.0, 0.0], "Bbt_their_order": [0.0, 0.0, 0.0],
        "drag": None,
        "initial_tip_mass": tip_mass,
        "initial_tip_force_their_frame": [tip_mass * c for c in g],
        "initial_tip_force_softarm_frame": to_softarm([tip_mass * c for c in g]),
        "load_after_release": "gravity only; tip free: n(L) = 0, m(L) = 0",
        "base": "clamped at the origin, R(0) = I, velocities q(0) = w(0) = 0",
        "time": bdf_alpha(dt, alpha) | {"duration": T, "steps": round(T / dt)},
        "grid": {"N_points": N, "ds": L / (N - 1),
                 "scheme": "explicit Euler in s on N equally spaced nodes including both ends"},
        "shooting": {"unknowns": "n(0), m(0) (spatial frame)",
                     "residual": "n(L), m(L) (spatial frame); static IC: n(L) - F_tip, m(L)",
                     "solver": "Levenberg-Marquardt, forward-difference Jacobian recomputed each "
                               "iteration, relative increment 1e-8 (floor 1e-12), stop when "
                               "|residual|^2 <= 1e-12, max 500 iterations, initial damping "
                               "1e-2 halved on success, warm start from the previous step"},
    }


def tendon_schedule_z(t):
    """Their motor displacement z(t) in m (the same branches and inequalities as their z())."""
    zA, zB, t1, t2, t3, t4 = 0.0, -0.01619, 3.652, 3.967, 17.63, 17.94
    if t1 < t <= t2:
        return zA + (zB - zA) * (t - t1) / (t2 - t1)
    if t2 < t <= t3:
        return zB
    if t3 < t <= t4:
        return zB + (zA - zB) * (t - t3) / (t4 - t3)
    return zA


def tendon_params():
    E = 207e9
    G = E / (2 * 1.3)
    radius = 0.00135 / 2
    L = 0.7144
    total_mass = 0.034
    A = math.pi * radius**2
    rho = total_mass / (L * A)
    g = [-9.81, 0.0, 0.0]
    dt, alpha, N, T = 5e-2, 0.0, 200, 25.0
    r = [0.01506, 0.0, 0.0]
    return {
        "example": "02_Dynamics/03_Tendon_Robot/Cpp/main.cpp",
        "what": "Horizontal spring-steel tendon robot (one straight tendon, displacement "
                "controlled by a motor), under gravity, with bending/torsion Kelvin-Voigt "
                "damping and quadratic drag. Initial condition: static equilibrium at motor "
                "z = 0 (the sagging rod stretches the tendon on its upper side, so it starts "
                "taut). The motor retracts the tendon 16.19 mm at t = 3.652..3.967 s, holds, "
                "and releases it at t = 17.63..17.94 s.",
        "length": L, "radius": radius, "youngs_modulus": E, "shear_modulus": G,
        "poisson_ratio_implied": 0.3, "total_mass": total_mass,
        "density": rho, "density_note": "effective: total_mass / (L A), spacer disks included "
                                        "in the rod's line density; rhoJ = density * J",
        "gravity_their_frame": g, "gravity_softarm_frame": to_softarm(g),
        "section": section(radius, E, G, rho),
        "reference_strains": "v* = e3, u* = 0",
        "constitutive_law": "material frame: nb = Kse (v - v*) + Bse v_t, mb = Kbt (u - u*) + "
                            "Bbt u_t (Kelvin-Voigt; n, m here are the backbone's internal "
                            "force and moment, the tendon acts through distributed loads)",
        "Bse_their_order": [0.0, 0.0, 0.0], "Bse_units": "N s",
        "Bbt_their_order": [5e-4, 5e-4, 5e-4], "Bbt_units": "N m^2 s",
        "drag": {"C_their_order": [1e-4, 1e-4, 1e-4], "units": "kg/m^2 (N s^2/m^3)",
                 "law": "distributed force per length, material frame: f = -C (q .* |q|), "
                        "q = material-frame velocity (componentwise quadratic drag)"},
        "tendon": {
            "count": 1,
            "offset_their_frame": r, "offset_softarm_frame": to_softarm(r),
            "routing": "straight, constant offset in the material frame (r_s = r_ss = 0), "
                       "from the base plate to the tip, terminating at s = L",
            "model": "Rucker & Webster 2011 distributed tendon loads, tendon friction-free; "
                     "tip: point force -tau pb_s/|pb_s| at r, moment r x that force",
            "base_to_motor": 0.0518,
            "compliance": 1e-4, "compliance_units": "1/N (tendon strain per newton)",
            "length_constraint": "integral_0^L |v + u x r| ds + base_to_motor + slack "
                                 "= l*(t) (1 + compliance tau), l*(t) = L + base_to_motor + "
                                 "z(t); one unknown x: tau = max(x, 0), slack = max(-x, 0)",
            "motor_schedule_z": {"zA": 0.0, "zB": -0.01619, "t1": 3.652, "t2": 3.967,
                                 "t3": 17.63, "t4": 17.94,
                                 "law": "z = zA for t <= t1; linear zA -> zB on (t1, t2]; "
                                        "zB on (t2, t3]; linear zB -> zA on (t3, t4]; zA after"},
            "time_variable_note": "their t is accumulated by t += dt (floating point), and "
                                  "step i is solved with z(t_i)",
        },
        "base": "clamped at the origin, R(0) = I, q(0) = w(0) = 0",
        "time": bdf_alpha(dt, alpha) | {"duration": T, "steps": round(T / dt)},
        "grid": {"N_points": N, "ds": L / (N - 1),
                 "scheme": "explicit Euler in s on N equally spaced nodes including both ends"},
        "shooting": {"unknowns": "Kse^-1 n-guess (so v(0) = Kse^-1 x + e3), u(0), tendon x "
                                 "(7 unknowns; v(0), u(0) are shot, not n(0))",
                     "state": "p, R, v, u, q, w, tendon length (strain-based, v_s, u_s from a "
                              "6x6 LLT solve per node)",
                     "residual": "tip force and moment balance with the tendon's end force "
                                 "(material frame), tendon length error",
                     "solver": "Levenberg-Marquardt, forward-difference Jacobian, relative "
                               "increment 1e-7 (floor 1e-9), stop when |residual|^2 <= "
                               "1e-12, max 1500 iterations, initial damping 1e-2, warm start"},
    }


def write_csv(path, header_lines, columns, rows, fmt="%.12g"):
    with open(path, "w") as f:
        for line in header_lines:
            f.write(f"# {line}\n")
        f.write(",".join(columns) + "\n")
        for row in rows:
            f.write(",".join(fmt % v if isinstance(v, float) else str(v) for v in row) + "\n")


def load(path):
    return np.genfromtxt(path, delimiter=",", names=True)


def cantilever_files(raw):
    d = load(raw / "cant_N40_tip.csv")
    prov = [f"Till, Aloi & Rucker dynamics example 02_Dynamics/00_Cosserat_Rod_PDE ({UPSTREAM} "
            f"@ {COMMIT[:12]}), run here with tests/data/till_rucker/till_dynamics.patch;",
            "N = 40 points, dt = 2 ms, BDF-alpha alpha = -0.2 (see params.json, README.md).",
            "Their frame: rod axis +z, gravity -x; tip y is 0 to 1e-20 and dropped. "
            "Row t = i dt is the state after step i (t = 0: static initial condition).",
            "Units: s, m. 12 significant digits (their shooting tolerance: |residual| <= 1e-6)."]
    first = d[d["t"] <= 2.0 + 1e-9]
    write_csv(OUT / "cantilever_tip_first2s.csv",
              [*prov, "Every step for 0 <= t <= 2 s."], ["step", "t", "x", "z"],
              [(int(r["step"]), float(r["t"]), float(r["x"]), float(r["z"])) for r in first])
    every = d[d["step"].astype(int) % 10 == 0]
    write_csv(OUT / "cantilever_tip_25s.csv",
              [*prov, "Every 10th step (20 ms) for 0 <= t <= 25 s."], ["step", "t", "x", "z"],
              [(int(r["step"]), float(r["t"]), float(r["x"]), float(r["z"])) for r in every])
    c = load(raw / "cant_N40_centreline.csv")
    keep = np.isin(np.round(c["t"], 6), [0.0, 0.05, 0.1, 0.15, 0.2, 0.5, 1.0, 2.0])
    write_csv(OUT / "cantilever_centreline.csv",
              [*prov, "Centreline (all 40 nodes, s = j L/39) at t = 0, 0.05, 0.1, 0.15, 0.2, "
                      "0.5, 1, 2 s; y dropped (0)."],
              ["step", "t", "j", "s", "x", "z"],
              [(int(r["step"]), float(r["t"]), int(r["j"]), float(r["s"]), float(r["x"]),
                float(r["z"])) for r in c[keep]])


CONV_RUNS = [  # name in RAW/conv, N, dt
    ("N40_dt2", 40, 2e-3), ("N80_dt2", 80, 2e-3), ("N160_dt2", 160, 2e-3),
    ("N320_dt2", 320, 2e-3), ("N640_dt2_T2", 640, 2e-3), ("N1280_dt2_T2", 1280, 2e-3),
    ("N40_dt4", 40, 4e-3), ("N40_dt8", 40, 8e-3),
    ("N320_dt4", 320, 4e-3), ("N320_dt8", 320, 8e-3),
]
CONV_TIMES = [0.0, 0.04, 0.08, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 25.0]


def convergence_file(raw):
    rows = []
    for name, N, dt in CONV_RUNS:
        path = raw / "conv" / f"{name}_tip.csv"
        if not path.exists():
            print(f"missing {path}", file=sys.stderr)
            continue
        d = load(path)
        for t in CONV_TIMES:
            i = round(t / dt)
            if i < len(d):
                rows.append((name, N, dt, float(d["t"][i]), float(d["x"][i]), float(d["z"][i])))
    write_csv(OUT / "cantilever_convergence.csv",
              ["Their cantilever example at other grids (N points) and time steps dt, same "
               "physics and solver (patch option -DTILL_N, -DTILL_DT, -DTILL_T).",
               "Tip position in their frame (axis +z, gravity -x), m. Runs named *_T2 stop "
               "at t = 2 s. dt < 2 ms could not be run: their shooting fails within the first "
               "steps (README.md)."],
              ["run", "N", "dt", "t", "x", "z"], rows)


def spatially_converged_file(raw):
    b = load(raw / "conv" / "N640_dt2_T2_tip.csv")
    c = load(raw / "conv" / "N1280_dt2_T2_tip.csv")
    a = load(raw / "conv" / "N320_dt2_tip.csv")[: len(b)]
    ex, ez = 2 * c["x"] - b["x"], 2 * c["z"] - b["z"]
    spread = max(np.abs(ex - (2 * b["x"] - a["x"])).max(), np.abs(ez - (2 * b["z"] - a["z"])).max())
    write_csv(OUT / "cantilever_tip_dt2ms_fine_grid_first2s.csv",
              ["Their cantilever example with the default time discretization (dt = 2 ms, "
               "BDF-alpha alpha = -0.2) on fine s-grids: x_N1280, z_N1280 from N = 1280 points; "
               "x_extrap, z_extrap = 2 X(N=1280) - X(N=640) (Richardson, their s-integrator is "
               "first-order Euler).",
               f"Largest change of the extrapolation from (320, 640) to (640, 1280): "
               f"{spread:.1e} m (an error bar for x_extrap, z_extrap as the N -> infinity limit "
               "at this dt). The time-discretization error is NOT removed (README.md).",
               "Their frame (axis +z, gravity -x), m, s; every step, 0 <= t < 2 s."],
              ["step", "t", "x_N1280", "z_N1280", "x_extrap", "z_extrap"],
              [(int(r["step"]), float(r["t"]), float(r["x"]), float(r["z"]), float(x), float(z))
               for r, x, z in zip(c, ex, ez, strict=True)])


def tendon_files(raw):
    d = load(raw / "tend" / "tendon_N200_tip.csv")
    prov = [f"Till, Aloi & Rucker dynamics example 02_Dynamics/03_Tendon_Robot ({UPSTREAM} "
            f"@ {COMMIT[:12]}), run here with tests/data/till_rucker/till_dynamics.patch;",
            "N = 200 points, dt = 50 ms, BDF-alpha alpha = 0 (BDF2) (params.json, README.md).",
            "Their frame: rod axis +z, gravity -x, tendon at +x. t: their accumulated time "
            "(t += dt); motor_z = z(t) used in that step's solve (m); tension in N.",
            "Row i: the solution of step i (row 0: static initial condition at z = 0). "
            "Tip y is 0 to 1e-20 and dropped. 12 significant digits."]
    write_csv(OUT / "tendon_tip.csv", prov, ["step", "t", "motor_z", "tension", "x", "z"],
              [(int(r["step"]), float(r["t"]), float(r["motor_z"]), float(r["tension"]),
                float(r["x"]), float(r["z"])) for r in d])
    c = load(raw / "tend" / "tendon_N200_centreline.csv")
    steps = [0, 74, 76, 78, 80, 90, 100, 200, 352, 356, 360, 370, 499]
    nodes = [*range(0, 200, 10), 199]
    keep = np.isin(c["step"].astype(int), steps) & np.isin(c["j"].astype(int), nodes)
    write_csv(OUT / "tendon_centreline.csv",
              [*prov, f"Centreline at steps {steps}, nodes j = 0, 10, ..., 190, 199 "
                      "(s = j L/199)."],
              ["step", "t", "j", "s", "x", "z"],
              [(int(r["step"]), float(r["t"]), int(r["j"]), float(r["s"]), float(r["x"]),
                float(r["z"])) for r in c[keep]])


def main():
    raw = Path(sys.argv[1])
    OUT.mkdir(parents=True, exist_ok=True)
    params = {
        "_about": "Parameters of Till, Aloi & Rucker's dynamics examples (IJRR 2019, 'Real-time "
                  "dynamics of soft and continuum robots based on Cosserat rod models'), read "
                  f"from {UPSTREAM} @ {COMMIT}, SI units. Derived values are computed with "
                  "their formulas. See README.md.",
        "repository": UPSTREAM, "commit": COMMIT,
        "frames": AXIS_MAP,
        "cantilever": cantilever_params(),
        "tendon_robot": tendon_params(),
    }
    (OUT / "params.json").write_text(json.dumps(params, indent=1) + "\n")
    cantilever_files(raw)
    convergence_file(raw)
    spatially_converged_file(raw)
    tendon_files(raw)


if __name__ == "__main__":
    main()
