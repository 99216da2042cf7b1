"""Dynamics (softarm.simulate, Simulator): checked against closed forms and second methods.

- the static limit: a damped arm settles to softarm.solve's equilibrium, with the error of
  Hermite's rule in s (fourth order in the station spacing, measured);
- the equivalence principle: a base accelerating upwards at a is gravity -a on a fixed base;
- the energy: kinetic + elastic constant for a free undamped arm (1 % over 20 periods),
  and with the dissipated energy for a damped one;
- batch = loop, Simulator.step = simulate, failures and bad input.
Frequencies against Timoshenko's beam and the large swing against an independent
method-of-lines solution: tests/test_dynamics_references.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import softarm
from softarm import Arm, Circle, Damping, Gravity, Material, Simulator, TipLoad, simulate

SOFT = Material(1e6, poisson_ratio=0.5, density=1100.0)
HEAVY = Arm(0.5, Circle(0.02), SOFT)  # the swinging arm of tests/_mol_rod.py
SHORT = Arm(0.2, Circle(0.01), Material(1e7, poisson_ratio=0.5, density=1100.0))
STRAIGHT = softarm.routing.Straight(0.0, 0.01)


def _first_period(arm) -> float:
    """Euler–Bernoulli's first cantilever period (only sets the time step here)."""
    mu = arm.linear_density
    return 2 * math.pi / (1.875104**2 * math.sqrt(arm.rigidities.EIy / (mu * arm.length**4)))


def test_a_damped_arm_settles_to_the_static_equilibrium_at_fourth_order_in_the_spacing():
    """Hermite's rule in s (issue 40): the settled state is softarm.solve's to O(h⁴), and
    at the default 101 stations within the default tol 1e-8 L."""
    errors = []
    for stations in (26, 51):
        path = simulate(HEAVY, [Gravity()], duration=9.0, dt=4e-3, stations=stations,
                        damping=Damping(retardation=0.4), tol=1e-10)
        eq = softarm.solve(HEAVY, [Gravity()], s=stations, tol=1e-10)
        assert np.abs(path.velocities[-1]).max() < 1e-9  # at rest
        errors.append(np.abs(path.positions[-1] - eq.positions).max() / HEAVY.length)
    # measured 6.2e-7 L and 3.9e-8 L (2.4e-9 L at 101 stations, 1.5e-10 L at 201; the
    # trapezoidal rule of before: 7.5e-4, 1.9e-4 and 4.8e-5 L)
    assert errors[1] < 6e-8
    assert 14.0 < errors[0] / errors[1] < 18.0


def test_a_base_accelerating_upwards_is_gravity_downwards():
    a = 3.0

    def base(t):
        pose = np.eye(4)
        pose[2, 3] = 0.5 * a * t * t
        return pose

    moving = simulate(HEAVY, [], duration=0.2, dt=1e-3, stations=51, base=base, tol=1e-10)
    heavy = simulate(HEAVY, [Gravity([0.0, 0.0, -a])], duration=0.2, dt=1e-3, stations=51,
                     tol=1e-10)
    carried = moving.positions - (0.5 * a * moving.times**2)[:, None, None] * [0, 0, 1]
    assert abs(heavy.tip_position[-1, 2]) > 0.08  # it moved: the comparison has content
    # measured 3.3e-6 L (the two loads are discretised differently in s: 1.1e-6 L at 101)
    assert np.abs(carried - heavy.positions).max() < 1e-5 * HEAVY.length


def test_a_base_function_is_never_called_before_the_start():
    """Issue 42: the base's velocity at the start was a central difference, calling the
    user's function at t = -1e-6 s, before the motion exists (a trajectory read from a
    table, a spline). The start's is one-sided now: every call at t >= the start, with a
    Python float. The reference: the base accelerating from rest at t = 0 moves the tip as
    gravity -a does (test_a_base_accelerating_upwards_is_gravity_downwards, 1e-5 L)."""
    a, calls = 3.0, []

    def base(t):
        calls.append(t)
        if t < 0.0:
            raise ValueError("no motion before t = 0")
        pose = np.eye(4)
        pose[2, 3] = 0.5 * a * t * t
        return pose

    moving = simulate(HEAVY, [], duration=0.05, dt=1e-3, stations=21, base=base, tol=1e-10)
    assert min(calls) == 0.0 and all(type(t) is float for t in calls)
    heavy = simulate(HEAVY, [Gravity([0.0, 0.0, -a])], duration=0.05, dt=1e-3, stations=21,
                     tol=1e-10)
    carried = moving.positions - (0.5 * a * moving.times**2)[:, None, None] * [0, 0, 1]
    assert np.abs(carried - heavy.positions).max() < 1e-5 * HEAVY.length
    calls.clear()  # continued from a state at t = 0.05 s: nothing before it either
    simulate(HEAVY, [], duration=0.002, dt=1e-3, stations=21, base=base, tol=1e-10,
             initial=moving.final)
    assert min(calls) >= 0.05


