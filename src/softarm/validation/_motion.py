"""The dynamics validation case of ``softarm reproduce``, and its helpers (shared with
tests/test_dynamics_references.py).

- Natural frequencies from a simulated free vibration (:func:`dominant_frequency` of
  :func:`free_vibration`) against Timoshenko's cantilever (``_timoshenko.py``).
- The energy of a released undamped arm over 20 periods.
- The heavy soft arm released horizontal and swinging under gravity against the method of
  lines (``data/swinging_arm_mol.csv``, written by tests/_mol_rod.py).
"""

from __future__ import annotations

import math

import numpy as np

from ..dispatch import solve
from ..dynamics import Damping, simulate
from ..loads import Gravity, PointLoad, TipLoad
from ..model import Arm, Circle, Material
from ._checks import CaseResult, gate
from ._checks import find_data_dir as _data_dir
from ._timoshenko import cantilever_axial, cantilever_bending, cantilever_torsion

__all__ = ["dominant_frequency", "dynamics", "free_vibration", "swinging_arm_reference"]

#: L/r = 20, where shear and rotary inertia lower the second bending frequency by 3.6 %
THICK = Arm(0.2, Circle(0.01), Material(1e7, poisson_ratio=0.5, density=1100.0))
#: the heavy soft arm of the method-of-lines reference (tests/_mol_rod.py)
HEAVY = Arm(0.5, Circle(0.02), Material(1e6, poisson_ratio=0.5, density=1100.0))
SWING_DAMPING = 0.01  # s, the reference's damped case


def swinging_arm_reference(case: str = "undamped") -> tuple[np.ndarray, np.ndarray]:
    """(t (151,), tip (151, 2): x, z in m) of the method-of-lines reference, ``case``
    'undamped' or 'damped' (data/swinging_arm_mol.csv, its header has the provenance)."""
    if case not in ("undamped", "damped"):
        raise ValueError(f"case must be 'undamped' or 'damped', got {case!r}")
    text = (_data_dir() / "swinging_arm_mol.csv").read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("#")]
    names = lines[0].split(",")
    data = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return data[:, names.index("t_s")], data[:, [names.index(f"x_{case}_m"),
                                                 names.index(f"z_{case}_m")]]


def dominant_frequency(signal, dt: float, near: float) -> float:
    """The angular frequency (rad/s) of the strongest oscillation near ``near`` in a signal
    sampled every ``dt``: the maximum of its Hann-windowed periodogram, searched between
    the neighbouring FFT bins (for a pure sinusoid, its frequency to far better than a bin).
    """
    from scipy.optimize import minimize_scalar

    x = np.asarray(signal, dtype=float) - np.mean(signal)
    t = np.arange(x.size) * dt
    window = np.hanning(x.size)

    def power(omega):
        return -abs(np.sum(window * x * np.exp(-1j * omega * t)))

    bin_ = 2 * math.pi / (x.size * dt)
    grid = near + bin_ * np.linspace(-3, 3, 61)
    start = grid[np.argmin([power(w) for w in grid])]
    found = minimize_scalar(power, bounds=(start - bin_ / 10, start + bin_ / 10),
                            method="bounded", options={"xatol": 1e-10 * near})
    return float(found.x)


def free_vibration(arm, loads, omega: float, stations: int = 51, periods: int = 20):
    """(trajectory, Δt): released at rest from the equilibrium under ``loads``, no load
    after, for ``periods`` periods of angular frequency ``omega`` at Δt = T/200."""
    dt = 2 * math.pi / omega / 200
    bent = solve(arm, loads, s=stations, tol=1e-12)
    return simulate(arm, [], duration=200 * periods * dt, dt=dt, stations=stations,
                    initial=bent, tol=1e-11), dt


def _frequencies(case: str) -> list:
    r, mu, inertia = THICK.rigidities, THICK.linear_density, THICK.rotary_inertia
    L = THICK.length
    bending = cantilever_bending(L, r.EIy, r.GAy, mu, inertia[1], count=2)
    force = 3e-3 * r.EIy / L**2
    runs = (
        ("first bending", bending[0], [TipLoad([0.0, 0.0, force])], 51,
         lambda path: path.tip_position[:, 2]),
        ("second bending", bending[1], [TipLoad([0.0, 0.0, -2 * force]),
                                        PointLoad(0.5 * L, [0.0, 0.0, 4 * force])], 101,
         lambda path: path.positions[:, 50, 2]),
        ("first torsional", cantilever_torsion(L, r.GJ, inertia[0]),
         [TipLoad(moment=[1e-3 * r.GJ / L, 0.0, 0.0])], 51,
         lambda path: np.arctan2(path.rotations[:, -1, 2, 1], path.rotations[:, -1, 1, 1])),
        ("first axial", cantilever_axial(L, r.EA, mu), [TipLoad([1e-3 * r.EA, 0.0, 0.0])], 51,
         lambda path: path.tip_position[:, 0]),
    )
    checks = []
    for name, omega, loads, stations, signal in runs:
        path, dt = free_vibration(THICK, loads, omega, stations)
        checks.append(gate(
            case, f"{name}, {stations} stations, Δt = T/200, 20 periods", "softarm.simulate",
            "ω [rad/s]", omega, dominant_frequency(signal(path), dt, omega), 2e-3,
            "Timoshenko's cantilever (Huang 1961) / the quarter wave", error_kind="rel"))
    return checks


def dynamics(tables) -> CaseResult:
    """Frequencies, energy and the large swing (the case's description: cases.py)."""
    case = "dynamics"
    result = CaseResult()
    result.checks += _frequencies(case)
    # the energy of the released arm (kinetic + elastic), undamped, over 20 periods
    r = THICK.rigidities
    omega = cantilever_bending(THICK.length, r.EIy, r.GAy, THICK.linear_density,
                               THICK.rotary_inertia[1])[0]
    path, _ = free_vibration(THICK, [TipLoad([0.0, 0.0, 0.5])], omega)
    total = path.energy.total
    result.checks.append(gate(
        case, "released from an 8.5 % tip deflection, undamped, Δt = T/200", "softarm.simulate",
        "max |E(t) - E(0)| / E(0) over 20 periods", 0.0,
        float(np.max(np.abs(total - total[0])) / total[0]), 0.01,
        "energy conservation (issue 32: within 1 %)"))
    # the heavy soft arm swinging down and up (one period), 101 stations, Δt = 1 ms
    for name, damping, bound in (("damped (τ = 0.01 s)", Damping(retardation=SWING_DAMPING),
                                  4e-4),
                                 ("undamped", None, 1.2e-3)):
        times, reference = swinging_arm_reference(name.split()[0])
        path = simulate(HEAVY, [Gravity()], duration=1.5, dt=1e-3, damping=damping)
        tip = path.tip_position[np.round(times / 1e-3).astype(int)][:, [0, 2]]
        distance = float(np.max(np.linalg.norm(tip - reference, axis=1)) / HEAVY.length)
        result.checks.append(gate(
            case, f"heavy soft arm released horizontal, {name}, 1.5 s", "softarm.simulate",
            "max |tip - reference| / L", 0.0, distance, bound,
            "method of lines, Richardson-extrapolated (data/swinging_arm_mol.csv)"))
    return result
