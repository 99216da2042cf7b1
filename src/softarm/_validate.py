"""Input coercion and validation shared by every public entry point.

Every failure is a ValueError (or TypeError) that names the parameter, what was expected and what
was received, so a user never has to read a traceback to learn what to fix.

Numbers are read strictly: a string, a bool, None or a complex number where a real number is
expected is a TypeError (never silently converted: ``"1"`` is not 1 and ``True`` is not 1.0),
while Python ints and floats and numpy integer and floating scalars and arrays of any width
(``np.float32(2)``, ``np.float16``) are accepted alike.
"""

from __future__ import annotations

import functools
import math
import os
from numbers import Integral, Real

import numpy as np

__all__ = [
    "BYTES_PER_CASE",
    "BYTES_PER_STATION",
    "CASES_PER_PART",
    "LENGTH_RANGE",
    "MAX_STEPS",
    "PART_BYTES",
    "WORK_PER_CASE",
    "as_array",
    "as_matrices",
    "as_vectors",
    "check_allocation",
    "check_array_size",
    "count",
    "format_bytes",
    "format_value",
    "length",
    "memory_limit",
    "nonnegative",
    "positive",
    "real",
    "rigid_transform",
    "stations",
]

#: Accepted lengths in m (arm lengths, radii, widths): far beyond any rod, and narrow enough
#: that every derived quantity (L², r⁴, E r⁴ / L², ...) stays a normal float64.
LENGTH_RANGE = (1e-12, 1e12)

#: Bytes of output per load case and station: a pose (16), strains (6) and stresses (6),
#: float64.
BYTES_PER_STATION = 28 * 8
#: Bytes of a result per load case besides its stations (residual, error estimate, base
#: wrench, verdict, ...): measured 200-610 B (tests/test_memory.py)
BYTES_PER_CASE = 640
#: The work (bytes) one part of a batch may take beside the result: every route cuts a large
#: batch into parts of about this much work (load channels, solver or closed-form arrays),
#: counted three times by the guard (measured up to 2.2: the part being solved, and what the
#: allocator still holds of the one before, tests/test_memory.py); the solver's parts also
#: copy their own result into the whole batch's (CASES_PER_PART, counted twice)
PART_BYTES = 1 << 26

#: The most RK4 steps along the arm a solve takes by default (the numerical solver's
#: ``max_steps``, the fine solution's count): the inputs' representable range is measured
#: against it (docs/solver.md, "Out-of-range inputs"): a step resolves a turning of about a
#: radian, and lengths (an elastic foundation's, a contact band's) of about L / MAX_STEPS.
MAX_STEPS = 1 << 15

#: Largest deviation ‖RᵀR − I‖ (max entry) of a base rotation that is re-orthonormalised; a
#: rotation off by more is rejected.
ROTATION_TOLERANCE = 1e-5

_OK = object()


