"""Dynamics: the cost of a time step and of a trajectory, beside the alternatives.

1. One step of Till, Aloi & Rucker's steel cantilever on their example's grid (40 stations,
   Δt = 2 ms, α = -0.2): ``Simulator.step`` (the real-time call) and a trajectory's cost per
   step, against their C++ at -O3 on this machine (tests/data/till_rucker/README.md, built
   and timed by tests/reference_scripts/till_rucker_dynamics.py; their numbers are read from
   that README, not re-measured here) and against the targets of issue 40 (a cantilever step
   ≤ 60 µs, faster than their C++; a 3-tendon robot step ≤ 200 µs at 41 stations).
2. One step of benchmarks/actuation.py's 3-tendon robot at tol 1e-6 and Δt = 1 ms, new
   tensions every step, at 41 and 101 stations; and its accuracy in s per cost (21 and 41
   stations against 161, :func:`robot_accuracy`).
3. The heavy soft arm swinging over one period (1.5 s) against the method-of-lines
   reference (tests/_mol_rod.py, its own error 2e-5 L): softarm's settings down to 1e-4 L
   (fourth order in s since issue 40, so Δt's error dominates from 26 stations on), beside
   PyElastica's settings (benchmarks/dynamics_pyelastica.py; none of them reaches 1e-3 L).
4. Throughput: a batch of trajectories of 1 s at Δt = 1 ms, all cases in each call (threads
   over the cores), run in chunks of steps of which only the tips are kept (1000
   trajectories whole would take 30 GB), and the projection to a Dask cluster of W workers.
5. Building a Simulator (a tendon, gravity, an obstacle) against its stations, 10³ to
   4·10⁵: linear (it was quadratic, issue 42: 17 s at 10⁵); 10⁶ stations need more memory
   for a step than half of a 24 GB machine (33 kB a station) and are refused at once.

CPU time (``process_time``) beside wall time (``perf_counter``), per step or per run; best of
``--repeats`` after a warm-up (the compile is not timed). Run::

    python benchmarks/dynamics.py [--quick] [--pyelastica]

Times are printed, never asserted. ``benchmarks/run.py`` puts the tables in
docs/performance.md ("Dynamics", :func:`markdown`).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import actuation  # noqa: E402 (benchmarks/actuation.py: the 3-tendon robot)
from _mol_rod import load_reference  # noqa: E402

import softarm  # noqa: E402

TARGET_CANTILEVER = 60e-6  # s a step (issue 40)
TARGET_ROBOT = 200e-6


def _till_rucker():
    """Their cantilever (params.json) as a softarm arm, its loads and initial equilibrium."""
    params = json.loads((ROOT / "tests/data/till_rucker/params.json").read_text())["cantilever"]
    section = params["section"]
    EA, GA, _ = section["Kse_softarm_order_EA_GA_GA"]
    GJ, EI, _ = section["Kbt_softarm_order_GJ_EI_EI"]
    arm = softarm.Arm.from_stiffness(params["length"], EA, GA, GA, GJ, EI, EI,
                                     mass_per_length=section["rhoA"],
                                     inertia_per_length=section["rhoJ_softarm_order"])
    gravity = softarm.Gravity(params["gravity_softarm_frame"])
    weight = softarm.TipLoad(params["initial_tip_force_softarm_frame"])
    start = softarm.solve(arm, [gravity, weight])
    return arm, [gravity], start, params["time"]["dt"], params["time"]["alpha"]


def their_costs() -> dict:
    """Till & Rucker's measured cost per step (µs, CPU range) from the reference README."""
    text = (ROOT / "tests/data/till_rucker/README.md").read_text()
    found = {}
    for name, key in (("cantilever", "cantilever, N = 40"), ("tendon", "tendon robot, N = 200")):
        line = next(ln for ln in text.splitlines() if ln.startswith(f"| {key}"))
        cpu = line.split("|")[2].strip()
        found[name] = cpu
    return found


def _per_step(run, steps: int, repeats: int) -> tuple[float, float]:
    """(best wall, best CPU) seconds per step of ``run()`` (which takes ``steps`` steps)."""
    walls, cpus = [], []
    for _ in range(repeats):
        w0, c0 = time.perf_counter(), time.process_time()
        run()
        walls.append((time.perf_counter() - w0) / steps)
        cpus.append((time.process_time() - c0) / steps)
    return min(walls), min(cpus)


