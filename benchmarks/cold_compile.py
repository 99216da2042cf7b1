"""The first minute: cold compile, measured as a new user meets it.

Prints, each in fresh processes with an empty numba cache of their own:

1. ``softarm demo`` cold (the whole command: imports, the compile, the solve, the picture), with
   the stability verdict compiled on the second core (the default) and in the same process
   (``SOFTARM_PREFETCH=0``), then warm (the cache filled); with ``--baseline REV``, the demo
   of another revision of this repository side by side (e.g. the last release), and the ratio;
2. ``softarm compile --all``: every capability in the order of ``softarm.warmup.STEPS``, each
   after the ones before it (what a user meets who adds capabilities one by one), and the
   compile time recorded per kernel capability (``softarm._jit``: the figures its notice
   estimates from), with this machine's probe time (``REFERENCE_SECONDS`` and
   ``_REFERENCE_PROBE`` in ``softarm/_jit.py`` come from this run on the reference machine).

Wall time beside CPU time (this process's children: the second core's work shows as CPU time
above the wall time). ``python benchmarks/cold_compile.py [--baseline REV] [--repeat N]``.
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


def _env(cache: str, src: Path, **extra) -> dict:
    return dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(src), **extra)


def demo(src: Path, **extra) -> tuple[tuple[float, float], tuple[float, float]]:
    """(cold (wall, CPU), warm (wall, CPU)) of ``softarm demo`` with the package in ``src``."""
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as work:
        command = [sys.executable, "-m", "softarm", "demo"]
        cold = _run(command, _env(cache, src, **extra), work)[:2]
        warm = _run(command, _env(cache, src, **extra), work)[:2]
    return cold, warm


def capabilities(src: Path) -> tuple[str, dict, dict, float]:
    """(``softarm compile --all``'s output, the compile record per capability key, the
    closed forms' record, this machine's probe time)."""
    with tempfile.TemporaryDirectory() as cache:
        env = _env(cache, src)
        _, _, done = _run([sys.executable, "-m", "softarm", "compile", "--all"], env, ROOT)
        records = {}
        for path in Path(cache).rglob("softarm-compile-seconds.json"):
            records[path.parent.name.split("_")[0]] = json.loads(path.read_text())
        probe = _run([sys.executable, "-c", "from softarm._jit import _probe; "
                      "print(min(_probe() for _ in range(5)))"], env, ROOT)[2]
    return done.stdout, records.get("statics", {}), records.get("analytic", {}), \
        float(probe.stdout)


def _baseline(rev: str, into: str) -> Path:
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", into, rev],
                   check=True, capture_output=True)
    return Path(into) / "src"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", metavar="REV", help="another revision's demo beside")
    parser.add_argument("--repeat", type=int, default=1, help="cold demos of each (default 1)")
    args = parser.parse_args()
    src = ROOT / "src"
    print(f"cold compile, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
          f"{os.cpu_count()} cores")
    rows = [("this tree", src, {}), ("this tree, verdict in the same process", src,
                                     {"SOFTARM_PREFETCH": "0"})]
    with tempfile.TemporaryDirectory() as scratch:
        if args.baseline:
            rows.append((f"baseline {args.baseline}", _baseline(args.baseline,
                                                                f"{scratch}/base"), {}))
        cold_demo = {}
        for name, where, extra in rows:
            for _ in range(args.repeat):
                (wall, cpu), (warm_wall, warm_cpu) = demo(where, **extra)
                cold_demo.setdefault(name, []).append(wall)
                print(f"  softarm demo, cold: {wall:6.1f} s wall, {cpu:6.1f} s CPU; warm: "
                      f"{warm_wall:4.1f} s wall, {warm_cpu:4.1f} s CPU  ({name})")
        if args.baseline:
            ours = min(cold_demo["this tree"])
            theirs = min(cold_demo[f"baseline {args.baseline}"])
            print(f"  cold demo: {theirs / ours:.2f}× faster than {args.baseline}")
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force",
                            f"{scratch}/base"], capture_output=True)
    output, statics, analytic, probe = capabilities(src)
    print("softarm compile --all (each step after the ones before it):")
    for line in output.splitlines():
        print("  " + line)
    print("compile record per capability (s, softarm._jit.REFERENCE_SECONDS' keys):")
    for key, seconds in sorted({**statics, **analytic}.items(), key=lambda kv: -kv[1]):
        print(f"  {key:28s} {seconds:6.1f}")
    print(f"probe (softarm._jit._probe, best of 5): {probe * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
