"""softarm's compiled kernels (numba), one module per capability.

The solvers in Python (statics/, dynamics/, control.py) prepare a problem and call one entry
point here for a whole batch; the numerical work is all here. The closed forms' one-load
kernels are apart, in analytic/_compiled.py. Lowest first, each module imports only the
ones above it in this list:

- ``_compile``: the decorators (numba's cached compile, inlined, entry points) and the
  capability names of a compile;
- ``layout``: the statuses and the array layouts shared with Python;
- ``linear``: small dense and banded linear algebra, the branch guard's eigenvalue test;
- ``rod``: the RK4 step along the arm, the constitutive laws, the contact's penalty law;
- ``shooting``: single shooting and its continuation (``solve_cases``, ``shoot``);
- ``stability``: the Morse index by conjugate points (``stability_cases``);
- ``inverse``: bounded Newton steps and inverse statics (``inverse_newton``);
- ``multiple``: multiple shooting for stiff problems (``solve_stiff_cases``);
- ``dynamics``: the implicit time step (``dynamic_steps``).

Design notes (layouts, the stage machine, compile time): statics/README.md.

**Importing this package imports nothing else** (not numba): ``import softarm`` stays fast
and compiles nothing. Its interface (below, :data:`_INTERFACE`) is loaded on first use: the
first attribute read imports every module (numba compiles nothing until a kernel is called,
per capability).

**The cache rule.** numba keys a function's on-disk cache on its own source file only: a
caller whose callee lives in another file would keep running the old callee's code after an
edit of that file. So every function compiled here is cached under a stamp of its own file
*and of every file of this package it imports, directly or through others*
(``softarm._jit.jit(..., key_on_imports=True)``, by ``_compile``'s decorators): an edit of
``rod.py`` recompiles everything that integrates the arm, one of ``dynamics.py`` only the
dynamics. tests/test_kernel_cache.py checks the rule on a package whose callee changes.
"""

from __future__ import annotations

import importlib

#: What Python reads from the kernels, and the module that defines it.
_INTERFACE = {
    "layout": ("ACT", "BUDGET", "CHAMBER", "CT", "FB", "FD", "FF", "FG", "JD", "JF", "LD", "LF",
               "MEMORY", "MPREDICTED", "MSTEP", "NEWTON_FAILED", "NOT_FINITE", "OK", "OPTIONS",
               "PATH_FAILED", "PIECE_LOADS", "SINGULAR", "TD", "TENDON", "TF", "TIP_LOADS",
               "TOO_MANY_STEPS"),
    "rod": ("CONTACT_PARAMS", "ZONE", "_law", "_route"),
    "shooting": ("solve_cases", "shoot", "_fill_steps", "_implicit_function", "_scratch"),
    "stability": ("stability_cases", "sweep_point", "record_points"),
    "inverse": ("box_least_squares", "regularised_step", "inverse_newton", "task_error",
                "redundant_task", "EFFORT", "NEWTON_DONE", "_rotation_log"),
    "multiple": ("solve_stiff_cases",),
    "dynamics": ("dynamic_steps", "DHIST", "DPROPS", "DUNK", "DYN", "_DKL", "_DN", "_DP",
                 "_DQ", "_DR", "_DW", "_PB", "_PF0", "_PK", "_PKD", "_PMU", "_PRJ"),
}
_WHERE = {name: module for module, names in _INTERFACE.items() for name in names}

__all__ = sorted(name for name in _WHERE if not name.startswith("_"))


def __getattr__(name: str):
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    # every module at once: the verdict's registers what a cold solver compile starts
    for module, names in _INTERFACE.items():
        loaded = importlib.import_module(f"{__name__}.{module}")
        globals().update({n: getattr(loaded, n) for n in names})  # read directly from now on
    return globals()[name]


def __dir__():
    return sorted([*globals(), *_WHERE])
