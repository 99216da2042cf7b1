"""Memory: what a batch needs is what the guard assumes, and a large batch is solved in parts.

A batch's peak memory is its result (:data:`softarm._validate.BYTES_PER_STATION` per case and
station, :data:`~softarm._validate.BYTES_PER_CASE` per case) plus the work of one part
(``statics.solver.CASES_PER_PART`` cases: load channels, work arrays, verdict): the guard
(``check_allocation``) refuses what cannot fit before anything is allocated, and must never
assume less than a batch really takes (measured here as the process's peak resident memory).
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest

import softarm
import softarm.statics.solver as solver_module

SILICONE = softarm.Material(youngs_modulus=1.5e6, poisson_ratio=0.49, density=1070.0)
ARM = softarm.Arm(0.3, softarm.Circle(0.01), SILICONE)


def _loads(shape):
    force = np.zeros((*shape, 3))
    force[..., 1] = np.linspace(0.0, 0.05, int(np.prod(shape))).reshape(shape)
    return [softarm.Gravity(), softarm.TipLoad(force=force)]


def _same(a: softarm.Equilibrium, b: softarm.Equilibrium) -> None:
    for field in dataclasses.fields(softarm.Equilibrium):
        x, y = getattr(a, field.name), getattr(b, field.name)
        if isinstance(x, np.ndarray):
            assert x.shape == y.shape and np.array_equal(x, y), field.name
    assert np.array_equal(a.stability.index, b.stability.index)
    assert np.array_equal(a.stability.conservative, b.stability.conservative)


@pytest.mark.parametrize("chained", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_a_batch_solved_in_parts_is_the_batch_to_the_bit(monkeypatch, chained):
    loads = _loads((5, 8))
    whole = softarm.statics.Solver(ARM, s=11)
    one = (whole.solve if chained else whole.solve_from_unloaded)(loads, jacobians=True)
    monkeypatch.setattr(solver_module, "CASES_PER_PART", 7)  # 40 cases in 6 parts
    parted = softarm.statics.Solver(ARM, s=11)
    parts = (parted.solve if chained else parted.solve_from_unloaded)(loads, jacobians=True)
    _same(one, parts)
    assert parts.loads[1].force.shape == (5, 8, 3)  # the loads as given
    assert parts.poses.flags.writeable is False


def test_a_failure_in_a_part_names_its_case_in_the_whole_batch(monkeypatch):
    # a budget of shootings that only the smaller loads meet: the first case over it is
    # (2, 3) of the (4, 5) batch, in the third part of 5 cases
    monkeypatch.setattr(solver_module, "CASES_PER_PART", 5)
    force = np.zeros((4, 5, 3))
    force[..., 2] = -0.05
    # bends the arm through several turns and pulls it hard: more shootings (-30 N, which
    # single shooting took more than 40 for, multiple shooting now solves within them)
    force[2, 3, 2] = -300.0
    loads = [softarm.TipLoad(force=force), softarm.DistributedForce([0.0, 0.0, 0.0])]
    counts = softarm.statics.Solver(ARM, s=3).solve_from_unloaded(
        [softarm.TipLoad(force=[0.0, 0.0, -0.05]), softarm.DistributedForce([0.0, 0.0, 0.0])])
    assert counts.residual < 1e-9
    with pytest.raises(softarm.ConvergenceError, match=r"for load case \(2, 3\)"):
        softarm.statics.Solver(ARM, s=3, max_shootings=40).solve_from_unloaded(loads)


def test_a_zero_copy_broadcast_batch_too_large_is_a_value_error():
    force = np.broadcast_to(np.array([0.0, 0.0, 1.0]), (10**6, 10**6, 3))
    with pytest.raises(ValueError, match=r"TipLoad.force: an array of shape "
                                         r"\(1000000, 1000000, 3\) would need 24 TB"):
        softarm.TipLoad(force=force)


def test_a_result_that_cannot_fit_is_refused_before_it_is_allocated():
    # 10⁴ cases × (10⁵ stations × 224 B + 640 B) for the result, and three parts' work
    # (at most PART_BYTES, 64 MiB, each): 224 GB
    with pytest.raises(ValueError, match=r"loads: 10000 load cases × 100000 stations would "
                                         r"need 224 GB of memory"):
        softarm.solve(ARM, _loads((10_000,)), s=100_000)


_MEASURE = """
import json, sys
import numpy as np, softarm
import softarm.statics.solver as solver
from softarm._validate import check_allocation
from softarm.routing import Straight
silicone = softarm.Material(youngs_modulus=1.5e6, poisson_ratio=0.49, density=1070.0)
arm = softarm.Arm(0.3, softarm.Circle(0.01), silicone)
kind, count, stations = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
s = stations if stations > 1 else [0.3]
def loads(n):  # each kind takes its own route: numeric, or a closed form
    x, vector = np.linspace(0.001, 0.05, n), np.zeros((n, 3))
    if kind == "numeric":
        vector[:, 1] = x
        return [softarm.Gravity(), softarm.TipLoad(force=vector)]
    if kind == "elastica":
        vector[:, 1], vector[:, 2] = x, -0.01
        return [softarm.TipLoad(force=vector)]
    if kind == "tendon":
        return [softarm.Tendon(50 * x, Straight(0.0, 0.005))]
    vector[:, 1], vector[:, 0] = x * 0.2, x * 0.05  # a helix
    return [softarm.TipLoad(moment=vector)]
