"""Issue 42 ("Trust, round 4"): what the route's force count, the ball's gap and the contact
critical load cost.

- the route's estimate per solve (``statics/_stiff.tension_kl``, from the loads' largest
  force, each load measured through its ``apply``), against the estimate it replaced (the
  kernel's force channels read directly; copied below), on one case as a control loop
  calls it: a tip load, and a 3-tendon robot under gravity;
- a field gradient pulling a magnetised arm (g m L³/EI = 1000, kL = 32), which the route
  now sends to multiple shooting (single shooting failed there with a false fold);
- the soft arm lying on a table, on a Plane and on a Sphere of radius 1e6 m;
- ``critical_load`` with the table, its weight varied up to 10 g (stable: None).

Wall time (``perf_counter``) and CPU time (``process_time``), best of ``--repeats`` after a
warm-up call. Times are printed, never asserted. Run::

    python benchmarks/trust_routes.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import math
import time
import warnings

import numpy as np
from contact import _timed  # (benchmarks/contact.py: best wall and CPU after a warm-up)

import softarm
from softarm.routing import Straight
from softarm.statics._stiff import tension_kl
from softarm.statics.solver import Solver


def _channel_kl(pieces, tip, lengths, length, soft):
    """The estimate before issue 42 (one case): the tip force against the distributed and
    point forces, read from the kernel's channels; blind to the magnets' pull."""
    along = points = 0.0
    for row, piece_length in zip(pieces[0, :, :21].tolist(), lengths.tolist(), strict=True):
        along += sum(abs(v) for v in row[0:6]) * piece_length
        points += sum(abs(v) for v in row[12:15]) + sum(abs(v) for v in row[18:21])
    t = tip[0].tolist()
    at_tip = sum(abs(v) for v in t[0:3]) + sum(abs(v) for v in t[6:9])
    return np.array([length * math.sqrt(max(at_tip, along + points) * soft)])


def route(repeats):
    arm = softarm.Arm.from_stiffness(1.0, EA=1e8, GAy=1e8, GAz=1e8, GJ=1.0, EIy=1.0, EIz=1.0,
                                     mass_per_length=0.1)
    cases = {"tip load": (softarm.TipLoad(force=[0.0, 0.0, 5.0]),),
             "3 tendons + gravity": (*(softarm.Tendon(1.0, Straight(*r)) for r in
                                       ((0.0, 0.01), (0.01, 0.0), (0.0, -0.01))),
                                     softarm.Gravity())}
    rows = []
    n = 20000
    for name, loads in cases.items():
        solver = Solver(arm)
        _, _, _, pieces, channels = solver._prepare(loads)
        soft = solver._data.soft
        now = (tension_kl, (arm, loads, (), soft))
        before = (_channel_kl, (channels.piece, channels.tip_loads, pieces[1], 1.0, soft))
        for label, (function, arguments) in (("now, from the loads", now),
                                             ("before, from the channels", before)):
            best_wall = best_cpu = math.inf
            for _ in range(max(1, repeats)):
                wall, cpu = time.perf_counter(), time.process_time()
                for _ in range(n):
                    function(*arguments)
                best_wall = min(best_wall, (time.perf_counter() - wall) / n)
                best_cpu = min(best_cpu, (time.process_time() - cpu) / n)
            rows.append((f"route estimate, {name}: {label}", best_wall, best_cpu, ""))
    return rows


def magnetic(repeats):
    g = 1000.0
    arm = softarm.Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0,
                                     magnetization=(1.0, 0.0, 0.0))
    field = softarm.MagneticField([0.0, 0.0, 2.0], gradient=np.diag([g, -g / 2, -g / 2]))
    eq, wall, cpu = _timed(lambda: softarm.solve(arm, field, method="numeric", s=3), repeats)
    return [("magnetised arm in a gradient, g m L³/EI = 1000 (kL = 32)", wall, cpu,
             f"tip ({eq.tip_position[0]:.8f}, {eq.tip_position[2]:.8f}) m")]


def floors(repeats):
    arm = softarm.Arm(0.5, softarm.Circle(0.01),
                      softarm.Material(youngs_modulus=1e6, poisson_ratio=0.5, density=1000.0))
    big = 1e6
    rows = []
    for name, floor in (("Plane", softarm.Plane((0.0, 0.0, -0.03), (0.0, 0.0, 1.0))),
                        ("Sphere of radius 1e6 m",
                         softarm.Sphere((0.0, 0.0, -0.03 - big), big))):
        loads = [softarm.Gravity(), softarm.Contact(floor)]
        eq, wall, cpu = _timed(lambda loads=loads: softarm.solve(arm, loads), repeats)
        rows.append((f"arm on the table, a {name} (tol 1e-8 L)", wall, cpu,
                     f"tip z {eq.tip_position[2]:.9f} m, δ = {eq.loads[-1].distance:g} m"))
    gravity = softarm.Gravity()
    table = softarm.Contact(softarm.Plane((0.0, 0.0, -0.03), (0.0, 0.0, 1.0)))
    point, wall, cpu = _timed(lambda: softarm.critical_load(arm, [gravity, table],
                                                            vary=[gravity], max_factor=10.0),
                              repeats)
    rows.append(("critical_load, the table's weight up to 10 g", wall, cpu,
                 f"returns {point}"))
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rows = [*route(args.repeats), *magnetic(args.repeats), *floors(args.repeats)]
    print(f"`python benchmarks/trust_routes.py --repeats {args.repeats}` "
          f"({time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}): best of {args.repeats}")
    print("\n| case | wall | CPU | answer |\n|---|---|---|---|")
    for name, wall, cpu, answer in rows:
        unit, scale = (("µs", 1e6) if wall < 1e-3 else ("ms", 1e3) if wall < 1.0
                       else ("s", 1.0))
        print(f"| {name} | {wall * scale:.3g} {unit} | {cpu * scale:.3g} {unit} | {answer} |")


if __name__ == "__main__":
    main()