def format_value(value, limit: int = 80) -> str:
    """``value`` as an error message shows it, on one line of at most ``limit`` characters.

    A number is shown as the plain Python number with the shortest repr that reads back to
    the same float: ``0.10000000001`` (never rounded to ``0.1``, which would hide why it is
    out of range) and ``-0.5`` (never ``np.float64(-0.5)``, numpy 2's repr). Lists, tuples and
    small arrays are shown element by element the same way; a large array by its shape and
    dtype; anything else by its repr. The numbers of the model's error messages go through
    here (a few older messages still show a value's repr).

    Examples
    --------
    >>> format_value(np.float64(0.10000000001)), format_value([np.float32(0.5), np.int64(2)])
    ('0.10000000001', '[0.5, 2]')
    >>> format_value((np.float64(0.1), None)), format_value(np.zeros(9))
    ('(0.1, None)', 'array of shape (9,) and dtype float64')
    """
    text = " ".join(_plain_text(value, limit, 0).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _plain_text(value, limit: int, depth: int) -> str:
    """:func:`format_value` before the cut; lists, tuples and dicts show at most ``limit``
    items (each takes at least a character) and 16 levels (no deep recursion on a hostile
    input)."""
    if isinstance(value, (bool, np.bool_)):
        return repr(bool(value))
    if isinstance(value, str):  # np.str_ too: 'text', never np.str_('text')
        return repr(str(value))
    if isinstance(value, (Integral, np.integer)):
        return repr(int(value))
    if isinstance(value, (Real, np.floating)):
        return repr(float(value))
    if isinstance(value, np.ndarray):
        if value.size > 8:
            return f"array of shape {value.shape} and dtype {value.dtype}"
        return _plain_text(value.tolist(), limit, depth)  # a scalar for shape ()
    if isinstance(value, dict):
        if depth >= 16:
            return "{…}"
        items = [f"{_plain_text(k, limit, depth + 1)}: {_plain_text(v, limit, depth + 1)}"
                 for k, v in list(value.items())[:limit]]
        return "{" + ", ".join(items + ["…"] * (len(value) > limit)) + "}"
    if isinstance(value, (list, tuple)):
        if depth >= 16:
            return "[…]" if isinstance(value, list) else "(…)"
        items = [_plain_text(v, limit, depth + 1) for v in value[:limit]]
        if len(value) > limit:
            items.append("…")
        inner = ", ".join(items)
        if isinstance(value, list):
            return f"[{inner}]"
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    return repr(value)


def _first_non_real(value):
    """The first element of ``value`` that is not a real number (``_OK`` if there is none).

    Bools, strings, None, complex numbers and other objects are not real numbers; ints, floats
    and numpy integer and floating scalars or arrays are.
    """
    if isinstance(value, np.ndarray):
        kind = value.dtype.kind
        if kind in "fiu":
            return _OK
        if kind == "O":
            for item in value.flat:
                bad = _first_non_real(item)
                if bad is not _OK:
                    return bad
            return _OK
        return value.flat[0] if value.size else value  # bool, complex, str, bytes arrays
    if isinstance(value, (list, tuple)):
        for item in value:
            bad = _first_non_real(item)
            if bad is not _OK:
                return bad
        return _OK
    if isinstance(value, (bool, np.bool_)):
        return value
    if isinstance(value, (Real, np.integer, np.floating)):
        return _OK
    if hasattr(value, "__array__") and not isinstance(value, (str, bytes)):
        return _first_non_real(np.asarray(value))
    return value


def _kind(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "a bool"
    if isinstance(value, (str, np.str_)):
        return "a string"
    if value is None:
        return "None"
    if isinstance(value, (complex, np.complexfloating)):
        return "a complex number"
    if isinstance(value, np.ndarray):
        return f"an array of dtype {value.dtype}"
    return f"a {type(value).__name__}"


def as_array(value, name: str) -> np.ndarray:
    """``value`` as a finite float64 array, or ValueError/TypeError naming ``name``.

    Examples
    --------
    >>> as_array([0, 0, np.float32(1.5)], "force")
    array([0. , 0. , 1.5])
    >>> as_array([0, 0, "1"], "force")
    Traceback (most recent call last):
    ...
    TypeError: force must be numeric (real numbers), got a string ('1') in [0, 0, '1']
    """
    bad = _first_non_real(value)
    if bad is not _OK:
        where = "" if bad is value else f" in {format_value(value)}"
        raise TypeError(f"{name} must be numeric (real numbers), got {_kind(bad)} "
                        f"({format_value(bad, 40)}){where}")
    if isinstance(value, np.ndarray):  # (a broadcast view may be far larger than its data)
        check_array_size(value.shape, name)
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as error:  # e.g. ragged nested lists
        raise ValueError(f"{name} must be a (nested) list or array of numbers of one shape, "
                         f"got {format_value(value)}") from error
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got {format_value(value)}")
    return array


def as_vectors(value, name: str, size: int) -> np.ndarray:
    """A finite float64 array of shape (..., size)."""
    array = as_array(value, name)
    if array.ndim == 0 or array.shape[-1] != size:
        raise ValueError(f"{name} must have shape (..., {size}), got shape {array.shape}")
    return array


def as_matrices(value, name: str, rows: int, cols: int | None = None) -> np.ndarray:
    """A finite float64 array of shape (..., rows, cols)."""
    cols = rows if cols is None else cols
    array = as_array(value, name)
    if array.ndim < 2 or array.shape[-2:] != (rows, cols):
        raise ValueError(f"{name} must have shape (..., {rows}, {cols}), got shape {array.shape}")
    return array


def real(value, name: str, unit: str = "") -> float:
    """A finite real number as a Python float: int, float or a numpy scalar of any width.

    TypeError for a bool, string, None, complex or anything else; ValueError if not finite.

    Examples
    --------
    >>> real(np.float32(2.0), "max_step")
    2.0
    >>> real(True, "max_step")
    Traceback (most recent call last):
    ...
    TypeError: max_step must be a real number, got a bool (True)
    """
    if type(value) is float and math.isfinite(value):  # the common case, first
        return value
    in_unit = f" in {unit}" if unit else ""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "fiu":
        value = value[()]
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (Real, np.integer,
                                                                      np.floating)):
        raise TypeError(f"{name} must be a real number{in_unit}, got {_kind(value)} "
                        f"({format_value(value, 40)})")
    number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{name} must be a finite number{in_unit}, got {format_value(value)}")
    return number


def positive(value, name: str, unit: str) -> float:
    """A positive finite real number, as float (numpy scalars of any width accepted)."""
    return _not_below_zero(value, name, unit, zero=False)


def nonnegative(value, name: str, unit: str) -> float:
    """A finite real number >= 0, as float: a quantity for which 0 is a valid model (a
    massless rod's mass per length)."""
    return _not_below_zero(value, name, unit, zero=True) + 0.0  # -0.0 as 0.0


def _not_below_zero(value, name: str, unit: str, *, zero: bool) -> float:
    what = "a finite value >= 0" if zero else "a positive finite value"
    in_unit = f" in {unit}" if unit else ""
    try:
        number = real(value, name, unit)
    except TypeError:
        raise TypeError(f"{name} must be {'a number >= 0' if zero else 'a positive number'}"
                        f"{in_unit}, got {_kind(value)} ({format_value(value, 40)})") from None
    except ValueError:
        number = math.nan
    if not (number >= 0 if zero else number > 0):
        raise ValueError(f"{name} must be {what}{in_unit}, got {format_value(value)}")
    return number


def length(value, name: str) -> float:
    """A length in m within :data:`LENGTH_RANGE` (Arm.length, Circle.radius, ...), as float.

    Examples
    --------
    >>> length(1e-300, "Circle.radius")
    Traceback (most recent call last):
    ...
    ValueError: Circle.radius must be a length in m between 1e-12 and 1e+12, got 1e-300
    """
    number = positive(value, name, "m")
    low, high = LENGTH_RANGE
    if not low <= number <= high:
        raise ValueError(f"{name} must be a length in m between {low:g} and {high:g}, got "
                         f"{format_value(value)}")
    return number


def count(value, name: str, minimum: int = 0) -> int:
    """An integer >= ``minimum`` (Python or numpy integer; not a bool or a float), as int."""
    if type(value) is int and value >= minimum:  # the common case, first
        return value
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (Integral, np.integer)):
        raise TypeError(f"{name} must be an integer, got {_kind(value)} "
                        f"({format_value(value, 40)})")
    if value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {format_value(value)}")
    return int(value)


