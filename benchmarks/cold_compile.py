"""The first minute: cold compile, measured as a new user meets it.

Prints, each in fresh processes with an empty numba cache of their own:

1. ``softarm demo`` cold (the whole command: imports, the compile, the solve, the picture), as
   it is (the stability verdict compiled on the second core where one is idle), with the
   verdict on the second core (``SOFTARM_PREFETCH=1``) and in the same process
   (``SOFTARM_PREFETCH=0``), then warm (the cache filled); with ``--venv``, also as a new user
   runs it: the ``softarm`` command of a fresh virtual environment where this tree was just
   installed (``pip install .[plot]``: no byte-code of softarm yet, the wheel's own
   ``softarm`` launcher); with ``--baseline REV``, the demo of another revision of this
   repository side by side (e.g. the last release), and the ratio, and (unless
   ``--no-capabilities``) both trees' cold ``softarm compile --all``, one after the other;
2. ``softarm compile --all``: every capability in the order of ``softarm.warmup.STEPS``, each
   after the ones before it (what a user meets who adds capabilities one by one), and the
   compile time recorded per kernel capability (``softarm._jit``: the figures its notice
   quotes; ``REFERENCE_SECONDS`` in ``softarm/_jit.py`` come from this run on the reference
   machine, a quiet one).

Wall time beside CPU time (this process's children: the second core's work shows as CPU time
above the wall time), and the load average before and after each measurement: on a shared
machine the wall time of a compile follows the load. ``python benchmarks/cold_compile.py
[--venv] [--baseline REV] [--repeat N] [--no-capabilities]``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load() -> str:
    """The 1-minute load average, or '?' where there is none."""
    try:
        return f"{os.getloadavg()[0]:.1f}"
    except OSError:
        return "?"


def _run(args, env, cwd) -> tuple[float, float, subprocess.CompletedProcess]:
    """(wall s, CPU s of the process and its children, the process)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(args, env=env, cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if done.returncode != 0:
        sys.exit(f"{' '.join(map(str, args))} failed:\n{done.stderr}")
    return wall, cpu, done


def _env(cache: str, src: Path | None, **extra) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, **extra)
    env.pop("PYTHONPATH", None)
    if src is not None:
        env["PYTHONPATH"] = str(src)
    return env


def demo(src: Path | None, command=None, **extra) -> tuple[tuple[float, float],
                                                           tuple[float, float]]:
    """(cold (wall, CPU), warm (wall, CPU)) of ``softarm demo`` with the package in ``src``, or
    of ``command`` (a fresh environment's ``softarm``) with ``src`` None."""
    command = [sys.executable, "-m", "softarm"] if command is None else command
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as work:
        cold = _run([*command, "demo"], _env(cache, src, **extra), work)[:2]
        warm = _run([*command, "demo"], _env(cache, src, **extra), work)[:2]
    return cold, warm


def capabilities(src: Path) -> tuple[str, dict, dict, str, tuple[float, float]]:
    """(``softarm compile --all``'s output, the compile record per capability key, (wall,
    CPU) seconds, the closed forms' record, the load average before and after, the whole
    command's (wall, CPU) seconds)."""
    with tempfile.TemporaryDirectory() as cache:
        env = _env(cache, src)
        loads = load()
        wall, cpu, done = _run([sys.executable, "-m", "softarm", "compile", "--all"], env,
                               ROOT)
        loads += f" -> {load()}"
        records = {}  # per capability, (wall, CPU) s: the sums of its compiled versions
        for path in Path(cache).rglob("softarm-compile-seconds.json"):
            records[path.parent.name.split("_")[0]] = {
                key: (sum(wall for wall, _ in versions.values()),
                      sum(cpu for _, cpu in versions.values()))
                for key, versions in json.loads(path.read_text()).items()
                if isinstance(versions, dict)}
    # (the kernels' folder: softarm/kernels, softarm/statics before issue 41)
    kernels = records.get("kernels", records.get("statics", {}))
    return done.stdout, kernels, records.get("analytic", {}), loads, (wall, cpu)