def step_costs(repeats: int, steps: int) -> list[tuple]:
    """Rows (what, stations, wall per step, CPU per step, target)."""
    rows = []
    arm, loads, start, dt, alpha = _till_rucker()
    for stations in (40, 101):
        sim = softarm.Simulator(arm, loads=loads, dt=dt, stations=stations, initial=start,
                                alpha=alpha)
        sim.step()

        def stepping(sim=sim):
            for _ in range(steps):
                sim.step()

        rows.append(("cantilever (Till & Rucker), Simulator.step", stations,
                     *_per_step(stepping, steps, repeats), TARGET_CANTILEVER))
        rows.append(("cantilever (Till & Rucker), a trajectory", stations,
                     *_per_step(lambda sim=sim: sim.run(steps), steps, repeats),
                     TARGET_CANTILEVER))
    robot = actuation.robot()
    tendons = actuation.loads(np.zeros(3))[1:]
    for stations in (41, 101):
        sim = softarm.Simulator(robot, tendons, [softarm.Gravity(actuation.GRAVITY)], dt=1e-3,
                                stations=stations, tol=1e-6,
                                damping=softarm.Damping(retardation=0.01))
        schedule = [actuation.TENSIONS * min(1.0, k / 50) for k in range(steps)]
        sim.step(schedule[0])

        def pulling(sim=sim, schedule=schedule):
            for q in schedule:
                sim.step(q)

        rows.append(("3-tendon robot, Simulator.step, new tensions", stations,
                     *_per_step(pulling, steps, repeats), TARGET_ROBOT))
    return rows


def swing(settings, repeats: int) -> list[tuple]:
    """Rows (stations, dt, max tip error / L, wall, CPU) of the swinging arm over 1.5 s."""
    arm = softarm.Arm(0.5, softarm.Circle(0.02),
                      softarm.Material(1e6, poisson_ratio=0.5, density=1100.0))
    times, reference = load_reference("undamped")
    rows = []
    for stations, dt in settings:
        softarm.simulate(arm, [softarm.Gravity()], duration=10 * dt, dt=dt, stations=stations)
        best = None
        for _ in range(repeats):
            w0, c0 = time.perf_counter(), time.process_time()
            path = softarm.simulate(arm, [softarm.Gravity()], duration=1.5, dt=dt,
                                    stations=stations)
            wall, cpu = time.perf_counter() - w0, time.process_time() - c0
            best = (wall, cpu) if best is None or cpu < best[1] else best
        tip = path.tip_position[np.round(times / dt).astype(int)][:, [0, 2]]
        error = float(np.max(np.linalg.norm(tip - reference, axis=1)) / 0.5)
        rows.append((stations, dt, error, *best))
    return rows


def robot_accuracy(counts=(21, 41), reference: int = 161, steps: int = 300) -> list[tuple]:
    """Rows (stations, CPU µs a step, tip error m): the 3-tendon robot pulled over 0.3 s
    (tensions ramped in 50 steps, Δt = 1 ms, tol 1e-8), its tip at the end against the same
    run on ``reference`` stations (the time step's error is the same on every grid: the
    difference is the error in s)."""
    robot = actuation.robot()
    tendons = actuation.loads(np.zeros(3))[1:]
    schedule = [actuation.TENSIONS * min(1.0, k / 50) for k in range(steps + 1)]
    tips, rows = {}, []
    for stations in (*counts, reference):
        sim = softarm.Simulator(robot, tendons, [softarm.Gravity(actuation.GRAVITY)], dt=1e-3,
                                stations=stations, tol=1e-8,
                                damping=softarm.Damping(retardation=0.01))
        sim.step(schedule[0])
        c0 = time.process_time()
        for q in schedule[1:]:
            state = sim.step(q)
        cpu = (time.process_time() - c0) / steps
        tips[stations] = state.positions[-1]
        rows.append((stations, cpu))
    return [(n, cpu, float(np.abs(tips[n] - tips[reference]).max())) for n, cpu in rows
            if n != reference]


