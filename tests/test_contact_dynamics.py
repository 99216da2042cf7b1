"""Contact in the dynamics (issue 33): a drop onto a table comes to rest at the static answer,
an undamped impact keeps the energy, friction against Coulomb's law in the sliding limit,
and far obstacles change nothing."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import softarm as sa

G = 9.81


def _arm(length=0.5, modulus=1e6):
    return sa.Arm(length, sa.Circle(0.01),
                  sa.Material(youngs_modulus=modulus, poisson_ratio=0.5, density=1000.0))


TABLE = sa.Contact(sa.Plane((0.0, 0.0, -0.05), (0.0, 0.0, 1.0)))


@pytest.mark.slow  # (~7 s)
def test_a_damped_drop_comes_to_rest_at_the_static_answer():
    arm = _arm()
    sim = sa.Simulator(arm, [], [sa.Gravity(), TABLE], dt=1e-3,
                       damping=sa.Damping(retardation=0.05), stations=101)
    law = sim.loads[-1]  # (the penalty lowered to μ/Δt², its band widened by as much)
    assert law.stiffness == pytest.approx(arm.linear_density / 1e-6)
    assert law.distance * law.stiffness == pytest.approx(
        sa.solve(arm, [sa.Gravity(), TABLE], s=3).loads[-1].distance
        * sa.solve(arm, [sa.Gravity(), TABLE], s=3).loads[-1].stiffness)
    path = sim.run(1500)
    rest = sa.solve(arm, sim.loads, s=path.s)
    # (the trapezoidal rule's O(h²) on 101 stations: about 1e-4 L of a large deflection)
    assert np.abs(path.positions[-1] - rest.positions).max() < 1e-4 * arm.length
    assert np.abs(path.velocities[-1]).max() < 1e-2
    # (the total over 101 stations: the lift-off zone spans a few of them)
    assert path.contact_wrench[-1, 2] == pytest.approx(rest.contact_wrench[2], rel=5e-2)
    assert path.gaps[0].min() > 0.03 and path.gaps[-1].min() < law.distance


@pytest.mark.slow  # (~8 s)
def test_an_arm_lifted_off_a_table_settles_as_if_it_had_never_touched():
    """Issue 40: a step that touches takes the trapezoidal rule, the others Hermite's; the
    history keeps the slopes in s through the contact, so that after it the arm settles as
    the same motion without the table does (a history without them leaves ε̇'s slope off).
    The base dips the arm onto a table 3 cm under its sag and lifts it off again."""
    arm = sa.Arm(0.3, sa.Circle(0.01),
                 sa.Material(youngs_modulus=1e6, poisson_ratio=0.5, density=1100.0))
    low = sa.solve(arm, [sa.Gravity()], s=26).positions[:, 2].min()
    table = sa.Contact(sa.Plane((0.0, 0.0, low - 0.03), (0.0, 0.0, 1.0)))

    def base(t):
        pose = np.eye(4)
        pose[2, 3] = -0.06 * min(t / 0.2, 1.0, max((0.6 - t) / 0.2, 0.0))
        return pose

    ends = []
    for loads in ([sa.Gravity(), table], [sa.Gravity()]):
        path = sa.simulate(arm, loads, duration=12.0, dt=4e-3, stations=26, base=base,
                           damping=sa.Damping(retardation=0.3), tol=1e-10)
        ends.append(path.positions[-1])
        touching = np.linalg.norm(path.contact_forces, axis=-1).max(axis=-1) > 0 \
            if path.contact_forces is not None else np.zeros(1, dtype=bool)
        assert touching.any() == (len(loads) == 2)  # (it touched, and lifted off)
        assert not touching[-1]
    rest = sa.solve(arm, [sa.Gravity()], s=26, tol=1e-10)
    # measured 5.4e-7 L: Hermite's rule on 26 stations, with the table and without
    assert np.abs(ends[1] - rest.positions).max() < 1e-6 * arm.length
    assert np.abs(ends[0] - ends[1]).max() < 1e-9 * arm.length


@pytest.mark.slow
def test_an_undamped_impact_keeps_the_energy_to_the_steps_accuracy():
    """Undamped, the impact's energy goes into the penalty and back (restitution 1): kinetic
    + elastic + gravity + the penalty's stored energy stays near its start (0), the error
    shrinking with Δt (measured: 7.1 % of the largest kinetic energy at 1 ms, 4.6 % at
    0.5 ms; the penalty's k = μ/Δt² stiffens as Δt shrinks)."""
    arm = _arm()
    errors = []
    for dt in (1e-3, 5e-4):
        path = sa.simulate(arm, [sa.Gravity(), TABLE], duration=0.2, dt=dt, stations=101)
        touching = np.flatnonzero(
            np.linalg.norm(path.contact_forces, axis=-1).max(axis=-1) > 0)
        assert touching.size and path.times[touching[0]] < 0.1  # it lands within 0.1 s
        assert path.contact_energy.max() > 0.1 * path.energy.kinetic.max()
        total = (path.energy.kinetic + path.energy.elastic + path.energy.gravity
                 + path.contact_energy)
        errors.append(np.abs(total).max() / path.energy.kinetic.max())
    assert errors[0] < 0.08
    assert errors[1] < 0.75 * errors[0]


@pytest.mark.slow
@pytest.mark.parametrize("slip", [1e-3, 1e-4])
def test_sliding_friction_follows_coulombs_law(slip):
    """A stiff arm lying on an inclined table (gravity tilted by θ), its base pulled up the
    slope at 5 cm/s: the axial force at the base is the weight's component along the slope
    plus μ times the normal contact force (regularised: times v/√(v² + w_ε²))."""
    theta, mu, speed = 0.2, 0.4, 0.05
    length = 0.3
    arm = _arm(length, modulus=1e7)
    gravity = sa.Gravity(acceleration=(G * np.sin(theta), 0.0, -G * np.cos(theta)))
    plane = sa.Contact(sa.Plane((0.0, 0.0, -0.012), (0.0, 0.0, 1.0)), friction=mu,
                       slip_velocity=slip)

    def base(t, start=0.1, ramp=0.05):
        t = max(t - start, 0.0)
        x = speed * t * t / (2 * ramp) if t < ramp else speed * (t - ramp / 2)
        pose = np.eye(4)
        pose[0, 3] = -x
        return pose

    path = sa.simulate(arm, [gravity, plane], duration=0.4, dt=1e-3, base=base, stations=61,
                       damping=sa.Damping(retardation=0.01))
    sliding = slice(200, 401)
    assert np.abs(path.velocities[sliding, -1, 0] + speed).mean() < 1e-3  # it slides
    mass = arm.linear_density * length
    normal = path.contact_wrench[sliding, 2]
    expected = mass * G * np.sin(theta) + mu * normal * speed / np.hypot(speed, slip)
    tension = path.stresses[sliding, 0, 0]
    assert tension.mean() == pytest.approx(expected.mean(), rel=3e-2)
    frictionless = sa.simulate(arm, [gravity, plane.replace(friction=0.0)], duration=0.4,
                               dt=1e-3, base=base, stations=61,
                               damping=sa.Damping(retardation=0.01))
    assert frictionless.stresses[sliding, 0, 0].mean() == pytest.approx(
        mass * G * np.sin(theta), rel=1e-2)


@pytest.mark.slow  # a dynamics variant no other default test compiles
def test_far_obstacles_change_nothing_in_motion():
    arm = _arm()
    far = sa.Contact(sa.Sphere((0.0, 5.0, 0.0), 0.1))
    free = sa.simulate(arm, [sa.Gravity()], duration=0.05, dt=1e-3, stations=41)
    near = sa.simulate(arm, [sa.Gravity(), far], duration=0.05, dt=1e-3, stations=41)
    assert np.abs(near.positions - free.positions).max() < 1e-12
    assert np.all(near.contact_forces == 0.0)
    assert np.isinf(free.gaps).all() and near.gaps.min() > 4.0


@pytest.mark.slow
@pytest.mark.parametrize("slip", [1e-3, 1e-4])
def test_friction_holds_a_pushed_arm_below_the_cone(slip):
    """Sticking: an arm lying on a table (μ = 0.5) pushed sideways at its tip by 0.02 N, a
    tenth of what friction can hold (μ N = 0.23 N): after 0.2 s it creeps at most at the
    regularising speed w_ε (the law's sticking), where the frictionless arm still swings at
    10⁻² m/s."""
    arm = _arm(0.3, modulus=1e7)
    push = sa.TipLoad(force=(0.0, 0.02, 0.0))
    speeds = {}
    for mu in (0.0, 0.5):
        plane = sa.Contact(sa.Plane((0.0, 0.0, -0.012), (0.0, 0.0, 1.0)), friction=mu,
                           slip_velocity=slip)
        path = sa.simulate(arm, [sa.Gravity(), push, plane], duration=0.4, dt=1e-3,
                           stations=61, damping=sa.Damping(retardation=0.01))
        speeds[mu] = np.abs(path.velocities[200:, :, 1]).max()
        if mu:
            assert 0.5 * path.contact_wrench[-1, 2] > 10 * 0.02  # μ N: ten times the push
    assert speeds[0.5] < slip  # at most w_ε: stuck (measured 1.3e-4 m/s at w_ε = 1e-3)
    assert speeds[0.0] > 1e-2  # (measured 2.8e-2 m/s)


FINGER = Path(__file__).resolve().parents[1] / "examples" / "gripper_finger.toml"


@pytest.mark.slow
def test_a_finger_pulled_from_0_to_15_n_stays_outside_the_cylinder():
    """Issue 42: a Simulator built at 0 N sized its penalty for 0 N, and the finger of
    examples/gripper_finger.toml, its tendon ramped to 15 N, went 34 mm through the
    cylinder. The law follows the inputs now (a step's, a run's whole schedule). The
    reference is the penalty's own bound: at k = μ/Δt² a surface arriving at speed v is
    stopped within about v Δt (μ v²/2 = k d²/2), so no station of the surface may be deeper
    than v Δt, v the largest speed of any station (measured: 0.42 mm deep at most, stepped,
    below v Δt = 0.56 mm; the schedule run at once, 0 deep: its law is sized for 15 N from
    the start)."""
    case = sa.load_case(FINGER)
    tendon, cylinder = case.loads
    dt, steps = 1e-3, 300

    def pull(t):
        return [15.0 * min(t / 0.2, 1.0)]

    sim = sa.Simulator(case.arm, [tendon.replace(tension=0.0)], [cylinder], dt=dt,
                       stations=41, damping=sa.Damping(retardation=0.02))
    deepest, fastest = np.inf, 0.0
    for k in range(1, steps + 1):
        state = sim.step(pull(k * dt))
        gaps, _ = cylinder.gaps(state.positions, cylinder.station_radii(case.arm, state.s))
        deepest = min(deepest, gaps.min())
        fastest = max(fastest, np.linalg.norm(state.velocities, axis=-1).max())
    assert fastest * dt < 1e-3  # (the bound has content: below a millimetre)
    assert deepest >= -fastest * dt, (deepest, fastest * dt)
    # the law at 15 N is the one a Simulator built at 15 N has
    at_15 = sa.Simulator(case.arm, [tendon], [cylinder], dt=dt, stations=41).loads[-1]
    assert sim.loads[-1].stiffness == pytest.approx(at_15.stiffness, rel=1e-12)
    assert sim.loads[-1].distance == pytest.approx(at_15.distance, rel=1e-12)
    # the same schedule as one run: its law is sized for the schedule's largest input
    path = sa.simulate(case.arm, [cylinder], duration=steps * dt, dt=dt, stations=41,
                       actuators=[tendon.replace(tension=0.0)], inputs=pull,
                       damping=sa.Damping(retardation=0.02))
    fastest = np.linalg.norm(path.velocities, axis=-1).max()
    assert path.gaps.min() >= -fastest * dt
    assert path.contact.distance == pytest.approx(at_15.distance, rel=1e-12)
    # and from a case file, run in chunks (one law for all of them, the schedule's)
    data = case.to_dict()
    data["load"][0]["tension"] = 0.0
    data["simulate"] = {"duration": steps * dt, "dt": dt, "stations": 41,
                        "damping": {"retardation": 0.02},
                        "input": [{"load": 1, "times": [0.0, 0.2], "values": [0.0, 15.0]}]}
    filed = sa.case.simulate_case(sa.case.parse_case(data))
    # (the chunks restart the chord iteration: the same to the steps' tolerance, 1e-6 L)
    np.testing.assert_allclose(filed.positions, path.positions, rtol=0, atol=1e-6 * 0.12)
    assert filed.contact.distance == pytest.approx(at_15.distance, rel=1e-12)


def test_an_arm_starting_inside_an_obstacle_is_refused_as_the_statics_refuse_it():
    """Issue 42: the dynamics said "a section turned inside out" (a ConvergenceError) for
    an arm whose start is inside an obstacle. The reference is the statics' refusal of the
    same arm and obstacle (softarm.solve's ValueError naming the station), and for an
    initial equilibrium solved without the obstacle, the first of its stations whose
    surface is inside, found here from softarm.solve's positions by hand."""
    arm = _arm()  # 0.5 m, radius 10 mm
    ball = sa.Contact(sa.Sphere((0.3, 0.0, 0.0), 0.05))
    with pytest.raises(ValueError) as statics:
        sa.solve(arm, [sa.Gravity(), ball])
    assert "starts inside an obstacle" in str(statics.value)
    for make in (lambda: sa.Simulator(arm, [], [sa.Gravity(), ball], dt=1e-3, stations=21),
                 lambda: sa.simulate(arm, [sa.Gravity(), ball], duration=2e-3, dt=1e-3,
                                     stations=21)):
        with pytest.raises(ValueError) as dynamics:
            make()
        assert str(dynamics.value) == str(statics.value)
    # sagging under gravity into a table that the straight arm clears
    hanging = sa.solve(arm, [sa.Gravity()], s=21, tol=1e-10)
    table = sa.Contact(sa.Plane((0.0, 0.0, -0.05), (0.0, 0.0, 1.0)))
    gaps = hanging.positions[:, 2] - 0.01 + 0.05  # (the surface's lowest point)
    first = int(np.flatnonzero(gaps < -1e-6 * arm.length)[0])
    with pytest.raises(ValueError) as start:
        sa.Simulator(arm, [], [sa.Gravity(), table], dt=1e-3, stations=21, initial=hanging)
    assert str(start.value).startswith(
        f"Contact: the initial equilibrium starts inside an obstacle (its surface "
        f"{-gaps[first]:.3g} m deep at station s = {hanging.s[first]:.6g} m)")


@pytest.mark.slow  # (dynamics from an equilibrium in contact: its compile)
def test_a_simulation_starts_at_rest_from_a_static_contact_equilibrium():
    """Issue 39: ``initial=eq`` with the same Contact failed ("residual 1.53e+07"): the
    step's Jacobian left out the penalty's ∂f/∂p, so Newton from the static answer crept and
    stopped. Now the arm starts at rest under the steps' law and stays there; the start is
    the statics' answer with that law given explicitly (a second route: the shooting
    solver), to the steps' grid error O(h²), and the warning says how far the tip is from
    the Equilibrium solved with the statics' stiffer law."""
    arm = _arm()
    loads = [sa.Gravity(), TABLE]
    eq = sa.solve(arm, loads)
    with pytest.warns(sa.ApproximationWarning, match=r"another contact law \(distance 5e-06 "
                      r"m\).*its tip 0\.000\d+ m from the Equilibrium's"):
        path = sa.simulate(arm, loads, duration=0.05, dt=1e-3, initial=eq)
    law = path.contact
    assert law.distance > 100 * eq.loads[-1].distance  # (the time step's cap: contact.md)
    assert np.abs(path.positions - path.positions[0]).max() < 1e-9 * arm.length
    rest = sa.solve(arm, [sa.Gravity(), law], s=path.s)
    assert np.abs(path.positions[0] - rest.positions).max() < 1e-4 * arm.length
    tip = np.linalg.norm(path.positions[0, -1] - eq.positions[-1])
    assert 0.2 * law.distance < tip < 2 * law.distance  # the bands' difference
    # a batch whose steps size the law per case: one static balance cannot hold them all
    pressed = [sa.Gravity(), sa.TipLoad([[0.0, 0.0, 0.0], [0.0, 0.0, -0.02]]), TABLE]
    with pytest.raises(ValueError, match=r"initial: this batch's time steps use a contact "
                                         r"law per case .* give the Contact its stiffness"):
        sa.Simulator(arm, [], pressed, dt=1e-3, initial=sa.solve(arm, pressed))


@pytest.mark.slow  # (dynamics from an equilibrium in contact: its compile)
def test_the_same_given_law_starts_at_the_statics_answer_without_a_word():
    """A Contact with its own stiffness and distance is one law in statics and dynamics:
    the simulation starts at the Equilibrium's shape (to the grid's O(h²)) and stays."""
    arm = _arm()
    loads = [sa.Gravity(), sa.Contact(TABLE.obstacles, stiffness=3e5, distance=1e-3)]
    eq = sa.solve(arm, loads, s=np.linspace(0.0, 0.5, 101))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", sa.ApproximationWarning)
        path = sa.simulate(arm, loads, duration=0.02, dt=1e-3, initial=eq)
    assert np.abs(path.positions[0] - eq.positions).max() < 1e-4 * arm.length
    assert np.abs(path.positions - path.positions[0]).max() < 1e-9 * arm.length
    # a batch too: one law for every case
    batch = [sa.Gravity(), sa.TipLoad([[0.0, 0.0, 0.0], [0.0, 0.0, -0.02]]), loads[1]]
    eqs = sa.solve(arm, batch, s=np.linspace(0.0, 0.5, 101))
    with warnings.catch_warnings():
        warnings.simplefilter("error", sa.ApproximationWarning)
        path = sa.simulate(arm, batch, duration=0.01, dt=1e-3, initial=eqs)
    assert np.abs(path.positions[:, 0] - eqs.positions).max() < 1e-4 * arm.length
    assert np.abs(path.positions - path.positions[:, :1]).max() < 1e-9 * arm.length


@pytest.mark.slow  # (dynamics from an equilibrium in contact: its compile)
def test_an_arm_at_rest_in_a_corner_with_friction_stays_at_rest():
    """Sections touching two obstacles at once, with friction: an arm pressed by a tilted
    gravity onto a floor and against a wall. The statics' frictionless equilibrium is a
    Coulomb one (no sliding, no tangential force), so the simulation started there stays.
    Found with it: the friction's factor overwrote the penalty's scale for the obstacles
    after the first (-μ φ/w_ε at rest: the wall pulled the arm in)."""
    arm = sa.Arm(0.5, sa.Circle(0.01),
                 sa.Material(youngs_modulus=2e7, poisson_ratio=0.5, density=1000.0))
    floor = sa.Plane((0.0, 0.0, -0.03), (0.0, 0.0, 1.0))
    wall = sa.Plane((0.0, -0.015, 0.0), (0.0, 1.0, 0.0))
    contact = sa.Contact([floor, wall], friction=0.5, stiffness=3e5, distance=1e-3)
    gravity = sa.Gravity((0.0, -3.0, -9.81))
    eq = sa.solve(arm, [gravity, contact], s=np.linspace(0.0, 0.5, 101))
    both = ((eq.positions[:, 2] + 0.03 - 0.01 < 1e-3)
            & (eq.positions[:, 1] + 0.015 - 0.01 < 1e-3))
    assert both.sum() >= 5  # sections on the floor and against the wall
    path = sa.simulate(arm, [gravity, contact], duration=0.03, dt=1e-3, initial=eq)
    assert np.abs(path.positions - path.positions[0]).max() < 1e-9 * arm.length


@pytest.mark.slow  # (dynamics with contact and friction: its compile)
@pytest.mark.parametrize("dt", [1e-3, 5e-4])
def test_a_touchdown_with_friction_runs_at_the_default_band(dt, monkeypatch):
    """Issue 39: the docs' table arm dropped with μ = 0.5 failed on touchdown at the default
    slip_velocity 1e-4 m/s (t = 0.088 s at Δt = 1 ms, sooner at 0.5 ms: the law's slope
    μ φ / w_ε defeats Newton from every guess). A step that fails is now solved along a
    continuation in the band (widened, narrowed back to the one given): the drop runs
    through the touchdown and the bounce. The reference is the frictionless drop: the
    same to the bit before the arm touches (friction acts only in contact); the impact's
    depth within the normal law's bound, v Δt (v the fastest station's speed). (Coulomb's
    law at the default band: the sliding and sticking tests above, at 1e-4 m/s too.) A
    step that still fails names the regularisation (forced here with 2 Newton
    iterations)."""
    arm = _arm()
    table = TABLE.obstacles
    path = sa.simulate(arm, [sa.Gravity(), sa.Contact(table, friction=0.5)],
                       duration=0.3, dt=dt)
    bare = sa.simulate(arm, [sa.Gravity(), sa.Contact(table)], duration=0.3, dt=dt)
    law = path.contact
    touching = (path.gaps.min(axis=-1) < law.distance)
    first = int(np.argmax(touching))
    assert touching.any() and first > 0  # it lands
    assert np.array_equal(path.positions[:first], bare.positions[:first])
    fastest = np.linalg.norm(path.velocities, axis=-1).max()
    assert path.gaps.min() > -fastest * dt  # the impact's depth, within v Δt
    from softarm.dynamics import _simulator

    monkeypatch.setattr(_simulator, "MAX_ITERATIONS", 2)
    with pytest.raises(sa.ConvergenceError, match=r"with friction, a larger "
                       r"Contact\.slip_velocity may help \(now 0\.0001 m/s"):
        sa.simulate(arm, [sa.Gravity(), sa.Contact(table, friction=0.5)], duration=0.1,
                    dt=dt)
