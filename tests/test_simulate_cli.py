"""Simulations from case files: the [simulate] table, `softarm simulate` and trajectory files.

References: the schedules and the base motion against values worked by hand; the command's
output against ``softarm.simulate`` called directly with hand-written inputs and base motion
(a second route to the same numbers); a sweep against the same cases simulated one by one;
an initial equilibrium against ``softarm.solve``.
"""

from __future__ import annotations

import inspect
import json
import math
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm import cli
from softarm._simulate_table import BaseMotion, Schedule, Simulation
from softarm.case import CaseError, load_case, parse_case, simulate_case
from softarm.io import read_trajectory

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

ARM = """
[arm]
length = 0.25
section = { kind = "circle", radius = 0.0006 }
material = { E = 6.0e10, nu = 0.33, density = 6450.0 }
mass_per_length = 0.02

[[load]]
kind = "gravity"

[[load]]
kind = "tendon"
tension = 0.0
routing = { kind = "straight", y = 0.0, z = 0.008 }
"""

SIMULATE = """
[simulate]
duration = 0.02
dt = 0.001
stations = 11
damping = { retardation = 0.004 }

[[simulate.input]]
load = 2
times = [0.0, 0.005]
values = [0.0, 1.5]

[simulate.base]
times = [0.0, 0.01]
positions = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.01]]
rotations = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.2]]
"""


def write_case(tmp_path, text, name="arm"):
    path = tmp_path / f"{name}.toml"
    path.write_text(f'name = "{name}"\n' + text, encoding="utf-8")
    return path