@pytest.mark.parametrize("damped", [False, True])
@pytest.mark.slow
def test_the_energy_of_a_released_arm_is_kept_over_20_periods(damped):
    period = _first_period(SHORT)
    dt = period / 200
    bent = softarm.solve(SHORT, [TipLoad([0.0, 0.0, 0.5])], s=51)  # tip at 8.5 % of L
    damping = Damping(retardation=0.002) if damped else None
    path = simulate(SHORT, [], duration=4000 * dt, dt=dt, stations=51, initial=bent,
                    damping=damping)
    energy = path.energy
    start = energy.total[0]
    assert start == pytest.approx(energy.elastic[0])  # released at rest
    # measured 0.38 % undamped, 0.26 % damped (the energy's quadrature on the stations is
    # the trapezoidal rule's, second order)
    assert np.abs(energy.total - start).max() < 0.01 * start
    if damped:
        assert energy.dissipated[-1] > 0.99 * start  # it came to rest: all dissipated
    else:
        assert (energy.kinetic + energy.elastic)[-1] > 0.99 * start


def test_a_batch_is_the_loop_of_its_cases_to_the_bit():
    g = np.array([[0.0, 0.0, -9.81], [0.0, -5.0, -5.0], [3.0, 0.0, -9.81]])
    batch = simulate(HEAVY, [Gravity(g)], duration=0.05, dt=1e-3, stations=21)
    assert batch.positions.shape == (3, 51, 21, 3)
    for i in range(3):
        alone = simulate(HEAVY, [Gravity(g[i])], duration=0.05, dt=1e-3, stations=21)
        np.testing.assert_array_equal(batch.positions[i], alone.positions)
        np.testing.assert_array_equal(batch.energy.total[i], alone.energy.total)


def test_stepping_one_by_one_is_the_trajectory():
    path = simulate(HEAVY, [Gravity()], duration=0.02, dt=1e-3, stations=21, tol=1e-10)
    sim = Simulator(HEAVY, loads=[Gravity()], dt=1e-3, stations=21, tol=1e-10)
    for i in range(20):
        state = sim.step()
        assert state.time == pytest.approx(path.times[i + 1])
    np.testing.assert_allclose(state.positions, path.positions[-1], rtol=0, atol=1e-10)
    np.testing.assert_allclose(state.velocities, path.velocities[-1], rtol=0, atol=1e-7)
    # and a trajectory continued from a state is the same trajectory
    later = simulate(HEAVY, [Gravity()], duration=0.01, dt=1e-3, stations=21, tol=1e-10,
                     initial=simulate(HEAVY, [Gravity()], duration=0.01, dt=1e-3,
                                      stations=21, tol=1e-10).final)
    np.testing.assert_allclose(later.positions[-1], path.positions[-1], rtol=0, atol=1e-10)
    assert later.times[0] == pytest.approx(0.01)


def test_a_step_that_cannot_be_solved_raises_and_changes_nothing():
    sim = Simulator(HEAVY, loads=[Gravity()], dt=1e-3, stations=21, tol=1e-6)
    sim.step()
    before = sim.state
    sim.tol = 0.0
    sim._options[0] = 0.0  # an unreachable tolerance: Newton cannot converge
    with pytest.raises(softarm.ConvergenceError, match="could not be solved") as caught:
        sim.step()
    assert caught.value.residual >= 0.0
    assert sim.state is before and sim.time == pytest.approx(1e-3)
    sim._options[0] = 1e-6
    assert sim.step().time == pytest.approx(2e-3)