def pyelastica_rows() -> list[tuple]:
    """PyElastica's settings on the same swing (benchmarks/dynamics_pyelastica.py)."""
    import dynamics_pyelastica as pe

    pe.warmup()
    rows = []
    for clamp in ("node", "centred"):
        for n in (20, 40, 80):
            r = pe.run(n, clamp)
            rows.append((f"{clamp} clamp, {n} elements", r.dt, r.max_tip_error, r.wall_s,
                         r.cpu_s))
    return rows


#: Steps per run of the throughput batch: its trajectory is 720 B a case, step and station
#: at most (Simulator._check_run), 1.5 GB for 1000 cases of 41 stations
CHUNK_STEPS = 50


def throughput(cases: int, duration: float, stations: int) -> dict:
    """A batch of ``cases`` trajectories (different gravity directions), every case in each
    call, in runs of :data:`CHUNK_STEPS` steps of which only the tip positions are kept."""
    arm = softarm.Arm(0.5, softarm.Circle(0.02),
                      softarm.Material(1e6, poisson_ratio=0.5, density=1100.0))
    angle = np.linspace(0.0, np.pi / 2, cases)
    g = 9.81 * np.stack([np.zeros(cases), -np.sin(angle), -np.cos(angle)], axis=-1)
    softarm.simulate(arm, [softarm.Gravity(g[:2])], duration=2e-3, dt=1e-3, stations=stations)
    steps = round(duration / 1e-3)
    tips = np.empty((cases, steps + 1, 3))
    w0, c0 = time.perf_counter(), time.process_time()
    sim = softarm.Simulator(arm, loads=[softarm.Gravity(g)], dt=1e-3, stations=stations)
    done = 0
    while done < steps:
        part = sim.run(min(CHUNK_STEPS, steps - done))
        tips[:, done:done + part.times.size] = part.tip_position
        done += part.times.size - 1
        del part
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    return {"cases": cases, "steps": steps, "stations": stations, "wall_s": wall, "cpu_s": cpu,
            "threads": softarm._threads.available_threads(),
            "cpu_per_trajectory_s": cpu / cases}


def construction(counts) -> list[tuple]:
    """Rows (stations, wall s, CPU s) of building a Simulator and reading its first state:
    the 3-tendon robot's arm with one of its tendons, gravity and a table under it."""
    robot = actuation.robot()
    tendon = actuation.loads(np.full(3, 1.0))[1]
    table = softarm.Contact(softarm.Plane((0.0, 0.0, -0.1), (0.0, 0.0, 1.0)))

    def build(stations):
        sim = softarm.Simulator(robot, [tendon], [softarm.Gravity(), table], dt=1e-3,
                                stations=stations)
        return sim.state

    build(21)  # (compiled)
    rows = []
    for stations in counts:
        w0, c0 = time.perf_counter(), time.process_time()
        build(stations)
        rows.append((stations, time.perf_counter() - w0, time.process_time() - c0))
    return rows


