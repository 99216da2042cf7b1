"""Sweep scaling (issue 17): a Sobol design of tip forces on the 3D soft arm (gravity and an
oblique tip force, 101 stations), solved in memory, into a Zarr store, on 1 and 2 local
processes and on a Dask LocalCluster of 1 and 2 workers; wall and CPU time side by side, and
the store size per case for each ``--fields`` choice.

::

    python benchmarks/sweep_scaling.py                   # 10^5 cases (the issue's size)
    python benchmarks/sweep_scaling.py --cases 10000     # fewer, on a small machine
    python benchmarks/sweep_scaling.py --no-dask         # without softarm[dask]

CPU time is this process's plus its children's (``RUSAGE_CHILDREN``, counted once the pool
or cluster has shut down), so it includes the workers. Every route is checked against the
in-memory batch, case by case, before its time is printed (a fast wrong answer is worthless).
Needs ``pip install 'softarm[sweep]'`` (and ``'softarm[dask]'`` for the Dask rows).
"""

from __future__ import annotations

import argparse
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

L, R, E, RHO = 0.3, 0.01, 1.0e6, 1100.0  # benchmarks/cases.py: soft_arm_problem()


def case_dict(cases: int, stations: int = 101) -> dict:
    """The 3D soft arm with a Sobol design over the tip force: each component spans the
    magnitudes of benchmarks/throughput.py (0.5 to 1.5 times (0.05, 0.1, -0.05) N, random
    signs on the transverse ones)."""
    return {
        "name": "soft_arm_sweep",
        "arm": {"length": L, "section": {"kind": "circle", "radius": R},
                "material": {"E": E, "nu": 0.5, "density": RHO}},
        "load": [{"kind": "gravity"}, {"kind": "tip", "force": [0.05, 0.1, -0.05]}],
        "solve": {"method": "numeric", "stations": stations, "tol": 1e-8},
        "sweep": {"design": "sobol", "samples": cases, "seed": 17, "parameter": [
            {"path": "load[2].force.x", "start": 0.025, "stop": 0.075},
            {"path": "load[2].force.y", "start": -0.15, "stop": 0.15},
            {"path": "load[2].force.z", "start": -0.075, "stop": 0.075}]},
    }


def clock():
    own = time.process_time()
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.perf_counter(), own + children.ru_utime + children.ru_stime


def since(start):
    wall, cpu = clock()
    return wall - start[0], cpu - start[1]


