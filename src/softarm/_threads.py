"""Threads for batches, one rule for the whole package: at most ``$SOFTARM_NUM_THREADS`` (a
positive integer) or, unset, every core this process may run on.

The compiled kernels and numpy's loops release the GIL, and every element of a batch (an arm
of a closed form, a load case solved from the unloaded arm) is computed from its own inputs
alone, so a batch cut into contiguous ranges gives the same answer to the bit, in a fraction
of the wall time on a multi-core machine (the CPU time is the same). A pool of worker
processes should set ``SOFTARM_NUM_THREADS=1`` in its workers (softarm's sweeps do), or its
threads only compete for the same cores.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

__all__ = ["THREADS_VARIABLE", "available_threads", "in_threads", "thread_setting", "threads_for"]

#: Environment variable capping the threads of every batch kernel.
THREADS_VARIABLE = "SOFTARM_NUM_THREADS"


def thread_setting() -> int | None:
    """``$SOFTARM_NUM_THREADS`` as a positive integer, None if unset, else ValueError."""
    setting = os.environ.get(THREADS_VARIABLE, "").strip()
    if not setting:
        return None
    try:
        limit = int(setting)
    except ValueError:
        limit = 0
    if limit < 1:
        raise ValueError(
            f"environment variable {THREADS_VARIABLE} must be a positive integer (the "
            f"most threads softarm's batch kernels may use), got {setting!r}"
        )
    return limit


def available_threads() -> int:
    """``$SOFTARM_NUM_THREADS`` or, unset, the cores this process may run on."""
    limit = thread_setting()
    if limit is not None:
        return limit
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1  # pragma: no cover - not on Linux


def threads_for(work: int, per_thread: int, limit: int | None = None) -> int:
    """Threads for ``work`` units with at least ``per_thread`` each (1 for small work): at
    most ``limit`` or, None, :func:`available_threads`."""
    return max(1, min(available_threads() if limit is None else limit, work // per_thread))


def in_threads(work, size: int, threads: int) -> None:
    """``work(first, last)`` over ``range(size)`` split into ``threads`` contiguous ranges,
    run concurrently (the calling thread takes the first). Each element must be computed
    from its own inputs alone: the result then does not depend on ``threads``."""
    threads = max(1, min(threads, size))
    if threads == 1:
        work(0, size)
        return
    edges = [size * i // threads for i in range(threads + 1)]
    with ThreadPoolExecutor(threads - 1) as pool:
        others = [pool.submit(work, edges[i], edges[i + 1]) for i in range(1, threads)]
        work(edges[0], edges[1])
        for other in others:
            other.result()