def test_a_free_fall_starts_at_g_to_second_order_in_dt():
    """In the first steps every section far from the clamp falls freely (the bending wave
    has not arrived yet): the tip's z is -g t²/2, to the scheme's O(Δt²) (its backward
    Euler first step puts the arm g Δt²/2 low)."""
    errors = []
    for dt in (5e-4, 2.5e-4):
        path = simulate(HEAVY, [Gravity()], duration=0.005, dt=dt, stations=51)
        errors.append(np.abs(path.tip_position[:, 2] + 0.5 * 9.81 * path.times**2).max())
        assert errors[-1] <= 0.51 * 9.81 * dt**2
    assert 3.9 < errors[0] / errors[1] < 4.1


@pytest.mark.parametrize("kwargs, match", [
    ({"dt": 0.0}, "dt"),
    ({"dt": 1e-3, "alpha": 0.3}, "alpha"),
    ({"dt": 1e-3, "stations": 2}, "stations"),
    ({"dt": 1e-3, "damping": 0.1}, "damping"),
    ({"dt": 1e-3, "actuators": [TipLoad([0.0, 0.0, 1.0])]}, "actuators"),
    ({"dt": 1e-3, "actuators": [softarm.Tendon(displacement=-1e-3, routing=STRAIGHT)]},
     "displacement"),
    ({"dt": 1e-3, "initial": "rest"}, "initial"),
])
def test_bad_simulator_input_is_named(kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        Simulator(HEAVY, **kwargs)


def test_bad_damping_and_durations_are_named():
    with pytest.raises(ValueError, match="exactly one"):
        Damping()
    with pytest.raises(ValueError, match="symmetric"):
        Damping(matrix=np.triu(np.ones((6, 6))))
    with pytest.raises(ValueError, match="semi-definite"):
        Damping(matrix=-np.eye(6))
    with pytest.raises(ValueError, match="retardation"):
        Damping(retardation=-1.0)
    with pytest.raises(ValueError, match="whole number"):
        simulate(HEAVY, [], duration=0.0105, dt=1e-3)
    stiff_only = Arm.from_stiffness(0.5, 1e3, 1e3, 1e3, 1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="mass"):
        Simulator(stiff_only, dt=1e-3)
    with_mass = Arm.from_stiffness(0.5, 1e3, 1e3, 1e3, 1.0, 1.0, 1.0, mass_per_length=0.1,
                                   inertia_per_length=(2e-6, 1e-6, 1e-6))
    assert Simulator(with_mass, dt=1e-3, stations=5).step().time == pytest.approx(1e-3)


# --------------------------------------------------------------------------- actuators

ROBOT = Arm(0.3, Circle(0.01), SOFT)


def _settled_error(arm, loads, actuators, stations):
    """Positions of a damped arm after it settled against softarm.solve's equilibrium of
    the same loads and actuators (relative to L), and the tendons' lengths of both."""
    path = simulate(arm, loads, actuators=actuators, duration=9.0, dt=4e-3, stations=stations,
                    damping=Damping(retardation=0.3), tol=1e-10)
    eq = softarm.solve(arm, [*loads, *actuators], s=stations, tol=1e-10)
    # at rest: the shape still over the last 2 s (the velocity states of a thinner arm
    # ring from step to step under the trapezoidal rule in time, α = -1/2, and decay slower
    # than its shape settles: 5e-7 m/s at 9 s for the magnetic arm, alternating in sign,
    # while it moves by 1.6e-12 m)
    assert np.abs(path.velocities[-1]).max() < 1e-5
    assert np.abs(path.positions[-1] - path.positions[-500]).max() < 1e-10 * arm.length
    error = np.abs(path.positions[-1] - eq.positions).max() / arm.length
    return error, path, eq


@pytest.mark.slow  # a dynamics variant (from an actuated equilibrium) compiled for it alone
@pytest.mark.parametrize("actuator", [
    softarm.Tendon(tension=0.5, routing=softarm.routing.Straight(0.0, 0.008), end=0.2),
    softarm.Chamber(pressure=2e4, area=2e-5, routing=softarm.routing.Straight(0.0, -0.005)),
], ids=["tendon", "chamber"])
def test_an_actuated_arm_settles_to_the_static_equilibrium(actuator):
    errors = []
    for stations in (26, 51):
        error, path, eq = _settled_error(ROBOT, [Gravity()], [actuator], stations)
        errors.append(error)
    assert np.abs(eq.tip_position - [ROBOT.length, 0, 0]).max() > 0.05 * ROBOT.length
    # measured 5.7e-7 L and 3.6e-8 L for the tendon, 5.6e-7 L and 3.5e-8 L for the chamber
    # (the trapezoidal rule of before issue 40: 6.3e-4 L and 1.6e-4 L for the tendon)
    assert errors[1] < 6e-8
    assert 13.0 < errors[0] / errors[1] < 18.0  # fourth order in the spacing
    if eq.tendon_lengths is not None:
        assert path.tendon_lengths[0, 0] == pytest.approx(0.2, rel=1e-12)  # unloaded
        # measured 4.8e-10 m at 51 stations (7.7e-9 m at 26: Hermite's rule for ∫ |w| ds,
        # the steps' own; the trapezoidal rule of before issue 40 was within 1e-5 m)
        assert path.tendon_lengths[-1, 0] == pytest.approx(eq.tendon_lengths[0], abs=2e-9)


@pytest.mark.slow
def test_a_magnetic_arm_settles_to_the_static_equilibrium():
    field = softarm.MagneticField([0.0, 0.0, 0.02])
    # a magnetisation along the arm turns it up by 85° (4.0e-5 L and 2.5e-6 L measured;
    # 2.6e-3 L and 6.6e-4 L with the trapezoidal rule of before issue 40)
    magnetic = Arm(0.3, Circle(0.01), SOFT, magnetization=(1e3, 0.0, 0.0))
    errors = [_settled_error(magnetic, [field], [], stations)[0] for stations in (26, 51)]
    assert errors[1] < 5e-6
    assert 13.0 < errors[0] / errors[1] < 18.0
    # a tip magnet: a tip couple that turns with the tip
    tipped = Arm(0.3, Circle(0.01), SOFT, tip_magnet=(0.5, 0.0, 0.0))
    errors = [_settled_error(tipped, [field], [], stations)[0] for stations in (26, 51)]
    # measured 4.8e-11 L and 8.0e-12 L: at the tolerance (1.7e-5 L at 26 stations with the
    # trapezoidal rule of before issue 40)
    assert max(errors) < 1e-9


def test_a_slowly_pulled_tendon_follows_the_quasi_static_path():
    tendon = softarm.Tendon(tension=0.0, routing=softarm.routing.Straight(0.0, 0.008))
    duration, dt = 8.0, 0.01

    def tension(t):
        return [0.8 * min(t / (0.75 * duration), 1.0)]

    path = simulate(ROBOT, [Gravity()], actuators=[tendon], inputs=tension, duration=duration,
                    dt=dt, stations=51, damping=Damping(retardation=0.3), tol=1e-10)
    for t in (2.0, 4.0, 8.0):
        i = round(t / dt)
        eq = softarm.solve(ROBOT, [Gravity(), tendon.replace(tension=tension(t)[0])], s=51)
        # the lag behind the quasi-static path is of the order of τ × the pull rate
        assert np.abs(path.positions[i] - eq.positions).max() < 2e-3 * ROBOT.length


def test_simulator_steps_take_the_inputs_given():
    tendon = softarm.Tendon(tension=0.2, routing=softarm.routing.Straight(0.0, 0.008))
    sim = Simulator(ROBOT, [tendon], dt=2e-3, stations=21, damping=Damping(retardation=0.1))
    schedule = 0.2 + 0.3 * np.sin(np.arange(11) * 0.3)
    path = simulate(ROBOT, actuators=[tendon], inputs=schedule[:, None], duration=0.02,
                    dt=2e-3, stations=21, damping=Damping(retardation=0.1))
    for q in schedule[1:]:
        state = sim.step([q])
    np.testing.assert_allclose(state.positions, path.positions[-1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(state.tendon_lengths, path.tendon_lengths[-1], atol=1e-12)
    with pytest.raises(ValueError, match="inputs"):
        sim.step([1.0, 2.0])
    with pytest.raises(ValueError, match="finite"):
        sim.step([np.nan])


def _refusal(make) -> str:
    with pytest.raises(ValueError) as info:
        make()
    return str(info.value)


def test_the_inputs_obey_the_statics_rules_on_every_route():
    """Issue 42: Simulator.step([-2]) pushed with the tendon and step([1e200]) raised a raw
    ZeroDivisionError (as did ForwardSolver.solve([1e200])). The reference is the statics'
    own rule, the one a Tendon and softarm.solve apply: the same words, named at the input's
    index (its time for a schedule given as a function), and the state unchanged."""
    tendon = softarm.Tendon(0.2, STRAIGHT)
    pushing = _refusal(lambda: softarm.Tendon(-2.0, STRAIGHT))
    assert pushing == "Tendon.tension must be >= 0 N (a tendon cannot push), got -2.0"
    huge = _refusal(lambda: softarm.solve(ROBOT, [tendon.replace(tension=1e200)]))
    assert huge.startswith("Tendon.tension: a load of 1e+200 N is not representable")
    sim = Simulator(ROBOT, [tendon], [Gravity()], dt=1e-3, stations=11)
    sim.step([0.5])
    before = sim.state
    assert _refusal(lambda: sim.step([-2.0])) == f"inputs[0]: {pushing}"
    assert _refusal(lambda: sim.step([1e200])) == f"inputs[0]: {huge}"
    assert sim.state is before and sim.time == pytest.approx(1e-3)
    schedule = np.full((6, 1), 0.5)
    schedule[4, 0] = -2.0
    assert _refusal(lambda: sim.run(5, schedule)) == f"inputs[4, 0]: {pushing}"
    assert _refusal(lambda: sim.run(5, lambda t: [-2.0 if t > 3.5e-3 else 0.5])) == \
        f"inputs(0.004)[0]: {pushing}"
    assert _refusal(lambda: simulate(ROBOT, [], duration=2e-3, dt=1e-3, stations=11,
                                     actuators=[tendon], inputs=lambda t: [1e200])) == \
        f"inputs(0.001)[0]: {huge}"
    assert sim.time == pytest.approx(1e-3)
    model = softarm.ForwardSolver(ROBOT, [tendon])
    assert _refusal(lambda: model.solve([1e200])) == f"inputs[0]: {huge}"
    with pytest.raises(ValueError, match="tensions >= 0"):
        model.solve([-2.0])
    # what the statics accept, the steps take: a vacuum (p < 0), a slack tendon (0 N)
    chamber = softarm.Chamber(0.0, area=2e-5, routing=softarm.routing.Straight(0.0, -0.005))
    both = Simulator(ROBOT, [tendon, chamber], [Gravity()], dt=1e-3, stations=11)
    assert both.step([0.0, -2e4]).time == pytest.approx(1e-3)
    assert _refusal(lambda: both.step([0.0, 1e300])).startswith(
        "inputs[1]: Chamber.pressure: a load of 1e+300 Pa is not representable")
    magnetic = Arm(0.3, Circle(0.01), SOFT, magnetization=(1e3, 0.0, 0.0))
    field = softarm.MagneticField([0.0, 0.0, 0.0])
    assert _refusal(lambda: Simulator(magnetic, [field], dt=1e-3, stations=11).step(
        [0.0, 0.0, 1e300])).startswith("inputs[0:3]: MagneticField.field: a load of 1e+300 T")


def test_a_batch_keeps_going_past_a_failed_case():
    """failures="keep": a case whose step cannot be solved (here pushed inside out, v₁ <= 0,
    by a compressive tip force of twice EA) stops where it failed, marked and blanked; the
    others are the same as alone. failures="raise" (the default) raises instead."""
    crush = np.zeros((3, 3))
    crush[1, 0] = -2.0 * HEAVY.rigidities.EA
    loads = [Gravity(), TipLoad(crush)]
    sim = Simulator(HEAVY, loads=loads, dt=1e-3, stations=21)
    with pytest.raises(softarm.ConvergenceError, match=r"for case \(1,\): .* inside out"):
        sim.run(5)
    assert sim.time == 0.0  # (unchanged)
    path = sim.run(5, failures="keep")
    assert path.failed.tolist() == [False, True, False]
    assert [case for case, _, _ in sim.failures] == [(1,)]
    assert sim.failures[0][1] == pytest.approx(1e-3)  # its first step
    assert np.all(np.isnan(path.positions[1, 1:])) and np.all(np.isfinite(path.positions[0]))
    alone = simulate(HEAVY, [Gravity()], duration=5e-3, dt=1e-3, stations=21)
    np.testing.assert_array_equal(path.positions[0], alone.positions)
    np.testing.assert_array_equal(path.positions[2], alone.positions)
    later = sim.run(2, failures="keep")  # the failed case is skipped from now on
    assert np.all(np.isnan(later.positions[1, 1:])) and len(sim.failures) == 1


def test_a_segmented_precurved_arm_with_point_and_follower_loads_settles():
    """Two segments (joints in the stations' grid), a precurved one, a point load inside
    (n and m jump at a joint) and a follower tip load: settled, as softarm.solve, at fourth
    order in the spacing (measured 6.2e-7 L and 4.1e-8 L; 2.0e-4 L and 5.8e-5 L with the
    trapezoidal rule of before issue 40)."""
    stiffer = Material(4e6, poisson_ratio=0.5, density=1500.0)
    arm = softarm.SegmentedArm([Arm(0.15, Circle(0.012), stiffer),
                                Arm(0.15, Circle(0.008), SOFT, curvature=(0.0, 0.0, 2.0))])
    loads = [Gravity(), softarm.PointLoad(0.1, [0.0, 0.05, 0.1]),
             TipLoad([0.0, 0.0, -0.05], follower=True)]
    errors = []
    for stations in (26, 51):
        path = simulate(arm, loads, duration=9.0, dt=4e-3, stations=stations,
                        damping=Damping(retardation=0.3), tol=1e-10)
        eq = softarm.solve(arm, loads, s=stations, tol=1e-10)
        assert np.abs(path.velocities[-1]).max() < 1e-8
        errors.append(np.abs(path.positions[-1] - eq.positions).max() / arm.length)
    assert errors[1] < 8e-8
    assert 13.0 < errors[0] / errors[1] < 18.0


def test_each_case_of_a_batch_takes_its_own_inputs():
    tendon = softarm.Tendon(0.0, softarm.routing.Straight(0.0, 0.008))
    pulls = np.array([0.2, 0.6])
    ramp = np.linspace(0.0, 1.0, 11)[:, None]
    schedule = pulls[:, None, None] * ramp  # (cases, steps + 1, inputs)
    loads = [Gravity([[0.0, 0.0, -9.81], [0.0, 0.0, -9.81]])]  # (a batch of two)
    both = simulate(ROBOT, loads, actuators=[tendon], inputs=schedule, duration=0.01,
                    dt=1e-3, stations=21, damping=Damping(retardation=0.05))
    for k, pull in enumerate(pulls):
        alone = simulate(ROBOT, [Gravity()], actuators=[tendon], inputs=pull * ramp,
                         duration=0.01, dt=1e-3, stations=21,
                         damping=Damping(retardation=0.05))
        np.testing.assert_array_equal(both.positions[k], alone.positions)
    assert not np.allclose(both.positions[0], both.positions[1])
    sim = Simulator(ROBOT, [tendon], loads, dt=1e-3, stations=21)
    state = sim.step(np.array([[0.1], [0.3]]))  # (cases, inputs)
    assert state.positions.shape == (2, 21, 3)
    with pytest.raises(ValueError, match="batch axes"):
        sim.step(np.ones((3, 1)))


@pytest.mark.slow  # a dynamics variant no other default test compiles
def test_runs_after_runs_with_and_without_tendons_carry_their_lengths():
    """A run continues from the last one's state: tendon lengths where there are tendons
    (the kernel's, the last run's last row; within the grid's O(h²) of the trapezoidal
    rule on the state's strains, the unloaded start's quadrature), None where the
    actuators are chambers only."""
    chamber = softarm.Chamber(2e4, area=2e-5, routing=softarm.routing.Straight(0.0, -0.005))
    sim = Simulator(ROBOT, [chamber], [Gravity()], dt=1e-3, stations=21)
    first, second = sim.run(2), sim.run(2)
    assert first.tendon_lengths is None and second.tendon_lengths is None
    assert second.times[0] == pytest.approx(2e-3)
    tendon = softarm.Tendon(0.5, softarm.routing.Straight(0.0, 0.008))
    sim = Simulator(ROBOT, [tendon, chamber], [Gravity()], dt=1e-3, stations=21)
    last = sim.run(3).tendon_lengths[-1]
    quadrature = sim._tendon_lengths(sim._arrays[2])[0]  # (of the state now)
    carried = sim.run(1).tendon_lengths[0]  # (the next run's first row: that state's)
    assert carried[0] < 0.2999  # (pulled in)
    np.testing.assert_array_equal(carried, last)
    np.testing.assert_allclose(carried, quadrature, rtol=0, atol=1e-5)  # (2.6e-6 m)
