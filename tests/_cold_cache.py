"""Processes with a numba cache of their own (a cold start, as on a new machine): the
helpers of tests/test_compile.py and tests/test_compile_all.py."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

#: a passive solve; prints numba's cache misses of the kernels named on its command line
PASSIVE_SOLVE = """
import sys, numpy as np, softarm
from softarm import kernels
silicone = softarm.Material(youngs_modulus=1.5e6, poisson_ratio=0.49, density=1070.0)
arm = softarm.Arm(0.2, softarm.Circle(0.01), silicone)
eq = softarm.solve(arm, [softarm.Gravity(), softarm.TipLoad(force=[0.0, 0.01, 0.0])],
                   method="numeric")
# what this process compiled: numba's cache misses per kernel (a load from the cache is a hit),
# each found by its name in the module of softarm.kernels that defines it
defined = {}
for module in [m for n, m in list(sys.modules.items()) if n.startswith("softarm.kernels.")]:
    defined.update({n: v for n, v in vars(module).items()
                    if getattr(getattr(v, "py_func", None), "__module__", None) == module.__name__})
print({name: sum(defined[name].stats.cache_misses.values()) for name in sys.argv[1:]})
print(repr(eq.tip_position.tolist()))
"""


def python_with(code: str, *args: str, cache: Path, notice: bool = True, prefetch: bool = False):
    """``python -c code args`` with its own numba cache, the compile notice on or off, and
    the verdict's compile on another core (kernels/_prefetch.py) or in the process."""
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          timeout=900, env=cache_env(cache, notice, prefetch))


def softarm_with(*args: str, cache: Path, notice: bool = True):
    return subprocess.run([sys.executable, "-m", "softarm", *args], capture_output=True,
                          text=True, timeout=900, env=cache_env(cache, notice))


def cache_env(cache: Path | None, notice: bool, prefetch: bool = False) -> dict:
    """This process's environment with numba's cache ``cache`` (None: the one the tests
    use), the compile notice and the verdict's compile on another core on or off."""
    env = dict(os.environ, SOFTARM_COMPILE_NOTICE="1" if notice else "0",
               SOFTARM_PREFETCH="1" if prefetch else "0")
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = str(cache)
    return env