def fresh_venv(into: str) -> list[str]:
    """A new virtual environment in ``into`` with this tree installed (``.[plot]``, no
    editable install): its ``softarm`` command."""
    subprocess.run([sys.executable, "-m", "venv", into], check=True)
    python = str(Path(into) / "bin" / "python")
    subprocess.run([python, "-m", "pip", "install", "-q", f"{ROOT}[plot]"], check=True,
                   cwd=into)
    return [str(Path(into) / "bin" / "softarm")]


def _baseline(rev: str, into: str) -> Path:
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", into, rev],
                   check=True, capture_output=True)
    return Path(into) / "src"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="REV", help="another revision's demo beside")
    parser.add_argument("--venv", action="store_true",
                        help="also the demo of a fresh virtual environment with this tree")
    parser.add_argument("--repeat", type=int, default=1, help="cold demos of each (default 1)")
    parser.add_argument("--no-capabilities", action="store_true",
                        help="the demo only, not softarm compile --all")
    args = parser.parse_args()
    src = ROOT / "src"
    print(f"cold compile, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
          f"{os.cpu_count()} cores, load average {load()}")
    rows = [("this tree", src, None, {}),
            ("this tree, verdict on the other core", src, None, {"SOFTARM_PREFETCH": "1"}),
            ("this tree, verdict in the same process", src, None, {"SOFTARM_PREFETCH": "0"})]
    with tempfile.TemporaryDirectory() as scratch:
        if args.venv:
            rows.insert(0, ("a fresh venv with this tree installed", None,
                            fresh_venv(f"{scratch}/venv"), {}))
        if args.baseline:
            rows.append((f"baseline {args.baseline}", _baseline(args.baseline,
                                                                f"{scratch}/base"), None, {}))
        cold_demo = {}
        for name, where, command, extra in rows:
            for _ in range(args.repeat):
                before = load()
                (wall, cpu), (warm_wall, warm_cpu) = demo(where, command, **extra)
                cold_demo.setdefault(name, []).append(wall)
                print(f"  softarm demo, cold: {wall:6.1f} s wall, {cpu:6.1f} s CPU; warm: "
                      f"{warm_wall:4.1f} s wall, {warm_cpu:4.1f} s CPU  ({name}; load "
                      f"{before} -> {load()})", flush=True)
        if args.baseline:
            ours = min(cold_demo["this tree"])
            theirs = min(cold_demo[f"baseline {args.baseline}"])
            print(f"  cold demo: {theirs / ours:.2f}× faster than {args.baseline}")
            if not args.no_capabilities:  # every capability of both, one after the other
                times = {name: capabilities(where)[4] for name, where in
                         (("this tree", src), (args.baseline, rows[-1][1]))}
                for name, (wall, cpu) in times.items():
                    print(f"  softarm compile --all, cold: {wall:6.1f} s wall, {cpu:6.1f} s "
                          f"CPU ({name})")
                print(f"  compile --all: {times[args.baseline][0] / times['this tree'][0]:.2f}×"
                      f" faster than {args.baseline} (wall)")
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            f"{scratch}/base"], capture_output=True)
    if args.no_capabilities:
        return
    output, statics, analytic, loads, _ = capabilities(src)
    print(f"softarm compile --all (each step after the ones before it; load {loads}):")
    for line in output.splitlines():
        print("  " + line)
    print("compile record per capability (wall s, CPU s; the CPU seconds on a busy machine are "
          "its wall seconds on a quiet one: softarm._jit.REFERENCE_SECONDS):")
    for key, (wall, cpu) in sorted({**statics, **analytic}.items(), key=lambda kv: -kv[1][1]):
        print(f"  {key:32s} {wall:6.1f} {cpu:6.1f}")


if __name__ == "__main__":
    main()
