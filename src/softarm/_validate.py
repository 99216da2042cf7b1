"""Input coercion and validation shared by every public entry point.

Every failure is a ValueError (or TypeError) that names the parameter, what was expected and what
was received, so a user never has to read a traceback to learn what to fix.
"""

from __future__ import annotations

import math
from numbers import Real

import numpy as np

__all__ = ["as_array", "as_matrices", "as_vectors", "positive", "stations"]


def as_array(value, name: str) -> np.ndarray:
    """``value`` as a finite float64 array, or ValueError/TypeError naming ``name``."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise TypeError(f"{name} must be numeric, got {value!r}") from error
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got {value!r}")
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


def positive(value, name: str, unit: str) -> float:
    """A positive finite real number, as float."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise TypeError(f"{name} must be a positive number in {unit}, got {value!r}")
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive finite value in {unit}, got {value!r}")
    return float(value)


def stations(s, length: float, name: str = "s", default: int = 101) -> np.ndarray:
    """Arc-length stations: ``default`` uniform points on [0, L] if None, else validated."""
    if s is None:
        return np.linspace(0.0, length, default)
    if isinstance(s, (int, np.integer)) and not isinstance(s, bool):
        if s < 2:
            raise ValueError(f"{name} as a count of stations must be >= 2, got {s}")
        return np.linspace(0.0, length, int(s))
    array = as_array(s, name)
    if array.ndim != 1 or array.size < 1:
        raise ValueError(f"{name} must be a 1-D array of stations in m, got shape {array.shape}")
    tolerance = 8 * np.finfo(float).eps * length
    if array[0] < -tolerance or array[-1] > length + tolerance:
        raise ValueError(
            f"{name} must lie in [0, L] = [0, {length!r}] m, got [{array[0]!r}, {array[-1]!r}]"
        )
    if np.any(np.diff(array) <= 0):
        raise ValueError(f"{name} must be strictly increasing, got {s!r}")
    return np.clip(array, 0.0, length)
