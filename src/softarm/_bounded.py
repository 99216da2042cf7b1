"""Bounded least squares for the bounded Newton methods of the solver (displacement-controlled
tendons, ``softarm.statics``) and of inverse statics (``softarm.control``): numpy only, below
both in the layering."""

from __future__ import annotations

import numpy as np

__all__ = ["box_least_squares"]


def box_least_squares(A, b, lower, upper, iterations: int = 100):
    """argmin |A x - b|² subject to lower <= x <= upper (A of full column rank; 0 feasible),
    by an active-set method (bounded-variable least squares, Stark & Parker 1995): the free
    variables solved by least squares; a variable that would leave its box is fixed at the
    bound it reaches first along the way; a fixed one is freed when the objective's slope
    points into the box."""
    n = A.shape[1]
    x = np.zeros(n)
    fixed = np.zeros(n, dtype=bool)
    for _ in range(iterations):
        free = ~fixed
        z = x.copy()
        if free.any():
            z[free] = np.linalg.lstsq(A[:, free], b - A[:, fixed] @ x[fixed], rcond=None)[0]
        below, above = free & (z < lower), free & (z > upper)
        if below.any() or above.any():
            d = z - x
            with np.errstate(divide="ignore", invalid="ignore"):
                t = np.where(below, (lower - x) / d, np.where(above, (upper - x) / d, np.inf))
            k = int(np.argmin(t))
            x[free] += np.clip(t[k], 0.0, 1.0) * d[free]
            x[k] = lower[k] if below[k] else upper[k]
            fixed[k] = True
            continue
        x = z
        g = A.T @ (A @ x - b)  # the objective's slope (half of it)
        wants_in = fixed & (((x <= lower) & (g < 0.0)) | ((x >= upper) & (g > 0.0)))
        if not wants_in.any():
            return x
        fixed[int(np.argmax(np.abs(g) * wants_in))] = False
    return np.clip(x, lower, upper)
