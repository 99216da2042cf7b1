"""Small dense and banded linear algebra of the kernels: Gaussian elimination of the 6 × 6
shooting systems, the branch guard's eigenvalue test (``_crossings``) and the banded LU of
multiple shooting and of the dynamics' step."""

from __future__ import annotations

import math

import numpy as np

from ._compile import _jit


@_jit
def _eliminate(M):
    """Gaussian elimination with partial pivoting of the 6 rows of M in place (the first 6
    columns are the matrix, any further ones right-hand sides). Returns the sign of the
    determinant (the permutation's sign times the pivots'), 0.0 if singular."""
    return _eliminate_upto(M, np.int64(6), M.shape[1])


@_jit
def _eliminate_upto(M, n, cols):
    """:func:`_eliminate` of the first n rows of M, on its first ``cols`` columns only (the
    first n the matrix)."""
    sign = 1.0
    for c in range(n):
        p = c
        best = abs(M[c, c])
        for i in range(c + 1, n):
            if abs(M[i, c]) > best:
                best = abs(M[i, c])
                p = i
        if not best > 0.0:
            return 0.0
        if p != c:
            sign = -sign
            for k in range(cols):
                M[c, k], M[p, k] = M[p, k], M[c, k]
        if M[c, c] < 0.0:
            sign = -sign
        for i in range(c + 1, n):
            g = M[i, c] / M[c, c]
            for k in range(c, cols):
                M[i, k] -= g * M[c, k]
    return sign


@_jit
def _eliminate_columns(M, k):
    """Solve M[:, :6] X = M[:, 6:6+k] in place (X overwrites those k columns; M[:, :6] is
    destroyed). Returns the sign of the determinant, 0.0 if singular."""
    sign = _eliminate_upto(M, np.int64(6), 6 + k)
    if sign == 0.0:
        return 0.0
    for col in range(6, 6 + k):
        for c in range(5, -1, -1):
            acc = M[c, col]
            for i in range(c + 1, 6):
                acc -= M[c, i] * M[i, col]
            M[c, col] = acc / M[c, c]
    return sign


@_jit
def _linear_solve(A, b, out):
    """out = A[:, :6]⁻¹ b; False if singular or not finite."""
    M = np.empty((6, 7))
    for i in range(6):
        for k in range(6):
            M[i, k] = A[i, k]
        M[i, 6] = b[i]
    if _eliminate(M) == 0.0:
        return False
    for c in range(5, -1, -1):
        acc = M[c, 6]
        for k in range(c + 1, 6):
            acc -= M[c, k] * out[k]
        out[c] = acc / M[c, c]
    for c in range(6):
        if not math.isfinite(out[c]):
            return False
    return True


@_jit
def _copy(src, dst):
    for i in range(src.size):
        dst.flat[i] = src.flat[i]


# ---------------------------------------------------------------------------- stability
#
# The second-variation test of an equilibrium with a clamped base and a free tip (docs/
# stability.md): the linearised equations integrated from the tip towards the base, seeded
# with the free-end conditions (each seed moves the tip section by a unit rotation, or with
# a position-dependent load also a unit translation, and carries the δn, δm that keep the
# linearised tip condition), count the points s in [0, L) where the (δp; δθ) block Θ(s) of
# that family is singular (conjugate points). Their number with multiplicity is the Morse
# index of the equilibrium: 0 means stable (for conservative loads).

# A step whose transition Θ_k⁻¹ Θ_k+1 is within this Frobenius distance of the identity
# has every eigenvalue in the disc |μ - 1| < 0.5: no crossing, no eigenvalue solve.
_NEAR_IDENTITY = 0.5


@_jit
def _small_solve(A, B, n, work, out):
    """out = A⁻¹ B for an n × n A and B of n rows (:func:`_eliminate_upto` on [A | B], work
    n × (n + B's columns)); False if A is singular."""
    cols = B.shape[1]
    for i in range(n):
        for k in range(n):
            work[i, k] = A[i, k]
        for k in range(cols):
            work[i, n + k] = B[i, k]
    if _eliminate_upto(work, n, n + cols) == 0.0:
        return False
    for col in range(cols):
        for c in range(n - 1, -1, -1):
            acc = work[c, n + col]
            for i in range(c + 1, n):
                acc -= work[c, i] * out[i, col]
            out[c, col] = acc / work[c, c]
    return True


@_jit
def _discs_right_of(M, n, edge):
    """True if every eigenvalue of M (n × n) has a real part >= ``edge`` by Gershgorin's
    theorem: every row's disc (centre M_ii, radius Σ_j≠i |M_ij|) lies right of it, or every
    column's. A cheap sufficient test, before the eigenvalues."""
    rows = cols = True
    for i in range(n):
        r = c = 0.0
        for j in range(n):
            if j != i:
                r += abs(M[i, j])
                c += abs(M[j, i])
        rows = rows and M[i, i] - r >= edge
        cols = cols and M[i, i] - c >= edge
    return rows or cols