def run(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# --------------------------------------------------------------------------------------------
# Schedules and base motion against hand values
# --------------------------------------------------------------------------------------------


def test_a_schedule_is_piecewise_linear_and_holds_its_ends():
    schedule = Schedule(0, times=(0.0, 0.1, 0.3), values=(0.0, 2.0, 5.0))
    # by hand: 0 before, 1 halfway up the first ramp, 2 + 3/4 of 3 on the second, 5 after
    for t, expected in ((-1.0, 0.0), (0.05, 1.0), (0.25, 4.25), (0.3, 5.0), (7.0, 5.0)):
        assert schedule(t) == pytest.approx([expected], abs=1e-15)
    field = Schedule(2, times=(0.0, 1.0), values=((0.0, 0.0, 0.01), (0.02, 0.0, -0.01)))
    np.testing.assert_allclose(field(0.25), [0.005, 0.0, 0.005], rtol=0, atol=1e-15)


def test_a_base_motion_is_a_clamped_cubic_from_rest_to_rest():
    motion = BaseMotion(times=(1.0, 2.0), positions=((0, 0, 0), (0.2, 0, 0)),
                        rotations=((0, 0, 0), (0, 0, 1.0)))
    # two knots clamped at zero velocity: the cubic 3τ² - 2τ³ between them
    for t in (0.5, 1.0, 1.25, 1.5, 1.9, 2.0, 3.0):
        tau = min(max(t - 1.0, 0.0), 1.0)
        w = 3 * tau**2 - 2 * tau**3
        pose = motion(t)
        np.testing.assert_allclose(pose[:3, 3], [0.2 * w, 0, 0], rtol=0, atol=1e-15)
        c, s = math.cos(w), math.sin(w)  # a turn by w rad about z
        np.testing.assert_allclose(pose[:3, :3], [[c, -s, 0], [s, c, 0], [0, 0, 1]],
                                   rtol=0, atol=1e-14)
    h = 1e-6  # at rest at the first and last knot (central differences)
    for t in (1.0, 2.0):
        assert np.max(np.abs(motion(t + h) - motion(t - h))) / (2 * h) < 1e-5
    assert np.allclose(motion(1.5 + h)[0, 3] - motion(1.5 - h)[0, 3], 2 * h * 0.2 * 1.5)


def test_the_table_defaults_are_softarm_simulate_s():
    defaults = inspect.signature(softarm.simulate).parameters
    table = Simulation(duration=1.0, dt=0.5)
    for name in ("stations", "tol", "alpha"):
        assert getattr(table, name) == defaults[name].default, name


# --------------------------------------------------------------------------------------------
# The table's errors name the key
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("table, message", [
    ("[simulate]\nduration = 0.02", "simulate.dt: missing (a number in s)"),
    ("[simulate]\nduration = 0.02\ndt = 'x'", "simulate.dt: must be a number in s, got 'x'"),
    ("[simulate]\nduration = 0.0205\ndt = 0.001",
     "simulate.duration: must be a whole number of time steps dt = 0.001 s"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\nalpha = 0.3", "simulate.alpha: must lie in"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\nstations = 2", "simulate.stations: must be >= 3"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\ninitial = 'equilibirum'",
     "simulate.initial: unknown value 'equilibirum'; expected one of 'rest', 'equilibrium'; "
     "did you mean 'equilibrium'?"),
    ("[simulate]\nduration = 0.02\ndtt = 0.001", "simulate.dtt: unknown key; did you mean 'dt'?"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[[simulate.input]]\nload = 1\ntimes = [0]\n"
     "values = [1]", "simulate.input[1].load: load 1 (gravity) has no actuation input"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[[simulate.input]]\nload = 5\ntimes = [0]\n"
     "values = [1]", "simulate.input[1].load: there are 2 [[load]] tables, got load = 5"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[[simulate.input]]\nload = 2\n"
     "times = [0, 0.1]\nvalues = [1]", "simulate.input[1].values: must hold a number or a "
     "list of numbers in the input's unit for each of the 2 times"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[[simulate.input]]\nload = 2\n"
     "times = [0.1, 0.0]\nvalues = [1, 2]", "simulate.input[1].times: must be strictly "
     "increasing"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[[simulate.input]]\nload = 2\n"
     "times = [0, 1]\nvalues = [[1, 2], [3, 4]]", "simulate.input[1].values: load 2 (tendon) "
     "has 1 input (tension); give one number per time, got 2"),
    # issue 42: a schedule's values obey the load's own rules (the words of Tendon(-1.5))
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[[simulate.input]]\nload = 2\n"
     "times = [0, 0.01]\nvalues = [0, -1.5]", "simulate.input[1].values: at t = 0.01 s: "
     "Tendon.tension must be >= 0 N (a tendon cannot push), got -1.5"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[[simulate.input]]\nload = 2\n"
     "times = [0, 0.01]\nvalues = [0, 1e200]", "simulate.input[1].values: at t = 0.01 s: "
     "Tendon.tension: a load of 1e+200 N is not representable on this arm"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[[simulate.input]]\nload = 2\ntimes = [0]\n"
     "values = [1]\n[[simulate.input]]\nload = 2\ntimes = [0]\nvalues = [2]",
     "simulate.input[2].load: load 2 has a schedule already (simulate.input[1])"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\ndamping = { retardation = -1.0 }",
     "simulate.damping.retardation: must be >= 0 s"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[simulate.base]\ntimes = [0, 1]\n"
     "positions = [[0, 0, 0]]", "simulate.base.positions: must hold a list of 3 numbers in m "
     "for each of the 2 times"),
    ("[simulate]\nduration = 0.02\ndt = 0.001\n[simulate.base]\npositions = [[0, 0, 0]]",
     "simulate.base.times: missing"),
])
def test_errors_name_the_file_and_key(tmp_path, table, message):
    path = write_case(tmp_path, ARM + table)
    with pytest.raises(CaseError) as error:
        load_case(path)
    assert str(error.value).startswith(f"{path}: {message}"), str(error.value)


# --------------------------------------------------------------------------------------------
# softarm simulate against softarm.simulate
# --------------------------------------------------------------------------------------------