def folder_bytes(path: Path) -> int:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=100_000)
    parser.add_argument("--chunk", type=int, default=1000)
    parser.add_argument("--size-cases", type=int, default=2000,
                        help="cases of the store-size runs (one per --fields choice)")
    parser.add_argument("--no-dask", action="store_true")
    args = parser.parse_args(argv)

    import softarm
    from softarm.case import parse_case

    case = parse_case(case_dict(args.cases))
    design = case.design
    forces = design.values()
    arm = case.arm
    loads = [softarm.Gravity(), softarm.TipLoad(force=forces)]
    softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=forces[:2])],
                  method="numeric")  # compile or load the kernels
    scratch = Path(tempfile.mkdtemp(prefix="sweep_scaling_"))
    rows = []
    try:
        start = clock()
        memory = softarm.solve(arm, loads, method="numeric", tol=1e-8)
        wall, cpu = since(start)
        rows.append(("in memory: one batched softarm.solve", wall, cpu))
        reference = np.array(memory.positions)  # (kept alone: 24 B, not 224 B, a station)
        del memory
        fields = ("tip", "positions")

        def check(ds, label):
            got = np.asarray(ds["positions"].values)
            gap = float(np.max(np.abs(got - reference)))
            if gap > 1e-12 or np.any(np.asarray(ds["status"].values) != 0):
                raise SystemExit(f"{label}: differs from the in-memory batch by {gap:.3e} m")

        def timed(label, out, make_map=None):
            start = clock()
            pool = make_map() if make_map is not None else None
            try:
                ds = softarm.sweep.run(case, out=out, chunk=args.chunk, fields=fields,
                                       map=None if pool is None else pool[0])
            finally:
                if pool is not None:
                    pool[1]()
            wall, cpu = since(start)
            check(ds, label)
            rows.append((label, wall, cpu))

        timed("in memory: softarm.sweep.run, in-process", None)
        timed("Zarr: softarm.sweep.run, in-process", scratch / "serial.zarr")
        for workers in (1, 2):
            def make(workers=workers):
                pool = softarm.sweep.process_pool(workers, case)
                return pool.map, pool.shutdown
            timed(f"Zarr: {workers} local process{'es' if workers > 1 else ''}",
                  scratch / f"pool{workers}.zarr", make)
        if not args.no_dask:
            from distributed import Client, LocalCluster

            for workers in (1, 2):
                def make(workers=workers):
                    cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                           processes=True, dashboard_address=None)
                    client = Client(cluster)

                    def close():
                        client.close()
                        cluster.close()
                    return client.get_executor(pure=False).map, close
                timed(f"Zarr: Dask LocalCluster, {workers} worker{'s' if workers > 1 else ''}",
                      scratch / f"dask{workers}.zarr", make)

        print(f"{args.cases} cases of the 3D soft arm (gravity + tip force, 101 stations), "
              f"chunks of {args.chunk}, --fields tip,positions, float64")
        base = rows[0][1]
        print(f"{'route':<46} {'wall s':>8} {'CPU s':>8} {'ms/case':>8} {'vs memory':>10}")
        for label, wall, cpu in rows:
            print(f"{label:<46} {wall:>8.2f} {cpu:>8.2f} {1e3 * wall / args.cases:>8.3f} "
                  f"{wall / base:>9.2f}x")
        by = {label: wall for label, wall, _ in rows}
        ratios = [("Zarr vs in memory (in-process)", by["Zarr: softarm.sweep.run, in-process"]
                   / by["in memory: one batched softarm.solve"]),
                  ("1 vs 2 local processes (speed-up)", by["Zarr: 1 local process"]
                   / by["Zarr: 2 local processes"])]
        if not args.no_dask:
            ratios.append(("1 vs 2 Dask workers (speed-up)",
                           by["Zarr: Dask LocalCluster, 1 worker"]
                           / by["Zarr: Dask LocalCluster, 2 workers"]))
        for label, ratio in ratios:
            print(f"RATIO {label}: {ratio:.2f}")

        # the fixed costs that set the chunk size: one chunk's store write, one Dask task
        from softarm.sweep import _run, _store

        spec = _run.Spec(case.to_dict(), None, design, "numeric", 101, 1e-8, fields,
                         "float64", args.chunk, str(scratch / "serial.zarr"))
        data = _store.allocate(spec, args.chunk)
        data["status"][:] = 0
        chunks = min(20, args.cases // args.chunk)
        start = clock()
        for k in range(chunks):
            task = _run.Task(spec, k, k * args.chunk, (k + 1) * args.chunk, None)
            _store.write_chunk(spec, task, data)
        wall, _ = since(start)
        print(f"COST store write of one chunk of {args.chunk} cases (tip, positions): "
              f"{1e3 * wall / chunks:.1f} ms")
        if not args.no_dask:
            with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                              dashboard_address=None) as cluster, Client(cluster) as client:
                mapper = client.get_executor(pure=False).map
                list(mapper(abs, range(100)))
                start = clock()
                list(mapper(abs, range(2000)))
                wall, _ = since(start)
            print(f"COST Dask task round trip (2 workers, 2000 no-op tasks): "
                  f"{1e3 * wall / 2000:.2f} ms a task")

        # store size per case for each --fields choice (actual compressed bytes on disk)
        small = parse_case(case_dict(args.size_cases))
        print(f"\nstore size per case ({args.size_cases} cases, 101 stations, Blosc-lz4 as "
              "zarr writes by default)")
        for choice in (("tip",), ("tip", "positions"), ("poses",), ("strains",),
                       ("stresses",), ("tip", "poses", "strains", "stresses")):
            for dtype in ("float64", "float32"):
                out = scratch / f"size-{'-'.join(choice)}-{dtype}.zarr"
                softarm.sweep.run(small, out=out, chunk=args.chunk, fields=choice,
                                  dtype=dtype)
                per_case = folder_bytes(out) / args.size_cases
                print(f"SIZE --fields {','.join(choice):<30} --dtype {dtype}: "
                      f"{per_case:>9.0f} B/case, {per_case * 1e8 / 1e12:>7.2f} TB per 10^8")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