@_jit
def _crossings(old, new, n, work, M, floor):
    """How many zeros of det Θ lie between two consecutive points of the sweep, with their
    multiplicity: the eigenvalues of Θ_old⁻¹ Θ_new with a negative real part. Away from a
    conjugate point that matrix is I + O(h); a direction in which Θ passes through zero
    between the two points has a negative eigenvalue (the ratio of its values there), a
    direction that only comes near zero a positive one. So a double root (a round section,
    det Θ touching zero without changing sign) counts twice, and a near miss not at all.
    Eigenvalues with a real part in [-floor, 0) are not counted. Returns -1 if Θ_old is
    singular (a conjugate point exactly on the grid)."""
    if not _small_solve(old, new, n, work, M):
        return -1
    dist = 0.0
    for i in range(n):
        for k in range(n):
            e = M[i, k] - (1.0 if i == k else 0.0)
            dist += e * e
    if dist < _NEAR_IDENTITY * _NEAR_IDENTITY or _discs_right_of(M, n, -floor):
        return 0
    C = np.empty((n, n), dtype=np.complex128)
    for i in range(n):
        for k in range(n):
            C[i, k] = M[i, k]
    values = np.linalg.eigvals(C)
    count = 0
    for i in range(n):
        if values[i].real < -floor:
            count += 1
    return count


@_jit
def _band_factor(B, n, kl, pivots, Lm):
    """Gaussian elimination with partial pivoting of the band matrix B (n rows; row r holds
    columns r - kl .. r + 2 kl, the last kl for the fill of the row exchanges; the upper
    width is at most kl) in place: U in B, the multipliers in Lm, and in ``pivots`` (3, n)
    the row exchanges (row 0) and the factors' extents (LAPACK's gbtrf, written out, with
    the extents). Returns the sign of the determinant, 0.0 if singular.

    Design note: the extents. The systems solved here are staircases (the rows of a
    shooting interval or of a time step's interval touch the unknowns of its two nodes
    only): half of the band is zero, in L and in U, and stays so. So each row of U keeps the
    last column it can hold a nonzero in (``pivots[2]``: its own at first, grown by the
    rows subtracted from it), and each column of L the last row with a nonzero multiplier
    (``pivots[1]``); elimination and :func:`_band_solve` stop there. Measured on the
    dynamics' step (40 stations: 708 unknowns, kl = 29): a solve 62 -> 27 µs, a
    factorisation 620 -> 280 µs (benchmarks/dynamics.py for the step)."""
    sign = 1.0
    for r in range(n):  # each row's last nonzero column
        e = r
        for col in range(min(n - 1, r + 2 * kl), r, -1):
            if B[r, col - r + kl] != 0.0:
                e = col
                break
        pivots[2, r] = e
    for c in range(n):
        last = min(n - 1, c + kl)
        p = c
        best = abs(B[c, kl])
        for r in range(c + 1, last + 1):
            v = abs(B[r, c - r + kl])
            if v > best:
                best = v
                p = r
        if not (best > 0.0 and math.isfinite(best)):
            return 0.0
        pivots[0, c] = p
        if p != c:
            sign = -sign
            right = min(c + 2 * kl, max(pivots[2, c], pivots[2, p]))
            for col in range(c, right + 1):
                a = B[c, col - c + kl]
                B[c, col - c + kl] = B[p, col - p + kl]
                B[p, col - p + kl] = a
            e = pivots[2, c]
            pivots[2, c] = pivots[2, p]
            pivots[2, p] = e
        pivot = B[c, kl]
        if pivot < 0.0:
            sign = -sign
        right = pivots[2, c]
        lowest = c
        for r in range(c + 1, last + 1):
            g = B[r, c - r + kl] / pivot
            Lm[c, r - c - 1] = g
            B[r, c - r + kl] = 0.0
            if g != 0.0:
                lowest = r
                for col in range(c + 1, right + 1):
                    B[r, col - r + kl] -= g * B[c, col - c + kl]
                if right > pivots[2, r]:
                    pivots[2, r] = right
        pivots[1, c] = lowest
    return sign


@_jit
def _band_solve(B, n, kl, pivots, Lm, b):
    """b ← A⁻¹ b from :func:`_band_factor`'s factors. False if the result is not finite."""
    for c in range(n):
        p = pivots[0, c]
        if p != c:
            a = b[c]
            b[c] = b[p]
            b[p] = a
        for r in range(c + 1, pivots[1, c] + 1):
            b[r] -= Lm[c, r - c - 1] * b[c]
    for c in range(n - 1, -1, -1):
        # four partial sums: one sum's chain of dependent additions is latency bound
        # (measured 88 -> 30 µs a solve of 726 unknowns, kl = 29)
        a0, a1, a2, a3 = b[c], 0.0, 0.0, 0.0
        last = pivots[2, c]
        col = c + 1
        while col + 3 <= last:
            o = col - c + kl
            a0 -= B[c, o] * b[col]
            a1 -= B[c, o + 1] * b[col + 1]
            a2 -= B[c, o + 2] * b[col + 2]
            a3 -= B[c, o + 3] * b[col + 3]
            col += 4
        while col <= last:
            a0 -= B[c, col - c + kl] * b[col]
            col += 1
        b[c] = ((a0 + a1) + (a2 + a3)) / B[c, kl]
        if not math.isfinite(b[c]):
            return False
    return True