warm = softarm.solve(arm, loads(20), s=s)  # compiled and warm
given = loads(count)
def status(key):  # resident memory now (VmRSS) or at its peak (VmHWM), bytes
    return int(open("/proc/self/status").read().split(key + ":")[1].split()[0]) * 1024
with open("/proc/self/clear_refs", "w") as file:  # the peak from here on (Linux >= 4.0)
    file.write("5")
before = status("VmRSS")
eq = softarm.solve(arm, given, s=s)
peak = status("VmHWM")
guard = check_allocation(count, eq.s.size)
print(json.dumps({"method": eq.method, "peak": peak - before, "guard": guard,
                  "kept": status("VmRSS") - before}))
"""


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc (Linux)")
@pytest.mark.parametrize(("kind", "method", "count", "stations"), [
    *((kind, method, 30_000, stations) for kind, method in (
        ("numeric", "numeric.shooting"), ("elastica", "analytic.elastica"),
        ("tendon", "analytic.actuated"), ("moment", "analytic.tip_moment.helix"))
      for stations in (1, 101)),
    # the solver's batch in two parts (CASES_PER_PART = 32768), their results copied in
    ("numeric", "numeric.shooting", 40_000, 101)])
def test_the_guard_assumes_at_least_what_a_batch_takes(kind, method, count, stations):
    run = subprocess.run([sys.executable, "-c", _MEASURE, kind, str(count), str(stations)],
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    figures = json.loads(run.stdout.splitlines()[-1])
    assert figures["method"] == method  # (the route meant)
    # the process's peak resident memory over the batch (result, work of the parts)
    assert figures["peak"] <= figures["guard"], figures
    if stations > 1:  # where the result, not one part's work, is most of it: not much more
        assert figures["guard"] <= 2.5 * figures["peak"], figures


# ------------------------------------------------------------------------------------------
# Dynamics (issue 42): a Simulator's stations and a run's steps, guarded like the statics
# ------------------------------------------------------------------------------------------

# A node of a step holds its state (Z 24, Zold 2 × 24, H 72 float64) nine times and 30
# outputs twice, 8 (9 × 144 + 60) = 10848 B, one factorisation's banded rows, 18 rows of
# 3 × 29 + 1 band columns, 29 multipliers and a pivot: 8 × 18 × 118 = 16992 B, and the
# node's Jacobian G and Hermite's G² (2 × 18 × 18) and slopes (25): 8 × 673 = 5384 B.
NODE = 10848 + 16992 + 5384


def test_a_simulator_and_its_runs_are_refused_before_allocating(monkeypatch):
    """The reference: the byte counts above by hand (the measurement below checks that
    they cover what a step and a run take). Before issue 42 a Simulator of 10⁹ stations
    began a 16 GB linspace (then an out-of-memory kill), run(10**12) a 7 TiB arange."""
    monkeypatch.setattr(softarm._validate, "memory_limit", lambda: 10**8)
    # 10⁴ stations and the two ends of the one piece: (10⁴ + 2) × 33224 B + 3 × 12288 B
    need = (10_000 + 2) * NODE + 3 * 12288
    with pytest.raises(ValueError, match=rf"^stations: 1 load case × 10002 stations would "
                                         rf"need {need / 1e6:.3g} MB of memory"):
        softarm.Simulator(ARM, [], [softarm.Gravity()], dt=1e-3, stations=10_000)
    sim = softarm.Simulator(ARM, [], [softarm.Gravity()], dt=1e-3, stations=21)
    # 10¹² steps × (21 stations × 3 copies of 30 float64 + 15 float64 a step) + the work
    need = 10**12 * (21 * 720 + 120) + 3 * 12288
    with pytest.raises(ValueError, match=rf"^run\(1000000000000 steps\): 1 load case × 21 "
                                         rf"stations would need {need / 1e15:.3g} PB .* run "
                                         r"fewer steps at a time"):
        sim.run(10**12)
    with pytest.raises(ValueError, match=r"^run\(1000000000000 steps\)"):
        softarm.simulate(ARM, [softarm.Gravity()], duration=1e9, dt=1e-3, stations=21)
    assert sim.run(3).positions.shape == (4, 21, 3)  # (what fits runs)


_MEASURE_DYNAMICS = """
import json, sys
import numpy as np, softarm
from softarm._validate import check_allocation
from softarm.dynamics._simulator import _node_bytes
from softarm.routing import Straight
silicone = softarm.Material(youngs_modulus=1.5e6, poisson_ratio=0.49, density=1070.0)
arm = softarm.Arm(0.3, softarm.Circle(0.01), silicone)
what, stations, steps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
act = [softarm.Tendon(0.1, Straight(0.0, 0.005))]
for warm in range(2):  # compiled, step and run
    sim = softarm.Simulator(arm, act, [softarm.Gravity()], dt=1e-3, stations=11)
    sim.step(); sim.run(2)
