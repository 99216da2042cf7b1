"""softarm's dynamics against independent references.

- The natural frequencies of a cantilever from a simulated free vibration against
  Timoshenko's beam (first two bending modes, shear factor and rotary inertia included; to
  1e-5 at 41 stations), the first torsional and first axial frequency
  (softarm/validation/_timoshenko.py), to 0.2 % at Δt = T/200 (softarm reproduce runs the
  same checks: softarm/validation/_motion.py).
- The heavy soft arm released horizontal, swinging down under gravity, against the
  method-of-lines solution of tests/_mol_rod.py (softarm/validation/data/swinging_arm_mol.csv).
- Till, Aloi & Rucker's steel cantilever (their C++ example at a stated commit,
  tests/data/till_rucker/).
- The order of the scheme in Δt.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _mol_rod import load_reference

import softarm
from softarm import Arm, Circle, Damping, Gravity, Material, Simulator, TipLoad, simulate
from softarm.validation._motion import dominant_frequency as _frequency
from softarm.validation._motion import free_vibration as _released
from softarm.validation._timoshenko import (
    cantilever_axial,
    cantilever_bending,
    cantilever_torsion,
)

DATA = Path(__file__).parent / "data"
THICK = Arm(0.2, Circle(0.01), Material(1e7, poisson_ratio=0.5, density=1100.0))  # L/r = 20


def _section(arm):
    r = arm.rigidities
    mu = arm.linear_density
    rho_j = arm.rotary_inertia
    return r, mu, rho_j


@pytest.mark.slow
def test_the_first_two_bending_frequencies_are_timoshenkos():
    """At 41 stations, to 1e-5 (issue 40). Δt = T/200 shifts a frequency by the trapezoidal
    rule's own dispersion in time, tan(ω_Δ Δt/2) = ω Δt/2 (-8.2e-5, exact for α = -1/2):
    the reference is Timoshenko's ω seen through it, which leaves the error in s."""
    r, mu, rho_j = _section(THICK)
    omega = cantilever_bending(THICK.length, r.EIy, r.GAy, mu, rho_j[1], count=2)
    assert omega[1] / omega[0] < 6.1  # (Euler-Bernoulli: 6.27: shear and rotary inertia)

    def in_time(w, dt):
        return 2.0 / dt * np.arctan(w * dt / 2.0)

    # mode 1: a small tip force (tip at 1e-3 L)
    path, dt = _released(THICK, [TipLoad([0.0, 0.0, 3e-3 * r.EIy / THICK.length**2])],
                         omega[0], stations=41)
    found = _frequency(path.tip_position[:, 2], dt, omega[0])
    # measured -5.8e-7 (-8.3e-5 against ω itself, on 21 to 101 stations alike)
    assert found == pytest.approx(in_time(omega[0], dt), rel=1e-5)
    # mode 2: forces at the middle and at the tip, opposite (a shape near mode 2's)
    force = 6e-3 * r.EIy / THICK.length**2
    path, dt = _released(THICK, [TipLoad([0.0, 0.0, -force]),
                                 softarm.PointLoad(0.5 * THICK.length, [0.0, 0.0, 2 * force])],
                         omega[1], stations=41)
    found = _frequency(path.positions[:, 20, 2], dt, omega[1])
    # measured 7.6e-6 (the trapezoidal rule in s of before issue 40: 2.9e-4 at 101 stations,
    # 1.4e-3 at 51)
    assert found == pytest.approx(in_time(omega[1], dt), rel=1e-5)


def test_the_first_torsional_and_axial_frequencies_are_the_quarter_waves():
    r, mu, rho_j = _section(THICK)
    omega_t = cantilever_torsion(THICK.length, r.GJ, rho_j[0])
    path, dt = _released(THICK, [TipLoad(moment=[1e-3 * r.GJ / THICK.length, 0.0, 0.0])],
                         omega_t)
    twist = np.arctan2(path.rotations[:, -1, 2, 1], path.rotations[:, -1, 1, 1])
    assert _frequency(twist, dt, omega_t) == pytest.approx(omega_t, rel=2e-3)  # -5.4e-7
    omega_a = cantilever_axial(THICK.length, r.EA, mu)
    path, dt = _released(THICK, [TipLoad([1e-3 * r.EA, 0.0, 0.0])], omega_a)
    found = _frequency(path.tip_position[:, 0], dt, omega_a)
    assert found == pytest.approx(omega_a, rel=2e-3)  # measured -5.4e-7