def _by_hand(case):
    """The same simulation through softarm.simulate, inputs and base motion written here."""
    def tension(t):  # 0 -> 1.5 N over 5 ms, held
        return np.array([1.5 * min(max(t / 0.005, 0.0), 1.0)])

    def base(t):  # 0 -> 1 cm up z, 0 -> 0.2 rad about z: 3τ² - 2τ³ over 10 ms
        tau = min(max(t / 0.01, 0.0), 1.0)
        w = 3 * tau**2 - 2 * tau**3
        pose = np.eye(4)
        c, s = math.cos(0.2 * w), math.sin(0.2 * w)
        pose[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
        pose[2, 3] = 0.01 * w
        return pose

    return softarm.simulate(case.arm, [case.loads[0]], duration=0.02, dt=0.001,
                            actuators=[case.loads[1]], inputs=tension,
                            damping=softarm.Damping(retardation=0.004), base=base,
                            stations=11)


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    folder = tmp_path_factory.mktemp("simulate")
    path = write_case(folder, ARM + SIMULATE)
    case = load_case(path)
    return folder, path, case, _by_hand(case)


def test_the_command_writes_softarm_simulate_s_numbers(small, capsys):
    folder, path, _case, expected = small
    outs = [folder / "arm.npz", folder / "arm.csv", folder / "arm.zarr"]
    code, out, err = run(capsys, "simulate", path, *[a for o in outs for a in ("-o", o)])
    assert code == 0, err
    assert "simulated 20 steps of 0.001 s to t = 0.02 s, 11 stations" in out
    with np.load(outs[0]) as data:
        # the command runs in chunks, each Newton solve warm-started differently: equal to
        # far inside the steps' tolerance (1e-6 L)
        for name in ("positions", "rotations", "velocities", "angular_velocities"):
            np.testing.assert_allclose(data[name], getattr(expected, name), rtol=0,
                                       atol=1e-9, err_msg=name)
        np.testing.assert_allclose(data["tendon_lengths"], expected.tendon_lengths, rtol=0,
                                   atol=1e-12)
        np.testing.assert_allclose(data["energy_dissipated"], expected.energy.dissipated,
                                   rtol=1e-6, atol=1e-12)
        # (each chunk counts its times from the last one's end: equal to a few ulps)
        np.testing.assert_allclose(data["times"], expected.times, rtol=0, atol=1e-17)
        meta = json.loads(str(data["meta"]))
    assert meta["complete"] and meta["steps"] == meta["steps_requested"] == 20
    npz = read_trajectory(outs[0])
    for other in outs[1:]:  # csv (quaternions, repr floats) and zarr hold the same numbers
        back = read_trajectory(other)
        np.testing.assert_allclose(back.positions, npz.positions, rtol=0, atol=1e-15)
        np.testing.assert_allclose(back.rotations, npz.rotations, rtol=0, atol=1e-14)
        np.testing.assert_allclose(back.stresses, npz.stresses, rtol=1e-15, atol=0)
        np.testing.assert_allclose(back.energy.total, npz.energy.total, rtol=1e-15, atol=0)
        np.testing.assert_array_equal(back.iterations, npz.iterations)
        assert back.case.simulation.steps == 20 and back.complete


def test_a_zarr_output_alone_is_written_as_the_run_goes(small, capsys, monkeypatch):
    """Issue 40 (long runs): with .zarr outputs alone, each part of the run is written to
    the store as it is done and dropped (softarm.io.TrajectoryStore), so a run of any length
    fits in memory. The numbers are softarm.simulate's (written here by hand, as above), the
    summary the same as a kept run's."""
    from softarm.io import TrajectoryStore

    folder, path, _case, expected = small
    appended = []
    append = TrajectoryStore.append
    monkeypatch.setattr(TrajectoryStore, "append",
                        lambda self, part: (appended.append(part.times.size),
                                            append(self, part)))
    out = folder / "streamed.zarr"
    code, stdout, err = run(capsys, "simulate", path, "-o", out)
    assert code == 0, err
    assert len(appended) >= 2 and sum(appended) == 21  # the parts, as they were done
    assert "simulated 20 steps of 0.001 s to t = 0.02 s, 11 stations" in stdout
    back = read_trajectory(out)
    assert back.complete and back.reason == "" and back.times.size == 21
    for name in ("positions", "rotations", "velocities", "angular_velocities"):
        np.testing.assert_allclose(getattr(back, name), getattr(expected, name), rtol=0,
                                   atol=1e-9, err_msg=name)
    np.testing.assert_allclose(back.times, expected.times, rtol=0, atol=1e-17)
    kept = folder / "kept.npz"
    monkeypatch.undo()
    assert run(capsys, "simulate", path, "-o", kept)[0] == 0
    both = read_trajectory(kept)
    np.testing.assert_allclose(back.energy.total, both.energy.total, rtol=1e-6, atol=1e-12)
    # --every 3: every third time, streamed or kept (the first included: t = 0 ... 0.018 s)
    for name in ("third.zarr", "third.npz"):
        assert run(capsys, "simulate", path, "-o", folder / name, "--every", "3")[0] == 0
        third = read_trajectory(folder / name)
        np.testing.assert_allclose(third.times, expected.times[::3], rtol=0, atol=1e-17)
        np.testing.assert_allclose(third.positions, expected.positions[::3], rtol=0,
                                   atol=1e-9)
    # Ctrl-C after the first part: the store holds it, marked incomplete
    monkeypatch.setattr(cli._Progress, "__call__", _interrupt)
    code, _stdout, stderr = run(capsys, "simulate", path, "-o", folder / "stopped.zarr")
    assert code == 130 and "wrote the 1 of 20 steps done" in stderr
    back = read_trajectory(folder / "stopped.zarr")
    assert not back.complete and back.reason == "interrupted" and back.times.size == 2


def _interrupt(self, done, total, failed=0):
    raise KeyboardInterrupt


def test_a_trajectory_store_holds_the_parts_given(small, tmp_path):
    """softarm.io.TrajectoryStore against the parts joined in memory (join_trajectories):
    equal to the bit, whole or every third time, written in one chunk or in many (a chunk of
    3 times); a store left open holds the chunks written, marked incomplete; an error in its
    block closes it incomplete, with the error."""
    from softarm.case import join_trajectories, simulation_parts
    from softarm.io import TrajectoryStore

    _folder, _path, case, _expected = small
    parts = list(simulation_parts(case, seconds=0.0))  # (20 parts of a step and more)
    whole = join_trajectories(parts)
    rotations_per_time = 8 * 9 * whole.s.size
    for every, chunk in ((1, 1 << 22), (3, 1 << 22), (1, 3 * rotations_per_time),
                         (3, 3 * rotations_per_time)):
        with TrajectoryStore(tmp_path / f"run{every}{chunk}.zarr", case, every=every,
                             chunk_bytes=chunk) as store:
            for part in parts:
                store.append(part)
        back = read_trajectory(store.path)
        assert back.complete and back.times.size == len(whole.times[::every])
        for name in ("times", "positions", "rotations", "stresses", "iterations"):
            # (an unbatched run: time is the first axis)
            assert np.array_equal(getattr(back, name), getattr(whole, name)[::every]), name
        assert np.array_equal(back.tendon_lengths, whole.tendon_lengths[::every])
        assert np.array_equal(back.energy.kinetic, whole.energy.kinetic[::every])
    # a Simulator's runs, called again and again: each starts at the last one's end
    sim = softarm.Simulator(case.arm, [case.loads[1]], [case.loads[0]], dt=1e-3,
                            stations=11)
    store = TrajectoryStore(tmp_path / "runs.zarr", arm=case.arm, loads=case.loads,
                            chunk_bytes=6 * rotations_per_time)
    runs = [sim.run(4) for _ in range(3)]  # 5 times, then 4 new ones twice
    for one in runs:
        store.append(one)
    # left open: what was written when 6 or more times were held (the first 9 of the 13),
    # marked incomplete
    back = read_trajectory(store.path)
    assert not back.complete and back.reason.startswith("the run did not close the store")
    assert back.times.size == 9
    store.close()
    back = read_trajectory(store.path)
    assert back.complete and np.array_equal(back.positions, np.concatenate(
        [runs[0].positions, runs[1].positions[1:], runs[2].positions[1:]]))
    assert back.case.arm == case.arm and [load.kind for load in back.case.loads] == \
        ["gravity", "tendon"]  # (the arm and loads given, kept as a case)
    with pytest.raises(RuntimeError, match="a controller crashed"):
        with TrajectoryStore(tmp_path / "crash.zarr", case) as store:
            store.append(parts[0])
            raise RuntimeError("a controller crashed")
    back = read_trajectory(tmp_path / "crash.zarr")
    assert not back.complete and back.reason == "RuntimeError: a controller crashed"
    with pytest.raises(ValueError, match=r"path must name a \.zarr folder"):
        TrajectoryStore(tmp_path / "run.npz", case)
    with pytest.raises(ValueError, match="every"):
        TrajectoryStore(tmp_path / "run.zarr", case, every=0)
    with pytest.raises(TypeError, match="case must be a softarm Case"):
        TrajectoryStore(tmp_path / "run.zarr", "arm.toml")
    with pytest.raises(TypeError, match=r"give case .* or arm"):
        TrajectoryStore(tmp_path / "run.zarr", case, arm=case.arm)


def test_ctrl_c_keeps_the_steps_done(small, capsys, monkeypatch):
    """A KeyboardInterrupt from the progress report after the first chunk (one step): the
    file holds that step, marked incomplete; exit code 130, one line on stderr."""
    folder, path, _case, expected = small

    def interrupt(self, done, total, failed=0):
        raise KeyboardInterrupt

    monkeypatch.setattr(cli._Progress, "__call__", interrupt)
    out = folder / "partial.npz"
    code, _stdout, stderr = run(capsys, "simulate", path, "-o", out)
    assert code == 130
    assert stderr.count("\n") == 1 and stderr.startswith("softarm: interrupted; wrote the 1 "
                                                         "of 20 steps done (to t = 0.001 s)")
    back = read_trajectory(out)
    assert not back.complete and back.reason == "interrupted"
    assert back.times.size == 2 and back.steps_requested == 20
    np.testing.assert_allclose(back.positions, expected.positions[:2], rtol=0, atol=1e-9)


def test_a_step_that_fails_keeps_the_steps_before(small, capsys, monkeypatch):
    folder, path, _case, _expected = small
    original = softarm.Simulator.run
    calls = []

    def failing(self, steps, inputs=None, **options):
        calls.append(steps)
        if len(calls) == 2:
            raise softarm.ConvergenceError("the time step could not be solved", 0.5)
        return original(self, steps, inputs, **options)

    monkeypatch.setattr(softarm.Simulator, "run", failing)
    out = folder / "failed.csv"
    code, _stdout, stderr = run(capsys, "simulate", path, "-o", out)
    assert code == 1
    assert stderr.startswith("softarm: the solver did not converge: the time step could not "
                             "be solved") and "wrote the 1 of 20 steps done" in stderr
    assert stderr.count("\n") == 1
    back = read_trajectory(out)
    assert not back.complete and back.times.size == 2


def test_an_interrupt_before_any_step_writes_nothing(small, capsys, monkeypatch):
    folder, path, _case, _ = small

    def interrupt(self, steps, inputs=None, **options):
        raise KeyboardInterrupt

    monkeypatch.setattr(softarm.Simulator, "run", interrupt)
    out = folder / "nothing.npz"
    code, _, stderr = run(capsys, "simulate", path, "-o", out)
    assert code == 130 and "no step done; nothing written" in stderr
    assert not out.exists()


@pytest.mark.parametrize("extra, argv, message", [
    ("", ["-o", "{dir}/out.npz"], "simulate: missing (softarm simulate needs a [simulate] "
     "table"),
    (SIMULATE, ["-o", "{dir}/out.txt"], "unknown trajectory format '.txt'; use one of .npz, "
     ".zarr, .csv"),
    (SIMULATE, ["-o", "{dir}/missing/out.npz"], "does not exist"),
    (SIMULATE, ["-o", "{dir}/out.npz", "--every", "0"], "argument --every: must be >= 1, "
     "got 0"),
    (SIMULATE, ["-o", "{dir}/out.zarr", "--every", "2.5"], "argument --every: must be an "
     "integer, got '2.5'"),
    (SIMULATE.replace("dt = 0.001", "dt = -0.001"), ["-o", "{dir}/out.npz"],
     "simulate.dt: must be a positive number of s, got -0.001"),
    # issue 42: an arm that starts inside an obstacle, as `softarm solve` says it (it was
    # "a section turned inside out", exit 1): a ball of 5 mm round s = 0.1 m meets the
    # arm's surface (0.6 mm) from s = 0.1 - 5.6 mm on: the first of 201 stations inside,
    # s = 0.095 m, is 0.6 mm deep (5 mm from the centre)
    (SIMULATE + '\n[[obstacle]]\nkind = "sphere"\ncenter = [0.1, 0.0, 0.0]\nradius = 0.005\n',
     ["-o", "{dir}/out.npz"], "Contact: the unloaded arm starts inside an obstacle (its "
     "surface 0.0006 m deep at station s = 0.095 m)"),
])
def test_bad_input_is_one_line_exit_2_and_no_output(tmp_path, capsys, extra, argv, message):
    path = write_case(tmp_path, ARM + extra)
    old = tmp_path / "out.npz"
    old.write_bytes(b"old")
    argv = [a.format(dir=tmp_path) for a in argv]
    code, stdout, stderr = run(capsys, "simulate", path, *argv)
    assert code == 2 and stdout == ""
    assert stderr.count("\n") == 1 and message in stderr, stderr
    assert "Traceback" not in stderr
    assert old.read_bytes() == b"old"  # an existing output stays as it was
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.toml", "out.npz"]


# --------------------------------------------------------------------------------------------
# Initial equilibrium, sweeps
# --------------------------------------------------------------------------------------------


HANGING = """
[arm]
length = 0.4
section = { kind = "circle", radius = 0.003 }
material = { E = 5.0e8, nu = 0.4, density = 1100.0 }

[[load]]
kind = "gravity"

[[load]]
kind = "tip"
force = [0.0, 0.0, -0.05]

[simulate]
duration = 0.004
dt = 0.001
stations = 41
initial = "equilibrium"
"""


def _hanging(tmp_path, extra=""):
    path = write_case(tmp_path, HANGING + extra, "hanging")
    return path, load_case(path)


def test_an_initial_equilibrium_is_softarm_solve_s_at_rest(tmp_path):
    _, case = _hanging(tmp_path)
    path = simulate_case(case)
    reference = softarm.solve(case.arm, case.loads, s=41)
    # the Simulator balances the loads again on its own grid (second order in h = L/40)
    np.testing.assert_allclose(path.positions[0], reference.positions, rtol=0,
                               atol=2e-4 * case.arm.length)
    assert np.max(np.abs(path.velocities[0])) == 0.0
    # at rest in equilibrium: it stays there (to the step's tolerance)
    np.testing.assert_allclose(path.positions[-1], path.positions[0], rtol=0,
                               atol=1e-6 * case.arm.length)


def test_a_sweep_gives_one_trajectory_per_case_as_if_run_one_by_one(tmp_path, capsys):
    path, case = _hanging(tmp_path, "[sweep]\nload = 2\ncomponent = \"z\"\n"
                               "values = [-0.05, 0.0, 0.05]\n")
    folder = tmp_path
    out = folder / "sweep.zarr"
    code, _stdout, stderr = run(capsys, "simulate", path, "-o", out)
    assert code == 0, stderr
    import xarray

    with xarray.open_dataset(out, engine="zarr") as data:
        assert data["positions"].dims == ("case", "time", "station", "axis")
        assert data["positions"].shape == (3, 5, 41, 3)
        positions = data["positions"].values
        np.testing.assert_array_equal(data[case.sweep.column].values, [-0.05, 0.0, 0.05])
    for k, value in enumerate(case.sweep.values):
        data = case.to_dict()
        data.pop("sweep")
        data["load"][1]["force"] = [0.0, 0.0, value]
        alone = simulate_case(parse_case(data))
        np.testing.assert_allclose(positions[k], alone.positions, rtol=0, atol=1e-9)


def test_a_sweep_goes_on_past_a_failed_case(tmp_path, capsys):
    """The middle case is pushed inside out (a compressive tip force of twice EA): it fails
    at its first step; the others are written whole, the failed one as NaN, and one line on
    stderr names it."""
    text = HANGING.replace('initial = "equilibrium"', 'initial = "rest"') + \
        '[sweep]\nload = 2\ncomponent = "x"\nvalues = [0.0, -1e9, 0.0]\n'
    path = write_case(tmp_path, text, "crushed")
    out = tmp_path / "sweep.npz"
    code, _stdout, stderr = run(capsys, "simulate", path, "-o", out)
    assert code == 0, stderr
    assert "1 of 3 cases failed" in stderr and "-1e+09" in stderr
    back = read_trajectory(out)
    assert np.all(np.isnan(back.positions[1, 1:])) and np.all(np.isfinite(back.positions[0]))
    np.testing.assert_array_equal(back.positions[0], back.positions[2])


# --------------------------------------------------------------------------------------------
# The examples
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name, kind", [("whip", "base"), ("tendon_fast_move", "inputs"),
                                        ("pneumatic_step", "inputs")])
def test_the_dynamics_examples_read(name, kind):
    case = load_case(EXAMPLES / f"{name}.toml")
    table = case.simulation
    assert table.initial == "equilibrium" and table.damping is not None
    if kind == "base":
        assert table.base(0.1)[0, 3] == pytest.approx(0.05)  # the knot's position
    else:
        assert table.inputs and all(case.loads[s.load].inputs for s in table.inputs)
    assert (Path(__file__).resolve().parents[1] / "docs" / "figures" / f"{name}.png").is_file()
