"""softarm.sweep.run and softarm sweep: the Zarr store, closed forms at every case, serial
equals parallel (processes, a Dask LocalCluster), resume after SIGKILL, failures recorded.

Needs pip install 'softarm[sweep]' (xarray, zarr); the Dask test also 'softarm[dask]'."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm.case import load_case, parse_case

#: CI sets SOFTARM_REQUIRE_SWEEP=1: a missing extra then fails instead of skipping.
REQUIRED = bool(os.environ.get("SOFTARM_REQUIRE_SWEEP"))


def need(module: str, extra: str):
    """``import module``, or skip saying what to install (fail under SOFTARM_REQUIRE_SWEEP)."""
    try:
        return __import__(module)
    except ImportError:
        message = f"{module} is missing: pip install 'softarm[{extra}]'"
        if REQUIRED:
            pytest.fail(message, pytrace=False)
        pytest.skip(message, allow_module_level=True)


xarray = need("xarray", "sweep")
need("zarr", "sweep")

SILICONE = {"E": 1.5e6, "nu": 0.49, "density": 1070.0}
OUTPUTS = ("positions", "orientations", "strains", "stresses", "tip_position",
           "tip_orientation", "residual", "error_estimate", "length", "status")

CLOSED_FORM = """
[arm]
length = 1.0
stiffness = { EA = 1.0e6, GAy = 1.0e6, GAz = 1.0e6, GJ = 1.0, EIy = 1.0, EIz = 2.0 }

[[load]]
kind = "tip"
moment = [0.0, 1.0, 0.0]

[solve]
method = "numeric"       # the solver, compared with the closed form
stations = 11
tol = 1e-10

