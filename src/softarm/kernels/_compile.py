"""How the kernels are compiled: numba's cached compile (softarm._jit) as plain, inlined and
entry-point decorators, and the capability helpers that name a compile from its argument
types (statics/README.md, "Compiled per capability")."""

from __future__ import annotations

from functools import partial

from numba.core import types

from .._jit import jit

# Integer constants passed to compiled callees are written np.int64(k): a bare literal makes
# numba compile the callee once more for the type Literal[int](k), and every such version is
# linked and optimised again in each caller's module (cold compile time).

#: numba's cached compile (in memory, with a warning, where the cache cannot be written),
#: keyed on the sources this module imports too (the cache rule: __init__.py)
_jit = partial(jit, key_on_imports=True)
#: The same, inlined into its callers at numba's level: the RK4 step and its right-hand side
#: (left to LLVM, they stay out of line once the actuated path exists, and every stage then
#: pays a call that passes the arm's arrays by value), and thin helpers called from one or
#: two places (_integrate, _output, _chord).
#:
#: Design note on compile time. numba links every callee's code into each compiled caller
#: and optimises and emits the whole module again there: the RK4 right-hand side is built
#: once per *compiled function above it*. So the step is compiled in one function
#: (`_steps`), the small layers above it are inlined (one module fewer each), and the
#: actuated constitutive law `_law` stays a compiled callee (inlined, it made actuated steps
#: 17 % faster but the cold compile 12 s longer). Measured cold compile of a first solve with
#: its stability verdict (benchmarks/run.py's figure): 110 s -> 62 s on this 2-core machine.
_inline = partial(jit, key_on_imports=True, inline="always")


def _entry(capability, **options):
    """The decorator of an entry point (a kernel called from Python): compiled and announced
    per capability (``capability``: argument types -> (key, text), softarm._jit). The batch
    entry points take ``nogil=True``: a batch runs in threads (chunks of independent cases:
    Solver's ``threads``)."""
    return partial(jit, key_on_imports=True, capability=capability, **options)


def _given(argument) -> bool:
    """Whether an optional argument's type is given (not None): the capabilities of a compile
    (None arguments prune their code, statics/README.md)."""
    return not isinstance(argument, types.NoneType)


def _per_arm(key: str, text: str, act: int):
    """The capability of an entry point that is compiled per kind of arm: ``act`` is the
    index of its argument ``act``."""
    def capability(args):
        actuated = _given(args[act])
        return (key + "+actuated" * actuated,
                text + (" for actuated, magnetic or touching arms" if actuated
                        else " for passive arms"))
    return capability


def _fixed(key: str, text: str):
    return lambda args: (key, text)
