"""Bounded least squares for the bounded Newton methods of the solver (displacement-controlled
tendons, ``softarm.statics``) and of inverse statics (``softarm.control``), below both in the
layering. The step is compiled (``_bounded_kernels``, imported on first use): a control loop
takes one per iteration, where scipy's bounded least squares costs about 90 µs a call."""

from __future__ import annotations

import numpy as np

__all__ = ["box_least_squares"]


def box_least_squares(A, b, lower, upper, iterations: int = 100):
    """argmin |A x - b|² subject to lower <= x <= upper, shape (n,), for A (m, n) of full
    column rank and a box that contains 0 (bounds may be ±inf), by an active-set method
    (bounded-variable least squares, Stark & Parker 1995): the free variables solved by
    Householder least squares; a variable that would leave its box is fixed at the bound it
    reaches first along the way; a fixed one is freed when the objective's slope points into
    the box. After ``iterations`` without convergence, the last iterate (in the box)."""
    from ._bounded_kernels import box_least_squares as compiled

    def floats(value):
        return np.ascontiguousarray(value, dtype=np.float64)

    x, _ = compiled(floats(A), floats(b), floats(lower), floats(upper), int(iterations))
    return x
