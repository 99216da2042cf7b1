"""Run a command in this process and write, when it exits, the versions of softarm's compiled
kernels it used: ``{kernel: [signature, ...]}``, each compiled here or loaded from numba's
cache (a numba dispatcher lists both among its signatures).

``python tests/_touched.py OUT.json -m softarm compile --all`` runs a module as ``python -m``
does, ``python tests/_touched.py OUT.json SCRIPT.py ARGS...`` a script (tests/test_compile_all.py).
"""

from __future__ import annotations

import atexit
import json
import runpy
import sys


def _write(path: str) -> None:
    from numba.core.registry import CPUDispatcher

    touched = {}
    for name, module in list(sys.modules.items()):
        if name != "softarm" and not name.startswith("softarm."):
            continue
        for value in list(vars(module).values()):
            if isinstance(value, CPUDispatcher) and value.signatures:
                kernel = f"{value.py_func.__module__}.{value.py_func.__qualname__}"
                touched[kernel] = sorted(str(signature) for signature in value.signatures)
    with open(path, "w", encoding="utf-8") as out:
        json.dump(touched, out, indent=1, sort_keys=True)


if __name__ == "__main__":
    out, *command = sys.argv[1:]
    atexit.register(_write, out)
    if command[0] == "-m":
        sys.argv = [command[1], *command[2:]]
        runpy.run_module(command[1], run_name="__main__", alter_sys=True)
    else:
        sys.argv = command
        runpy.run_path(command[0], run_name="__main__")