HEAVY = Arm(0.5, Circle(0.02), Material(1e6, poisson_ratio=0.5, density=1100.0))


@pytest.mark.parametrize("case, damping, bound", [
    # measured 2.7e-5 L at 101 and 51 stations alike: Δt's error (3.1e-4 L and 1.3e-3 L with
    # the trapezoidal rule in s of before issue 40)
    ("damped", Damping(retardation=0.01), 5e-5),
    ("undamped", None, 7e-4),  # measured 4.9e-4 L (8.4e-4 L before issue 40)
])
def test_the_swinging_arm_follows_the_method_of_lines_solution(case, damping, bound):
    """Released horizontal, the heavy soft arm swings down and back up over 1.5 s (about
    one period); the tip against the method-of-lines reference (its own error 2e-5 L
    undamped, 3e-7 L damped), at the default 101 stations and Δt = 1 ms."""
    times, tip_xz = load_reference(case)
    dt = 1e-3
    path = simulate(HEAVY, [Gravity()], duration=1.5, dt=dt, damping=damping)
    tip = path.tip_position[np.round(times / dt).astype(int)][:, [0, 2]]
    assert np.ptp(tip_xz[:, 1]) > 0.3  # a large swing
    assert np.abs(tip - tip_xz).max() < bound * HEAVY.length


def test_the_damped_swing_converges_at_fourth_order_in_the_spacing():
    """Hermite's rule in s (issue 40): at one Δt, the tip's differences between 26, 51 and
    101 stations shrink 16× a halving (the time step's own error, the same on every grid,
    drops out of the differences; against the reference it is 1e-5 L on each grid)."""
    tips = []
    for stations in (26, 51, 101):
        path = simulate(HEAVY, [Gravity()], duration=0.5, dt=1e-3, stations=stations,
                        damping=Damping(retardation=0.01), tol=1e-11)
        tips.append(path.tip_position)
    first, second = np.abs(tips[0] - tips[1]).max(), np.abs(tips[1] - tips[2]).max()
    assert first > 1e-6 * HEAVY.length  # (the comparison has content)
    assert 13.0 < first / second < 19.0


def test_the_scheme_is_of_second_order_in_dt():
    tips = [simulate(HEAVY, [Gravity()], duration=0.4, dt=dt, stations=26,
                     damping=Damping(retardation=0.01), tol=1e-10).tip_position[-1]
            for dt in (4e-3, 2e-3, 1e-3)]
    first, second = np.abs(tips[0] - tips[1]).max(), np.abs(tips[1] - tips[2]).max()
    assert first > 1e-6  # (the comparison has content)
    assert 3.6 < first / second < 4.4  # measured 4.02 (and 4.01 from 1 to 0.5 ms)


def _till_rucker(example: str):
    """(their parameters, the rod in softarm's frame, its gravity) of one of Till, Aloi &
    Rucker's examples (tests/data/till_rucker/params.json)."""
    params = json.loads((DATA / "till_rucker" / "params.json").read_text())[example]
    section = params["section"]
    EA, GA, _ = section["Kse_softarm_order_EA_GA_GA"]
    GJ, EI, _ = section["Kbt_softarm_order_GJ_EI_EI"]
    rod = Arm.from_stiffness(params["length"], EA, GA, GA, GJ, EI, EI,
                             mass_per_length=section["rhoA"],
                             inertia_per_length=section["rhoJ_softarm_order"])
    return params, rod, Gravity(params["gravity_softarm_frame"])