[sweep]
design = "grid"
[[sweep.parameter]]
path = "arm.length"
values = [0.5, 1.0]
[[sweep.parameter]]
path = "load[1].moment.y"
start = 0.0
stop = 3.0
steps = 4
[[sweep.parameter]]
path = "load[1].moment.z"
values = [0.0, 1.5]
"""


def soft_arm_case(sweep: dict, stations: int = 11) -> dict:
    """A 3D silicone arm under its weight and a tip force (the benchmark's case, small)."""
    return {
        "arm": {"length": 0.3, "section": {"kind": "circle", "radius": 0.01},
                "material": dict(SILICONE)},
        "load": [{"kind": "gravity"}, {"kind": "tip", "force": [0.0, 0.02, -0.05]}],
        "solve": {"method": "numeric", "stations": stations, "tol": 1e-8},
        "sweep": sweep,
    }


SOFT_GRID = {"design": "grid", "parameter": [
    {"path": "arm.section.radius", "values": [0.009, 0.011]},
    {"path": "load[2].force.y", "start": 0.0, "stop": 0.1, "steps": 3},
    {"path": "load[2].force.z", "values": [-0.05, 0.0]}]}


def assert_same_outputs(a, b, atol=0.0):
    for name in OUTPUTS:
        if name in a:
            np.testing.assert_allclose(np.asarray(a[name].values, dtype=float),
                                       np.asarray(b[name].values, dtype=float),
                                       rtol=0, atol=atol, err_msg=name)


def test_closed_form_at_every_case(tmp_path):
    """A grid over arm length and a tip moment about y and z (principal axes, EIy != EIz:
    each moment alone is a circular arc, eqs. 30-34 of Grazioso et al. 2018; both together
    are not, so z is swept as 0 only where the closed form is exact): the solver's store
    matches softarm.analytic.tip_moment at every case and station."""
    path = tmp_path / "closed.toml"
    path.write_text(CLOSED_FORM.replace("values = [0.0, 1.5]", "values = [0.0]"))
    case = load_case(path)
    ds = softarm.sweep.run(case, out=tmp_path / "closed.zarr", chunk=3,
                           fields=("tip", "poses", "strains", "stresses"))
    assert ds.sizes["case"] == 8 and ds.sizes["station"] == 11
    assert np.all(ds["status"].values == 0)
    for k in range(8):
        length = float(ds["arm.length"][k])
        moment = [0.0, float(ds["load[1].moment.y"][k]), 0.0]
        arm = softarm.Arm.from_stiffness(length, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0,
                                         EIz=2.0)
        exact = softarm.analytic.tip_moment(arm, moment=moment, s=11)
        assert exact.exact
        np.testing.assert_allclose(ds["positions"][k].values, exact.positions, rtol=0,
                                   atol=1e-9 * length)
        np.testing.assert_allclose(ds["strains"][k].values, exact.strains, rtol=0, atol=1e-7)
        np.testing.assert_allclose(ds["tip_position"][k].values, exact.tip_position, rtol=0,
                                   atol=1e-9 * length)
        np.testing.assert_allclose(ds["length"][k], length)
        np.testing.assert_allclose(ds["stresses"][k].values[:, 4], moment[1], rtol=0,
                                   atol=1e-7)  # m2 = EIy κ2 = τ along the arm


def test_store_layout_units_and_attributes(tmp_path):
    case = parse_case(soft_arm_case(SOFT_GRID), tmp_path / "soft.toml")
    ds = softarm.sweep.run(case, out=tmp_path / "soft.zarr", fields=("poses", "tip"),
                           dtype="float32", stations=5)
    assert ds["positions"].dims == ("case", "station", "axis")
    assert ds["orientations"].dims == ("case", "station", "quaternion")
    assert ds["status"].dims == ("case",) and ds["status"].dtype == np.int8
    assert ds["positions"].dtype == np.float32 and ds["residual"].dtype == np.float64
    assert ds["positions"].attrs["units"] == "m"
    assert ds["arm.section.radius"].attrs["units"] == "m"
    assert ds["load[2].force.y"].attrs["units"] == "N"
    assert "strains" not in ds and ds.sizes["station"] == 5
    np.testing.assert_array_equal(ds["station"].values, np.linspace(0, 1, 5))
    # the design's points as coordinates on case (the grid, radius slowest)
    np.testing.assert_array_equal(ds["arm.section.radius"].values, [0.009] * 6 + [0.011] * 6)
    np.testing.assert_array_equal(ds["load[2].force.z"].values, [-0.05, 0.0] * 6)
    assert ds.attrs["softarm_version"] == softarm.__version__
    assert ds.attrs["method"] == "numeric" and ds.attrs["tol"] == 1e-8
    assert "unloaded arm" in ds.attrs["semantics"]
    assert np.all(ds["chunk_done"].values == 1)
    # the store is a Zarr v2 store (both zarr 2 and 3 read it)
    assert (tmp_path / "soft.zarr" / ".zgroup").is_file()
    # each case equals softarm.solve of that case alone (float32 storage)
    for k in (0, 7, 11):
        arm = softarm.Arm(0.3, softarm.Circle(float(ds["arm.section.radius"][k])),
                          softarm.Material(1.5e6, poisson_ratio=0.49, density=1070.0))
        force = [0.0, float(ds["load[2].force.y"][k]), float(ds["load[2].force.z"][k])]
        eq = softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=force)],
                           method="numeric", s=5)
        np.testing.assert_allclose(ds["positions"][k].values, eq.positions, rtol=0,
                                   atol=1e-7)


@pytest.mark.slow
def test_serial_equals_two_processes_case_by_case(tmp_path):
    case = parse_case(soft_arm_case(SOFT_GRID), tmp_path / "soft.toml")
    serial = softarm.sweep.run(case, out=tmp_path / "serial.zarr", chunk=2,
                               fields=("poses", "strains", "stresses", "tip"))
    with softarm.sweep.process_pool(2, case) as pool:
        parallel = softarm.sweep.run(case, out=tmp_path / "parallel.zarr", chunk=2,
                                     map=pool.map,
                                     fields=("poses", "strains", "stresses", "tip"))
    assert np.all(serial["status"].values == 0)
    assert_same_outputs(serial, parallel, atol=1e-12)
    memory = softarm.sweep.run(case, chunk=5, fields=("poses", "strains", "stresses", "tip"))
    assert_same_outputs(serial, memory, atol=1e-12)  # chunking changes nothing


@pytest.mark.slow
def test_dask_local_cluster_equals_serial(tmp_path):
    distributed = need("distributed", "dask")
    case = parse_case(soft_arm_case(SOFT_GRID), tmp_path / "soft.toml")
    serial = softarm.sweep.run(case, chunk=3)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        executor = client.get_executor(pure=False)
        cluster_run = softarm.sweep.run(case, out=tmp_path / "dask.zarr", chunk=3,
                                        map=executor.map)
        workers = client.run(lambda: os.getpid())
    assert len(set(workers.values())) == 2 and os.getpid() not in workers.values()
    assert np.all(cluster_run["status"].values == 0)
    assert_same_outputs(serial, cluster_run, atol=1e-12)


