"""Batch throughput of softarm (issue 7): closed forms and the batched exact solver.

Used by ``benchmarks/run.py``; also runnable on its own::

    python benchmarks/throughput.py                  # both measurements, full sizes
    python benchmarks/throughput.py --batch-child N  # one batched solve in this process (JSON)

The batched-solver memory is measured in a fresh child process per batch size: after a
warm-up solve the peak resident set size (VmHWM, the number ``resource.getrusage`` reports as
``ru_maxrss``) is reset to the current RSS through ``/proc/self/clear_refs``, so the peak read
after the batched call belongs to that call alone (numba's and LLVM's import peak would hide
it otherwise).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["batch_solver", "closed_form_throughput", "soft_arm", "soft_arm_loads"]

_HERE = Path(__file__).resolve()

sys.path.insert(0, str(_HERE.parent))
from cases import soft_arm_problem, to_softarm  # noqa: E402  (benchmarks/ is not a package)

_PROBLEM = soft_arm_problem()
_L = _PROBLEM.length
_BASE_FORCE = np.array(_PROBLEM.tip_force)  # N, spatial, the case's oblique tip force


def soft_arm():
    """The 3D soft arm of the benchmark cases as a :class:`softarm.Arm` (with its mass)."""
    return to_softarm(_PROBLEM)[0]


def soft_arm_loads(n_cases: int, seed: int = 7):
    """Gravity plus a batch of oblique dead tip forces, shape (n_cases, 3), in random order.

    Each force is the case's (0.05, 0.1, -0.05) N scaled by U(0.5, 1.5) per component with
    random signs on the transverse components: consecutive cases are unrelated, so the warm
    start gets no help from a smooth sweep.
    """
    import softarm

    rng = np.random.default_rng(seed)
    scale = rng.uniform(0.5, 1.5, size=(n_cases, 3))
    signs = np.ones((n_cases, 3))
    signs[:, 1:] = rng.choice([-1.0, 1.0], size=(n_cases, 2))
    forces = _BASE_FORCE * scale * signs
    return [softarm.Gravity(), softarm.TipLoad(force=forces)], forces


def _max_rss_bytes() -> int:
    """Peak resident set size of this process in bytes (VmHWM, else ru_maxrss)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # Linux: KiB