def markdown(steps, swings, peers, batch, theirs, builds=(), accuracy=()) -> str:
    lines = ["## Dynamics", "",
             "`python benchmarks/dynamics.py`: best of several runs after a warm-up, CPU time "
             "beside wall time. Till & Rucker's C++ (-O3, this machine, "
             "tests/data/till_rucker/README.md): cantilever (N = 40, Δt = 2 ms) "
             f"{theirs['cantilever']} CPU a step; tendon robot (N = 200, Δt = 50 ms) "
             f"{theirs['tendon']}.", "",
             "| one time step | stations | wall | CPU | issue 40 target |",
             "|---|---|---|---|---|"]
    for what, stations, wall, cpu, target in steps:
        lines.append(f"| {what} | {stations} | {1e6 * wall:.0f} µs | {1e6 * cpu:.0f} µs | "
                     f"≤ {1e6 * target:.0f} µs: {'met' if wall <= target else 'NOT met'} |")
    if accuracy:
        lines += ["", "The 3-tendon robot pulled over 0.3 s (tol 1e-8): its tip against a "
                  "161-station run (the error in s) and the cost of a step:", "",
                  "| stations | CPU a step | tip error |", "|---|---|---|"]
        lines += [f"| {n} | {1e6 * cpu:.0f} µs | {error:.1e} m |" for n, cpu, error in accuracy]
    lines += ["", "The heavy soft arm swinging for 1.5 s (one period), tip error against the "
              "method-of-lines reference:", "",
              "| tool | setting | max tip error | wall | CPU |", "|---|---|---|---|---|"]
    for stations, dt, error, wall, cpu in swings:
        lines.append(f"| softarm | {stations} stations, Δt = {1e3 * dt:g} ms | {error:.1e} L | "
                     f"{wall:.2f} s | {cpu:.2f} s |")
    for setting, dt, error, wall, cpu in peers:
        lines.append(f"| PyElastica | {setting}, Δt = {dt:.1e} s | {error:.1e} L | "
                     f"{wall:.2f} s | {cpu:.2f} s |")
    b = batch
    whole = 720 * b["cases"] * b["steps"] * b["stations"] / 1e9  # GB (Simulator._check_run)
    lines += ["", f"Throughput: {b['cases']} trajectories of {b['steps']} steps "
              f"({b['stations']} stations), every case in each call: {b['wall_s']:.1f} s wall, "
              f"{b['cpu_s']:.1f} s CPU on {b['threads']} threads "
              f"({b['cpu_per_trajectory_s']:.3f} s CPU a trajectory). A Dask cluster of W "
              f"single-threaded workers would take about {b['cpu_per_trajectory_s']:.3f} × "
              f"cases / W seconds (10⁶ trajectories on 100 workers: "
              f"{b['cpu_per_trajectory_s'] * 1e6 / 100 / 3600:.1f} h), the scheduler's "
              f"overhead aside (docs/scaling.md). The batch runs {CHUNK_STEPS} steps a call, "
              f"keeping the tips only (the whole trajectories would hold up to {whole:.3g} GB)."]
    if builds:
        lines += ["", "Building a Simulator (a tendon, gravity, a plane) and its first state:",
                  "", "| stations | wall | CPU |", "|---|---|---|"]
        lines += [f"| {n:.0e} | {wall:.3f} s | {cpu:.3f} s |" for n, wall, cpu in builds]
    return "\n".join(lines) + "\n"


def measure(quick: bool, with_pyelastica: bool = False) -> str:
    repeats = 1 if quick else 3
    steps = step_costs(repeats, 50 if quick else 500)
    for row in steps:
        print(f"  step: {row[0]} ({row[1]} stations): {1e6 * row[2]:.0f} µs wall, "
              f"{1e6 * row[3]:.0f} µs CPU", flush=True)
    accuracy = robot_accuracy()
    for stations, cpu, error in accuracy:
        print(f"  robot accuracy: {stations} stations: {1e6 * cpu:.0f} µs CPU a step, tip "
              f"{error:.1e} m from 161 stations", flush=True)
    settings = [(26, 1e-3)] if quick else [(26, 2e-3), (26, 1e-3), (26, 5e-4), (26, 2.5e-4),
                                           (41, 2.5e-4), (101, 1e-3)]
    swings = swing(settings, repeats)
    for row in swings:
        print(f"  swing: {row[0]} stations, dt {row[1]:g}: error {row[2]:.1e} L, "
              f"{row[3]:.2f} s wall, {row[4]:.2f} s CPU", flush=True)
    peers = pyelastica_rows() if with_pyelastica else []
    batch = throughput(*((20, 0.1, 41) if quick else (1000, 1.0, 41)))
    print(f"  batch: {json.dumps(batch)}", flush=True)
    builds = construction((1000, 10_000, 100_000) if quick else
                          (1000, 10_000, 100_000, 400_000))
    for stations, wall, cpu in builds:
        print(f"  build: {stations} stations: {wall:.3f} s wall, {cpu:.3f} s CPU", flush=True)
    return markdown(steps, swings, peers, batch, their_costs(), builds, accuracy)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="few steps, one repeat")
    parser.add_argument("--pyelastica", action="store_true",
                        help="run PyElastica beside (its first run compiles for ~90 s)")
    args = parser.parse_args(argv)
    text = measure(args.quick, args.pyelastica)
    print()
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