def _chunk_files(store: Path) -> int:
    folder = store / "chunk_done"
    return sum(1 for p in folder.iterdir() if p.name.isdigit()) if folder.is_dir() else 0


#: A design of 160 cases in chunks of 4: long enough to kill a sweep while it writes
_KILLED_DESIGN = {"design": "grid", "parameter": [
    {"path": "load[2].force.y", "start": 0.0, "stop": 0.1, "steps": 20},
    {"path": "load[2].force.z", "start": -0.1, "stop": 0.0, "steps": 8}]}


@pytest.mark.slow
def test_resume_after_sigkill_equals_an_uninterrupted_run(tmp_path, capsys):
    """softarm sweep is killed (SIGKILL) while writing; --resume finishes the chunks whose
    done flag is missing, and the store then equals an uninterrupted run."""
    sweep = _KILLED_DESIGN
    case_file = tmp_path / "resume.toml"
    case_file.write_text(_toml(soft_arm_case(sweep)))
    out = tmp_path / "killed.zarr"
    command = [sys.executable, "-m", "softarm", "sweep", str(case_file), "-o", str(out),
               "--chunk", "4", "--fields", "tip,positions,strains"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while _chunk_files(out) < 3 and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    assert process.returncode == -signal.SIGKILL
    done_at_kill = _chunk_files(out)
    assert 3 <= done_at_kill < 40, done_at_kill  # killed mid-way
    partial = softarm.open_sweep(out)
    assert np.sum(partial["status"].values == -1) > 0  # cases left to solve
    from softarm.cli import main

    assert main([*command[3:], "--resume"]) == 0
    assert "160 ok, 0 failed" in capsys.readouterr().out
    whole = softarm.sweep.run(load_case(case_file), out=tmp_path / "whole.zarr", chunk=4,
                              fields=("tip", "positions", "strains"))
    final = softarm.open_sweep(out)
    assert np.all(final["chunk_done"].values == 1)
    assert_same_outputs(final, whole, atol=1e-12)


def _toml(data: dict) -> str:
    """A case dict as TOML (only the shapes used here)."""
    lines = []

    def value(v):
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        return repr(v)

    for name in ("arm", "solve"):
        lines.append(f"[{name}]")
        lines += [f"{k} = {value(v)}" for k, v in data[name].items()]
    for load in data["load"]:
        lines.append("[[load]]")
        lines += [f"{k} = {value(v)}" for k, v in load.items()]
    sweep = dict(data["sweep"])
    rows = sweep.pop("parameter")
    lines.append("[sweep]")
    lines += [f"{k} = {value(v)}" for k, v in sweep.items()]
    for row in rows:
        lines.append("[[sweep.parameter]]")
        lines += [f"{k} = {value(v)}" for k, v in row.items()]
    return "\n".join(lines) + "\n"


def test_failures_are_recorded_not_raised(tmp_path, monkeypatch):
    """A point load placed beyond the end of a shortened arm is invalid only in combination
    (each value alone is fine): those cases get status 2 and the model's reason, NaN outputs;
    every other case equals softarm.solve of that case alone."""
    data = {
        "arm": {"length": 1.0, "stiffness": {"EA": 1e6, "GAy": 1e6, "GAz": 1e6, "GJ": 1.0,
                                             "EIy": 1.0, "EIz": 1.0}},
        "load": [{"kind": "point", "s": 0.2, "force": [0.0, 0.0, 1.0]}],
        "solve": {"method": "numeric", "stations": 5},
        "sweep": {"design": "grid", "parameter": [
            {"path": "arm.length", "values": [1.0, 0.5]},
            {"path": "load[1].s", "values": [0.2, 0.8]},
            {"path": "load[1].force.z", "values": [0.5, 1.0]}]}}
    case = parse_case(data, "point.toml")
    ds = softarm.sweep.run(case, out=tmp_path / "point.zarr", chunk=3)
    status = ds["status"].values
    bad = (ds["arm.length"].values == 0.5) & (ds["load[1].s"].values == 0.8)
    np.testing.assert_array_equal(status, np.where(bad, 2, 0))
    assert all("must lie on the arm" in m for m in ds["message"].values[bad])
    assert np.all(np.isnan(ds["positions"].values[bad]))
    for k in np.flatnonzero(~bad):
        arm = softarm.Arm.from_stiffness(float(ds["arm.length"][k]), EA=1e6, GAy=1e6,
                                         GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0)
        load = softarm.PointLoad(float(ds["load[1].s"][k]),
                                 force=[0.0, 0.0, float(ds["load[1].force.z"][k])])
        eq = softarm.solve(arm, load, method="numeric", s=5)
        np.testing.assert_allclose(ds["positions"][k].values, eq.positions, rtol=0,
                                   atol=1e-12)


def test_a_solver_failure_in_a_batch_spares_its_neighbours(monkeypatch):
    """The solver raises ConvergenceError for a whole batch when one case fails; the sweep
    halves the batch until the failed case is alone. Here the failure is injected for tip
    moments above 2.5 N m (a stand-in for a fold), and every other case must still match the
    closed form (tip_moment, eqs. 30-34)."""
    from softarm import dispatch

    real = dispatch.solve_prepared

    def failing(solver, loads, method="auto"):
        moment = np.asarray(loads[0].moment)
        if np.any(moment[..., 1] > 2.5):
            raise softarm.ConvergenceError("the loading path could not be followed beyond "
                                           "load factor λ = 0.9 for load case (3,)", 1e-3)
        return real(solver, loads, method)

    monkeypatch.setattr(dispatch, "solve_prepared", failing)
    data = {"arm": {"length": 1.0, "stiffness": {"EA": 1e6, "GAy": 1e6, "GAz": 1e6, "GJ": 1.0,
                                                 "EIy": 1.0, "EIz": 1.0}},
            "load": [{"kind": "tip", "moment": [0.0, 1.0, 0.0]}],
            "solve": {"method": "numeric", "stations": 5},
            "sweep": {"design": "list", "parameter": [
                {"path": "load[1].moment.y", "values": [0.5, 3.0, 1.0, 2.0, 2.6, 1.5, 0.1]}]}}
    ds = softarm.sweep.run(parse_case(data), chunk=7)
    values = ds["load[1].moment.y"].values
    failed = values > 2.5
    np.testing.assert_array_equal(ds["status"].values, np.where(failed, 1, 0))
    assert all(m == "the loading path could not be followed beyond load factor λ = 0.9 "
               "(residual 1.000e-03)" for m in ds["message"].values[failed])
    arm = softarm.Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0)
    for k in np.flatnonzero(~failed):
        exact = softarm.analytic.tip_moment(arm, moment=[0.0, values[k], 0.0], s=5)
        np.testing.assert_allclose(ds["positions"][k].values, exact.positions, rtol=0,
                                   atol=1e-8)


