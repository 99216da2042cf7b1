"""Compile softarm's kernels ahead of time (``softarm compile [--all]``).

softarm compiles its numerical kernels with numba the first time each capability is used on a
machine (a first passive solve, Jacobians, actuated arms, inverse statics, ...) and caches the
machine code. A container build, a cluster image or a course's setup pays that once, ahead of
time, with :func:`compile_kernels` or ``softarm compile``: each step below runs a small
problem that uses its capability (a cached capability costs a fraction of a second).

Example
-------
>>> from softarm.warmup import STEPS
>>> [step.name for step in STEPS if step.first]
['solve', 'closed forms']
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from . import analytic
from .contact import Contact, Plane
from .control import ForwardSolver, inverse
from .dispatch import solve
from .dynamics import simulate
from .loads import Chamber, DistributedForce, Gravity, Tendon, TipLoad
from .model import Arm, Circle, Material
from .routing import Straight
from .stability import critical_load
from .statics import Solver

__all__ = ["STEPS", "Step", "compile_kernels"]


def _arm() -> Arm:
    return Arm(0.2, Circle(0.01), Material(youngs_modulus=1.5e6, poisson_ratio=0.49,
                                           density=1070.0))


def _tendons() -> list:
    return [Tendon(0.2, Straight(0.0, 0.006)), Tendon(0.1, Straight(0.006, 0.0))]


def _passive():
    solve(_arm(), [Gravity(), TipLoad(force=[0.0, 0.01, 0.0])], method="numeric")


def _closed_forms():
    arm = _arm()
    analytic.tip_moment(arm, moment=[0.0, 1e-3, 0.0])
    solve(arm, [TipLoad(force=[0.0, 0.0, -0.05])])  # the elastica


def _jacobians():
    solve(_arm(), [Gravity(), TipLoad(force=[0.0, 0.01, 0.0])], method="numeric",
          jacobians=True)


def _chained():
    solver = Solver(_arm())
    for f in (0.005, 0.01, 0.015):  # the last with Jacobians
        solver.solve([Gravity(), TipLoad(force=[0.0, f, 0.0])], jacobians=f > 0.012)


def _actuated():
    solve(_arm(), [Gravity(), *_tendons(), Chamber(1e3, area=1e-5, routing=Straight(0.0, -0.005))],
          method="numeric")


def _actuated_jacobians():
    solve(_arm(), [Gravity(), *_tendons()], method="numeric", jacobians=True)


def _actuated_chained():
    solver = Solver(_arm())
    for tension in (0.1, 0.2):
        solver.solve([Gravity(), Tendon(tension, Straight(0.0, 0.006))])


def _control():
    model = ForwardSolver(_arm(), _tendons(), [Gravity()])
    model.solve([0.2, 0.1])
    model.solve([0.25, 0.1])


def _inverse():
    arm, tendons = _arm(), _tendons()
    target = solve(arm, [Gravity(), *tendons]).tip_position
    inverse(arm, tendons, target, loads=[Gravity()])


def _displacement():
    solve(_arm(), [Gravity(), Tendon(routing=Straight(0.0, 0.006), displacement=-1e-4)])


def _critical():
    arm = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0)
    critical_load(arm, [TipLoad(force=[-1.0, 0.0, 0.0]), DistributedForce([0.0, 0.0, 0.0])],
                  max_factor=4.0)


def _critical_actuated():
    critical_load(_arm(), [Gravity(), Tendon(0.1, Straight(0.0, 0.006))], max_factor=2.0)


def _each_verdict_and_jacobians(arm, loads) -> None:
    """Multiple shooting compiles one version per (verdict, Jacobians) pair: all four."""
    for stability in (True, False):
        for jacobians in (False, True):
            Solver(arm, stability=stability).solve(loads, jacobians=jacobians)


def _stiff():
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    _each_verdict_and_jacobians(arm, [TipLoad(force=[1e3, 0.0, 1.0]),
                                      DistributedForce([0.0, 0.0, 0.0])])
    # without the distributed load, a closed form (the elastica), whose verdict under this
    # tension sweeps the closed form's own states (softarm.statics.stability)
    solve(arm, [TipLoad(force=[1e3, 0.0, 1.0])])


def _contact():
    # a tip pressed lightly on a plane, solved both ways: with the penalty (its contact
    # distance given: the law of contact zones, an arm lying on a table; the same compiled
    # versions as any touching arm, and the shortest solve of those tried, about 1 s each
    # here, where a tip pushed 10 N into the plane took 6-7 s and one that grazes it 15 s),
    # and held exactly at the tip (statics/tip_contact.py: plain solves and their verdict)
    arm = Arm.from_stiffness(1.0, EA=1e4, GAy=1e4, GAz=1e4, GJ=1.0, EIy=1.0, EIz=1.0)
    plane = Plane((0.0, 0.0, -0.03), (0.0, 0.0, 1.0))
    for contact in (Contact(plane, radius=0.01, distance=1e-5), Contact(plane, radius=0.01)):
        _each_verdict_and_jacobians(arm, [TipLoad(force=[0.0, 0.0, -0.1]), contact])


def _moving() -> Arm:
    return Arm(0.2, Circle(0.01), Material(1e6, poisson_ratio=0.5, density=1100.0))


def _tendon(tension: float = 0.1) -> Tendon:
    return Tendon(tension=tension, routing=Straight(0.0, 0.005))


def _steps(*args, **options):
    """Three implicit steps on five stations."""
    simulate(*args, duration=3e-3, dt=1e-3, stations=5, **options)


def _dynamics():
    arm = Arm.from_stiffness(1.0, EA=1e3, GAy=1e3, GAz=1e3, GJ=1.0, EIy=1.0, EIz=1.0,
                             mass_per_length=1.0, inertia_per_length=(1e-4, 5e-5, 5e-5))
    _steps(arm, [Gravity()])
    # from an equilibrium: its loads balanced on the simulation's stations first (the
    # kernel's other argument types, numba's other compiled version)
    _steps(_moving(), [Gravity()],
           initial=solve(_moving(), [Gravity(), TipLoad(force=[0.0, 0.0, -0.01])], s=5))


def _dynamics_actuated():
    _steps(_moving(), actuators=[_tendon()])
    _steps(_moving(), [Gravity()], actuators=[_tendon()],
           initial=solve(_moving(), [Gravity(), _tendon(0.05)], s=5))
    # from an equilibrium without a tendon (a chamber: the settle step has no lengths to
    # integrate, another compiled version)
    chamber = Chamber(1e3, area=1e-5, routing=Straight(0.0, -0.005))
    _steps(_moving(), [Gravity()], actuators=[chamber],
           initial=solve(_moving(), [Gravity(), chamber], s=5))


def _dynamics_contact():
    table = Contact(Plane((0.0, 0.0, -0.0102), (0.0, 0.0, 1.0)))  # touched from the start
    _steps(_moving(), [Gravity(), table])
    _steps(_moving(), [Gravity(), table], actuators=[_tendon()])


@dataclass(frozen=True)
class Step:
    """One capability to compile: ``name`` (its keys in the compile record, see
    ``softarm._jit.REFERENCE_SECONDS``), what it is for, the problem that uses it, and whether
    a first solve needs it (``softarm compile`` without ``--all``)."""

    name: str
    text: str
    keys: tuple[str, ...]
    run: Callable[[], None]
    first: bool = False


STEPS: tuple[Step, ...] = (
    Step("solve", "the solver and its stability verdict for passive arms",
         ("solve", "verdict"), _passive, first=True),
    Step("closed forms", "the closed forms", ("closed forms",), _closed_forms, first=True),
    Step("jacobians", "Jacobians (tip and station compliance)", ("solve+jacobians",),
         _jacobians),
    Step("chained", "quasi-static solves (Solver.solve, softarm app)",
         ("solve+chained", "solve+chained+jacobians"), _chained),
    Step("actuated", "actuated and magnetic arms (tendons, chambers, magnets)",
         ("actuated", "verdict+actuated"), _actuated),
    Step("actuated jacobians", "actuation Jacobians", ("actuated+jacobians",),
         _actuated_jacobians),
    Step("actuated chained", "quasi-static solves of actuated arms",
         ("actuated+chained",), _actuated_chained),
    Step("control", "the control loop's forward call (ForwardSolver)",
         ("actuated+chained+jacobians",), _control),
    Step("inverse", "inverse statics", ("inverse",), _inverse),
    Step("displacement", "displacement-controlled tendons", ("bounded",), _displacement),
    Step("critical", "critical loads and continuation", ("shoot", "branch"), _critical),
    Step("critical actuated", "critical loads and continuation of actuated arms",
         ("shoot+actuated", "branch+actuated"), _critical_actuated),
    Step("stiff", "multiple shooting (arms in strong tension: kL >= 15), with and without "
         "the verdict and Jacobians, and the verdict of a closed form in strong tension",
         ("stiff+verdict", "stiff", "stiff+jacobians+verdict", "stiff+jacobians",
          "verdict+given"), _stiff),
    Step("contact", "contact with obstacles (softarm.Contact: multiple shooting, and a free "
         "tip held exactly), with and without the verdict and Jacobians",
         ("stiff+actuated+verdict", "stiff+actuated", "stiff+actuated+jacobians+verdict",
          "stiff+actuated+jacobians"), _contact),
    Step("dynamics", "dynamics of passive arms (softarm.simulate, Simulator), from rest and "
         "from an equilibrium", ("dynamics",), _dynamics),
    Step("actuated dynamics", "dynamics of actuated and magnetic arms, from rest and from an "
         "equilibrium", ("dynamics+actuated",), _dynamics_actuated),
    Step("contact dynamics", "dynamics with contact, passive and actuated",
         ("dynamics", "dynamics+actuated"), _dynamics_contact),
)


def compile_kernels(all: bool = False, progress: Callable | None = None,
                    jobs: int = 1) -> list[tuple]:
    """Compile (or load from the cache) every kernel a first solve needs, or with ``all``
    every capability of :data:`STEPS`. ``progress(step, index, count, elapsed, estimate)``
    is called about five times a second while a step runs and once when it ends (``elapsed``
    None at the start). Returns [(step, seconds, compiled keys)] (compiled keys: what missed
    the cache, with its time: ``[(key, text, seconds)]``).

    ``jobs`` > 1: the steps are shared among this process and ``jobs - 1`` helper processes
    (each a numba compile on one core), balanced by their reference times; a helper's steps
    are reported when it ends. Design note: two processes that write the same function's
    cache index at the same moment can lose one entry (numba reads, updates and replaces the
    index file), so this process then runs the helpers' steps once more, from the cache:
    whatever was lost compiles again, and ``softarm compile --all`` leaves nothing to
    compile."""
    if not isinstance(jobs, int) or isinstance(jobs, bool) or jobs < 1:
        raise ValueError(f"jobs must be a positive integer, got {jobs!r}")
    from . import _jit  # the compiled modules' helper: imports numba (an optional heavy import)

    steps = [step for step in STEPS if all or step.first]
    groups = _shares(steps, min(jobs, len(steps)))
    helpers = []
    done = []
    previous, _jit.notices = _jit.notices, progress is None and _jit.notices
    try:
        helpers += [_start_helper(group) for group in groups[1:]]
        for index, step in enumerate(steps):
            if step not in groups[0]:
                continue
            estimate = sum(_jit.compile_seconds(key, _dispatcher(key))[0] or 0.0
                           for key in step.keys)
            with _Ticker(progress, (step, index, len(steps)), estimate):
                seconds, compiled = _run_step(step)
            if progress is not None:
                progress(step, index, len(steps), seconds, -1.0)
            done.append((step, seconds, compiled))
        for helper, group in zip(helpers, groups[1:], strict=True):
            for name, seconds, compiled in _finish_helper(helper):
                step = next(step for step in group if step.name == name)
                if progress is not None:
                    progress(step, steps.index(step), len(steps), seconds, -1.0)
                done.append((step, seconds, [tuple(entry) for entry in compiled]))
            for step in group:  # (from the cache: see the design note)
                _run_step(step)
    finally:
        _jit.notices = previous
        for helper in helpers:
            if helper.poll() is None:
                helper.kill()
                helper.wait()
    done.sort(key=lambda entry: steps.index(entry[0]))
    return done


def _run_step(step: Step) -> tuple[float, list]:
    """Run one step: (its seconds, what it compiled: ``[(key, text, seconds)]``)."""
    from . import _jit

    before, start = len(_jit.COMPILED), time.perf_counter()
    with np.errstate(all="ignore"):
        step.run()
    return time.perf_counter() - start, list(_jit.COMPILED[before:])


def _shares(steps: list[Step], jobs: int) -> list[list[Step]]:
    """``steps`` in ``jobs`` groups of about equal reference compile time (longest first, each
    to the group with the least so far); the first group holds the first step."""
    from ._jit import REFERENCE_SECONDS

    def cost(step: Step) -> float:
        return sum(REFERENCE_SECONDS.get(key, 5.0) for key in step.keys)

    groups: list[list[Step]] = [[] for _ in range(jobs)]
    totals = [0.0] * jobs
    for step in sorted(steps, key=cost, reverse=True):
        share = 0 if step is steps[0] else int(np.argmin(totals))
        groups[share].append(step)
        totals[share] += cost(step)
    return [sorted(group, key=steps.index) for group in groups]


#: a helper process of compile_kernels: runs the steps named on its command line, prints
#: [[name, seconds, compiled keys], ...] as JSON on its last line
_HELPER = """
import json, sys
from softarm.warmup import STEPS, _run_step
steps = {step.name: step for step in STEPS}
print(json.dumps([[name, *_run_step(steps[name])] for name in sys.argv[1:]]))
"""


def _start_helper(group: list[Step]):
    import os
    import subprocess
    import sys

    return subprocess.Popen([sys.executable, "-c", _HELPER, *(step.name for step in group)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, SOFTARM_COMPILE_NOTICE="0"))


def _finish_helper(helper) -> list:
    import json

    out, err = helper.communicate()
    if helper.returncode != 0:
        last = (err.strip().splitlines() or ["(no message)"])[-1]
        raise RuntimeError(f"a helper process of softarm compile failed (exit "
                           f"{helper.returncode}): {last}")
    return json.loads(out.strip().splitlines()[-1])


class _Ticker:
    """Calls ``progress(*what, elapsed, estimate)`` at the start and then five times a second
    from a thread while the body runs (numba releases the GIL often enough for it)."""

    def __init__(self, progress, what, estimate):
        self.progress, self.what, self.estimate = progress, what, estimate
        self.stop = threading.Event()
        self.thread = None

    def __enter__(self):
        if self.progress is not None:
            self.progress(*self.what, None, self.estimate)
            self.start = time.perf_counter()
            self.thread = threading.Thread(target=self._run, daemon=True)
            self.thread.start()
        return self

    def _run(self):
        while not self.stop.wait(0.2):
            self.progress(*self.what, time.perf_counter() - self.start, self.estimate)

    def __exit__(self, *exc):
        self.stop.set()
        if self.thread is not None:
            self.thread.join()


def _dispatcher(key: str):
    """The compiled entry point whose cache folder holds ``key``'s record."""
    if key == "closed forms":
        from .analytic._elastica_math import compiled

        return compiled().solve
    from . import kernels

    return kernels.solve_cases