def status(key):
    return int(open("/proc/self/status").read().split(key + ":")[1].split()[0]) * 1024
with open("/proc/self/clear_refs", "w") as file:
    file.write("5")
before = status("VmRSS")
sim = softarm.Simulator(arm, act, [softarm.Gravity()], dt=1e-3, stations=stations)
state, storage = _node_bytes()
nodes = sim._nodes.size
guard = check_allocation(1, nodes, per_station=state + storage, per_case=0.0)
if what == "step":
    for _ in range(steps):
        sim.step([0.2])
    guard += check_allocation(1, nodes, per_station=storage, per_case=0.0)
else:
    guard += sim._check_run(steps, "run")
    path = sim.run(steps)
peak = status("VmHWM")
print(json.dumps({"peak": peak - before, "guard": guard}))
"""


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc (Linux)")
@pytest.mark.parametrize(("what", "stations", "steps"), [("step", 20_000, 3),
                                                         ("run", 1001, 1000)])
def test_the_dynamics_guards_assume_at_least_what_a_step_and_a_run_take(what, stations,
                                                                         steps):
    """The reference: the process's peak resident memory (measured 490 MB for the steps of
    20 000 stations, 0.54 GB for 1000 steps of 1001 stations)."""
    run = subprocess.run([sys.executable, "-c", _MEASURE_DYNAMICS, what, str(stations),
                          str(steps)], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    figures = json.loads(run.stdout.splitlines()[-1])
    assert figures["peak"] <= figures["guard"] <= 2.5 * figures["peak"], figures