def test_path_option_follows_the_sweep_quasi_statically():
    """--path: one prepared Solver driven through the values in order; on a path without
    folds it reaches the same equilibria as independent solves (Mattiasson 1981 cantilever,
    k = PL²/EI = 1, 2, 5: w/L = 0.30172, 0.49346, 0.71379, Table 1)."""
    data = {"arm": {"length": 1.0, "stiffness": {"EA": 1e9, "GAy": 1e9, "GAz": 1e9, "GJ": 1.0,
                                                 "EIy": 1.0, "EIz": 1.0}},
            "load": [{"kind": "tip", "force": [0.0, 0.0, 1.0]}],
            "solve": {"method": "numeric", "stations": 3},
            "sweep": {"load": 1, "component": "z", "values": [1.0, 2.0, 5.0]}}
    ds = softarm.sweep.run(parse_case(data), path=True)
    assert "quasi-static" in ds.attrs["semantics"]
    np.testing.assert_allclose(ds["tip_position"].values[:, 2], [0.30172, 0.49346, 0.71379],
                               rtol=0, atol=6e-6)


def test_cli_sweep(tmp_path):
    from softarm.cli import main

    case_file = tmp_path / "closed.toml"
    case_file.write_text(CLOSED_FORM)
    out = tmp_path / "cli.zarr"
    assert main(["sweep", str(case_file), "-o", str(out), "--stations", "3"]) == 0
    ds = softarm.open_sweep(out)
    assert ds.sizes == {"case": 16, "station": 3, "axis": 3, "quaternion": 4, "component": 6,
                        "chunk": 16}
    assert np.all(ds["status"].values == 0)
    # an existing store is never overwritten; a resume with other options is refused
    assert main(["sweep", str(case_file), "-o", str(out)]) == 2
    assert main(["sweep", str(case_file), "-o", str(out), "--resume", "--dtype",
                 "float32"]) == 2
    assert main(["sweep", str(case_file), "-o", str(out), "--stations", "3", "--resume"]) == 0


