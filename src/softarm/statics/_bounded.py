"""Bounded least squares for the bounded Newton methods of the solver (displacement-controlled
tendons, :mod:`softarm.statics.displacement`) and of inverse statics (:mod:`softarm.control`).
The step is compiled (softarm/kernels/inverse.py, beside inverse statics' compiled iteration,
which calls it): a control loop takes one per iteration, where scipy's bounded least squares
costs about 90 µs a call."""

from __future__ import annotations

import numpy as np

from .. import kernels

__all__ = ["box_least_squares", "regularised_step"]


def _floats(value):
    return np.ascontiguousarray(value, dtype=np.float64)


def box_least_squares(A, b, lower, upper, iterations: int = 100):
    """argmin |A x - b|² subject to lower <= x <= upper, shape (n,), for A (m, n) of full
    column rank and a box that contains 0 (bounds may be ±inf), by an active-set method
    (bounded-variable least squares, Stark & Parker 1995): the free variables solved by
    Householder least squares; a variable that would leave its box is fixed at the bound it
    reaches first along the way; a fixed one is freed when the objective's slope points into
    the box. After ``iterations`` without convergence, the last iterate (in the box)."""
    x, _ = kernels.box_least_squares(_floats(A), _floats(b), _floats(lower),
                                         _floats(upper), int(iterations))
    return x


def regularised_step(J, b, q, scales, mu, lower, upper, iterations: int = 100, *,
                     redundant: bool = True):
    """The bounded Gauss–Newton step δq of inverse statics: in scaled inputs u = q/s,
    argmin |J s δu - b|² + μ σ² |δu|² + ε σ² |u + δu|² subject to lower <= q + δq <= upper,
    σ = |J s|_F, δq = s δu; :func:`box_least_squares` of the stacked system, built in
    compiled code. ε = 1e-12 for a ``redundant`` task (the least effort along its null
    space, moving the task solution by ~1e-12 relative), else 0 (it would only bias the
    answer: along J s's weakest direction, of singular value σ / c, it weighs ε c²)."""
    k = kernels
    return k.regularised_step(_floats(J), _floats(b), _floats(q), _floats(scales), float(mu),
                              k.EFFORT if redundant else 0.0, _floats(lower), _floats(upper),
                              int(iterations))