def format_bytes(size: float) -> str:
    """``size`` bytes in a readable unit, e.g. ``'224 GB'`` (powers of 1000)."""
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if size < 1000 or unit == "PB":
            return f"{size:.3g} {unit}"
        size /= 1000
    raise AssertionError("unreachable")  # pragma: no cover


@functools.cache
def memory_limit() -> int:
    """The most one result may take, in bytes: half the physical memory of this machine (the
    solver's work arrays and an export need room too), or 2⁴⁰ where that is unknown. Read
    once per process."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES")) // 2
    except (AttributeError, ValueError, OSError):  # pragma: no cover - e.g. Windows
        return 1 << 40


def check_array_size(shape, name: str) -> None:
    """ValueError naming ``name`` if a float64 array of this shape (an input softarm copies,
    e.g. a zero-copy ``np.broadcast_to`` view) cannot fit in :func:`memory_limit`."""
    size = 8.0 * math.prod(int(n) for n in shape)  # (exact: Python ints)
    if size > memory_limit():
        raise ValueError(
            f"{name}: an array of shape {tuple(int(n) for n in shape)} would need "
            f"{format_bytes(size)} of memory as softarm's own float64 copy, more than the "
            f"{format_bytes(memory_limit())} (half of this machine's memory) one result may "
            "take; solve fewer cases at a time")


#: The most work (bytes) any route needs per load case of a part beside its result
#: (measured: the elastica's batch route, its quadrature, about 10 kB; the solver 1-2 kB)
WORK_PER_CASE = 12_288
#: The solver's parts (statics.solver.CASES_PER_PART): its work is about 2 kB a case, and
#: each part's result is copied into the whole batch's (the closed forms write in place)
CASES_PER_PART = PART_BYTES // 2048


def check_allocation(cases, stations, name: str = "the result", *,
                     per_station: float = BYTES_PER_STATION,
                     per_case: float = BYTES_PER_CASE,
                     hint: str = "solve fewer cases or stations at a time") -> int:
    """Reject, before allocating, a result of ``cases`` × ``stations`` that cannot fit in memory.

    The output of one solve is a pose, strains and stresses per load case and station
    (:data:`BYTES_PER_STATION`; more with Jacobians: ``per_station``) and a few numbers per
    case (``per_case``), plus the work the solve needs beside it: a batch is solved in parts
    of at most :data:`PART_BYTES` of work (:data:`WORK_PER_CASE` a case; counted three times:
    the part being solved and what the allocator still holds of the one before), and the
    solver copies each part's result into the whole batch's (:data:`CASES_PER_PART` cases,
    twice). ValueError naming the sizes and the memory they would need if that exceeds
    :func:`memory_limit`; else the number of bytes. ``hint``: what the message advises (a
    simulation's runs: fewer steps at a time).

    Examples
    --------
    >>> try:
    ...     check_allocation(10**7, 101, "loads")
    ... except ValueError as error:
    ...     print(str(error)[:69])
    loads: 10000000 load cases × 101 stations would need 234 GB of memory
    """
    result = float(stations) * per_station
    work = 3.0 * min(PART_BYTES, float(cases) * WORK_PER_CASE)
    if cases > CASES_PER_PART:  # the solver's part results, copied in (up to 2 at once)
        work += 2.0 * CASES_PER_PART * (result + per_case)
    size = float(cases) * (result + per_case) + work
    limit = memory_limit()
    if size > limit:
        raise ValueError(
            f"{name + ': ' if name else ''}{cases} load case{'s' if cases != 1 else ''} × "
            f"{stations} stations would need "
            f"{format_bytes(size)} "
            "of memory for the result and its solve, more than the "
            f"{format_bytes(limit)} (half of this machine's memory) one result may take; {hint}"
        )
    return int(size)


def rigid_transform(value, name: str = "base") -> np.ndarray:
    """A single 4×4 rigid transform [[R, p], [0, 0, 0, 1]] with R exactly orthonormal.

    A nearly rigid pose (‖RᵀR − I‖ ≤ :data:`ROTATION_TOLERANCE`, entrywise, det R > 0, e.g.
    printed to a few digits or stored in float32) is re-orthonormalised to the nearest rotation
    (polar decomposition, R → U Vᵀ from the SVD R = U S Vᵀ); anything else is rejected with a
    ValueError naming ``name``. Returns a fresh float64 array.

    Examples
    --------
    >>> H = np.eye(4); H[:3, :3] = [[1.0, 1e-7, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    >>> R = rigid_transform(H)[:3, :3]
    >>> bool(np.allclose(R.T @ R, np.eye(3), rtol=0.0, atol=1e-15))
    True
    """
    H = as_matrices(value, name, 4)
    if H.shape != (4, 4):
        raise ValueError(f"{name} must be a single 4×4 rigid transform, got shape {H.shape}")
    R = H[:3, :3]
    deviation = float(np.max(np.abs(R.T @ R - np.eye(3))))
    if not (np.allclose(H[3], [0.0, 0.0, 0.0, 1.0], rtol=0.0, atol=1e-12)
            and deviation <= ROTATION_TOLERANCE and np.linalg.det(R) > 0.0):
        raise ValueError(
            f"{name} must be a rigid transform [[R, p], [0, 0, 0, 1]] with R a proper rotation "
            f"(RᵀR = I to {ROTATION_TOLERANCE:g}, det R = +1, last row 0, 0, 0, 1), got "
            f"{format_value(H.tolist(), 200)}"
        )
    U, _, Vt = np.linalg.svd(R)
    out = np.eye(4)
    out[:3, :3] = U @ Vt
    out[:3, 3] = H[:3, 3]
    return out


def stations(s, length: float, name: str = "s", default: int = 101) -> np.ndarray:
    """Arc-length stations: ``default`` uniform points on [0, L] if None, else validated.

    An int gives that many uniform stations (checked against the memory first, see
    :func:`check_allocation`). An array is checked to be strictly increasing within [0, L],
    up to the rounding of its own precision (float32 stations ending at float32(L) are
    accepted), and clipped to [0, L].
    """
    if s is None:
        return np.linspace(0.0, length, default)
    if isinstance(s, (int, np.integer)) and not isinstance(s, (bool, np.bool_)):
        if s < 2:
            raise ValueError(f"{name} as a count of stations must be >= 2, got {s}")
        check_allocation(1, int(s), name)
        return np.linspace(0.0, length, int(s))
    array = as_array(s, name)
    if array.ndim != 1 or array.size < 1:
        raise ValueError(f"{name} must be a 1-D array of stations in m, got shape {array.shape}")
    given = s.dtype if isinstance(s, np.ndarray) else np.asarray(s).dtype
    eps = np.finfo(given).eps if given.kind == "f" else np.finfo(np.float64).eps
    tolerance = 8 * max(float(eps), float(np.finfo(np.float64).eps)) * length
    if array[0] < -tolerance or array[-1] > length + tolerance:
        raise ValueError(
            f"{name} must lie in [0, L] = [0, {format_value(length)}] m, got "
            f"[{format_value(array[0])}, {format_value(array[-1])}]"
        )
    if np.any(np.diff(array) <= 0):
        raise ValueError(f"{name} must be strictly increasing, got {format_value(s)}")
    return np.clip(array, 0.0, length)