def test_segment_parameters_group_cases_onto_their_arm():
    """A grid over the second segment's Young's modulus and the tip force: each case equals
    softarm.solve of the SegmentedArm built here by hand (two arms, three forces)."""
    soft = {"E": 1.0e6, "nu": 0.5, "density": 1100.0}
    data = {
        "segment": [{"length": 0.2, "section": {"kind": "circle", "radius": 0.012},
                     "material": dict(soft)},
                    {"length": 0.1, "section": {"kind": "tube", "outer_radius": 0.01,
                                                "inner_radius": 0.004},
                     "material": dict(soft)}],
        "load": [{"kind": "gravity"}, {"kind": "tip", "force": [0.0, 0.0, -1.0]}],
        "solve": {"method": "numeric", "stations": 7},
        "sweep": {"design": "grid", "parameter": [
            {"path": "segment[2].material.E", "values": [5e5, 2e6]},
            {"path": "load[2].force.magnitude", "values": [0.0, 0.05, 0.1]}]}}
    ds = softarm.sweep.run(parse_case(data), fields=("poses",))
    assert np.all(ds["status"].values == 0)
    for k in range(6):
        E = float(ds["segment[2].material.E"][k])
        arm = softarm.SegmentedArm([
            softarm.Arm(0.2, softarm.Circle(0.012), softarm.Material(1e6, poisson_ratio=0.5,
                                                                     density=1100.0)),
            softarm.Arm(0.1, softarm.Tube(0.01, 0.004),
                        softarm.Material(E, poisson_ratio=0.5, density=1100.0))])
        force = [0.0, 0.0, -float(ds["load[2].force.magnitude"][k])]
        eq = softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=force)],
                           method="numeric", s=7)
        np.testing.assert_allclose(ds["positions"][k].values, eq.positions, rtol=0,
                                   atol=1e-12)
        np.testing.assert_allclose(ds["orientations"][k].values,
                                   softarm.lie.so3.to_quaternion(eq.rotations), rtol=0,
                                   atol=1e-12)
    np.testing.assert_allclose(ds["length"].values, 0.3)


# --------------------------------------------------------------------------------------------
# softarm sweep: what goes wrong around the sweep (issue 30)
# --------------------------------------------------------------------------------------------

