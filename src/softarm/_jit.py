"""``jit``: numba's ``njit(cache=True)`` with a fallback where the cache cannot be written.

Imported only by compiled modules, on first use: ``import softarm`` does not import numba.
"""

from __future__ import annotations

import os
import warnings

from numba import njit

__all__ = ["jit"]

_WARNED = set()


def jit(function=None, *, what: str = "softarm's compiled kernels", **options):
    """``njit(cache=True, **options)``, or without the cache where numba has nowhere to write.

    Numba stores its cache beside the source file or in a user cache directory; with a
    read-only package and no writable cache directory (a service user, a container) it raises
    at decoration time. The function is then compiled in memory on first use, and a
    RuntimeWarning naming ``what`` says so once per ``what``. Usable as ``@jit`` or
    ``@jit(error_model="numpy")``.
    """
    if function is None:
        return lambda f: jit(f, what=what, **options)
    try:
        return njit(cache=True, **options)(function)
    except RuntimeError as error:
        if "cannot cache" not in str(error):
            raise
        if what not in _WARNED:
            _WARNED.add(what)
            warnings.warn(
                f"softarm: numba cannot cache {what} here (read-only package and no writable "
                "cache directory); they compile on first use in every process. Set "
                "NUMBA_CACHE_DIR to a writable directory to cache them"
                + (f" (now {os.environ['NUMBA_CACHE_DIR']!r})"
                   if "NUMBA_CACHE_DIR" in os.environ else ""),
                RuntimeWarning, stacklevel=2)
        return njit(cache=False, **options)(function)
