"""The compiled bounded least-squares step of ``softarm._bounded`` (numba; imported on first
use, so ``import softarm`` does not import numba).

Its own compiled module: nothing here calls the solver's kernels, and nothing there calls
this, so numba's per-file cache sees every change (``statics/README.md``).
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np

from ._jit import jit

_jit = partial(jit, what="the bounded least-squares step")


@_jit
def _free_least_squares(A, b, x, fixed, z, work, rhs):
    """z = x with the free variables replaced by argmin |A z - b|² over them (the fixed ones
    held at x), by Householder QR of the free columns (``work``: A's shape, ``rhs``: b's).
    A free variable whose column is dependent on the others (|R_kk| at round-off of the
    largest) is held at x: the basic solution, which the callers' full-rank A never meets."""
    m, n = A.shape
    k = 0  # the free columns, packed to the left of work
    for i in range(m):
        acc = b[i]
        for j in range(n):
            if fixed[j]:
                acc -= A[i, j] * x[j]
        rhs[i] = acc
    for j in range(n):
        z[j] = x[j]
        if not fixed[j]:
            for i in range(m):
                work[i, k] = A[i, j]
            k += 1
    largest = 0.0
    for c in range(k):  # Householder reflection of column c, applied to the rest and to rhs
        norm = 0.0
        for i in range(c, m):
            norm += work[i, c] * work[i, c]
        norm = math.sqrt(norm)
        if norm == 0.0:
            continue
        alpha = -norm if work[c, c] >= 0.0 else norm
        work[c, c] -= alpha  # v = column - alpha e_c, stored in place below the diagonal
        vv = 0.0
        for i in range(c, m):
            vv += work[i, c] * work[i, c]
        for cc in range(c + 1, k):
            dot = 0.0
            for i in range(c, m):
                dot += work[i, c] * work[i, cc]
            f = 2.0 * dot / vv
            for i in range(c, m):
                work[i, cc] -= f * work[i, c]
        dot = 0.0
        for i in range(c, m):
            dot += work[i, c] * rhs[i]
        f = 2.0 * dot / vv
        for i in range(c, m):
            rhs[i] -= f * work[i, c]
        work[c, c] = alpha  # R's diagonal
        largest = max(largest, abs(alpha))
    solution = np.zeros(k)
    for c in range(k - 1, -1, -1):  # back substitution R u = Qᵀ rhs
        if c >= m or abs(work[c, c]) <= 1e-14 * largest:
            continue
        acc = rhs[c]
        for cc in range(c + 1, k):
            acc -= work[c, cc] * solution[cc]
        solution[c] = acc / work[c, c]
    c = 0
    for j in range(n):
        if not fixed[j]:
            if c < m and abs(work[c, c]) > 1e-14 * largest:
                z[j] = solution[c]
            c += 1


@_jit
def box_least_squares(A, b, lower, upper, iterations):
    """argmin |A x - b|² subject to lower <= x <= upper (A of full column rank; 0 feasible),
    by an active-set method (bounded-variable least squares, Stark & Parker 1995): the free
    variables solved by least squares; a variable that would leave its box is fixed at the
    bound it reaches first along the way; a fixed one is freed when the objective's slope
    points into the box. Returns x clipped to the box (the last iterate after ``iterations``
    without convergence)."""
    m, n = A.shape
    x = np.zeros(n)
    z = np.zeros(n)
    fixed = np.zeros(n, dtype=np.bool_)
    work = np.empty((m, n))
    rhs = np.empty(m)
    converged = False
    for _ in range(iterations):
        _free_least_squares(A, b, x, fixed, z, work, rhs)
        first, k = np.inf, -1  # the first free variable to reach a bound on the way x → z
        for j in range(n):
            if fixed[j]:
                continue
            if z[j] < lower[j]:
                t = (lower[j] - x[j]) / (z[j] - x[j])
            elif z[j] > upper[j]:
                t = (upper[j] - x[j]) / (z[j] - x[j])
            else:
                continue
            if t < first:
                first, k = t, j
        if k >= 0:
            t = min(max(first, 0.0), 1.0)
            for j in range(n):
                if not fixed[j]:
                    x[j] += t * (z[j] - x[j])
            x[k] = lower[k] if z[k] < lower[k] else upper[k]
            fixed[k] = True
            continue
        for j in range(n):
            x[j] = z[j]
        best, k = 0.0, -1  # the fixed variable whose slope points most into the box
        for j in range(n):
            if not fixed[j]:
                continue
            g = 0.0  # the objective's slope (half of it), (Aᵀ (A x - b))_j
            for i in range(m):
                r = -b[i]
                for jj in range(n):
                    r += A[i, jj] * x[jj]
                g += A[i, j] * r
            if (x[j] <= lower[j] and g < 0.0) or (x[j] >= upper[j] and g > 0.0):
                if abs(g) > best:
                    best, k = abs(g), j
        if k < 0:
            converged = True
            break
        fixed[k] = False
    for j in range(n):
        x[j] = min(max(x[j], lower[j]), upper[j])
    return x, converged


@_jit
def regularised_step(J, b, q, scales, mu, lower, upper, iterations):
    """The bounded Gauss–Newton step of inverse statics, in scaled inputs u = q / s:
    argmin |J' δu - b|² + μ σ² |δu|² + ε σ² |u + δu|² within the bounds, J' = J s (columns
    scaled), σ = |J'|_F, ε = 1e-12 (root 1e-6); returns δq = s δu. The stacked system built
    here, one call instead of a dozen numpy ones per step."""
    m, n = J.shape
    sigma = 0.0
    for i in range(m):
        for j in range(n):
            sigma += (J[i, j] * scales[j]) ** 2
    sigma = max(math.sqrt(sigma), 1e-300)
    root_eps = 1e-6
    A = np.zeros((m + 2 * n, n))
    rhs = np.zeros(m + 2 * n)
    lo = np.empty(n)
    hi = np.empty(n)
    for i in range(m):
        rhs[i] = b[i]
        for j in range(n):
            A[i, j] = J[i, j] * scales[j]
    for j in range(n):
        u = q[j] / scales[j]
        A[m + j, j] = math.sqrt(mu) * sigma
        A[m + n + j, j] = root_eps * sigma
        rhs[m + n + j] = -root_eps * sigma * u
        lo[j] = lower[j] / scales[j] - u
        hi[j] = upper[j] / scales[j] - u
    step, _ = box_least_squares(A, rhs, lo, hi, iterations)
    for j in range(n):
        step[j] *= scales[j]
    return step