@pytest.mark.slow
def test_till_aloi_ruckers_cantilever():
    """Their example 02_Dynamics/00_Cosserat_Rod_PDE (tests/data/till_rucker/README.md): a
    steel rod under gravity released from its equilibrium with a 20 g tip weight, BDF-α
    (α = -0.2) at Δt = 2 ms, against their code on fine grids (N = 640 and 1280 points,
    Richardson-extrapolated: 3.6e-5 m of its own). Their first step takes the history of
    a start at rest (ẋ = 0) where softarm's takes backward Euler (test_dynamics.py): for
    this comparison softarm starts as they do (through a private switch)."""
    params, rod, gravity = _till_rucker("cantilever")
    loaded = softarm.solve(rod, [gravity, TipLoad(params["initial_tip_force_softarm_frame"])])
    reference = np.genfromtxt(
        DATA / "till_rucker" / "cantilever_tip_dt2ms_fine_grid_first2s.csv", delimiter=",",
        comments="#", skip_header=3, names=True)
    sim = Simulator(rod, loads=[gravity], dt=params["time"]["dt"], stations=40,
                    initial=loaded, alpha=params["time"]["alpha"])
    sim._fresh = False  # their start (see above)
    path = sim.run(reference.size - 1)
    tip = path.tip_position  # theirs: x = softarm's y, z = softarm's x
    assert np.ptp(reference["x_extrap"]) > 0.1  # it swings by 10 cm
    # measured 9.5e-6 m on their own grid of 40 points (8.2e-6 m at 101, 9.0e-6 m at 201;
    # with the trapezoidal rule in s of before issue 40, 3.9e-5 m at 201 and 1.2e-4 m at 101)
    assert np.abs(tip[:, 1] - reference["x_extrap"]).max() < 3e-5
    assert np.abs(tip[:, 0] - reference["z_extrap"]).max() < 3e-5


@pytest.mark.slow
def test_till_aloi_ruckers_tendon_robot_converges_to_softarm():
    """Their example 02_Dynamics/03_Tendon_Robot: a spring-steel rod with one tendon,
    displacement-controlled by a motor that pulls the arm up, holds it and lets it fall
    (25 s, BDF2, Δt = 50 ms, bending damping), run on 200 (their default), 400 and 800
    points (tests/data/till_rucker/). softarm is driven by each run's tension history (its
    tendons are tension-controlled in dynamics) and its tip compared with theirs: their
    s-integrator is explicit Euler, first order, so the distance halves with each doubling
    of their points (measured 12.0, 6.0, 3.0 mm of a 0.6 m swing): their code converges
    to softarm's answer. Their quadratic drag (1e-4 kg/m², below 1e-4 of the weight at
    these speeds) is not modelled."""
    params, rod, gravity = _till_rucker("tendon_robot")
    offset = params["tendon"]["offset_softarm_frame"]
    bending = Damping(matrix=np.diag([0.0, 0.0, 0.0, *params["Bbt_their_order"]]))
    distances = []
    for name, header in (("tendon_tip_N400.csv", 3), ("tendon_tip_N800.csv", 3)):
        theirs = np.genfromtxt(DATA / "till_rucker" / name, delimiter=",", comments="#",
                               skip_header=header, names=True)
        tendon = softarm.Tendon(float(theirs["tension"][0]),
                                softarm.routing.Straight(offset[1], offset[2]))
        start = softarm.solve(rod, [gravity, tendon], s=201)
        path = simulate(rod, [gravity], actuators=[tendon], inputs=theirs["tension"][:, None],
                        duration=0.05 * (theirs.size - 1), dt=0.05, stations=201,
                        initial=start, alpha=0.0, damping=bending)
        tip = path.tip_position  # theirs: x = softarm's y, z = softarm's x
        assert np.ptp(theirs["x"]) > 0.5  # the arm swings up by 0.6 m and back
        distances.append(np.hypot(tip[:, 0] - theirs["z"], tip[:, 1] - theirs["x"]).max())
    assert distances[1] < 4e-3
    assert 1.8 < distances[0] / distances[1] < 2.2