def _reset_peak_rss() -> bool:
    """Reset the peak-RSS high-water mark to the current RSS (Linux >= 4.0); False if not."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        return False
    return True


def _batch_child(n_cases: int, tol: float, n_stations: int) -> dict:
    """One warm batched solve in this process: time, CPU time, peak RSS and accuracy."""
    import softarm
    from softarm._threads import threads_for
    from softarm.statics.solver import CASES_PER_THREAD

    arm = soft_arm()
    loads, forces = soft_arm_loads(n_cases)
    warm_loads, _ = soft_arm_loads(2, seed=1)
    softarm.solve(arm, warm_loads, method="numeric", tol=tol, s=n_stations)  # load kernels
    gc.collect()
    reset = _reset_peak_rss()  # else the peak of the imports (numba, LLVM) would hide ours
    rss_before = _max_rss_bytes()
    w0, c0 = time.perf_counter(), time.process_time()
    eq = softarm.solve(arm, loads, method="numeric", tol=tol, s=n_stations)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    rss_peak = _max_rss_bytes()
    output_bytes = eq.poses.nbytes + eq.strains.nbytes + eq.stresses.nbytes
    # Accuracy: a few cases against single tight solves.
    picks = np.unique(np.linspace(0, n_cases - 1, 4).astype(int))
    gaps = []
    for b in picks:
        tight = softarm.solve(
            arm,
            [softarm.Gravity(), softarm.TipLoad(force=forces[b])],
            method="numeric",
            tol=1e-11,
            s=2,
        )
        gaps.append(float(np.linalg.norm(eq.tip_position[b] - tight.tip_position)) / _L)
    return {
        "n_cases": n_cases,
        "tol": tol,
        "n_stations": n_stations,
        "wall_s": wall,
        "cpu_s": cpu,
        "rss_before_bytes": rss_before,
        "rss_peak_bytes": rss_peak,
        "peak_reset": reset,
        "output_bytes": output_bytes,
        "max_error_estimate_over_L": float(np.max(eq.error_estimate)) / _L,
        "max_gap_to_tight_over_L": max(gaps),
        "threads": threads_for(n_cases, CASES_PER_THREAD),
    }


def batch_solver(n_cases: int, tol: float = 1e-6, n_stations: int = 101,
                 threads: int | None = None) -> dict:
    """Run :func:`_batch_child` in a fresh Python process and return its measurements;
    ``threads``: its ``$SOFTARM_NUM_THREADS`` (None: as it is here)."""
    cmd = [
        sys.executable,
        str(_HERE),
        "--batch-child",
        str(n_cases),
        "--tol",
        repr(tol),
        "--stations",
        str(n_stations),
    ]
    env = dict(os.environ)
    if threads is not None:
        env["SOFTARM_NUM_THREADS"] = str(threads)
    done = subprocess.run(cmd, capture_output=True, text=True, check=False, env=env)
    if done.returncode != 0:
        raise RuntimeError(f"batch child failed:\n{done.stdout}\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def closed_form_throughput(n_arms: int, chunk: int, n_stations: int = 100,
                           principal: bool = False, seed: int = 3,
                           threads: int | None = None) -> dict:
    """``softarm.analytic.tip_moment`` on ``n_arms`` moments, in chunks, vs numpy writes.

    For each chunk of ``chunk`` arms: time one ``tip_moment(arm, moments, s=n_stations)``
    call (poses, strains and stresses of every arm at every station), then the time numpy
    takes to write the same chunk's poses once (``np.empty((chunk, n_stations, 4, 4))`` +
    ``fill``) and all three output arrays once (poses, strains, stresses: 28 floats per
    station). Totals are sums over the chunks (the full 10^6-arm pose array alone would be
    12.8 GB).

    ``principal=False``: the arm of the pure-bending case (EIy = EIz, so the helix route,
    exact for any moment direction) with random moment directions. ``principal=True``: an
    arm with EIy != EIz and moments about +y (the constant-strain route, eqs. 30-34).

    ``threads``: cap the pose kernel's threads (``$SOFTARM_NUM_THREADS``) for this
    measurement; None keeps softarm's default (the CPUs available). numpy's writes are
    single-threaded either way.
    """
    from softarm.analytic import _common

    with _thread_cap(_common.THREADS_VARIABLE, threads):
        result = _closed_form_chunks(n_arms, chunk, n_stations, principal, seed)
        result["threads"] = _common.thread_count(min(chunk, n_arms) * n_stations)
    return result


@contextlib.contextmanager
def _thread_cap(variable: str, threads: int | None):
    """The environment variable set to ``threads`` inside the block (None: left as it is)."""
    saved = os.environ.get(variable)
    if threads is not None:
        os.environ[variable] = str(threads)
    try:
        yield
    finally:
        if saved is None:
            os.environ.pop(variable, None)
        else:
            os.environ[variable] = saved


def _closed_form_chunks(n_arms, chunk, n_stations, principal, seed) -> dict:
    """The timed loop of :func:`closed_form_throughput`."""
    from softarm import Arm
    from softarm.analytic import tip_moment

    EIz = 2.0 if principal else 1.0
    arm = Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0 / 1.5, EIy=1.0, EIz=EIz)
    rng = np.random.default_rng(seed)
    tip_moment(arm, [0.0, 1.0, 0.0], s=n_stations)  # first-call imports, not timed
    t_tip = c_tip = t_poses = t_all = 0.0
    done = 0
    max_err = 0.0
    while done < n_arms:
        size = min(chunk, n_arms - done)
        if principal:
            moments = np.zeros((size, 3))
            moments[:, 1] = rng.uniform(-3.0, 3.0, size)
        else:
            moments = rng.normal(size=(size, 3))
            moments *= (rng.uniform(0.0, 3.0, size) / np.linalg.norm(moments, axis=1))[:, None]
        gc.collect()
        w0, c0 = time.perf_counter(), time.process_time()
        eq = tip_moment(arm, moments, s=n_stations)
        t_tip += time.perf_counter() - w0
        c_tip += time.process_time() - c0
        if principal:  # circle of eqs. 37-38 (kappa = tau / EIy, L = 1)
            k = moments[:, 1]
            ks = np.where(k == 0.0, 1.0, k)
            x = np.where(k == 0.0, 1.0, np.sin(k) / ks)
            z = np.where(k == 0.0, 0.0, -(1.0 - np.cos(k)) / ks)
            ref = np.stack([x, 0 * x, z], axis=-1)
            max_err = max(max_err, float(np.max(np.abs(eq.tip_position - ref))))
        del eq
        gc.collect()
        w0 = time.perf_counter()
        out = np.empty((size, n_stations, 4, 4))
        out.fill(1.0)
        t_poses += time.perf_counter() - w0
        del out
        w0 = time.perf_counter()
        outs = [np.empty((size, n_stations, 4, 4)), np.empty((size, n_stations, 6)),
                np.empty((size, n_stations, 6))]
        for a in outs:
            a.fill(1.0)
        t_all += time.perf_counter() - w0
        del outs
        done += size
    return {
        "n_arms": n_arms,
        "chunk": chunk,
        "n_stations": n_stations,
        "route": "principal" if principal else "helix",
        "tip_moment_s": t_tip,
        "tip_moment_cpu_s": c_tip,
        "write_poses_s": t_poses,
        "write_all_s": t_all,
        "ratio_poses": t_tip / t_poses,
        "ratio_all": t_tip / t_all,
        "max_tip_error": max_err if principal else float("nan"),
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batch-child", type=int, default=None, metavar="N")
    parser.add_argument("--tol", type=float, default=1e-6)
    parser.add_argument("--stations", type=int, default=101)
    parser.add_argument("--arms", type=int, default=10**6)
    parser.add_argument("--chunk", type=int, default=10**5)
    args = parser.parse_args(argv)
    if args.batch_child is not None:
        print(json.dumps(_batch_child(args.batch_child, args.tol, args.stations)))
        return
    print(json.dumps(closed_form_throughput(args.arms, args.chunk), indent=1))
    for n in (10**3, 10**4):
        print(json.dumps(batch_solver(n, args.tol, args.stations), indent=1))


if __name__ == "__main__":
    main()
