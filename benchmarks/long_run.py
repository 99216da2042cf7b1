"""Long runs (issue 40): the memory of ``softarm simulate`` when its trajectory is written to
a Zarr store as the run goes (``-o run.zarr`` alone: softarm.io.TrajectoryStore) against the
same run kept whole and written at the end (``-o run.npz``), for runs 1×, 10× and 30× as long.

The arm: 0.3 m of silicone, 10 mm radius, 11 stations, under its weight, damped, Δt = 1 ms
(about 60 µs a step: 1000 steps a second of the arm's time in 60 ms). Each run is a fresh
``softarm simulate`` process; its peak memory is that process's maximum resident set
(``resource.getrusage``, read at its end), beside its wall and CPU time. Figures are printed, never
asserted. Run::

    python benchmarks/long_run.py [--durations 20 200 600] [--kept 20 200]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CASE = """name = "long"
[arm]
length = 0.3
section = {{ kind = "circle", radius = 0.01 }}
material = {{ E = 1.0e6, nu = 0.49, density = 1070.0 }}
[[load]]
kind = "gravity"
[simulate]
duration = {duration}
dt = 0.001
stations = 11
damping = {{ retardation = 0.01 }}
"""


def _run(folder: Path, duration: float, suffix: str) -> tuple[float, float, float, float]:
    """(wall s, CPU s, peak resident MB, output MB) of one ``softarm simulate``."""
    case = folder / f"long{duration:g}.toml"
    case.write_text(CASE.format(duration=float(duration)), encoding="utf-8")
    out = folder / f"long{duration:g}{suffix}"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", _CHILD, str(case), str(out)], check=True,
                          capture_output=True, text=True,
                          env={**os.environ, "SOFTARM_COMPILE_NOTICE": "0"})
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    size = sum(p.stat().st_size for p in out.rglob("*")) if out.is_dir() else \
        out.stat().st_size
    return wall, cpu, float(done.stdout.splitlines()[-1]) / 1024, size / 2**20


#: The child: ``softarm simulate CASE -o OUT``, then its own peak resident set (kB, Linux).
_CHILD = """
import resource, sys
from softarm.cli import main
code = main(["simulate", sys.argv[1], "-o", sys.argv[2]])
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)
sys.exit(code)
"""


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--durations", type=float, nargs="+", default=[20.0, 200.0, 600.0],
                        help="simulated seconds of the streamed runs (Δt = 1 ms)")
    parser.add_argument("--kept", type=float, nargs="*", default=[20.0, 200.0],
                        help="simulated seconds of the runs kept whole (.npz)")
    args = parser.parse_args(argv)
    print("softarm simulate, 11 stations, Δt = 1 ms: peak memory of a streamed run (.zarr "
          "alone) and of a kept one (.npz)")
    print(f"{'run':>24} {'steps':>9} {'wall s':>8} {'CPU s':>8} {'peak MB':>9} "
          f"{'file MB':>9}")
    with tempfile.TemporaryDirectory() as folder:
        # the kernels compiled first, outside the figures (a cold compile takes a minute)
        _run(Path(folder), 0.01, ".zarr")
        rows = [("streamed (.zarr)", d, ".zarr") for d in sorted(args.durations)] + \
            [("kept whole (.npz)", d, ".npz") for d in sorted(args.kept)]
        peaks = {}
        for label, duration, suffix in rows:
            wall, cpu, peak, size = _run(Path(folder), duration, suffix)
            peaks[(suffix, duration)] = peak
            print(f"{label:>24} {round(duration * 1000):>9} {wall:>8.3g} {cpu:>8.3g} "
                  f"{peak:>9.0f} {size:>9.0f}")
    common = sorted(set(args.durations) & set(args.kept))
    for duration in common:
        print(f"at {duration:g} s of the arm's time: kept / streamed peak memory "
              f"{peaks[('.npz', duration)] / peaks[('.zarr', duration)]:.2f}")


if __name__ == "__main__":
    main()