SMALL_GRID = {"design": "grid", "parameter": [
    {"path": "load[2].force.y", "start": 0.0, "stop": 0.1, "steps": 10},
    {"path": "load[2].force.z", "start": -0.1, "stop": 0.0, "steps": 4}]}


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (Linux /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rpartition(")")[2].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.append(int(entry.name))
    return found


@pytest.mark.slow  # (~7 s)
@pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="reads /proc (Linux)")
def test_a_killed_worker_is_one_line_naming_the_resume_command(tmp_path):
    """One worker of --workers 2 gets SIGKILL (what the kernel's out-of-memory killer sends):
    one line on stderr that names the command to resume, exit 1 (a failure, not bad input);
    that command, run as printed, finishes a store equal to the bit to an uninterrupted run."""
    sweep = _KILLED_DESIGN
    case_file = tmp_path / "killed.toml"
    case_file.write_text(_toml(soft_arm_case(sweep)))
    out = tmp_path / "killed.zarr"
    process = subprocess.Popen(
        [sys.executable, "-m", "softarm", "sweep", str(case_file), "-o", str(out), "--chunk",
         "2", "--workers", "2", "--dtype", "float32"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 180
    while _chunk_files(out) < 3 and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    workers = _children(process.pid)
    assert len(workers) >= 2, workers
    os.kill(workers[0], signal.SIGKILL)
    _, err = process.communicate(timeout=180)
    assert process.returncode == 1, err
    lines = [line for line in err.splitlines() if line.strip() and  # but the progress bar
             not line.startswith("sweep [")]
    assert len(lines) == 1 and "Traceback" not in err, err
    command = f"softarm sweep {case_file} -o {out} --resume"
    assert lines[0].startswith("softarm: ") and lines[0].endswith(command)
    assert _chunk_files(out) < 80  # the run stopped with chunks left to solve
    resumed = subprocess.run([sys.executable, "-m", *command.split()], capture_output=True,
                             text=True, timeout=300, check=False)
    assert resumed.returncode == 0, resumed.stderr
    assert "160 ok, 0 failed" in resumed.stdout
    whole = softarm.sweep.run(load_case(case_file), out=tmp_path / "whole.zarr", chunk=2,
                              fields=("tip", "positions"), dtype="float32")
    final = softarm.open_sweep(out)
    assert final["positions"].dtype == np.float32
    assert_same_outputs(final, whole, atol=0.0)


@pytest.mark.parametrize("name", ["out.csv", "out.zarr.d", "out"])
def test_an_output_that_is_not_a_zarr_store_is_refused(tmp_path, capsys, name):
    from softarm.cli import main

    case_file = tmp_path / "case.toml"
    case_file.write_text(_toml(soft_arm_case(SMALL_GRID)))
    assert main(["sweep", str(case_file), "-o", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and ".zarr" in err and name in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml"]  # nothing written


def _interrupted_store(case_file: Path, out: Path, options: list[str], after: int) -> None:
    """``softarm sweep`` with ``options``, stopped by Ctrl-C after ``after`` cases."""
    from softarm import cli

    calls = {"n": 0}
    real = cli._Progress.__call__

    def progress(self, done, total, *rest):
        calls["n"] += 1
        if done >= after:
            raise KeyboardInterrupt
        return real(self, done, total, *rest)

    handler = signal.getsignal(signal.SIGINT)  # the command ignores a second Ctrl-C after one
    try:
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(cli._Progress, "__call__", progress)
            assert cli.main(["sweep", str(case_file), "-o", str(out), *options]) == 130
    finally:
        signal.signal(signal.SIGINT, handler)
    assert calls["n"] >= 1


def test_resume_takes_the_options_recorded_in_the_store(tmp_path, capsys):
    """The README's two lines: a sweep with --fields and --dtype, interrupted, then
    `softarm sweep CASE -o STORE --resume` with no option: it resumes with the store's
    options (it said "holds another sweep (its dtype differ)"), and the store equals an
    uninterrupted run with those options, to the bit."""
    case_file = tmp_path / "design.toml"
    case_file.write_text(_toml(soft_arm_case(SMALL_GRID)))
    out = tmp_path / "design.zarr"
    options = ["--fields", "tip,strains", "--dtype", "float32", "--chunk", "4",
               "--stations", "7"]
    _interrupted_store(case_file, out, options, after=8)
    partial = softarm.open_sweep(out)
    assert 0 < int(np.sum(partial["status"].values == -1)) < 40
    capsys.readouterr()
    from softarm.cli import main

    assert main(["sweep", str(case_file), "-o", str(out), "--resume"]) == 0, \
        capsys.readouterr().err
    assert "40 ok, 0 failed" in capsys.readouterr().out
    whole = softarm.sweep.run(load_case(case_file), out=tmp_path / "whole.zarr", chunk=4,
                              stations=7, fields=("tip", "strains"), dtype="float32")
    final = softarm.open_sweep(out)
    assert final["strains"].dtype == np.float32 and final.sizes["station"] == 7
    assert "positions" not in final
    assert_same_outputs(final, whole, atol=0.0)
    # given again, the same options are accepted
    assert main(["sweep", str(case_file), "-o", str(out), "--resume", *options]) == 0


def test_resume_refuses_options_that_differ_from_the_store(tmp_path, capsys):
    """An option given with --resume that differs from the store's: one line that names it
    with both values, exit 2, the store untouched."""
    case_file = tmp_path / "design.toml"
    case_file.write_text(_toml(soft_arm_case(SMALL_GRID)))
    out = tmp_path / "design.zarr"
    _interrupted_store(case_file, out, ["--dtype", "float32", "--chunk", "4"], after=8)
    before = np.asarray(softarm.open_sweep(out)["chunk_done"].values)
    capsys.readouterr()
    from softarm.cli import main

    code = main(["sweep", str(case_file), "-o", str(out), "--resume", "--dtype", "float64",
                 "--fields", "tip"])
    err = capsys.readouterr().err
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "dtype" in err and "float32" in err and "float64" in err
    assert "fields" in err and "tip,positions" in err
    assert "chunk" not in err  # given the same as the store's: not named
    np.testing.assert_array_equal(softarm.open_sweep(out)["chunk_done"].values, before)
    # the same in Python
    with pytest.raises(ValueError, match=r"dtype float32.*given dtype float64"):
        softarm.sweep.run(load_case(case_file), out=out, resume=True, dtype="float64")


@pytest.mark.parametrize(("change", "words"), [
    (("force = [0.0, 0.02, -0.05]", "force = [0.0, 0.03, -0.05]"), "(its case differs)"),
    (("steps = 10", "steps = 11"), "(its case and design differ)"),
])
def test_resume_of_another_sweep_says_what_differs(tmp_path, capsys, change, words):
    case_file = tmp_path / "design.toml"
    case_file.write_text(_toml(soft_arm_case(SMALL_GRID)))
    out = tmp_path / "design.zarr"
    _interrupted_store(case_file, out, ["--chunk", "4"], after=8)
    text = case_file.read_text()
    assert change[0] in text
    case_file.write_text(text.replace(change[0], change[1]))
    capsys.readouterr()
    from softarm.cli import main

    assert main(["sweep", str(case_file), "-o", str(out), "--resume"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and f"{out}: holds another sweep {words}" in err, err
    assert err.count(str(out)) == 1


def test_resume_in_python_takes_the_store_options(tmp_path):
    """softarm.sweep.run(..., resume=True) without options resumes with the store's."""
    case = parse_case(soft_arm_case(SMALL_GRID), "design.toml")
    out = tmp_path / "design.zarr"
    calls = []

    def stop(done, total, failed):
        calls.append(done)
        if done >= 8:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        softarm.sweep.run(case, out=out, chunk=4, dtype="float32", fields=("tip",),
                          progress=stop)
    ds = softarm.sweep.run(case, out=out, resume=True)
    assert ds["tip_position"].dtype == np.float32 and "positions" not in ds
    assert int(np.sum(ds["status"].values == 0)) == 40
    whole = softarm.sweep.run(case, chunk=4, dtype="float32", fields=("tip",))
    assert_same_outputs(ds, whole, atol=0.0)


def test_an_unreachable_scheduler_is_named_with_the_time_waited(tmp_path, capsys):
    """--scheduler tcp://ADDRESS where nothing answers: one line that says so, with the
    connect timeout of Dask's configuration (it said "cannot write: Timed out"); exit 2."""
    need("distributed", "dask")
    import socket

    import dask

    from softarm.cli import main

    with socket.socket() as probe:  # a port nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    case_file = tmp_path / "case.toml"
    case_file.write_text(_toml(soft_arm_case(SMALL_GRID)))
    address = f"tcp://127.0.0.1:{port}"
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        code = main(["sweep", str(case_file), "-o", str(tmp_path / "out.zarr"), "--scheduler",
                     address])
    err = capsys.readouterr().err
    assert code == 2
    assert err == f"softarm: error: cannot reach the Dask scheduler at {address} within 1 s\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.toml"]


def test_resuming_a_path_store_with_workers_is_refused_first(tmp_path, capsys):
    """A store started with --path resumes serially: --resume --workers 2 is refused in one
    line before any worker starts (it built a process pool, then failed naming `map`)."""
    from softarm.cli import main

    case_file = tmp_path / "path.toml"
    case_file.write_text('[arm]\nlength = 1.0\nstiffness = { EA = 1e9, GAy = 1e9, GAz = 1e9, '
                         'GJ = 1.0, EIy = 1.0, EIz = 1.0 }\n[[load]]\nkind = "tip"\n'
                         'force = [0.0, 0.0, 1.0]\n[sweep]\nload = 1\ncomponent = "z"\n'
                         'values = [1.0, 2.0]\n')
    out = tmp_path / "path.zarr"
    assert main(["sweep", str(case_file), "-o", str(out), "--stations", "3", "--path"]) == 0
    capsys.readouterr()
    assert main(["sweep", str(case_file), "-o", str(out), "--resume", "--workers", "2"]) == 2
    err = capsys.readouterr().err
    assert err == ("softarm: error: this store was started with --path: it follows the cases "
                   "one after the other, in this process; give no --workers or --scheduler\n")
