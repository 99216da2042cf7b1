"""Compiled kernels of the shooting solver (numba; the closed forms' one-load kernels are in
analytic/_compiled.py), with the bounded least squares of the bounded Newton methods and the
compiled iteration of inverse statics, which call them (sections at the end).

Design notes (layouts, the stage machine, why this file is whole): ``README.md`` beside it.

State along the arm, from the clamped base to the tip: centreline p (3), material frame R
(3×3, row-major), internal force n and moment m in *spatial* components (3 + 3):

    p' = R v,   R' = R û,   n' = -(f_d + R f_f),   m' = -p' × n - (l_d + R l_f),
    (v; u) = strain(Rᵀn, Rᵀm)   (today f⁰ + K⁻¹ (Rᵀn; Rᵀm), the linear law),

the static Cosserat (Simo–Reissner) rod (Grazioso et al. 2018, eq. 20, with the stress
resultant in spatial components), under distributed forces and moments that are dead (d,
spatial components) or follower (f, material components). Point wrenches make n and m jump.
The unknowns are the base reaction x = (n(0); m(0)); the tip boundary condition is

    r(x, λ) = (n(L) - F_d - R(L) F_f;  m(L) - M_d - R(L) M_f) = 0.

Every load is affine in the load factor λ: load(λ) = start + λ (end - start), the homotopy that
the continuation follows (start = 0: the unloaded arm; start = the previous case: a slowly
driven arm).

Integration: classical RK4 with R projected back onto SO(3) after every step (one Björck step,
R ← R (3I - RᵀR)/2, Hairer–Lubich–Wanner, *Geometric Numerical Integration*, §IV.4). The
tangents (δp, δθ, δn, δm), δR = R δθ~ with δθ in material components, are integrated with the
same stages:

    δθ' = -u × δθ + δu,   δp' = R (δθ × v + δv),
    δn' = -R (δθ × f_f) - ∂_λ(f_d + R f_f),
    δm' = -δp' × n - p' × δn - R (δθ × l_f) - ∂_λ(l_d + R l_f),
    (δv; δu) = dstrain(Rᵀδn + σ_n × δθ;  Rᵀδm + σ_m × δθ),

where the ∂_λ terms belong to the load-factor column only. Columns 0-5 are the derivatives
with respect to x (δn(0), δm(0) = e_d), column 6 the one with respect to λ.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
from numba.core import types

from .._jit import jit, on_cold_compile
from . import _prefetch

__all__ = ["MEMORY", "OPTIONS", "PIECE_LOADS", "TIP_LOADS", "shoot", "solve_cases"]


# Integer constants passed to compiled callees are written np.int64(k): a bare literal makes
# numba compile the callee once more for the type Literal[int](k), and every such version is
# linked and optimised again in each caller's module (cold compile time).

#: numba's cached compile (in memory, with a warning, where the cache cannot be written)
_jit = partial(jit, what="the shooting solver's kernels")
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
_inline = partial(jit, what="the shooting solver's kernels", inline="always")


def _entry(capability, **options):
    """The decorator of an entry point (a kernel called from Python): compiled and announced
    per capability (``capability``: argument types -> (key, text), softarm._jit). The batch
    entry points take ``nogil=True``: a batch runs in threads (chunks of independent cases:
    Solver's ``threads``)."""
    return partial(jit, what="the shooting solver's kernels", capability=capability, **options)


def _given(argument) -> bool:
    """Whether an optional argument's type is given (not None): the capabilities of a compile
    (None arguments prune their code, README.md)."""
    return not isinstance(argument, types.NoneType)


def _solver(args):
    """solve_cases' capability: passive or actuated (``act``), chained (``memory``), with
    Jacobians (``inputs``)."""
    actuated, chained, jacobians = _given(args[2]), _given(args[7]), _given(args[8])
    key = "+".join(["actuated" if actuated else "solve"] + ["chained"] * chained
                   + ["jacobians"] * jacobians)
    text = "the solver for " + ("actuated, magnetic or touching arms" if actuated
                                else "passive arms")
    text += " (quasi-static, chained)" * chained + " with Jacobians" * jacobians
    return key, text


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



# Status codes returned per load case.
OK = 0
NEWTON_FAILED = 1  # the corrector did not converge at the final load (refinement)
TOO_MANY_STEPS = 2  # the error estimate stayed above tol up to the largest step count
PATH_FAILED = 3  # the loading path could not be followed past a load factor (x: its last point)
BUDGET = 4  # the shooting budget ran out
NOT_FINITE = 5  # the state became non-finite at an accepted point
SINGULAR = 6  # jacobians: ∂r/∂x is singular at the solution (no compliance exists there)

# Layout of the state y (18) and of each tangent row (12).
_P, _R, _N, _M = 0, 3, 12, 15
_TP, _TT, _TN, _TM = 0, 3, 6, 9
NT = 12
LAM = 6  # the tangent column of the load factor

# Per-piece load channels (PIECE_LOADS = 37, then one column per actuator): distributed dead
# force (spatial), follower force (material), dead moment, follower moment, each per unit
# length; the point wrench at the piece start, dead (spatial) and follower (material); the
# magnetic field B(x) = B0 + G x (B0 in T, G row-major in T/m, spatial; the same on every
# piece); from ACT on, each actuator's magnitude on this piece (0 where it does not act):
# a tendon's tension τ (N), a chamber's pressure times area p A (N).
FD, FF, LD, LF, JD, JF = _FD, _FF, _LD, _LF, _JD, _JF = 0, 3, 6, 9, 12, 18
FB, FG = _FB, _FG = 24, 27
# The contact's penalty scale: 1 with a Contact (0 without), so that a path from the
# unloaded arm (λ from 0 to 1) stiffens the contact with the loads (contact.md, "The path").
CT = _CT = 36
PIECE_LOADS = 37
ACT = _ACT = 37
# Actuator kinds (``act``'s ``kinds``).
TENDON, CHAMBER = 0, 1
# The columns of an actuator's routing row (``act``'s ``routes``): a bound of its
# distance from the centreline (m, for load sizes), the helix radius (m), angular rate
# 2π n (rad/m) and phase (rad), then D power-series coefficients of y(s), then D of z(s).
_RHO, _HR, _HW, _HP, _POLY = 0, 1, 2, 3, 4
# Newton on the actuated constitutive law: the largest number of iterations, and the size
# of a correction (strain; curvature times L) below which the next would be at round-off.
_LAW_ITER = 30
_LAW_TOL = 1e-9
# A Newton correction no larger than this may be followed by a chord step (_law).
_LAW_CHORD = 1e-3
# Tip channels (TIP_LOADS = 12): the dead tip wrench (spatial), the follower one (material).
TD, TF = _TD, _TF = 0, 6
TIP_LOADS = 12

# Solver options, one float array (OPTIONS long): see solve_cases.
(_O_TOL, _O_ITER, _O_LOADSTEP, _O_NFIXED, _O_NMAX, _O_BUDGET, _O_COARSE, _O_NEAR) = range(8)
OPTIONS = 8

# The memory of a chained (quasi-static) solve, in and out (MEMORY long): x at the coarse
# step count N (6), x at 2N (6), N, valid (1 if the memory holds a solved case), the sign of
# det ∂r/∂x at that solution (N), and in only: a predicted step of x to the next case's
# loads (6) and whether it is given (PreparedSolve: -J_x⁻¹ J_q Δq, see solve_cases).
_MXC, _MXF, _MN, _MVALID, _MSIGN, _MSTEP, _MPREDICTED = 0, 6, 12, 13, 14, 15, 21
MEMORY = 22
MSTEP, MPREDICTED = _MSTEP, _MPREDICTED

# Continuation: largest first-corrector distance accepted, the distance aimed at by the step
# control, largest contraction of successive corrector steps, smallest load-factor step.
_DIST_MAX = 0.15
_DIST_AIM = 0.05
_CONTRACTION_MAX = 0.5
_DLAM_FLOOR = 1e-13
# Corrector steps no larger than this end a corrector on the way (not at λ = 1), and the
# first load step predicts a tip motion of about _FIRST_MOTION (L or rad).
_LOOSE = 1e-2
_FIRST_MOTION = 0.15
# A residual that stops decreasing is accepted within this factor of the threshold (round-off
# of an ill-conditioned shooting map; still 1e-9 of the case's own load).
_STALL = 1e3
# The branch guard (_follow, _ms_follow; docs/solver.md, "Branch guard"). A step across
# which a singular point is detected (_crossings: an eigenvalue of J_before⁻¹ J_after with a
# negative real part, so that a double root, as a round section's two bending planes
# buckling at one load, counts too) is accepted only when no longer than _CROSS_REL times
# the load factor's scale: only a singular point that the path itself passes (a perfect
# bifurcation, like a column compressed exactly along its axis) is crossed; the sharp turn
# of an imperfect one (a load a hair off the axis) is resolved by steps this short.
_CROSS_REL = 1e-7
# A step may not advance the path's phase Φ = ∫ √(F/EI) ds + ½ ∫ M/EI ds (F, M: bounds of
# the loads' forces and moments; Jacobi fields oscillate with about that phase under
# compression or torsion, and a singular point lies about every π of it) by more than
# _PHASE_STEP: at most one crossing per bending direction in a step, which the eigenvalue
# test then sees. Both apply while Φ <= _PHASE_TESTED; beyond, the arm is in strong
# tension (its growing Jacobi fields make J's eigenvalues ill-conditioned), and det's sign
# and the tip's direction of motion guard the path.
_PHASE_STEP = 0.5 * math.pi
_PHASE_TESTED = 12.0
# Refinement of a solution under a change of step count: distances are of the order of the
# discretisation error, far below this.
_REFINE_MAX = 0.05
# A predicted fine solution's output pass is accepted when its Newton step would move the
# arm by less than this fraction of tol (the answer is then that step from the converged one).
_PREDICTED_FINE = 0.01


@_inline
def _strain(C, f0, j, diag, s0, s1, s2, s3, s4, s5):
    """The constitutive step of piece j: strains (v; u) = f⁰ + C σ from the stress σ in
    material components. With ``f0`` zero rows it is the linear map of the tangents
    (dstrain); every future law (tendon coupling) replaces this one function."""
    if diag:
        return (f0[j, 0] + C[j, 0, 0] * s0, f0[j, 1] + C[j, 1, 1] * s1,
                f0[j, 2] + C[j, 2, 2] * s2, f0[j, 3] + C[j, 3, 3] * s3,
                f0[j, 4] + C[j, 4, 4] * s4, f0[j, 5] + C[j, 5, 5] * s5)
    return (f0[j, 0] + C[j, 0, 0] * s0 + C[j, 0, 1] * s1 + C[j, 0, 2] * s2 + C[j, 0, 3] * s3
            + C[j, 0, 4] * s4 + C[j, 0, 5] * s5,
            f0[j, 1] + C[j, 1, 0] * s0 + C[j, 1, 1] * s1 + C[j, 1, 2] * s2 + C[j, 1, 3] * s3
            + C[j, 1, 4] * s4 + C[j, 1, 5] * s5,
            f0[j, 2] + C[j, 2, 0] * s0 + C[j, 2, 1] * s1 + C[j, 2, 2] * s2 + C[j, 2, 3] * s3
            + C[j, 2, 4] * s4 + C[j, 2, 5] * s5,
            f0[j, 3] + C[j, 3, 0] * s0 + C[j, 3, 1] * s1 + C[j, 3, 2] * s2 + C[j, 3, 3] * s3
            + C[j, 3, 4] * s4 + C[j, 3, 5] * s5,
            f0[j, 4] + C[j, 4, 0] * s0 + C[j, 4, 1] * s1 + C[j, 4, 2] * s2 + C[j, 4, 3] * s3
            + C[j, 4, 4] * s4 + C[j, 4, 5] * s5,
            f0[j, 5] + C[j, 5, 0] * s0 + C[j, 5, 1] * s1 + C[j, 5, 2] * s2 + C[j, 5, 3] * s3
            + C[j, 5, 4] * s4 + C[j, 5, 5] * s5)


@_jit
def _route(routes, a, s):
    """Actuator a's path in the section at arc length s: (y, z, dy/ds, dz/ds), m and m/m,
    material frame (a power series in s plus a helix)."""
    D = (routes.shape[1] - _POLY) // 2
    y, z, dy, dz = 0.0, 0.0, 0.0, 0.0
    for k in range(D - 1, -1, -1):  # Horner, value and derivative together
        dy = dy * s + y
        y = y * s + routes[a, _POLY + k]
        dz = dz * s + z
        z = z * s + routes[a, _POLY + D + k]
    radius = routes[a, _HR]
    if radius != 0.0:
        angle = routes[a, _HP] + routes[a, _HW] * s
        c, sn = math.cos(angle), math.sin(angle)
        y += radius * c
        z += radius * sn
        dy -= radius * routes[a, _HW] * sn
        dz += radius * routes[a, _HW] * c
    return y, z, dy, dz


@_jit
def _law(arm, act, j, s, now, law, tangents, s0, s1, s2, s3, s4, s5):
    """The constitutive law of piece j at arc length s with its actuators (Rucker & Webster
    2011, in total-wrench form): the strains ε = (v; u) solving

        K (ε - f⁰) + Σ_tendons τ (t; r × t) = σ + Σ_chambers p A (e1; r × e1),
        t = w/|w|, w = v + u × r + r',

    σ the total wrench (rod, tendons, fluid) in material components, r(s) each actuator's
    path in the section. For τ ≥ 0 the left side is the gradient of a strictly convex
    function, so Newton from the tendons-along-d1 guess (exact for straight tendons on a
    diagonal K) converges to the unique root, to round-off: the last correction is at most
    ``_LAW_TOL`` (strain, curvature × L), so the error left is of its square.

    With ``tangents`` > 0 (the caller maps that many tangent columns with H⁻¹), every
    correction is a Newton step, and on return ``law[0][:, :6]`` holds
    H = K + Σ τ Jᵀ (I - t tᵀ) J / |w|, J = [I, -r~], at the point before the last
    correction (within ``_LAW_TOL`` relative of its value at the root): its LDLᵀ factors
    (:func:`_ldl_correction`) when the 7th value returned is 1.0, else H itself (no
    tendon, or a tension < 0: not definite).
    ``law[1][a]`` = (t, |w|, y, z, dy, dz) of every active actuator at that same point.

    With ``tangents`` = 0 (a state-only stage, a station), a correction that follows a
    Newton step reuses that step's factor (a chord step: the residual only, no new H): its
    own error is of the order of the two corrections' product, so after a small Newton
    step (at most ``_LAW_CHORD``; from the tendons-along-d1 guess, about 1e-4) it converges
    as a Newton step would; a chord step not yet below ``_LAW_TOL`` is followed by a Newton
    step.
    ``law[0]`` is then scratch. NaN strains if Newton fails (|w| → 0: a tendon path folded
    onto itself).
    """
    f0, C, K = arm[3], arm[2], arm[8]
    routes, kinds, active = act[0], act[1], act[2]
    M, tw, vec, jw = law
    length = arm[6]
    rhs, eps = vec[0], vec[2]
    rhs[0], rhs[1], rhs[2], rhs[3], rhs[4], rhs[5] = s0, s1, s2, s3, s4, s5
    g = vec[1]
    for i in range(6):
        g[i] = rhs[i]
    tendons = 0
    for a in range(routes.shape[0]):
        if active[j, a] == 0.0:
            continue
        y, z, dy, dz = _route(routes, a, s)
        tw[a, 4], tw[a, 5], tw[a, 6], tw[a, 7] = y, z, dy, dz
        q = now[j, _ACT + a]
        # the fluid's wrench p A (e1; r × e1), r × e1 = (0, z, -y); a tendon along d1: -τ that
        sign = 1.0 if kinds[a] == CHAMBER else -1.0
        if kinds[a] == CHAMBER:
            rhs[0] += q
            rhs[4] += q * z
            rhs[5] -= q * y
        else:
            tendons += 1
        g[0] += sign * q
        g[4] += sign * q * z
        g[5] -= sign * q * y
    for i in range(6):
        acc = f0[j, i]
        for k in range(6):
            acc += C[j, i, k] * g[k]
        eps[i] = acc
    if tendons == 0:  # (else the factors or H itself overwrite M[:, :6])
        for i in range(6):
            for k in range(6):
                M[i, k] = K[j, i, k]
        return eps[0], eps[1], eps[2], eps[3], eps[4], eps[5], 0.0
    F, H = vec[1], jw
    factored = False  # M[:, :6] holds the LDLᵀ factors of the last Newton step's H
    chord = False  # the next correction may reuse it
    for _ in range(_LAW_ITER):
        newton = not chord
        v0, v1, v2, u0, u1, u2 = eps[0], eps[1], eps[2], eps[3], eps[4], eps[5]
        for i in range(6):
            acc = -rhs[i]
            for k in range(6):
                acc += K[j, i, k] * (eps[k] - f0[j, k])
            F[i] = acc
        if newton:
            for i in range(6):
                for k in range(6):
                    H[i, k] = K[j, i, k]
        for a in range(routes.shape[0]):
            if active[j, a] == 0.0 or kinds[a] == CHAMBER:
                continue
            y, z, dy, dz = tw[a, 4], tw[a, 5], tw[a, 6], tw[a, 7]
            w0 = v0 + u1 * z - u2 * y
            w1 = v1 - u0 * z + dy
            w2 = v2 + u0 * y + dz
            nw = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            inv = 1.0 / nw
            t0, t1, t2 = w0 * inv, w1 * inv, w2 * inv
            tw[a, 0], tw[a, 1], tw[a, 2], tw[a, 3] = t0, t1, t2, nw
            q = now[j, _ACT + a]
            if q == 0.0:
                continue
            # g = Jᵀ t = (t; r × t), r = (0, y, z)
            g0, g1, g2, g3, g4, g5 = t0, t1, t2, y * t2 - z * t1, z * t0, -y * t0
            F[0] += q * g0
            F[1] += q * g1
            F[2] += q * g2
            F[3] += q * g3
            F[4] += q * g4
            F[5] += q * g5
            if not newton:
                continue
            # H += τ/|w| Jᵀ (I - t tᵀ) J = c (JᵀJ - g gᵀ), J = [I | N], N = -r~ =
            # (0 z -y; -z 0 0; y 0 0): JᵀJ = (I N; Nᵀ NᵀN), NᵀN = |r|² I - r rᵀ
            c = q * inv
            H[0, 0] += c
            H[1, 1] += c
            H[2, 2] += c
            H[0, 4] += c * z
            H[4, 0] += c * z
            H[0, 5] -= c * y
            H[5, 0] -= c * y
            H[1, 3] -= c * z
            H[3, 1] -= c * z
            H[2, 3] += c * y
            H[3, 2] += c * y
            H[3, 3] += c * (y * y + z * z)
            H[4, 4] += c * z * z
            H[5, 5] += c * y * y
            H[4, 5] -= c * y * z
            H[5, 4] -= c * y * z
            g = (g0, g1, g2, g3, g4, g5)
            for i in range(6):
                ci = c * g[i]
                for k in range(6):
                    H[i, k] -= ci * g[k]
        if not newton:
            _ldl_solve(M, F)  # the chord step, with the factors of the step before
        elif _ldl_correction(H, F, M):
            factored = True
        else:  # τ < 0 somewhere: not definite
            factored = False
            for i in range(6):
                for k in range(6):
                    M[i, k] = H[i, k]
                M[i, 6] = -F[i]
            if _eliminate_columns(M, np.int64(1)) == 0.0:
                return np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, 0.0
        size = 0.0
        for i in range(6):
            eps[i] += M[i, 6]
            size = max(size, abs(M[i, 6]) * (length if i >= 3 else 1.0))
        if not math.isfinite(size):
            return np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, 0.0
        if size <= _LAW_TOL:
            # converged (the next correction would be ~ size²); H is the Jacobian before
            # this last correction, within ~size of the one at ε (t and |w| likewise)
            if factored:
                return eps[0], eps[1], eps[2], eps[3], eps[4], eps[5], 1.0
            for i in range(6):
                for k in range(6):
                    M[i, k] = H[i, k]
            return eps[0], eps[1], eps[2], eps[3], eps[4], eps[5], 0.0
        # a chord step follows a small Newton step only, and is followed by a Newton step
        chord = newton and factored and tangents == 0 and size <= _LAW_CHORD
    return np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, 0.0


@_inline
def _ldl_correction(H, F, M):
    """The Newton correction M[:, 6] = -H⁻¹F by the square-root-free Cholesky factorisation
    H = L D Lᵀ (L unit lower triangular below M[:, :6]'s diagonal, 1/D on it, L D above
    it: see :func:`_ldl_substitute`): H is symmetric, and positive definite when every
    tension is >= 0 (K plus Σ τ/|w| Jᵀ (I - t tᵀ) J, each term semi-definite). No pivoting,
    about a third of the work of the general elimination, and one division a column, no
    square root (the law's time is the latency of these chains: LDLᵀ made it 17 % faster
    than L Lᵀ with a division per entry). False (M garbage) if H is not positive definite."""
    for c in range(6):
        d = H[c, c]
        for k in range(c):
            d -= M[c, k] * M[k, c]  # L[c, k] (L D)[c, k]
        if not d > 0.0:
            return False
        inv = 1.0 / d
        M[c, c] = inv
        for i in range(c + 1, 6):
            acc = H[i, c]
            for k in range(c):
                acc -= M[i, k] * M[k, c]
            M[c, i] = acc  # (L D)[i, c], kept above the diagonal
            M[i, c] = acc * inv
    _ldl_solve(M, F)
    return True


@_inline
def _ldl_solve(M, F):
    """M[:, 6] = -H⁻¹ F, H's factors in M[:, :6] (:func:`_ldl_correction`)."""
    for i in range(6):
        M[i, 6] = -F[i]
    _ldl_substitute(M, np.int64(1))


@_jit
def _ldl_substitute(M, k):
    """Solve H X = M[:, 6:6+k] in place (X overwrites those k columns), H = L D Lᵀ factored
    by :func:`_ldl_correction` in M[:, :6]: L (unit diagonal) below the diagonal, 1/D on it
    (kept)."""
    for col in range(6, 6 + k):
        for i in range(6):  # L z = b
            acc = M[i, col]
            for q in range(i):
                acc -= M[i, q] * M[q, col]
            M[i, col] = acc
        for i in range(5, -1, -1):  # D Lᵀ x = z
            acc = M[i, col] * M[i, i]
            for q in range(i + 1, 6):
                acc -= M[q, i] * M[q, col]
            M[i, col] = acc


@_jit
def _actuator_rates(act, j, rate, law, ds):
    """The actuators' own change with λ in the constitutive law, added to the λ column ds
    (material): Σ_chambers d(pA)/dλ (e1; r × e1) - Σ_tendons dτ/dλ (t; r × t)."""
    routes, kinds, active = act[0], act[1], act[2]
    tw = law[1]
    for a in range(routes.shape[0]):
        if active[j, a] == 0.0:
            continue
        q = rate[j, _ACT + a]
        y, z = tw[a, 4], tw[a, 5]
        if kinds[a] == CHAMBER:
            ds[0] += q
            ds[4] += q * z
            ds[5] -= q * y
        else:
            t0, t1, t2 = tw[a, 0], tw[a, 1], tw[a, 2]
            ds[0] -= q * t0
            ds[1] -= q * t1
            ds[2] -= q * t2
            ds[3] -= q * (y * t2 - z * t1)
            ds[4] -= q * z * t0
            ds[5] += q * y * t0


@_inline
def _actuated(act, j):
    """Whether actuators act on piece j (the constitutive law then is :func:`_law`)."""
    active = act[2]
    for a in range(active.shape[1]):
        if active[j, a] != 0.0:
            return True
    return False


@_inline
def _deriv(work, twork, nt, stage, s, arm, act, j, now, rate, law):
    """F(y) and the right-hand side of the first nt tangent columns, on piece j at arc
    length s.

    Reads the state from ``work[4]`` and the tangents from ``twork[4]``; writes F(y) into
    ``work[stage]`` and the tangent derivatives into ``twork[stage]``. Scalars throughout
    where it matters: no array views in the passive arm's path, no allocation.

    Design note: this function is inlined into :func:`_steps` by numba
    (``inline="always"``). Left to LLVM, it stays out of line once the actuated path is in
    the body, and every RK4 step and output station then pays calls that pass the arm's
    arrays by value: a passive solve measured 1.5-2× slower than 0.1's kernel that way,
    and at parity inlined. The actuated path's own work is in :func:`_law`.
    """
    C, f0, zero, diag = arm[2], arm[3], arm[4], arm[5]
    Y = 4
    R00, R01, R02 = work[Y, _R], work[Y, _R + 1], work[Y, _R + 2]
    R10, R11, R12 = work[Y, _R + 3], work[Y, _R + 4], work[Y, _R + 5]
    R20, R21, R22 = work[Y, _R + 6], work[Y, _R + 7], work[Y, _R + 8]
    nx, ny, nz = work[Y, _N], work[Y, _N + 1], work[Y, _N + 2]
    mx, my, mz = work[Y, _M], work[Y, _M + 1], work[Y, _M + 2]
    # σ = (Rᵀn; Rᵀm), material components
    s0 = R00 * nx + R10 * ny + R20 * nz
    s1 = R01 * nx + R11 * ny + R21 * nz
    s2 = R02 * nx + R12 * ny + R22 * nz
    s3 = R00 * mx + R10 * my + R20 * mz
    s4 = R01 * mx + R11 * my + R21 * mz
    s5 = R02 * mx + R12 * my + R22 * mz
    # (every use of ``act`` is behind ``act is not None``: compiled for a passive arm, the
    # actuated law, the tendons' lengths and the magnets are pruned before typing)
    actuated = act is not None and _actuated(act, j)
    if act is not None and actuated:
        v0, v1, v2, u0, u1, u2, factored = _law(arm, act, j, s, now, law, nt, s0, s1, s2, s3,
                                                s4, s5)
    else:
        v0, v1, v2, u0, u1, u2 = _strain(C, f0, j, diag, s0, s1, s2, s3, s4, s5)
        factored = 0.0
    # follower loads in spatial components: R f_f, R l_f
    ff0, ff1, ff2 = now[j, _FF], now[j, _FF + 1], now[j, _FF + 2]
    lf0, lf1, lf2 = now[j, _LF], now[j, _LF + 1], now[j, _LF + 2]
    px = R00 * v0 + R01 * v1 + R02 * v2
    py = R10 * v0 + R11 * v1 + R12 * v2
    pz = R20 * v0 + R21 * v1 + R22 * v2
    w = work[stage]
    w[_P] = px
    w[_P + 1] = py
    w[_P + 2] = pz
    w[_R] = R01 * u2 - R02 * u1
    w[_R + 1] = -R00 * u2 + R02 * u0
    w[_R + 2] = R00 * u1 - R01 * u0
    w[_R + 3] = R11 * u2 - R12 * u1
    w[_R + 4] = -R10 * u2 + R12 * u0
    w[_R + 5] = R10 * u1 - R11 * u0
    w[_R + 6] = R21 * u2 - R22 * u1
    w[_R + 7] = -R20 * u2 + R22 * u0
    w[_R + 8] = R20 * u1 - R21 * u0
    w[_N] = -(now[j, _FD] + R00 * ff0 + R01 * ff1 + R02 * ff2)
    w[_N + 1] = -(now[j, _FD + 1] + R10 * ff0 + R11 * ff1 + R12 * ff2)
    w[_N + 2] = -(now[j, _FD + 2] + R20 * ff0 + R21 * ff1 + R22 * ff2)
    w[_M] = -(py * nz - pz * ny) - (now[j, _LD] + R00 * lf0 + R01 * lf1 + R02 * lf2)
    w[_M + 1] = -(pz * nx - px * nz) - (now[j, _LD + 1] + R10 * lf0 + R11 * lf1 + R12 * lf2)
    w[_M + 2] = -(px * ny - py * nx) - (now[j, _LD + 2] + R20 * lf0 + R21 * lf1 + R22 * lf2)
    # a hard magnetisation m (material, A m²/m) in B(x) = B0 + G x: force Gᵀ (R m), torque
    # (R m) × B(p) per unit length
    ma0 = ma1 = ma2 = 0.0
    if act is not None:
        ma0, ma1, ma2 = act[3][j, 0], act[3][j, 1], act[3][j, 2]
    magnetic = ma0 != 0.0 or ma1 != 0.0 or ma2 != 0.0
    if act is not None and magnetic:
        _dipole(work[Y], twork[Y], np.int64(0), ma0, ma1, ma2, now[j], rate[0, j], law[2][3])
        for i in range(3):
            w[_N + i] -= law[2][3, i]
            w[_M + i] -= law[2][3, 3 + i]
    # contact with the obstacles: a force per unit length through the centreline (_contact)
    cf0 = cf1 = cf2 = c00 = c01 = c02 = c11 = c12 = c22 = 0.0
    touching = False
    contact = 0.0  # the penalty's scale at this λ (the channel CT)
    if act is not None and act[5].shape[0] > 0:
        contact = now[j, _CT]
        cf0, cf1, cf2, c00, c01, c02, c11, c12, c22 = _contact(
            work[Y, _P], work[Y, _P + 1], work[Y, _P + 2], act[5], act[6][j])
        touching = cf0 != 0.0 or cf1 != 0.0 or cf2 != 0.0
        w[_N] -= contact * cf0
        w[_N + 1] -= contact * cf1
        w[_N + 2] -= contact * cf2
    # the tendons' lengths: ℓ' = |w| where they run
    if act is not None:
        for a in range(w.size - 18):
            w[18 + a] = law[1][a, 3] if actuated and act[2][j, a] != 0.0 and \
                act[1][a] == TENDON else 0.0
    if nt == 0:
        return
    # δσ = (Rᵀδn + σ_n × δθ; Rᵀδm + σ_m × δθ), then δ(v; u) = dstrain δσ (+ the actuators'
    # own change with λ), all columns at once (a passive arm's δ(v; u) are computed in the
    # loop below, in registers: one loop, no round trip through memory; an actuated one's
    # need one solve with H for all columns, by substitution with the LDLᵀ factors the law
    # left, or by elimination where it left H itself)
    M = law[0]
    for d in range(nt if actuated else 0):
        t = twork[Y, d]
        th0, th1, th2 = t[_TT], t[_TT + 1], t[_TT + 2]
        dn0, dn1, dn2 = t[_TN], t[_TN + 1], t[_TN + 2]
        dm0, dm1, dm2 = t[_TM], t[_TM + 1], t[_TM + 2]
        M[0, 6 + d] = R00 * dn0 + R10 * dn1 + R20 * dn2 + s1 * th2 - s2 * th1
        M[1, 6 + d] = R01 * dn0 + R11 * dn1 + R21 * dn2 + s2 * th0 - s0 * th2
        M[2, 6 + d] = R02 * dn0 + R12 * dn1 + R22 * dn2 + s0 * th1 - s1 * th0
        M[3, 6 + d] = R00 * dm0 + R10 * dm1 + R20 * dm2 + s4 * th2 - s5 * th1
        M[4, 6 + d] = R01 * dm0 + R11 * dm1 + R21 * dm2 + s5 * th0 - s3 * th2
        M[5, 6 + d] = R02 * dm0 + R12 * dm1 + R22 * dm2 + s3 * th1 - s4 * th0
    if act is not None and actuated:
        for d in range(LAM, nt):
            _actuator_rates(act, j, rate[d - LAM], law, law[2][4])
            for i in range(6):
                M[i, 6 + d] += law[2][4, i]
                law[2][4, i] = 0.0
        if factored > 0.0:  # H's LDLᵀ factors, from the law's last Newton step
            _ldl_substitute(M, nt)
        elif _eliminate_columns(M, nt) == 0.0:
            for d in range(nt):
                for i in range(6):
                    M[i, 6 + d] = np.nan
    for d in range(nt):
        t = twork[Y, d]
        th0, th1, th2 = t[_TT], t[_TT + 1], t[_TT + 2]
        dn0, dn1, dn2 = t[_TN], t[_TN + 1], t[_TN + 2]
        if act is not None and actuated:
            c0, c1, c2 = M[0, 6 + d], M[1, 6 + d], M[2, 6 + d]
            c3, c4, c5 = M[3, 6 + d], M[4, 6 + d], M[5, 6 + d]
        else:  # δσ = (Rᵀδn + σ_n × δθ; Rᵀδm + σ_m × δθ), then the constitutive step
            dm0, dm1, dm2 = t[_TM], t[_TM + 1], t[_TM + 2]
            c0, c1, c2, c3, c4, c5 = _strain(
                C, zero, j, diag,
                R00 * dn0 + R10 * dn1 + R20 * dn2 + s1 * th2 - s2 * th1,
                R01 * dn0 + R11 * dn1 + R21 * dn2 + s2 * th0 - s0 * th2,
                R02 * dn0 + R12 * dn1 + R22 * dn2 + s0 * th1 - s1 * th0,
                R00 * dm0 + R10 * dm1 + R20 * dm2 + s4 * th2 - s5 * th1,
                R01 * dm0 + R11 * dm1 + R21 * dm2 + s5 * th0 - s3 * th2,
                R02 * dm0 + R12 * dm1 + R22 * dm2 + s3 * th1 - s4 * th0)
        # δp' = R (δθ × v + δv)
        a0 = th1 * v2 - th2 * v1 + c0
        a1 = th2 * v0 - th0 * v2 + c1
        a2 = th0 * v1 - th1 * v0 + c2
        q0 = R00 * a0 + R01 * a1 + R02 * a2
        q1 = R10 * a0 + R11 * a1 + R12 * a2
        q2 = R20 * a0 + R21 * a1 + R22 * a2
        # -R (δθ × f_f) and -R (δθ × l_f), material cross products rotated to spatial
        b0 = -(th1 * ff2 - th2 * ff1)
        b1 = -(th2 * ff0 - th0 * ff2)
        b2 = -(th0 * ff1 - th1 * ff0)
        e0 = -(th1 * lf2 - th2 * lf1)
        e1 = -(th2 * lf0 - th0 * lf2)
        e2 = -(th0 * lf1 - th1 * lf0)
        rr = max(d - LAM, 0)  # columns from LAM on: the loads' own change along rate[d - LAM]
        if d >= LAM:
            b0 -= rate[rr, j, _FF]
            b1 -= rate[rr, j, _FF + 1]
            b2 -= rate[rr, j, _FF + 2]
            e0 -= rate[rr, j, _LF]
            e1 -= rate[rr, j, _LF + 1]
            e2 -= rate[rr, j, _LF + 2]
        g0 = R00 * b0 + R01 * b1 + R02 * b2
        g1 = R10 * b0 + R11 * b1 + R12 * b2
        g2 = R20 * b0 + R21 * b1 + R22 * b2
        k0 = R00 * e0 + R01 * e1 + R02 * e2
        k1 = R10 * e0 + R11 * e1 + R12 * e2
        k2 = R20 * e0 + R21 * e1 + R22 * e2
        if d >= LAM:
            g0 -= rate[rr, j, _FD]
            g1 -= rate[rr, j, _FD + 1]
            g2 -= rate[rr, j, _FD + 2]
            k0 -= rate[rr, j, _LD]
            k1 -= rate[rr, j, _LD + 1]
            k2 -= rate[rr, j, _LD + 2]
        if act is not None and magnetic:  # the magnetic force and torque densities' variations
            _dipole(work[Y], twork[Y], d + 1, ma0, ma1, ma2, now[j], rate[rr, j], law[2][3])
            g0 -= law[2][3, 0]
            g1 -= law[2][3, 1]
            g2 -= law[2][3, 2]
            k0 -= law[2][3, 3]
            k1 -= law[2][3, 4]
            k2 -= law[2][3, 5]
        if act is not None and touching:  # -∂f/∂p δp (∂f/∂p symmetric: the obstacles' Hessians)
            dp0, dp1, dp2 = t[_TP], t[_TP + 1], t[_TP + 2]
            g0 -= contact * (c00 * dp0 + c01 * dp1 + c02 * dp2)
            g1 -= contact * (c01 * dp0 + c11 * dp1 + c12 * dp2)
            g2 -= contact * (c02 * dp0 + c12 * dp1 + c22 * dp2)
            if d >= LAM:  # the penalty's own change along the path
                g0 -= rate[rr, j, _CT] * cf0
                g1 -= rate[rr, j, _CT] * cf1
                g2 -= rate[rr, j, _CT] * cf2
        o = twork[stage, d]
        o[_TP] = q0
        o[_TP + 1] = q1
        o[_TP + 2] = q2
        o[_TT] = -(u1 * th2 - u2 * th1) + c3
        o[_TT + 1] = -(u2 * th0 - u0 * th2) + c4
        o[_TT + 2] = -(u0 * th1 - u1 * th0) + c5
        o[_TN] = g0
        o[_TN + 1] = g1
        o[_TN + 2] = g2
        # δm' = -δp' × n - p' × δn - R (δθ × l_f) - ∂_λ l
        o[_TM] = -(q1 * nz - q2 * ny) - (py * dn2 - pz * dn1) + k0
        o[_TM + 1] = -(q2 * nx - q0 * nz) - (pz * dn0 - px * dn2) + k1
        o[_TM + 2] = -(q0 * ny - q1 * nx) - (px * dn1 - py * dn0) + k2
    if act is not None and twork.shape[2] > NT:  # the tendons' lengths' tangents
        _length_rates(twork[stage], nt, act, j, actuated, law)


@_inline
def _length_rates(out, nt, act, j, actuated, law):
    """The tangent rates of the tendons' lengths, out[d, NT + a] = δ|w_a| = g_aᵀ δε for
    the first nt columns: δw = δv + δu × r = J δε (J = [I, -r~]), so δ|w| = tᵀ J δε with
    Jᵀ t = g = (t; r × t), t = w/|w| (from ``law[1]``), δε the columns' strain variations
    (``law[0][:, 6 + d]``); 0 where tendon a does not run, and for a chamber."""
    kinds, active = act[1], act[2]
    tw, M = law[1], law[0]
    for a in range(out.shape[1] - NT):
        if not (actuated and active[j, a] != 0.0 and kinds[a] == TENDON):
            for d in range(nt):
                out[d, NT + a] = 0.0
            continue
        t0, t1, t2, y, z = tw[a, 0], tw[a, 1], tw[a, 2], tw[a, 4], tw[a, 5]
        g3, g4, g5 = y * t2 - z * t1, z * t0, -y * t0
        for d in range(nt):
            out[d, NT + a] = (t0 * M[0, 6 + d] + t1 * M[1, 6 + d] + t2 * M[2, 6 + d]
                              + g3 * M[3, 6 + d] + g4 * M[4, 6 + d] + g5 * M[5, 6 + d])


@_jit
def _dipole(y, T, which, m0, m1, m2, now, rate, out):
    """The wrench of a magnetic dipole m (material components, A m², or A m²/m for a
    density) carried by the section of state y in the field B(x) = B0 + G x of the load row
    ``now``: out = (Gᵀ (R m); (R m) × B(p)), spatial. With ``which`` = d + 1 instead its
    variation along tangent column d of T: R (δθ × m) = δ(R m) in both terms, G δp in the
    torque, and in a load column (d >= LAM) the field's own change (``rate``: that column's
    rate row of this piece)."""
    R = y[_R:_R + 9]
    a0 = R[0] * m0 + R[1] * m1 + R[2] * m2  # R m, spatial
    a1 = R[3] * m0 + R[4] * m1 + R[5] * m2
    a2 = R[6] * m0 + R[7] * m1 + R[8] * m2
    px, py, pz = y[_P], y[_P + 1], y[_P + 2]
    if which == 0:
        G, B = now[_FG:_FG + 9], now[_FB:_FB + 3]
        b0 = B[0] + G[0] * px + G[1] * py + G[2] * pz
        b1 = B[1] + G[3] * px + G[4] * py + G[5] * pz
        b2 = B[2] + G[6] * px + G[7] * py + G[8] * pz
        out[0] = G[0] * a0 + G[3] * a1 + G[6] * a2
        out[1] = G[1] * a0 + G[4] * a1 + G[7] * a2
        out[2] = G[2] * a0 + G[5] * a1 + G[8] * a2
        out[3] = a1 * b2 - a2 * b1
        out[4] = a2 * b0 - a0 * b2
        out[5] = a0 * b1 - a1 * b0
        return
    d = which - 1
    t = T[d]
    th0, th1, th2 = t[_TT], t[_TT + 1], t[_TT + 2]
    c0, c1, c2 = th1 * m2 - th2 * m1, th2 * m0 - th0 * m2, th0 * m1 - th1 * m0
    e0 = R[0] * c0 + R[1] * c1 + R[2] * c2  # δ(R m) = R (δθ × m)
    e1 = R[3] * c0 + R[4] * c1 + R[5] * c2
    e2 = R[6] * c0 + R[7] * c1 + R[8] * c2
    G, B = now[_FG:_FG + 9], now[_FB:_FB + 3]
    b0 = B[0] + G[0] * px + G[1] * py + G[2] * pz
    b1 = B[1] + G[3] * px + G[4] * py + G[5] * pz
    b2 = B[2] + G[6] * px + G[7] * py + G[8] * pz
    dp0, dp1, dp2 = t[_TP], t[_TP + 1], t[_TP + 2]
    g0 = G[0] * dp0 + G[1] * dp1 + G[2] * dp2  # G δp
    g1 = G[3] * dp0 + G[4] * dp1 + G[5] * dp2
    g2 = G[6] * dp0 + G[7] * dp1 + G[8] * dp2
    f0 = G[0] * e0 + G[3] * e1 + G[6] * e2
    f1 = G[1] * e0 + G[4] * e1 + G[7] * e2
    f2 = G[2] * e0 + G[5] * e1 + G[8] * e2
    if d >= LAM:
        Gr, Br = rate[_FG:_FG + 9], rate[_FB:_FB + 3]
        f0 += Gr[0] * a0 + Gr[3] * a1 + Gr[6] * a2
        f1 += Gr[1] * a0 + Gr[4] * a1 + Gr[7] * a2
        f2 += Gr[2] * a0 + Gr[5] * a1 + Gr[8] * a2
        g0 += Br[0] + Gr[0] * px + Gr[1] * py + Gr[2] * pz
        g1 += Br[1] + Gr[3] * px + Gr[4] * py + Gr[5] * pz
        g2 += Br[2] + Gr[6] * px + Gr[7] * py + Gr[8] * pz
    out[0], out[1], out[2] = f0, f1, f2
    out[3] = e1 * b2 - e2 * b1 + a1 * g2 - a2 * g1
    out[4] = e2 * b0 - e0 * b2 + a2 * g0 - a0 * g2
    out[5] = e0 * b1 - e1 * b0 + a0 * g1 - a1 * g0


# Contact (issue 33; docs/contact.md). ``act[5]``: the obstacles (K, 8), one row each: kind,
# then a plane's point and outward unit normal, a sphere's centre (and 0, 0, 0), or a
# capsule's two axis ends, then the radius (0 for a plane). ``act[6]`` (P, 5): per piece the
# arm's surface radius r (m), the contact distance δ (m), the penalty stiffness k
# (N/m per m of arm), Coulomb's μ and the friction's regularising speed w_ε (m/s; dynamics).
PLANE, SPHERE, CAPSULE = 0, 1, 2
OBSTACLE = 8


@_jit
def _pressure(gap, band, stiffness):
    """The contact force per unit length at a gap g (the law's value and its derivative in
    g): zero for g >= δ, then k δ (t³ - t⁴/2) with t = (δ - g)/δ up to g = 0, then linear,
    k (δ/2 - g): twice continuously differentiable (RK4 keeps its order across the onset),
    k δ/2 at contact, and the slope k from g = 0 into the obstacle. Penetration is what is
    left of a pressure beyond k δ/2 (the Solver raises k until none is left; contact.md)."""
    if gap >= band:
        return 0.0, 0.0
    if gap <= 0.0:
        return stiffness * (0.5 * band - gap), -stiffness
    t = (band - gap) / band
    return stiffness * band * t * t * t * (1.0 - 0.5 * t), -stiffness * t * t * (3.0 - 2.0 * t)


@_jit
def _nearest(px, py, pz, row):
    """(distance d, outward unit normal n (3), curvature c, axis e (3)) of the point p from
    obstacle ``row`` (act[5]'s layout): d the signed distance from its surface, n = ∇d, and
    the Hessian ∇²d = c (I - n nᵀ - e eᵀ) (c = 1/|p - q| around a sphere's centre or a
    capsule's axis, e the axis on a capsule's cylinder, else 0)."""
    kind = row[0]
    if kind == PLANE:
        return ((px - row[1]) * row[4] + (py - row[2]) * row[5] + (pz - row[3]) * row[6],
                row[4], row[5], row[6], 0.0, 0.0, 0.0, 0.0)
    if kind == SPHERE:
        # row: a surface point q, the outward normal m there, the radius R (contact.py's
        # Sphere.kernel_row): with w = p - q, |p - c| - R = (2R m·w + w·w)/(|p - c| + R),
        # without the cancellation of |p - c| - R (a ball of 1e6 m as a floor: 1e-10 m of
        # rounding in every gap, a noisy law within a band of µm)
        wx, wy, wz = px - row[1], py - row[2], pz - row[3]
        radius = row[7]
        ux, uy, uz = wx + radius * row[4], wy + radius * row[5], wz + radius * row[6]
        r = math.sqrt(ux * ux + uy * uy + uz * uz)
        if r == 0.0:  # on the centre: the normal is undefined (deep inside)
            return -radius, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        d = (2.0 * radius * (wx * row[4] + wy * row[5] + wz * row[6])
             + wx * wx + wy * wy + wz * wz) / (r + radius)
        return d, ux / r, uy / r, uz / r, 1.0 / r, 0.0, 0.0, 0.0
    qx, qy, qz = row[1], row[2], row[3]
    e0 = e1 = e2 = 0.0
    if kind == CAPSULE:
        a0, a1, a2 = row[4] - qx, row[5] - qy, row[6] - qz
        aa = a0 * a0 + a1 * a1 + a2 * a2
        t = ((px - qx) * a0 + (py - qy) * a1 + (pz - qz) * a2) / aa
        if t > 0.0 and t < 1.0:
            qx, qy, qz = qx + t * a0, qy + t * a1, qz + t * a2
            norm = math.sqrt(aa)
            e0, e1, e2 = a0 / norm, a1 / norm, a2 / norm
        elif t >= 1.0:
            qx, qy, qz = row[4], row[5], row[6]
    dx, dy, dz = px - qx, py - qy, pz - qz
    r = math.sqrt(dx * dx + dy * dy + dz * dz)
    if r == 0.0:  # on the centre or the axis: the normal is undefined (deep inside)
        return -row[7], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return r - row[7], dx / r, dy / r, dz / r, 1.0 / r, e0, e1, e2


@_jit
def _contact(px, py, pz, obstacles, params):
    """The contact force per unit length on a section at p (spatial, N/m; frictionless,
    along each obstacle's normal, through the centreline: no moment) and its Jacobian
    ∂f/∂p (row-major), summed over the obstacles: f = φ(d - r) ∇d,
    ∂f/∂p = φ' ∇d ∇dᵀ + φ ∇²d (``params`` = the piece's act[6] row: r, δ, k)."""
    f0 = f1 = f2 = 0.0
    j00 = j01 = j02 = j11 = j12 = j22 = 0.0
    for k in range(obstacles.shape[0]):
        d, n0, n1, n2, c, e0, e1, e2 = _nearest(px, py, pz, obstacles[k])
        phi, dphi = _pressure(d - params[0], params[1], params[2])
        if phi == 0.0:
            continue
        f0 += phi * n0
        f1 += phi * n1
        f2 += phi * n2
        pc = phi * c
        j00 += dphi * n0 * n0 + pc * (1.0 - n0 * n0 - e0 * e0)
        j01 += dphi * n0 * n1 - pc * (n0 * n1 + e0 * e1)
        j02 += dphi * n0 * n2 - pc * (n0 * n2 + e0 * e2)
        j11 += dphi * n1 * n1 + pc * (1.0 - n1 * n1 - e1 * e1)
        j12 += dphi * n1 * n2 - pc * (n1 * n2 + e1 * e2)
        j22 += dphi * n2 * n2 + pc * (1.0 - n2 * n2 - e2 * e2)
    return f0, f1, f2, j00, j01, j02, j11, j12, j22


@_inline
def _station_rotation(y0, f0, y1, f1, u, h, out):
    """The rotation of a station at u ∈ [0, 1] of a step of length h, from the states y0, y1
    and derivatives f0, f1 at its ends: R = R0 exp(θ~), θ(u) the cubic Hermite polynomial of
    the rotation vector from R0 (θ(0) = 0, θ(1) = log(R0ᵀ R1), θ' = h u0 and h J_r⁻¹(θ1) u1,
    u the curvature R' = R u~). The rotation vector is what varies slowly (exactly linearly
    on an arc), so this interpolates R to the accuracy of the positions' Hermite polynomial,
    where interpolating R's entries was 10× worse; exactly a rotation. Writes out[3:12]."""
    # u0 = vee(R0ᵀ R0'), u1 = vee(R1ᵀ R1') (the antisymmetric part's axial vector)
    c = np.empty((2, 3))
    for e in range(2):
        y, f = (y0, f0) if e == 0 else (y1, f1)
        for a in range(3):  # (RᵀR')[a, b] = Σ_i R[i, a] R'[i, b]
            b, d = (a + 1) % 3, (a + 2) % 3
            m_db = (y[_R + d] * f[_R + b] + y[_R + 3 + d] * f[_R + 3 + b]
                    + y[_R + 6 + d] * f[_R + 6 + b])
            m_bd = (y[_R + b] * f[_R + d] + y[_R + 3 + b] * f[_R + 3 + d]
                    + y[_R + 6 + b] * f[_R + 6 + d])
            c[e, a] = 0.5 * (m_db - m_bd)  # û[d, b] = u_a
    # Q = R0ᵀ R1 and its rotation vector
    q = np.empty((3, 3))
    for a in range(3):
        for b in range(3):
            q[a, b] = (y0[_R + a] * y1[_R + b] + y0[_R + 3 + a] * y1[_R + 3 + b]
                       + y0[_R + 6 + a] * y1[_R + 6 + b])
    w0, w1, w2 = q[2, 1] - q[1, 2], q[0, 2] - q[2, 0], q[1, 0] - q[0, 1]
    sine = 0.5 * math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    cosine = 0.5 * (q[0, 0] + q[1, 1] + q[2, 2] - 1.0)
    angle = math.atan2(sine, cosine)
    scale = 0.5 + angle * angle / 12.0 if angle < 1e-4 else 0.5 * angle / math.sin(angle)
    t0, t1, t2 = scale * w0, scale * w1, scale * w2  # θ1
    # θ1' = J_r⁻¹(θ1) u1 = u1 + ½ θ1 × u1 + β θ1 × (θ1 × u1)
    beta = (1.0 / 12.0 + angle * angle / 720.0 if angle < 1e-3 else
            1.0 / (angle * angle) - (1.0 + math.cos(angle)) / (2.0 * angle * math.sin(angle)))
    v0, v1, v2 = c[1, 0], c[1, 1], c[1, 2]
    x0, x1, x2 = t1 * v2 - t2 * v1, t2 * v0 - t0 * v2, t0 * v1 - t1 * v0  # θ1 × u1
    z0, z1, z2 = t1 * x2 - t2 * x1, t2 * x0 - t0 * x2, t0 * x1 - t1 * x0
    d0, d1, d2 = v0 + 0.5 * x0 + beta * z0, v1 + 0.5 * x1 + beta * z1, v2 + 0.5 * x2 + beta * z2
    # the Hermite polynomial at u (θ(0) = 0)
    c1 = u * (1.0 - u) * (1.0 - u) * h
    c2 = u * u * (3.0 - 2.0 * u)
    c3 = -u * u * (1.0 - u) * h
    a0 = c1 * c[0, 0] + c2 * t0 + c3 * d0
    a1 = c1 * c[0, 1] + c2 * t1 + c3 * d1
    a2 = c1 * c[0, 2] + c2 * t2 + c3 * d2
    _rotated(y0, a0, a1, a2, out)


@_inline
def _rotated(y0, a0, a1, a2, out):
    """out's rotation = y0's R times exp(a~) (a material, by Rodrigues; the series below
    1e-4 rad, to round-off); ``out`` may be ``y0`` (a row is read before it is written)."""
    angle = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    if angle < 1e-4:
        sa, ca = 1.0 - angle * angle / 6.0, 0.5 - angle * angle / 24.0
    else:
        sa, ca = math.sin(angle) / angle, (1.0 - math.cos(angle)) / (angle * angle)
    e00 = 1.0 - ca * (a1 * a1 + a2 * a2)
    e11 = 1.0 - ca * (a0 * a0 + a2 * a2)
    e22 = 1.0 - ca * (a0 * a0 + a1 * a1)
    e01 = -sa * a2 + ca * a0 * a1
    e10 = sa * a2 + ca * a0 * a1
    e02 = sa * a1 + ca * a0 * a2
    e20 = -sa * a1 + ca * a0 * a2
    e12 = -sa * a0 + ca * a1 * a2
    e21 = sa * a0 + ca * a1 * a2
    for a in range(3):
        r0, r1, r2 = y0[_R + 3 * a], y0[_R + 3 * a + 1], y0[_R + 3 * a + 2]
        out[_R + 3 * a] = r0 * e00 + r1 * e10 + r2 * e20
        out[_R + 3 * a + 1] = r0 * e01 + r1 * e11 + r2 * e21
        out[_R + 3 * a + 2] = r0 * e02 + r1 * e12 + r2 * e22


@_inline
def _bjorck(y):
    """R ← R (3I - RᵀR)/2 on the state's rotation: one Björck step towards the nearest
    rotation (quadratic: an error ε of RᵀR = I becomes about ε²)."""
    g00 = 1.5 - 0.5 * (y[3] * y[3] + y[6] * y[6] + y[9] * y[9])
    g11 = 1.5 - 0.5 * (y[4] * y[4] + y[7] * y[7] + y[10] * y[10])
    g22 = 1.5 - 0.5 * (y[5] * y[5] + y[8] * y[8] + y[11] * y[11])
    g01 = -0.5 * (y[3] * y[4] + y[6] * y[7] + y[9] * y[10])
    g02 = -0.5 * (y[3] * y[5] + y[6] * y[8] + y[9] * y[11])
    g12 = -0.5 * (y[4] * y[5] + y[7] * y[8] + y[10] * y[11])
    for i in range(3):
        a, b, c = y[_R + 3 * i], y[_R + 3 * i + 1], y[_R + 3 * i + 2]
        y[_R + 3 * i] = a * g00 + b * g01 + c * g02
        y[_R + 3 * i + 1] = a * g01 + b * g11 + c * g12
        y[_R + 3 * i + 2] = a * g02 + b * g12 + c * g22


@_jit
def _steps(y, T, nt, h, s, n, arm, act, j, now, rate, work, twork, law):
    """``n`` RK4 steps of length h (negative: towards the base) from arc length s on piece j,
    in place (the state and the first nt tangent columns of T), each followed by
    R ← R (3I - RᵀR)/2: one Björck step towards the nearest rotation. ``n`` < 0: |n| steps,
    the first one's first-stage derivatives already in ``work[0]`` and ``twork[0]`` (left
    there by the output pass: not evaluated again); ``n`` = 0: those derivatives at (y, T, s)
    only, y and T unchanged (encodings, not more arguments, so that every caller shares one
    compiled version, with one inlined copy of the right-hand side).

    Design note: this is the one function the right-hand side (:func:`_deriv`) is compiled
    into. Every integration (the shooting pass, the output pass, the stability sweep) calls
    it for a run of steps, so numba and LLVM build and optimise the right-hand side once
    instead of once per caller (cold compile: see statics/README.md), and a call costs once
    per run of steps, not once per stage. The RK4 step is written here, not in a function of
    its own: each level of numba inlining deep-copies the inlined IR twice, and the step's
    own level cost about 5 s of cold compile.

    Loops are written out (no slice assignment, no array expression): numba compiles those
    with shape checks whose error messages pull in its string machinery.
    """
    lengths = act is not None and T.shape[1] > NT  # the tendons' lengths' tangents
    for step in range(max(abs(n), 1)):
        at = s + step * h
        for stage in range(4):  # work rows 0-3: the stage derivatives; row 4: the stage state
            if stage == 0 and n < 0 and step == 0:
                continue
            a = 0.0 if stage == 0 else (h if stage == 3 else 0.5 * h)
            prev = max(stage - 1, 0)
            for i in range(y.size):
                work[4, i] = y[i] + a * work[prev, i] if stage else y[i]
            for d in range(nt):
                for i in range(NT):
                    twork[4, d, i] = T[d, i] + a * twork[prev, d, i] if stage else T[d, i]
            if act is not None and lengths:
                for d in range(nt):
                    for i in range(NT, T.shape[1]):
                        twork[4, d, i] = T[d, i] + a * twork[prev, d, i] if stage else T[d, i]
            _deriv(work, twork, nt, stage, at + a, arm, act, j, now, rate, law)
            if n == 0:
                return
        w = h / 6.0
        for i in range(y.size):
            y[i] += w * (work[0, i] + 2.0 * work[1, i] + 2.0 * work[2, i] + work[3, i])
        for d in range(nt):
            for i in range(NT):
                T[d, i] += w * (twork[0, d, i] + 2.0 * twork[1, d, i] + 2.0 * twork[2, d, i]
                                + twork[3, d, i])
        if act is not None and lengths:
            for d in range(nt):
                for i in range(NT, T.shape[1]):
                    T[d, i] += w * (twork[0, d, i] + 2.0 * twork[1, d, i]
                                    + 2.0 * twork[2, d, i] + twork[3, d, i])
        _bjorck(y)


@_jit
def _jump(y, T, nt, now, rate, j, arm, act, law):
    """The point wrench at the start of piece j: n and m drop by W_d + R W_f (and their
    tangents by R (δθ × W_f), plus ∂_λ W in the load-factor column), and by the wrench of a
    magnetic dipole there (a segment's ``tip_magnet``)."""
    if act is not None:
        _dipole_jump(y, T, nt, act[4], j, now[j], rate, j, law[2][5], y, T, -1.0)
    for half in range(2):
        at = 3 * half
        W0, W1, W2 = now[j, _JF + at], now[j, _JF + at + 1], now[j, _JF + at + 2]
        for i in range(3):
            y[_N + at + i] -= now[j, _JD + at + i] + (
                y[_R + 3 * i] * W0 + y[_R + 3 * i + 1] * W1 + y[_R + 3 * i + 2] * W2)
        for d in range(nt):
            th0, th1, th2 = T[d, _TT], T[d, _TT + 1], T[d, _TT + 2]
            c0 = th1 * W2 - th2 * W1
            c1 = th2 * W0 - th0 * W2
            c2 = th0 * W1 - th1 * W0
            if d >= LAM:
                c0 += rate[d - LAM, j, _JF + at]
                c1 += rate[d - LAM, j, _JF + at + 1]
                c2 += rate[d - LAM, j, _JF + at + 2]
            for i in range(3):
                T[d, _TN + at + i] -= (y[_R + 3 * i] * c0 + y[_R + 3 * i + 1] * c1
                                       + y[_R + 3 * i + 2] * c2)
                if d >= LAM:
                    T[d, _TN + at + i] -= rate[d - LAM, j, _JD + at + i]


@_jit
def _dipole_jump(y, T, nt, dipoles, at, now, rate, j, out, ydst, Tdst, sign):
    """Add ``sign`` × the wrench of dipole ``dipoles[at]`` (A m², material) to n, m of
    ``ydst`` and its variations to the first nt tangent columns of ``Tdst`` (rows 6:12), or
    with ``ydst`` the residual r (6) and ``Tdst`` the Jacobian J (6, nt) (see callers); the
    field and its rates are piece j's (``now``, ``rate[:, j]``)."""
    m0, m1, m2 = dipoles[at, 0], dipoles[at, 1], dipoles[at, 2]
    if m0 == 0.0 and m1 == 0.0 and m2 == 0.0:
        return
    off = _N if ydst.size >= 18 else 0
    for d in range(nt):
        _dipole(y, T, d + 1, m0, m1, m2, now, rate[max(d - LAM, 0), j], out)
        for i in range(6):
            if off:
                Tdst[d, _TN + i] += sign * out[i]
            else:
                Tdst[i, d] += sign * out[i]
    _dipole(y, T, np.int64(0), m0, m1, m2, now, rate[0, j], out)
    for i in range(6):
        ydst[off + i] += sign * out[i]


@_jit
def _start(y, T, nt, base, x):
    """The state at the clamp from the base reaction x, and the tangents' initial values."""
    for i in range(3):
        y[_P + i] = base[i, 3]
        for k in range(3):
            y[_R + 3 * i + k] = base[i, k]
        y[_N + i] = x[i]
        y[_M + i] = x[3 + i]
    for i in range(18, y.size):
        y[i] = 0.0  # the tendons' lengths
    for d in range(nt):
        for i in range(T.shape[1]):  # with the tendons' lengths' (0 at the base)
            T[d, i] = 0.0
        if d < 6:
            T[d, _TN + d] = 1.0  # δ(n(0); m(0)) = e_d


@_jit
def _tip_residual(y, T, nt, tip_now, tip_rate, r, J, arm, act, now, rate, law):
    """The boundary residual r at the tip and its Jacobian columns J[:, :nt]: the total
    wrench n(L), m(L) minus the tip loads (and the tip dipole's wrench)."""
    for half in range(2):
        at = 3 * half
        F0, F1, F2 = tip_now[_TF + at], tip_now[_TF + at + 1], tip_now[_TF + at + 2]
        for i in range(3):
            r[at + i] = y[_N + at + i] - tip_now[_TD + at + i] - (
                y[_R + 3 * i] * F0 + y[_R + 3 * i + 1] * F1 + y[_R + 3 * i + 2] * F2)
        for d in range(nt):
            th0, th1, th2 = T[d, _TT], T[d, _TT + 1], T[d, _TT + 2]
            c0 = th1 * F2 - th2 * F1
            c1 = th2 * F0 - th0 * F2
            c2 = th0 * F1 - th1 * F0
            if d >= LAM:
                c0 += tip_rate[d - LAM, _TF + at]
                c1 += tip_rate[d - LAM, _TF + at + 1]
                c2 += tip_rate[d - LAM, _TF + at + 2]
            for i in range(3):
                J[at + i, d] = T[d, _TN + at + i] - (
                    y[_R + 3 * i] * c0 + y[_R + 3 * i + 1] * c1 + y[_R + 3 * i + 2] * c2)
                if d >= LAM:
                    J[at + i, d] -= tip_rate[d - LAM, _TD + at + i]
    if act is not None:
        last = now.shape[0] - 1
        _dipole_jump(y, T, nt, act[4], last + 1, now[last], rate, last, law[2][5], r, J, -1.0)


@_jit
def _set_loads(lam, case, now, tip_now):
    """The loads at load factor λ: start + λ (end - start), per piece and at the tip."""
    start, rate, tip_start, tip_rate = case
    for j in range(start.shape[0]):
        for i in range(start.shape[1]):
            now[j, i] = start[j, i] + lam * rate[0, j, i]
    for i in range(TIP_LOADS):
        tip_now[i] = tip_start[i] + lam * tip_rate[0, i]


@_inline
def _integrate(x, lam, nt, steps, base, arm, act, case, scratch, r, J):
    """Integrate base → tip from the base reaction x at load factor λ: the residual r (6) and
    the first nt Jacobian columns J[:, :nt] (6 by x, the 7th by λ). The tip state is left in
    scratch's y and its tangents in T (for the tip motion per unit x)."""
    y, T, work, twork, now, tip_now = scratch[0], scratch[1], scratch[2], scratch[3], \
        scratch[4], scratch[5]
    law = scratch[8]
    rate, tip_rate = case[1], case[3]
    _set_loads(lam, case, now, tip_now)
    piece_start, piece_len = arm[0], arm[1]
    _start(y, T, nt, base, x)
    for j in range(piece_len.size):
        _jump(y, T, nt, now, rate, j, arm, act, law)
        _steps(y, T, nt, piece_len[j] / steps[j], piece_start[j], steps[j], arm, act, j, now, rate,
               work, twork, law)
    _tip_residual(y, T, nt, tip_now, tip_rate, r, J, arm, act, now, rate, law)


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
def _newton_step(J, r, dx):
    """dx = -J_x⁻¹ r."""
    neg = np.empty(6)
    for i in range(6):
        neg[i] = -r[i]
    return _linear_solve(J, neg, dx)


@_jit
def _norm_scaled(r, scale):
    out = 0.0
    for i in range(6):
        a = abs(r[i]) / scale[i]
        if not a <= out:  # also catches NaN
            out = a if math.isfinite(a) else np.inf
    return out


@_jit
def _distance(dx, T, scale, length):
    """The size of a change dx of the base reaction, nondimensional: the largest of the tip
    displacement / L and tip rotation (rad) it causes (to first order, from the tip tangents
    T[:6]) and of its components in units of ``scale`` (the bending scale times the case's
    load size, so that a given relative change of the reaction counts alike at any load)."""
    out = 0.0
    for i in range(6):
        out = max(out, abs(dx[i]) / scale[i])
    for row in range(6):
        acc = 0.0
        for d in range(6):
            acc += T[d, row] * dx[d]
        out = max(out, abs(acc) / (length if row < 3 else 1.0))
    if not math.isfinite(out):
        return np.inf
    return out


@_jit
def _corrector(x, lam, nt, steps, base, arm, act, case, scratch, scale, dscale, length, threshold,
               max_iterations, first_limit, loose, r, J, tip, counter):
    """Newton at fixed λ from the prediction x, accepted only if it stays near it.

    The steps together must be no larger than ``first_limit`` (nondimensional, see
    _distance) and every step after the first at most half the one before (contraction): a
    corrector that wanders or stalls is rejected instead of accepted at whatever root it
    reaches. Converged when the
    residual is below ``threshold``, or when a step is no larger than ``loose``: that step is
    taken without integrating again (its error is of the order of its square), the tip
    position ``tip`` is moved by its linearisation and J is the one of the point before.
    True when converged; x, r, J (nt columns) and tip hold the solution; x changes even on
    failure.
    """
    dx = np.empty(6)
    previous = np.inf
    travelled = 0.0
    y, T = scratch[0], scratch[1]
    for k in range(max_iterations + 1):
        _integrate(x, lam, nt, steps, base, arm, act, case, scratch, r, J)
        counter[0] += 1
        for i in range(3):
            tip[i] = y[_P + i]
        res = _norm_scaled(r, scale)
        if res <= threshold:
            return True
        if k == max_iterations or not math.isfinite(res) or not _newton_step(J, r, dx):
            return False
        size = _distance(dx, T, dscale, length)
        if k == 0:
            if size > first_limit:
                return False
        elif size > _CONTRACTION_MAX * previous:
            # a step at round-off level cannot contract further: accept a tiny residual
            return res <= _STALL * threshold
        previous = size
        travelled += size
        if travelled > first_limit:
            return False  # wandered: the sum of the steps is a bound of the distance moved
        for i in range(6):
            x[i] += dx[i]
        if size <= loose:
            for i in range(3):
                for d in range(6):
                    tip[i] += T[d, _TP + i] * dx[d]
            return True
    return False


@_jit
def _det_sign(J):
    """The sign of det ∂r/∂x (J[:, :6]); 0 if singular. Its parity is that of the number of
    unstable directions: a change between two points of the path means a singular point
    (fold or bifurcation) between them."""
    M = np.empty((6, 6))
    for i in range(6):
        for k in range(6):
            M[i, k] = J[i, k]
    return _eliminate(M)


@_jit
def _tip_motion(T, t, out):
    """The tip displacement (spatial) per unit load factor along the path tangent t."""
    for i in range(3):
        acc = 0.0
        for d in range(6):
            acc += T[d, _TP + i] * t[d]
        out[i] = acc


@_jit
def _cosine(a, b):
    """The cosine of the angle between two 3-vectors (1 if either is zero). The norms are
    multiplied, not their squares: two tiny motions (an input of 1e-113 N) have squares
    whose product underflows to 0 (a ZeroDivisionError)."""
    aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2]
    bb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2]
    if not (aa > 0.0 and bb > 0.0):
        return 1.0
    return (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (math.sqrt(aa) * math.sqrt(bb))


@_jit
def _tangent(J, t):
    """The path tangent dx/dλ = -J_x⁻¹ J_λ."""
    rhs = np.empty(6)
    for i in range(6):
        rhs[i] = -J[i, LAM]
    return _linear_solve(J, rhs, t)


@_inline
def _load_step(lam, dl, end):
    """(Δλ, the target λ + Δλ): a step that would leave less than half a step to ``end``
    (the path's end, λ = 1 but on a level of the stiff path) is stretched to reach it."""
    if lam + 1.5 * dl >= end:
        dl = end - lam
    target = lam + dl
    if target >= end - 1e-12 * end:
        target = end
    return dl, target


@_inline
def _grown(dl, moved, max_load_step):
    """The next Δλ after an accepted step whose corrector moved ``moved`` from the
    prediction: Δλ (aim/δ)^(1/3) within [Δλ/2, 2Δλ], at most max_load_step."""
    grow = 2.0 if moved <= 0.0 else min(2.0, max(0.5, (_DIST_AIM / moved) ** (1 / 3)))
    return min(max_load_step, dl * grow)


@_jit
def _sizes(arm, act, loads, tip):
    """(F, M): bounds of the total force (N) and moment (N m) that one set of load channels
    (``loads`` (P, W) per piece, ``tip`` (TIP_LOADS,)) applies to the arm, each the sum of
    its components' magnitudes: tip, distributed (times the piece length) and point forces
    and moments, and the magnets' forces and torques (|m| |G| and |m| |B| per length, |B|
    bounded as in :func:`_load_size`). Not the actuators': a tendon's tension or a chamber's
    pressure is internal to the arm (it bends it without buckling it)."""
    piece_len = arm[1]
    L = arm[6]
    force = moment = 0.0
    for i in range(3):
        force += abs(tip[_TD + i]) + abs(tip[_TF + i])
        moment += abs(tip[_TD + 3 + i]) + abs(tip[_TF + 3 + i])
    for j in range(piece_len.size):
        f = m = 0.0
        for i in range(3):
            f += abs(loads[j, _FD + i]) + abs(loads[j, _FF + i])
            m += abs(loads[j, _LD + i]) + abs(loads[j, _LF + i])
            force += abs(loads[j, _JD + i]) + abs(loads[j, _JF + i])
            moment += abs(loads[j, _JD + 3 + i]) + abs(loads[j, _JF + 3 + i])
        if act is not None:
            mag, dipoles = act[3], act[4]
            field = gradient = 0.0
            for i in range(3):
                field += abs(loads[j, _FB + i])
            for i in range(9):
                gradient += abs(loads[j, _FG + i])
            field += gradient * 2.0 * L
            strength = abs(mag[j, 0]) + abs(mag[j, 1]) + abs(mag[j, 2])
            dipole = abs(dipoles[j, 0]) + abs(dipoles[j, 1]) + abs(dipoles[j, 2])
            if j == piece_len.size - 1:
                dipole += (abs(dipoles[j + 1, 0]) + abs(dipoles[j + 1, 1])
                           + abs(dipoles[j + 1, 2]))
            f += strength * gradient
            m += strength * field
            force += dipole * gradient
            moment += dipole * field
        force += f * piece_len[j]
        moment += m * piece_len[j]
    return force, moment


@_jit
def _path_bounds(arm, act, case, scale, out):
    """What the branch guard needs to know of a case's homotopy, loads(λ) = start + λ rate
    (``case``), in ``out`` (7,): Q = ∫ √(1/EI) ds and ∫ ds/EI (each piece's softest
    bending), the force bounds (N) of the start loads and of the rate, the moment bounds
    (N m) likewise (:func:`_sizes`; the phase is Φ(λ) = Q √(F(λ)) + ½ ∫ds/EI M(λ)), and the
    load factor's offset: the start loads' size over the rate's (0 from the unloaded arm),
    so that λ + offset measures the loads on the path's own scale (a chained Solver's
    small step from large loads)."""
    piece_len, C = arm[1], arm[2]
    Q = flex = 0.0
    for j in range(piece_len.size):
        c = max(C[j, 4, 4], C[j, 5, 5])
        Q += piece_len[j] * math.sqrt(c)
        flex += piece_len[j] * c
    start, rate, tip_start, tip_rate = case
    fs, ms = _sizes(arm, act, start, tip_start)
    fr, mr = _sizes(arm, act, rate[0], tip_rate[0])
    ws, _ = _load_size(arm, act, scale, start, start, tip_start, tip_start)
    wr, _ = _load_size(arm, act, scale, rate[0], rate[0], tip_rate[0], tip_rate[0])
    out[0], out[1], out[2], out[3], out[4], out[5] = Q, flex, fs, fr, ms, mr
    out[6] = 0.0 if ws == 0.0 else (ws / wr if wr > 0.0 else np.inf)


@_jit
def _phase(bounds, lam):
    """The path's phase Φ at load factor λ (:func:`_path_bounds`)."""
    return (bounds[0] * math.sqrt(bounds[2] + lam * bounds[3])
            + 0.5 * bounds[1] * (bounds[4] + lam * bounds[5]))


@_jit
def _phase_limited(bounds, lam, dl):
    """Δλ, shortened so that the step from λ advances the phase by at most _PHASE_STEP
    (half of it by the forces, half by the moments), while Φ <= _PHASE_TESTED."""
    if not _phase(bounds, lam) <= _PHASE_TESTED:
        return dl
    Q, flex, fs, fr, mr = bounds[0], bounds[1], bounds[2], bounds[3], bounds[5]
    if fr > 0.0 and Q > 0.0:
        u0 = math.sqrt(fs + lam * fr)
        u1 = u0 + 0.5 * _PHASE_STEP / Q
        dl = min(dl, (u1 * u1 - u0 * u0) / fr)
    if mr > 0.0 and flex > 0.0:
        dl = min(dl, _PHASE_STEP / (flex * mr))
    return dl


@_jit
def _crossed(J_before, J_after, scale, guard):
    """How many singular points the path passed between two of its points: the
    :func:`_crossings` of ∂r/∂x there (columns in units of the bending scale), -1 if the
    first is singular. ``guard``: work arrays (:func:`_guard_work`)."""
    A, B, work, M = guard
    for i in range(6):
        for k in range(6):
            A[i, k] = J_before[i, k] * scale[k]
            B[i, k] = J_after[i, k] * scale[k]
    return _crossings(A, B, np.int64(6), work, M, 0.0)


@_jit
def _guard_work():
    """The branch guard's work arrays: two 6 × 6 matrices, the elimination's 6 × 12, the
    product's 6 × 6."""
    return (np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 12)), np.empty((6, 6)))


@_jit
def _cross_step(bounds, lam):
    """The longest step accepted across a singular point at load factor λ."""
    return _CROSS_REL * (lam + bounds[6])


@_jit
def _follow(x, steps, base, arm, act, case, scratch, scale, dscale, length, threshold,
            max_iterations, max_load_step, max_shootings, open_end, final, r, J, tip,
            counter, reached, J_path):
    """Follow the equilibrium path from λ = 0 (x: the solution there, exact or close) to
    λ = 1 by predictor–corrector continuation. True on success, with x, r, J (7 columns) and
    the tip position at λ = 1, converged as the caller's own corrector would leave them (a
    last step no larger than ``final``, or the threshold: no refinement is needed on these
    steps); otherwise ``reached[0]`` is the last load factor reached (a fold, or a point the
    path cannot be followed past) and x the solution there. Points on the way are converged
    to ``_LOOSE``. ``J_path`` receives ∂r/∂x at the last point
    accepted (the caller checks its own last correction against it).

    Predictor: the tangent dx/dλ = -J_x⁻¹ J_λ from the variational equations for the first
    step, then the cubic Hermite extrapolation of the last two points and their tangents.
    Corrector: :func:`_corrector` (distance and contraction tests). Step control: the first
    Δλ makes the predicted motion ``_FIRST_MOTION``; then Δλ ← Δλ (aim/δ)^(1/3) within
    [Δλ/2, 2Δλ], δ the corrector's distance from the predictor; Δλ × 0.4 after a failure; a
    step that would leave less than half a step to λ = 1 is stretched to reach it; no step
    advances the phase by more than _PHASE_STEP (:func:`_phase_limited`).

    Branch guard: a step is refused when a singular point lies in it (det ∂r/∂x changes
    sign, or :func:`_crossed` counts a crossing: a double root too) or the tip's direction of
    motion turns by more than 60°, unless the step is no longer than :func:`_cross_step`: a
    singular point of the path itself (a perfect bifurcation) is crossed; the sharp turn
    beside an imperfect one is followed in steps short enough to see it.

    With ``open_end``, the last step (to λ = 1) is predicted but not corrected: x is the
    prediction, for the caller's corrector on a finer grid (with the same first-step limit
    ``_DIST_MAX`` and contraction test, so the last step is checked as any other).
    """
    reached[0] = 0.0
    end = 1.0
    nt = J.shape[1]  # all 7 columns (a variable, not a literal: one compiled version)
    if not _corrector(x, 0.0, nt, steps, base, arm, act, case, scratch, scale, dscale, length,
                      threshold, max_iterations, _REFINE_MAX, _LOOSE, r, J, tip, counter):
        return False
    t = np.empty(6)
    t_new = np.empty(6)
    x0 = np.empty(6)
    xp = np.empty(6)  # the point before (λp), and its tangent
    tp = np.empty(6)
    dx = np.empty(6)
    if not _tangent(J, t):
        return False
    bounds = np.empty(7)
    _path_bounds(arm, act, case, scale, bounds)
    guard = _guard_work()
    _copy_jx(J, J_path)
    sign = _det_sign(J)
    reached[1] = sign
    motion_prev = np.empty(3)
    _tip_motion(scratch[1], t, motion_prev)
    motion_new = np.empty(3)
    lam = 0.0
    lam_p = -1.0  # no point before yet
    motion = _distance(t, scratch[1], dscale, length)
    dl = max_load_step if motion <= 0.0 else min(max_load_step, _FIRST_MOTION / motion)
    while lam < 1.0:
        if counter[0] > max_shootings:
            return False
        dl, target = _load_step(lam, _phase_limited(bounds, lam, dl), end)
        for i in range(6):
            x0[i] = x[i]
        h = lam - lam_p
        tau = (target - lam_p) / h
        if lam_p >= 0.0 and tau <= 3.0:
            # cubic Hermite through (λp, xp, tp) and (λ, x, t), evaluated at the target
            t2, t3 = tau * tau, tau * tau * tau
            h00, h10 = 2 * t3 - 3 * t2 + 1.0, t3 - 2 * t2 + tau
            h01, h11 = -2 * t3 + 3 * t2, t3 - t2
            for i in range(6):
                x[i] = h00 * xp[i] + h10 * h * tp[i] + h01 * x0[i] + h11 * h * t[i]
        else:
            for i in range(6):
                x[i] = x0[i] + (target - lam) * t[i]
        if open_end and target == 1.0:
            reached[0] = lam  # reached[1]: the sign of det ∂r/∂x there, for the caller
            return True
        for i in range(6):
            dx[i] = x[i]  # the prediction
        ok = _corrector(x, target, nt, steps, base, arm, act, case, scratch, scale, dscale, length,
                        threshold, max_iterations, _DIST_MAX,
                        final if target == 1.0 else _LOOSE, r, J, tip, counter)
        if ok:
            for i in range(6):
                dx[i] = x[i] - dx[i]  # the corrector's distance from the prediction
            ok = _tangent(J, t_new)
        if ok:
            new_sign = _det_sign(J)
            _tip_motion(scratch[1], t_new, motion_new)
            crossing = new_sign != sign or _crossed(J_path, J, scale, guard) != 0
            ok = dl <= _cross_step(bounds, lam) or (
                not crossing and _cosine(motion_prev, motion_new) >= 0.5)
            if ok:
                sign = new_sign
                reached[1] = sign
                for i in range(3):
                    motion_prev[i] = motion_new[i]
        if ok:
            for i in range(6):
                xp[i] = x0[i]
                tp[i] = t[i]
                t[i] = t_new[i]
            _copy_jx(J, J_path)
            lam_p = lam
            lam = target
            reached[0] = lam
            dl = _grown(dl, _distance(dx, scratch[1], dscale, length), max_load_step)
        else:
            for i in range(6):
                x[i] = x0[i]
            dl *= 0.4
            if dl < _smallest_step(bounds, lam):
                return False
    return True


@_jit
def _copy_jx(J, out):
    """out = J[:, :6] (∂r/∂x of a Jacobian with more columns)."""
    for i in range(6):
        for k in range(6):
            out[i, k] = J[i, k]


@_jit
def _smallest_step(bounds, lam):
    """The shortest load step tried before a path is given up at λ (a fold, or a point it
    cannot pass): below any step that crosses a singular point (:func:`_cross_step`)."""
    return max(_DLAM_FLOOR, 0.01 * _cross_step(bounds, lam))


@_jit
def _write(y, T, nt, j, s, arm, act, now, law, pose, strain, stress, E):
    """One station's outputs: pose, the rod's own material strain ε - f⁰ and stress
    K (ε - f⁰) (with actuators, the total wrench less the tendons' and the fluid's share),
    and (nt >= 6) the station's motion per unit base reaction, E[:, :6] = ∂(δp; δθ)/∂x,
    and per unit input (E[:, 6:nt], the input columns), both rows in spatial components."""
    for i in range(4):
        for k in range(4):
            pose[i, k] = 0.0
    pose[3, 3] = 1.0
    for i in range(3):
        pose[i, 3] = y[_P + i]
        for k in range(3):
            pose[i, k] = y[_R + 3 * i + k]
    for i in range(3):
        stress[i] = y[_R + i] * y[_N] + y[_R + 3 + i] * y[_N + 1] + y[_R + 6 + i] * y[_N + 2]
        stress[3 + i] = (y[_R + i] * y[_M] + y[_R + 3 + i] * y[_M + 1]
                         + y[_R + 6 + i] * y[_M + 2])
    if act is not None and _actuated(act, j):
        f0, K = arm[3], arm[8]
        eps = _law(arm, act, j, s, now, law, np.int64(0), stress[0], stress[1], stress[2],
                   stress[3], stress[4], stress[5])
        for i in range(6):
            strain[i] = eps[i] - f0[j, i]
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += K[j, i, k] * strain[k]
            stress[i] = acc
    else:
        C = arm[2]
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += C[j, i, k] * stress[k]
            strain[i] = acc
    for d in range(nt):
        for i in range(3):
            E[i, d] = T[d, _TP + i]
            E[3 + i, d] = (y[_R + 3 * i] * T[d, _TT] + y[_R + 3 * i + 1] * T[d, _TT + 1]
                           + y[_R + 3 * i + 2] * T[d, _TT + 2])


@_jit
def _record(x, nt, steps, base, arm, act, case, lam, scratch, s_out, out, b, r, J):
    """Integrate the solution x at load factor ``lam`` once more and write every station's
    outputs (the same steps as :func:`_integrate`, so the same numbers), the tip residual r
    and, with nt >= 6, the Jacobian J and the station tangents (columns 6.. along the
    case's rate rows: the inputs); and the case's base reaction and tendon lengths.

    A station inside a step is interpolated: the cubic Hermite polynomial of the state and
    tangents on the step, from their values and derivatives at both ends (the derivative at
    the end is the next step's first stage, so it costs nothing inside a piece), then one
    Björck step on R. Its error is of the order of the step's own discretisation error
    (statics/README.md: measured against tight solves); the stations never change the
    steps of the solution. A station at a piece start gets the state after the point wrench
    there (the tip side). The station s = L (and any station past the last step's start) is
    written from the tip state itself.
    """
    y, T, work, twork, now, tip_now, ys, Ts, law = scratch
    poses, strains, stresses = out[0][b], out[1][b], out[2][b]
    E = out[6][b if nt > 0 else 0]  # a (1, S, 6, 6) placeholder without tangents
    rate, tip_rate = case[1], case[3]
    piece_start, piece_len = arm[0], arm[1]
    _set_loads(lam, case, now, tip_now)
    _start(y, T, nt, base, x)
    k = 0
    ns = s_out.size
    npieces = piece_len.size
    one = np.int64(1)  # not a literal 1: _steps is compiled once for every caller
    zero = one - one
    for j in range(npieces):
        _jump(y, T, nt, now, rate, j, arm, act, law)
        h = piece_len[j] / steps[j]
        i = 0
        known = False  # work[0], twork[0] hold the derivatives at (y, T, this step's start)
        while i < steps[j]:
            # the steps surely before the next station's step, as one run (one step of
            # margin against rounding: the step-by-step branch below decides exactly)
            run = steps[j] - i
            if k < ns:
                run = min(run, max(int((s_out[k] - piece_start[j]) / h) - 1 - i, 0))
            if run > 0:
                _steps(y, T, nt, h, piece_start[j] + i * h, -run if known else run, arm, act, j,
                       now, rate, work, twork, law)
                known = False
                i += run
                continue
            t0 = piece_start[j] + i * h
            last = j == npieces - 1 and i == steps[j] - 1
            t1 = piece_start[j] + (i + 1) * h if i < steps[j] - 1 else (
                piece_start[j + 1] if j < npieces - 1 else np.inf)
            inside = k < ns and s_out[k] < t1 and not (last and s_out[k] >= arm[6])
            if not inside:  # (the tip station is the tip state itself, below)
                _steps(y, T, nt, h, t0, -one if known else one, arm, act, j, now, rate, work,
                       twork, law)
                known = False
                i += 1
                continue
            # stations inside this step: the step from its start (kept with its derivative,
            # the step's first stage), the derivative at its end (the next step's first
            # stage on this piece), then each station by Hermite interpolation
            _copy(y, work[5])
            for d in range(nt):
                for a in range(T.shape[1]):
                    twork[5, d, a] = T[d, a]
            _steps(y, T, nt, h, t0, -one if known else one, arm, act, j, now, rate, work, twork,
                   law)
            _copy(work[0], work[6])
            for d in range(nt):
                for a in range(T.shape[1]):
                    twork[6, d, a] = twork[0, d, a]
            # (at the next step's own start, to the bit: its first stage is this one)
            _steps(y, T, nt, h, piece_start[j] + (i + 1) * h, zero, arm, act, j, now, rate, work,
                   twork, law)
            known = i + 1 < steps[j]
            while k < ns and s_out[k] < t1:
                if last and s_out[k] >= arm[6]:
                    break
                u = (s_out[k] - t0) / h
                c0 = (1.0 + 2.0 * u) * (1.0 - u) * (1.0 - u)  # cubic Hermite basis
                c1 = u * (1.0 - u) * (1.0 - u) * h
                c2 = u * u * (3.0 - 2.0 * u)
                c3 = -u * u * (1.0 - u) * h
                for a in range(y.size):
                    ys[a] = c0 * work[5, a] + c1 * work[6, a] + c2 * y[a] + c3 * work[0, a]
                for d in range(nt):
                    for a in range(T.shape[1]):
                        Ts[d, a] = (c0 * twork[5, d, a] + c1 * twork[6, d, a] + c2 * T[d, a]
                                    + c3 * twork[0, d, a])
                _station_rotation(work[5], work[6], y, work[0], u, h, ys)
                _write(ys, Ts, nt, j, s_out[k], arm, act, now, law, poses[k], strains[k],
                       stresses[k], E[k])
                k += 1
            i += 1
    for i in range(k, ns):
        _write(y, T, nt, npieces - 1, arm[6], arm, act, now, law, poses[i], strains[i],
               stresses[i], E[i])
    _tip_residual(y, T, nt, tip_now, tip_rate, r, J, arm, act, now, rate, law)
    for a in range(J.shape[0] - 6):  # rows 6 + a (when given): tendon a's length's tangents
        for d in range(nt):
            J[6 + a, d] = T[d, NT + a]
    base_out, lengths = out[7], out[8]
    for i in range(6):
        base_out[b, i] = x[i]
    for a in range(lengths.shape[1]):
        lengths[b, a] = y[18 + a]


@_jit
def _fill_steps(length, piece_len, N, factor, out):
    """Steps per piece for a nominal N steps over the whole arm (at least one per piece,
    rounded to the nearest whole number), times ``factor`` (2 for the fine solution)."""
    for j in range(piece_len.size):
        out[j] = factor * max(1, math.floor(N * piece_len[j] / length + 0.5))


@_jit
def _load_size(arm, act, scale, start, end, tip_start, tip_end):
    """(w, turning): the case's largest load in units of the bending scale (EI/L² for
    forces, EI/L for moments; distributed loads times the piece length, at either end of
    the homotopy) and an upper estimate of the total turning of the arm (rad), the largest
    load moment about the base times ∫ ds/EI with each piece's softest bending
    compliance (bending; the pieces of a very soft segment need as many steps as its
    turning). An actuator's tension or pressure force is internal (no net force on the arm)
    but bends it: it counts as a moment |q| ρ (ρ its largest distance from the centreline)
    on each piece it acts on; a magnetisation m as a moment |m| |B|
    per length, and a dipole as a moment |m| |B|, |B| bounded by |B0| + |G| (L + |p0|)."""
    piece_len, C = arm[1], arm[2]
    L = arm[6]
    fs, ms = scale[0], scale[3]
    flexibility = 0.0  # ∫ ds / EI, with each piece's largest rotational compliance
    for j in range(piece_len.size):
        flexibility += piece_len[j] * max(C[j, 4, 4], C[j, 5, 5])
    w = 0.0
    moment = 0.0
    for which in range(2):
        loads = start if which == 0 else end
        tip = tip_start if which == 0 else tip_end
        f_tip, m_tip = 0.0, 0.0
        for i in range(3):
            f_tip += abs(tip[_TD + i]) + abs(tip[_TF + i])
            m_tip += abs(tip[_TD + 3 + i]) + abs(tip[_TF + 3 + i])
        w = max(w, f_tip / fs, m_tip / ms)
        total = f_tip * L + m_tip
        f_along = 0.0
        actuators = 0.0
        for j in range(piece_len.size):
            f, m, jf, jm = 0.0, 0.0, 0.0, 0.0
            for i in range(3):
                f += abs(loads[j, _FD + i]) + abs(loads[j, _FF + i])
                m += abs(loads[j, _LD + i]) + abs(loads[j, _LF + i])
                jf += abs(loads[j, _JD + i]) + abs(loads[j, _JF + i])
                jm += abs(loads[j, _JD + 3 + i]) + abs(loads[j, _JF + 3 + i])
            actuated = 0.0  # internal: a moment along the piece, no net force
            if act is not None:
                routes, mag, dipoles = act[0], act[3], act[4]
                field = 0.0
                for i in range(3):
                    field += abs(loads[j, _FB + i])
                for i in range(9):
                    field += abs(loads[j, _FG + i]) * 2.0 * L
                dipole = abs(dipoles[j, 0]) + abs(dipoles[j, 1]) + abs(dipoles[j, 2])
                if j == piece_len.size - 1:
                    dipole += (abs(dipoles[j + 1, 0]) + abs(dipoles[j + 1, 1])
                               + abs(dipoles[j + 1, 2]))
                m += (abs(mag[j, 0]) + abs(mag[j, 1]) + abs(mag[j, 2])) * field
                jm += dipole * field
                for a in range(routes.shape[0]):
                    actuated += abs(loads[j, _ACT + a]) * routes[a, _RHO]
            actuators = max(actuators, actuated)
            f_along += f * piece_len[j] + jf
            w = max(w, f_along / fs, m * piece_len[j] / ms, jm / ms, actuated / ms)
            total += f * piece_len[j] * 0.5 * L + jf * L + m * piece_len[j] + jm
        w = max(w, f_along / fs)
        moment = max(moment, total + actuators)
    return w, moment * flexibility


#: Coarse steps per radian of the unloaded arm's turning Σ |κ⁰| L at the least
#: (_first_steps): one radian a step on the path's quarter grid.
_CURVED_STEPS = 4.0


@_jit
def _first_steps(arm, tol, turning):
    """The first coarse step count: 0.07 (1 + turning) (tol/L)^-1/4, in [2, 256] (the
    constant measured: the Richardson estimate then lands at 0.003-0.5 tol on the benchmark
    cases, so N rarely has to grow)."""
    kappa0 = 0.0
    for j in range(arm[1].size):
        kappa0 += arm[1][j] * math.sqrt(arm[3][j, 3] ** 2 + arm[3][j, 4] ** 2
                                        + arm[3][j, 5] ** 2)
    rel = tol / arm[6] if math.isfinite(tol) else 1e-8
    n = math.ceil(0.07 * (1.0 + kappa0 + turning) * rel ** -0.25)
    # and _CURVED_STEPS per radian of the unloaded arm's own turning, beyond the cap: the
    # path runs on a quarter of N, and RK4 turns a section stably by < 2.8 rad a step
    return max(min(256, max(2, n)), math.ceil(_CURVED_STEPS * kappa0))


@_inline
def _chord(x, J_c, steps, base, arm, act, case, scratch, scale, threshold, max_iterations,
           may_defer, r, J, tip, counter):
    """The solution at λ = 1 with another step count by chord iterations from x (a solution
    with a nearby step count) with that solution's Jacobian J_c, state only (no tangents).

    The first step may change x only by a discretisation-sized amount (``_REFINE_MAX``) and
    each iteration must at least halve the residual. Returns 0 (failed), 1 (converged: r and
    tip are x's) or 2 (the last step was taken without integrating it, because the observed
    contraction predicts a residual below the threshold: the output pass checks it, and
    ``tip`` is the position before that step, an error of the order of the step; only if
    ``may_defer``). A residual that stops halving is accepted if within ``_STALL`` times the
    threshold: the round-off floor of an ill-conditioned shooting map (a long, thin, stiff
    wire), still 1e-9 of the case's own load.
    """
    dx = np.empty(6)
    previous = np.inf
    none = J.shape[1] - 7  # no tangents (a variable, not a literal: one compiled version)
    for _ in range(max_iterations):
        _integrate(x, 1.0, none, steps, base, arm, act, case, scratch, r, J)
        counter[0] += 1
        for i in range(3):
            tip[i] = scratch[0][_P + i]
        res = _norm_scaled(r, scale)
        if res <= threshold:
            return 1
        if not res < 0.5 * previous:
            # stalled: at round-off for this problem's conditioning, if small against the
            # case's own load (1e-9 of it), else a failure
            return 1 if res <= _STALL * threshold else 0
        if not _newton_step(J_c, r, dx):
            return 0
        if not math.isfinite(previous):  # the first step: a change of discretisation only
            size = 0.0
            for i in range(6):
                size = max(size, abs(dx[i]) / scale[i])
            if not size <= _REFINE_MAX:
                return 0
        # the chord contraction: observed, or at first ~ 10 res (the Jacobians of N and 2N
        # steps differ by the discretisation error, as r does; a cautious guess, since a
        # wrong one costs a whole output pass)
        rate = res / previous if math.isfinite(previous) else 10.0 * res
        previous = res
        for i in range(6):
            x[i] += dx[i]
        if may_defer and rate * res <= threshold:
            return 2
    return 0


@_jit
def _scratch(npieces, nact, ncols):
    """Work arrays of one integration (state with the nact tendon lengths, ncols tangent
    columns, RK4 stages (rows 0-3 the stage derivatives, 4 the stage state, 5-6 the output
    pass's step start: state and derivative), loads at λ, a station's own state and
    tangents, and the
    constitutive law's: the 6 × (6 + ncols) elimination matrix, per actuator (t, |w|, y, z,
    y', z'), small vectors)."""
    width = 18 + nact
    law = (np.empty((6, 6 + ncols)), np.zeros((max(nact, 1), 8)), np.zeros((6, 6)),
           np.zeros((6, 6)))
    return (np.empty(width), np.empty((ncols, NT + nact)), np.empty((7, width)),
            np.empty((7, ncols, NT + nact)), np.empty((npieces, PIECE_LOADS + nact)),
            np.empty(TIP_LOADS), np.empty(width), np.empty((ncols, NT + nact)), law)


@_jit
def _copy(src, dst):
    for i in range(src.size):
        dst.flat[i] = src.flat[i]


@_inline
def _output(x, nt, steps, base, arm, act, case, piece_loads, tip_loads, inputs, scratch, s_out,
            out, b, r, J, J_out):
    """The output pass of case b (:func:`_record` at λ = 1); with tangents (nt = 6) and
    actuation inputs, also one tangent column per input: the pass then runs on the case's
    final loads with the inputs as its rate rows (at λ = 0, the same loads), J_out gets the
    6 + n columns. (``inputs`` is None without Jacobians: that part is not compiled.)"""
    if inputs is None or nt == 0 or inputs[0].shape[0] == 0:
        _record(x, nt, steps, base, arm, act, case, 1.0, scratch, s_out, out, b, r, J)
        return
    n_inputs = inputs[0].shape[0]
    at_inputs = (piece_loads, inputs[0], tip_loads, inputs[1])
    _record(x, 6 + n_inputs, steps, base, arm, act, at_inputs, 0.0, scratch, s_out, out, b, r,
            J_out)


@_inline
def _retry_finer(n_fixed, N, n_max, failures, reached, failed_at):
    """Whether a path that failed at load factor ``reached`` is tried again on twice the
    steps: a fold persists under refinement at about the same load factor; a failure of an
    under-resolved path moves or disappears (at most 4 times, within the step limit)."""
    return (n_fixed == 0 and 2 * N <= n_max // 2 and failures < 4
            and abs(reached - failed_at) > 0.02)


@_inline
def _read_options(options):
    """(tol, max_iterations, max_load_step, fixed step count, largest step count, budget)
    from the solver options (see solve_cases)."""
    return (options[_O_TOL], int(options[_O_ITER]), options[_O_LOADSTEP],
            int(options[_O_NFIXED]), int(options[_O_NMAX]), int(options[_O_BUDGET]))


@_entry(_solver, nogil=True)
def solve_cases(base, arm, act, loads, first, options, s_out, memory, inputs, out):
    """Solve every load case of a flattened batch.

    Each case follows its own homotopy from λ = 0 to 1 (see the module docstring): from the
    unloaded arm (start loads 0, x = 0) unless chained (``memory`` given), where case b
    starts from case b - 1's loads and solution (case 0 from ``first`` and ``memory``): a
    slowly driven arm.

    Capabilities are compiled on first use (README.md, "Compiled per capability"): ``act``,
    ``first`` and ``memory``, and ``inputs`` are None for a passive arm, an unchained batch
    and a solve without Jacobians, and numba then prunes the code that uses them before
    typing it: a first passive solve compiles neither the actuated law nor the chained
    starts nor the input columns.

    Per case, the stage machine of README.md: the path at N steps (continuation),
    the solution at 2N (chord iterations, else a checked Newton, else the path at 2N), the
    Richardson estimate |p_2N - p_N| / 15 against tol, N grown by the order-4 model (a
    checked Newton from the 2N solution, else the path again) until it is met, then the
    output pass.

    Parameters (B cases, P pieces, S stations)
    ----------
    base : (4, 4) base pose.
    arm : (piece_start (P,), piece_len (P,), C (P, 6, 6) compliance, f0 (P, 6) reference
        strain, zero (P, 6), diag (bool: every C diagonal), length, scale (6,) residual
        scale, K (P, 6, 6) stiffness); see README.md.
    act : None for a passive arm (no actuator, no magnet), else (routes (A, 4 + 2D)
        actuator paths, kinds (A,) TENDON or CHAMBER, active (P, A) 1.0 where actuator a
        acts on piece j, mag (P, 3) magnetisation (A m²/m, material), dipoles (P + 1, 3)
        dipole at each piece start and at the tip (A m², material)).
    loads : (piece (B, P, PIECE_LOADS + A), tip (B, TIP_LOADS)): each case's loads at λ = 1.
    first : None (every case from the unloaded arm), or with ``memory``: (piece
        (P, PIECE_LOADS + A), tip (TIP_LOADS,)), case 0's start loads.
    options : (OPTIONS,) tol (m; inf with a fixed step count), max_iterations, max_load_step,
        fixed step count (0: from tol), largest step count, shootings budget, the ratio of
        the step counts of the solution and of the path, near (0/1, chained only: case 0's
        start loads are its own and ``memory`` holds a solution on its fine grid,
        :meth:`Solver.solve_near`; its coarse solution is corrected from there, the path
        only if that fails).
    memory : None (unchained), or (MEMORY,) the chained start (x at N, x at 2N, N, valid,
        sign of det ∂r/∂x at N), read and rewritten; with a predicted step
        (``memory[_MPREDICTED]``, consumed), case 0 tries it before its path.
    inputs : None (no Jacobians), or (piece (n, P, PIECE_LOADS + A), tip (n, TIP_LOADS)):
        the load channels per unit of each actuation input (n = 0: none); the output pass
        then integrates the tangents, with one more column per input: J and E have 6 + n
        columns.
    out : (poses (B, S, 4, 4), strains (B, S, 6), stresses (B, S, 6), info (B, 5) [residual,
        error estimate, load factor reached, shootings, N], status (B,), J (B, 6, 6) at the
        solution (jacobians), E (B, S, 6, 6) station motion per unit x (jacobians), x (B, 6)
        the base reaction (total wrench at the clamp, spatial), lengths (B, A) each tendon's
        length).
    """
    piece_loads, tip_loads = loads
    nb = piece_loads.shape[0]
    npieces = arm[1].size
    scale = arm[7]
    length = arm[6]
    tol, max_iterations, max_load_step, n_fixed, n_max, budget = _read_options(options)
    near = memory is not None and options[_O_NEAR] > 0.0
    # (nb - nb: a variable, not the literal 0, which would compile _record and everything
    # below it a second time, for the type Literal[int](0))
    nt_out = nb - nb if inputs is None else 6
    coarse_ratio = int(options[_O_COARSE])
    info, status, jac = out[3], out[4], out[5]
    width = piece_loads.shape[2]
    n_inputs = 0 if inputs is None else inputs[0].shape[0]
    scratch = _scratch(npieces, width - PIECE_LOADS, 7 + n_inputs)
    start = np.zeros((npieces, width))
    rate = np.empty((1, npieces, width))
    tip_start = np.zeros(TIP_LOADS)
    tip_rate = np.empty((1, TIP_LOADS))
    case = (start, rate, tip_start, tip_rate)
    # the output pass's Jacobian: x, then the inputs; rows 6 + a: tendon a's length's
    J_out = np.empty((6 + width - PIECE_LOADS, 6 + n_inputs))
    r = np.empty(6)
    J = np.empty((6, 7))
    J_c = np.empty((6, 7))
    x = np.zeros(6)
    x_f = np.zeros(6)
    tip_c = np.empty(3)
    tip_f = np.empty(3)
    dscale = np.empty(6)
    six = nt_out * 0 + 6  # not a literal: one compiled version
    seven = six + 1
    t_end = np.empty(6)
    dx_f = np.empty(6)
    # a Newton step of this size at N leaves an error of about its square: far below tol
    final_step = min(1e-3, math.sqrt(0.01 * tol / length)) if math.isfinite(tol) else 1e-9
    reached = np.zeros(2)  # the load factor reached, the sign of det ∂r/∂x there
    J_path = np.empty((6, 6))  # ∂r/∂x at the path's last point
    guard = _guard_work()
    steps = np.empty(npieces, dtype=np.int64)
    counter = np.zeros(1, dtype=np.int64)
    for b in range(nb):
        counter[0] = 0
        # the homotopy of this case: start loads and their rate of change with λ
        if first is not None:
            for j in range(npieces):
                for i in range(width):
                    start[j, i] = first[0][j, i] if b == 0 else piece_loads[b - 1, j, i]
            for i in range(TIP_LOADS):
                tip_start[i] = first[1][i] if b == 0 else tip_loads[b - 1, i]
        for j in range(npieces):
            for i in range(width):
                rate[0, j, i] = piece_loads[b, j, i] - start[j, i]
        for i in range(TIP_LOADS):
            tip_rate[0, i] = tip_loads[b, i] - tip_start[i]
        w, turning = _load_size(arm, act, scale, start, piece_loads[b], tip_start, tip_loads[b])
        threshold = 1e-12 * w + 1e-300
        for i in range(6):
            dscale[i] = scale[i] * (1.0 + w)
        warm = memory is not None and memory[_MVALID] > 0.0
        if n_fixed > 0:
            N = n_fixed // 2
        elif memory is not None and warm:
            N = int(memory[_MN])
        else:
            N = _first_steps(arm, tol, turning)
        N = min(N, n_max // 2)
        status[b] = OK
        estimate = np.inf
        path = True  # the coarse solution must come from the path
        failures = 0
        failed_at = -1.0
        fine_path = False
        recorded = False
        resume = False
        deferred_failed = False
        if memory is not None and near and warm and b == 0:
            # a solution at 2N is known: its coarse partner at N is one correction away (the
            # distance between them is the discretisation error), no path needed
            _fill_steps(length, arm[1], N, np.int64(1), steps)
            for i in range(6):
                x[i] = memory[_MXF + i]
            if _corrector(x, 1.0, six, steps, base, arm, act, case, scratch, scale, dscale, length,
                          threshold, max_iterations, _REFINE_MAX, final_step, r, J, tip_c,
                          counter):
                _copy(J, J_c)
                path = False
                for i in range(6):  # the chord at 2N starts from the known solution
                    x_f[i] = memory[_MXF + i]
                resume = True
                # the output pass from it is also the fine check (a chord integration there
                # would repeat it without the stations): accepted if its residual is
                # converged and the estimate meets tol, else the stages below go on
                _fill_steps(length, arm[1], N, np.int64(2), steps)
                _output(x_f, nt_out, steps, base, arm, act, case, piece_loads[b], tip_loads[b],
                        inputs, scratch, s_out, out, b, r, J, J_out)
                counter[0] += 1
                d2 = 0.0
                for i in range(3):
                    d2 += (scratch[0][_P + i] - tip_c[i]) ** 2
                if _norm_scaled(r, scale) <= threshold and (math.sqrt(d2) / 15.0 <= tol
                                                            or n_fixed > 0):
                    estimate = math.sqrt(d2) / 15.0
                    recorded = True
        if (memory is not None and warm and b == 0 and not near
                and memory[_MPREDICTED] > 0.0 and N == int(memory[_MN])):
            # The path in one step whose tangent is given: the caller knows that only the
            # actuation inputs changed, by Δq, and the last solution's -J_x⁻¹ J_q (its output
            # pass), so the step x(1) - x(0) ≈ -J_x⁻¹ J_q Δq needs no integration at λ = 0.
            # One corrector from that prediction at λ = 1, accepted only as _follow accepts a
            # single step from λ = 0 to 1: near the prediction (within _REFINE_MAX, a third
            # of _follow's _DIST_MAX: a poor prediction costs little), the whole step
            # small enough to be one step (_FIRST_MOTION), det ∂r/∂x of the same sign, the
            # path's tangent turned by less than 60° (in x scaled by the bending scale).
            # Otherwise the path, from the last solution, as without a prediction.
            _fill_steps(length, arm[1], N, np.int64(1), steps)
            for i in range(6):
                x[i] = memory[_MXC + i] + memory[_MSTEP + i]
            if (_corrector(x, 1.0, seven, steps, base, arm, act, case, scratch, scale, dscale,
                           length, threshold, max_iterations, _REFINE_MAX, final_step, r, J,
                           tip_c, counter)
                    and _det_sign(J) == memory[_MSIGN] and _tangent(J, t_end)):
                aa = bb = ab = 0.0
                for i in range(6):
                    dx_f[i] = x[i] - memory[_MXC + i]  # the step taken
                    a = memory[_MSTEP + i] / scale[i]
                    c = t_end[i] / scale[i]
                    aa, bb, ab = aa + a * a, bb + c * c, ab + a * c
                if (_distance(dx_f, scratch[1], dscale, length) <= _FIRST_MOTION
                        and ab >= 0.5 * math.sqrt(aa * bb)):
                    _copy(J, J_c)
                    path = False
                    if nt_out > 0:
                        # The fine solution predicted too: the coarse one plus the last
                        # case's x_2N - x_N (the discretisation's offset, which the inputs'
                        # small change moves by O(h⁴ Δq)). The output pass from it is also
                        # the fine check: accepted, as near's, if it is converged, or if its
                        # Newton step would move the arm by under 1 % of tol (its error is
                        # then that step's size: the residual reported says how far);
                        # otherwise the chord from it, as without the prediction.
                        for i in range(6):
                            x_f[i] = x[i] + memory[_MXF + i] - memory[_MXC + i]
                        resume = True
                        _fill_steps(length, arm[1], N, np.int64(2), steps)
                        _output(x_f, nt_out, steps, base, arm, act, case, piece_loads[b],
                                tip_loads[b], inputs, scratch, s_out, out, b, r, J, J_out)
                        counter[0] += 1
                        d2 = 0.0
                        for i in range(3):
                            d2 += (scratch[0][_P + i] - tip_c[i]) ** 2
                        converged = _norm_scaled(r, scale) <= threshold or (
                            math.isfinite(tol)
                            and _newton_step(J_out if n_inputs > 0 else J, r, dx_f)
                            and _distance(dx_f, scratch[1], dscale, length) * length
                            <= _PREDICTED_FINE * tol)
                        if converged and math.sqrt(d2) / 15.0 <= tol:
                            estimate = math.sqrt(d2) / 15.0
                            recorded = True
        while not recorded:
            if path:
                # the path on a coarse grid (N / coarse_ratio steps) unless that failed
                n_path = N if fine_path or N <= 6 else max(3, (N + coarse_ratio - 1)
                                                           // coarse_ratio)
                _fill_steps(length, arm[1], n_path, np.int64(1), steps)
                for i in range(6):
                    x[i] = 0.0
                    if memory is not None and warm:
                        if n_path == int(memory[_MN]):
                            x[i] = memory[_MXC + i]  # exact at this step count
                        else:
                            x[i] = memory[_MXF + i]  # close: corrected at λ = 0
                coarse = n_path < N  # the last step is corrected on the grid of N
                if not _follow(x, steps, base, arm, act, case, scratch, scale, dscale, length,
                               threshold, max_iterations, max_load_step, budget, coarse,
                               final_step, r, J, tip_c, counter, reached, J_path):
                    if counter[0] > budget:
                        status[b] = BUDGET
                        break
                    if n_path < N:
                        fine_path = True
                        continue
                    if _retry_finer(n_fixed, N, n_max, failures, reached[0], failed_at):
                        failures += 1
                        failed_at = reached[0]
                        N = 2 * N
                        continue
                    status[b] = PATH_FAILED
                    break
                # the coarse solution at N: the end of a path on N steps; from the last
                # prediction of a path on a coarser grid, a checked Newton, which must not
                # cross a singular point either (the path's last step)
                _fill_steps(length, arm[1], N, np.int64(1), steps)
                if coarse and (not _corrector(x, 1.0, six, steps, base, arm, act, case, scratch,
                                              scale, dscale, length, threshold,
                                              max_iterations, _DIST_MAX, final_step, r, J,
                                              tip_c, counter)
                               or _det_sign(J) != reached[1]
                               or _crossed(J_path, J, scale, guard) != 0):
                    fine_path = True
                    continue
                _copy(J, J_c)
            if counter[0] > budget:
                status[b] = BUDGET
                break
            # the fine solution, 2N steps (from the coarse one, or where a check left it)
            _fill_steps(length, arm[1], N, np.int64(2), steps)
            if not resume:
                _copy(x, x_f)
            resume = False
            fine = _chord(x_f, J_c, steps, base, arm, act, case, scratch, scale, threshold,
                          max_iterations, not deferred_failed, r, J, tip_f, counter)
            if fine == 0:
                _copy(x, x_f)
                fine = _corrector(x_f, 1.0, six, steps, base, arm, act, case, scratch, scale,
                                  dscale, length, threshold, max_iterations, _REFINE_MAX, 1e-9,
                                  r, J, tip_f, counter)
                if not fine:
                    if 4 * N > n_max or n_fixed > 0:
                        status[b] = NEWTON_FAILED
                        break
                    N = 2 * N  # the fine solution is not near the coarse one: finer path
                    path = True
                    continue
            d2 = 0.0
            for i in range(3):
                d2 += (tip_f[i] - tip_c[i]) ** 2
            estimate = math.sqrt(d2) / 15.0
            if estimate <= tol or n_fixed > 0:
                if fine == 2:
                    # the output pass integrates the last chord step: it must converge
                    _output(x_f, nt_out, steps, base, arm, act, case, piece_loads[b], tip_loads[b],
                            inputs, scratch, s_out, out, b, r, J, J_out)
                    counter[0] += 1
                    if _norm_scaled(r, scale) <= threshold:
                        recorded = True
                        break
                    path = False
                    resume = True
                    deferred_failed = True  # from now on every chord step is integrated
                    continue  # not converged after all: chord again from here
                break
            if 2 * N >= n_max:
                status[b] = TOO_MANY_STEPS
                break
            # order 4: the coarse N whose fine partner meets tol with a margin
            grow = (estimate / (0.3 * tol)) ** 0.25
            N = min(n_max // 2, max(N + 1, math.ceil(N * grow)))
            _fill_steps(length, arm[1], N, np.int64(1), steps)
            _copy(x_f, x)
            path = not _corrector(x, 1.0, six, steps, base, arm, act, case, scratch, scale, dscale,
                                  length, threshold, max_iterations, _REFINE_MAX, final_step, r, J,
                                  tip_c, counter)
            if not path:
                _copy(J, J_c)
        info[b, 1] = estimate
        info[b, 2] = 1.0 if status[b] == OK else reached[0]
        info[b, 4] = N
        if status[b] != OK:
            info[b, 0] = _norm_scaled(r, scale)
            info[b, 3] = counter[0]
            if status[b] == PATH_FAILED:  # the path's last point on N steps: whether the
                for i in range(6):        # path turns there is for the caller to find out
                    out[7][b, i] = x[i]
            if memory is not None:
                memory[_MVALID] = memory[_MPREDICTED] = 0.0
            continue
        if not recorded:
            _fill_steps(length, arm[1], N, np.int64(2), steps)
            _output(x_f, nt_out, steps, base, arm, act, case, piece_loads[b], tip_loads[b],
                    inputs, scratch, s_out, out, b, r, J, J_out)
            counter[0] += 1
        residual = 0.0
        for i in range(6):
            if not abs(r[i]) <= residual:  # NaN propagates
                residual = abs(r[i])
        info[b, 0] = residual
        info[b, 3] = counter[0]
        if not math.isfinite(residual):
            status[b] = NOT_FINITE
        if inputs is not None:
            for i in range(jac.shape[1]):
                for k in range(jac.shape[2]):
                    jac[b, i, k] = J_out[i, k] if n_inputs else J[i, k]
            if status[b] == OK and not _implicit_function(jac[b], out[6][b]):
                status[b] = SINGULAR
        if memory is not None:
            for i in range(6):
                memory[_MXC + i] = x[i]
                memory[_MXF + i] = x_f[i]
            memory[_MN] = N
            memory[_MVALID] = 1.0 if status[b] == OK else 0.0
            memory[_MSIGN] = _det_sign(J_c)
            memory[_MPREDICTED] = 0.0


@_jit
def _implicit_function(J, E):
    """The implicit function theorem at a solution, in place. Given J (6 + A, 6 + n): rows
    0:6 [J_x | J_q] (∂r/∂x, ∂r/∂inputs), rows 6 + a [E_ℓx | E_ℓq] (actuator a's length per
    x and per input), and E (S, 6, 6 + n): each station's motion [E_x | E_q]. A dead tip
    wrench δW moves x by J_x⁻¹ δW, an input change δq by -J_x⁻¹ J_q δq, so every row
    e = [e_x | e_q] of E and of J's rows 6.. becomes [e_x J_x⁻¹ | e_q - e_x J_x⁻¹ J_q] (the
    compliance, then the actuation Jacobian), and J's rows 0:6 become [J_x⁻¹ | J_x⁻¹ J_q].
    False, nothing changed, if J_x is singular. (In Python, numpy's inverse and products on
    these small arrays cost 45-60 µs a call: a control loop's Python, not its arithmetic.)"""
    m = J.shape[1]
    X = np.empty((6, 6 + m))  # [J_x | I | J_q] -> [· | J_x⁻¹ | J_x⁻¹ J_q]
    for i in range(6):
        for k in range(6):
            X[i, k] = J[i, k]
            X[i, 6 + k] = 1.0 if i == k else 0.0
        for k in range(6, m):
            X[i, 6 + k] = J[i, k]
    if _eliminate_columns(X, m) == 0.0:
        return False
    row = np.empty(m)
    for a in range(6, J.shape[0]):
        _through_x(J[a], X, row)
    for s in range(E.shape[0]):
        for i in range(6):
            _through_x(E[s, i], X, row)
    for i in range(6):
        for k in range(m):
            J[i, k] = X[i, 6 + k]
    return True


@_jit
def _through_x(e, X, row):
    """e = [e_x | e_q] -> [e_x J_x⁻¹ | e_q - e_x J_x⁻¹ J_q] in place, X[:, 6:] = [J_x⁻¹ |
    J_x⁻¹ J_q] (:func:`_implicit_function`); ``row`` scratch of e's size."""
    m = e.size
    for k in range(m):
        acc = 0.0
        for i in range(6):
            acc += e[i] * X[i, 6 + k]
        row[k] = acc
    for k in range(6):
        e[k] = row[k]
    for k in range(6, m):
        e[k] -= row[k]


# A cold compile of the solver starts its verdict's compile on another core (_prefetch.py)
on_cold_compile(solve_cases, lambda args: _prefetch.start(
    "actuated" if _given(args[2]) else "passive", stability_cases))


@_entry(_per_arm("shoot", "the shooting primitive (Solver.shoot)", 5))
def shoot(x, lam, steps, base, arm, act, case, r, J, tip_state, tip_tangents):
    """The shooting primitive: integrate from the base reaction x (6) at load factor λ with
    ``steps`` RK4 steps per piece; returns in place the residual r (6), its Jacobian J
    (6, 6 + R) (columns: ∂r/∂x, then the derivative along each of the case's R rate rows:
    ∂r/∂λ for the homotopy's own), the tip state (18 + A: p, R row-major, n, m spatial, the
    tendon lengths) and the tip tangents (6 + R, 12) (per column: δp spatial, δθ material,
    δn, δm spatial)."""
    scratch = _scratch(arm[1].size, case[0].shape[1] - PIECE_LOADS, J.shape[1])
    _integrate(x, lam, J.shape[1], steps, base, arm, act, case, scratch, r, J)
    _copy(scratch[0], tip_state)
    _copy(scratch[1], tip_tangents)


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
# In the last step (to the clamp), an eigenvalue of the transition within this of zero is a
# conjugate point at the clamp itself (a critical or neutral equilibrium: the orbit of a round
# section's buckled shape turning about the axis), not inside (0, L): not counted.
_AT_CLAMP = 1e-8


@_jit
def _block(T, nt, length, out):
    """Θ: the (δp/L; δθ) rows of the first nt tangent columns (nt = 3: δθ only, material),
    one seed per column."""
    for d in range(nt):
        for i in range(nt):
            if nt == 3:
                out[i, d] = T[d, _TT + i]
            elif i < 3:
                out[i, d] = T[d, _TP + i] / length
            else:
                out[i, d] = T[d, _TT + i - 3]


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
def _orthonormalise(T, nt, weights, A):
    """Modified Gram–Schmidt on the first nt tangent columns, in the weighted norm
    (δp/L, δθ, δn L²/EI, δm L/EI): a change of basis of the same family of solutions (the
    conjugate points are those of the family, not of the basis), against growth and loss
    of independence along the sweep. A (nt × nt) receives the change of basis: the new
    columns are the old ones times A."""
    for d in range(nt):
        for e in range(nt):
            A[e, d] = 1.0 if e == d else 0.0
    for d in range(nt):
        for e in range(d):
            dot = 0.0
            for i in range(NT):
                dot += T[d, i] * T[e, i] * weights[i] * weights[i]
            for i in range(NT):
                T[d, i] -= dot * T[e, i]
            for i in range(nt):
                A[i, d] -= dot * A[i, e]
        norm = 0.0
        for i in range(NT):
            norm += (T[d, i] * weights[i]) ** 2
        norm = math.sqrt(norm)
        if norm > 0.0 and math.isfinite(norm):
            for i in range(NT):
                T[d, i] /= norm
            for i in range(nt):
                A[i, d] /= norm


@_inline
def _sweep(x, lam, steps, base, arm, act, case, scratch, nt, r, J, states, fields, theta0, tip,
           given):
    """The backward sweep of one equilibrium (base reaction x at load factor λ, ``steps``
    RK4 steps per piece, the solution's own grid): the state integrated forward to the tip
    (state only), then the state and nt seeded tangent columns back to the base with the
    same steps reversed (the point wrenches undone at each piece start); with a tip pose
    ``tip`` (4, 4) (the solution's own, e.g. its last station) the forward pass is skipped
    (n(L), m(L) are then the tip loads, by the tip condition). Returns the number
    of conjugate points in (0, L) with multiplicity (the Morse index), or -1 if one lies
    exactly on a grid point. ``theta0`` receives Θ(0) of the orthonormalised family; with
    ``states`` of length steps + 1, the state and the tangents at every grid point from the
    tip (index steps) to the base (0) are stored, and in ``fields[k, nt:2nt, :nt]`` the
    change of basis A_k of step k (the columns stored at k are those propagated from k + 1
    times A_k: a solution with coefficients c at k has A_k c at k + 1).

    ``given`` (None, or the solution's state at every grid point, base (0) to tip): the
    state is then not integrated backwards but taken from it at the top of every step (a
    piece's top excepted, reached from the state after the point wrench by undoing it).
    Backwards, the state has the growing modes e^{ks} of a rod in tension too; the multiple
    shooting solver gives its states (:func:`solve_stiff_cases`), so that the sweep of a
    stiff case integrates only the Jacobi fields, which it orthonormalises at every step."""
    y, T, work, twork, now = scratch[0], scratch[1], scratch[2], scratch[3], scratch[4]
    tip_now, law = scratch[5], scratch[8]
    rate, tip_rate = case[1], case[3]
    length = arm[6]
    scale = arm[7]
    # no tangents: a variable, not a literal 0, and x copied (it may be read-only), so that
    # the callees are the same compiled versions as the solver's (one compile, not two)
    none = nt - nt
    one = np.int64(1)
    if given is not None:
        _set_loads(lam, case, now, tip_now)
        _copy(given[given.shape[0] - 1], y)
    elif tip.shape[0] == 4:
        _set_loads(lam, case, now, tip_now)
        for i in range(y.size):
            y[i] = 0.0
        for i in range(3):
            y[_P + i] = tip[i, 3]
            for k2 in range(3):
                y[_R + 3 * i + k2] = tip[i, k2]
        _tip_residual(y, T, none, tip_now, tip_rate, r, J, arm, act, now, rate, law)
        for i in range(6):
            y[_N + i] = -r[i]  # the total wrench at the tip equals the tip loads
    else:
        _integrate(x.copy(), lam, none, steps, base, arm, act, case, scratch, r, J)
    # seeds: unit rotations of the tip section (and translations with nt = 6), with the δn,
    # δm of the linearised tip loads (follower and dipole terms), so that δr(L) = 0
    for d in range(nt):
        for i in range(NT):
            T[d, i] = 0.0
        if nt == 3:
            T[d, _TT + d] = 1.0
        elif d < 3:
            T[d, _TP + d] = 1.0
        else:
            T[d, _TT + d - 3] = 1.0
    _tip_residual(y, T, nt, tip_now, tip_rate, r, J, arm, act, now, rate, law)
    for d in range(nt):
        for i in range(6):
            T[d, _TN + i] = -J[i, d]
    undo = np.empty_like(now)
    for j in range(now.shape[0]):
        for i in range(now.shape[1]):
            undo[j, i] = -now[j, i]
    weights = np.empty(NT)
    for i in range(3):
        weights[_TP + i] = 1.0 / length
        weights[_TT + i] = 1.0
        weights[_TN + i] = 1.0 / scale[0]
        weights[_TM + i] = 1.0 / scale[3]
    old = np.empty((nt, nt))
    new = np.empty((nt, nt))
    M = np.empty((nt, nt))
    lu = np.empty((nt, 2 * nt))
    _block(T, nt, length, old)
    piece_start, piece_len = arm[0], arm[1]
    k = 0
    for j in range(piece_len.size):
        k += steps[j]
    store = states.shape[0] == k + 1
    if store:
        _copy(y, states[k])
        for d in range(nt):
            for i in range(NT):
                fields[k, d, i] = T[d, i]
    count = 0
    exact = False
    for j in range(piece_len.size - 1, -1, -1):
        h = piece_len[j] / steps[j]
        for i in range(steps[j] - 1, -1, -1):
            top = piece_start[j] + (i + 1) * h
            if given is not None and (i < steps[j] - 1 or j == piece_len.size - 1):
                _copy(given[k], y)
            _steps(y, T, nt, -h, top, one, arm, act, j, now, rate, work, twork, law)
            _block(T, nt, length, new)
            c = _crossings(old, new, nt, lu, M, _AT_CLAMP if j == 0 and i == 0 else 0.0)
            if c < 0:
                exact = True
            else:
                count += c
            _orthonormalise(T, nt, weights, M)
            _block(T, nt, length, old)
            k -= 1
            if store:
                _copy(y, states[k])
                for d in range(nt):
                    for i2 in range(NT):
                        fields[k, d, i2] = T[d, i2]
                    for i2 in range(nt):
                        fields[k, nt + i2, d] = M[i2, d]
        _jump(y, T, nt, undo, rate, j, arm, act, law)  # the point wrench there, undone
    for i in range(nt):
        for d in range(nt):
            theta0[i, d] = old[i, d]
    return -1 if exact else count


@_jit
def _tangent_columns(arm, act, piece):
    """3, or 6 where a load depends on position (a field gradient, contact): then a
    translation of the tip section is no longer a solution of the linearised equations by
    itself."""
    if act is not None and act[5].shape[0] > 0:
        return 6
    for j in range(piece.shape[0]):
        for i in range(9):
            if piece[j, _FG + i] != 0.0:
                return 6
    return 3


@_jit
def _conservative(piece, tip):
    """False if a follower load (any channel) or a dead couple acts (see
    softarm.statics.stability.conservative, which says why)."""
    for j in range(piece.shape[0]):
        for i in range(3):
            if (piece[j, _FF + i] != 0.0 or piece[j, _LF + i] != 0.0
                    or piece[j, _LD + i] != 0.0 or piece[j, _JF + i] != 0.0
                    or piece[j, _JF + 3 + i] != 0.0 or piece[j, _JD + 3 + i] != 0.0):
                return False
    for i in range(6):
        if tip[_TF + i] != 0.0:
            return False
    for i in range(3):
        if tip[_TD + 3 + i] != 0.0:
            return False
    return True


def _verdict_capability(args):
    key, text = _per_arm("verdict", "the stability verdict", 2)(args)
    if _given(args[11]):
        return key + "+given", text + " from given states (stiff closed forms)"
    return key, text


@_entry(_verdict_capability, nogil=True)
def stability_cases(base, arm, act, loads, xs, Ns, tips, factor, index, theta0, conservative,
                    given):
    """The Morse index of every solved case of a batch (loads at λ = 1 from zero, the
    solution x, as :func:`solve_cases` returns them), swept on ``factor`` × Ns[b] steps
    (the solution's coarse grid N: the count needs the Jacobi fields resolved, not the
    solution's 1e-8 L): ``index[b]`` (-1 if a conjugate point falls exactly on a grid
    point) and Θ(0) of the sweep (``theta0[b]``, nt × nt in its top-left corner). With
    ``tips`` (B, 4, 4), the solution's tip poses, the forward pass is skipped.
    ``conservative[b]``: whether case b's loads are conservative. ``given``: None, or the
    solutions' states on the sweep's grid (B, K + 1, 18 + A), base to tip (every case on
    the same grid), which the sweep then takes instead of integrating the state backwards
    (:func:`_sweep`)."""
    piece_loads, tip_loads = loads
    npieces = arm[1].size
    width = piece_loads.shape[2]
    scratch = _scratch(npieces, width - PIECE_LOADS, np.int64(7))
    start = np.zeros((npieces, width))
    tip_start = np.zeros(TIP_LOADS)
    r = np.empty(6)
    J = np.empty((6, 7))
    steps = np.empty(npieces, dtype=np.int64)
    none3 = np.empty((0, 1))
    none4 = np.empty((0, 1, 1))
    for b in range(piece_loads.shape[0]):
        case = (start, piece_loads[b:b + 1], tip_start, tip_loads[b:b + 1])
        nt = _tangent_columns(arm, act, piece_loads[b])
        conservative[b] = _conservative(piece_loads[b], tip_loads[b])
        _fill_steps(arm[6], arm[1], int(Ns[b]), factor, steps)
        t0 = np.zeros((nt, nt))
        if given is None:
            index[b] = _sweep(xs[b], 1.0, steps, base, arm, act, case, scratch, nt, r, J, none3,
                              none4, t0, tips[b] if tips.shape[0] > b else none3, None)
        else:
            index[b] = _sweep(xs[b], 1.0, steps, base, arm, act, case, scratch, nt, r, J, none3,
                              none4, t0, none3, given[b])
        for i in range(nt):
            for d in range(nt):
                theta0[b, i, d] = t0[i, d]


@_entry(_per_arm("branch", "the stability sweep of a branch (continuation)", 5))
def sweep_point(x, lam, steps, base, arm, act, case, theta0, states, fields):
    """One backward sweep at (x, λ) of a homotopy ``case`` (continuation, critical loads):
    the Morse index (or -1), Θ(0) into ``theta0`` (nt × nt, nt = its size), and with
    ``states`` (K + 1, 18 + A), ``fields`` (K + 1, 2 nt, 12), K the total number of steps,
    the state and the orthonormalised Jacobi fields at every grid point (with the changes of
    basis, see :func:`_sweep`)."""
    scratch = _scratch(arm[1].size, case[0].shape[1] - PIECE_LOADS, np.int64(7))
    r = np.empty(6)
    J = np.empty((6, 7))
    return _sweep(x, lam, steps, base, arm, act, case, scratch, theta0.shape[0], r, J, states,
                  fields, theta0, np.empty((0, 1)), None)


@_entry(_per_arm("branch", "the stations of a branch (continuation)", 2))
def record_points(base, arm, act, loads, xs, steps, s_out, out):
    """The outputs (stations) of equilibria given by their base reactions: case b has the
    loads (loads[0][b], loads[1][b]) and the solution xs[b] on ``steps`` RK4 steps per piece
    (continuation points); ``out`` as in :func:`solve_cases` (poses, strains, stresses,
    info, status, J, E, x, lengths), without tangents. info[b, 0] is the residual."""
    piece_loads, tip_loads = loads
    npieces = arm[1].size
    width = piece_loads.shape[2]
    scratch = _scratch(npieces, width - PIECE_LOADS, np.int64(7))
    start = np.zeros((npieces, width))
    tip_start = np.zeros(TIP_LOADS)
    r = np.empty(6)
    J = np.empty((6, 7))
    none = J.shape[1] - 7  # no tangents (a variable: one compiled version)
    for b in range(piece_loads.shape[0]):
        case = (start, piece_loads[b:b + 1], tip_start, tip_loads[b:b + 1])
        _record(xs[b], none, steps, base, arm, act, case, 1.0, scratch, s_out, out, b, r, J)
        residual = 0.0
        for i in range(6):
            if not abs(r[i]) <= residual:
                residual = abs(r[i])
        out[3][b, 0] = residual


# ---------------------------------------------------------------------------- bounded steps
#
# Bounded least squares for the bounded Newton methods (displacement-controlled tendons,
# statics/displacement.py; inverse statics, softarm.control), called through
# softarm._bounded. Here, not in a module of their own, because inverse statics' compiled
# iteration (``inverse_newton``) calls them: numba's cache keys a function on its own file
# only (README.md), so a caller and its callees must share one.

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


@_entry(_fixed("bounded", "the bounded least squares"))
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


@_entry(_fixed("bounded", "the bounded least squares"))
def regularised_step(J, b, q, scales, mu, effort, lower, upper, iterations):
    """The bounded Gauss–Newton step of inverse statics, in scaled inputs u = q / s:
    argmin |J' δu - b|² + μ σ² |δu|² + ε σ² |u + δu|² within the bounds, J' = J s (columns
    scaled), σ = |J'|_F, ε = ``effort`` (1e-12 for a redundant task: the least effort along
    its null space; 0 otherwise, where it would only bias the answer); returns δq = s δu.
    The stacked system built here, one call instead of a dozen numpy ones per step."""
    m, n = J.shape
    sigma = 0.0
    for i in range(m):
        for j in range(n):
            sigma += (J[i, j] * scales[j]) ** 2
    sigma = max(math.sqrt(sigma), 1e-300)
    root_eps = math.sqrt(effort)
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


# ---------------------------------------------------------------------------- inverse statics
#
# The fast route of softarm.control (docs/control.md): Newton on the base reaction x and the
# actuation inputs q together, one integration with the input columns per iteration, each
# step a bounded least-squares problem. Compiled whole: in Python the iteration's small numpy
# calls cost three times its integrations.

# inverse_newton's outcomes (info[0]): the stop rule met; the iteration cap; the merit grew
# (diverging); J_x singular or a value not finite.
NEWTON_DONE, NEWTON_CAP, NEWTON_DIVERGED, NEWTON_SINGULAR = 0, 1, 2, 3
#: The weight of the least effort along a redundant task's null space (regularised_step's
#: ε: it moves the task solution by about 1e-12 relative)
EFFORT = 1e-12


@_jit
def _rotation_log(Q, out):
    """out = log(Q), the rotation vector of the rotation matrix Q (|out| <= π): from the
    skew part away from π, from the symmetric part near it (the skew part vanishes there)."""
    w0, w1, w2 = Q[2, 1] - Q[1, 2], Q[0, 2] - Q[2, 0], Q[1, 0] - Q[0, 1]
    sine = 0.5 * math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    cosine = 0.5 * (Q[0, 0] + Q[1, 1] + Q[2, 2] - 1.0)
    angle = math.atan2(sine, cosine)
    if angle < 1e-4:
        f = 0.5 + angle * angle / 12.0  # θ / (2 sin θ)
    elif angle < 3.0:
        f = 0.5 * angle / math.sin(angle)
    else:
        # near π: Q + Qᵀ = 2 cos θ I + 2 (1 - cos θ) a aᵀ; the axis from its largest diagonal
        # entry's column, the sign from the skew part
        d = 0
        for i in range(1, 3):
            if Q[i, i] > Q[d, d]:
                d = i
        a = np.empty(3)
        for i in range(3):
            a[i] = 0.5 * (Q[i, d] + Q[d, i]) - (cosine if i == d else 0.0)
        norm = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
        if w0 * a[0] + w1 * a[1] + w2 * a[2] < 0.0:
            norm = -norm
        for i in range(3):
            out[i] = angle * a[i] / norm
        return
    out[0], out[1], out[2] = f * w0, f * w1, f * w2


@_entry(_fixed("inverse", "inverse statics"))
def task_error(tip, target, orientation, length, e):
    """The weighted task error at the tip state ``tip`` (p, R row-major): e[:3] = (target - p)
    / L and, with a 6-row task, e[3:] = log(orientation Rᵀ) (spatial, rad)."""
    for i in range(3):
        e[i] = (target[i] - tip[_P + i]) / length
    if e.size == 6:
        Q = np.empty((3, 3))
        for i in range(3):
            for j in range(3):
                Q[i, j] = (orientation[i, 0] * tip[_R + 3 * j] + orientation[i, 1]
                           * tip[_R + 3 * j + 1] + orientation[i, 2] * tip[_R + 3 * j + 2])
        _rotation_log(Q, e[3:])


@_jit
def _task_size(e):
    """|δp|/L, or with an orientation the larger of that and |δθ| (rad)."""
    p = e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
    r = e[3] * e[3] + e[4] * e[4] + e[5] * e[5] if e.size == 6 else 0.0
    return math.sqrt(max(p, r))


@_entry(_fixed("inverse", "inverse statics"))
def redundant_task(singular, n):
    """Whether a task Jacobian with these singular values (largest first) has a rank below
    its n inputs (values at most 1e-10 n σ₁ count as zero): the least-effort term then
    picks the answer among many (softarm.control)."""
    rank = 0
    for v in singular:
        if v > 1e-10 * n * singular[0]:
            rank += 1
    return n > rank


@_jit
def _scaled_singular_values(J, scales, out):
    """out = the singular values of J diag(scales), largest first."""
    Js = np.empty(J.shape)
    for i in range(J.shape[0]):
        for c in range(J.shape[1]):
            Js[i, c] = J[i, c] * scales[c]
    values = np.linalg.svd(Js)[1]
    for i in range(out.size):
        out[i] = values[i]


@_entry(_fixed("inverse", "inverse statics"))
def inverse_newton(x, q, every, first, steps, base, arm, act, units, goal, bounds, settings, warm,
                   out, info):
    """The fast route's iteration of inverse statics (softarm.control), in place on x (6)
    and q (n), from a solution of the same grid nearby.

    Per iteration one integration from x with the inputs q (``every``, every input of the
    loads, the actuators' at [first, first + n), updated with q): the residual r, J_x, J_q and
    the tip's motion E_x, E_q (spatial); G = J_x⁻¹ [r | J_q], A = E_q - E_x G[:, 1:] (the
    actuation Jacobian), the task error e at the tip and as linearised to the equilibrium,
    rhs = e + w (E_x G[:, 0]); the bounded step δq (``regularised_step``, μ = 0), then
    x -= G[:, 0] + G[:, 1:] δq. With ``warm`` (a solution: r = 0), the first step needs no
    integration: its tip, A and G are given, and the second-order term of the last target
    (its ``miss``, scaled by f = α², α the projection of this task step on that one, if
    0 < f <= 4) is added. Stops at an integration whose task error is within tol / 2, also
    as linearised, with max |r_i|/scale_i <= 1e-6 and, when the task is redundant, a step
    below 1e-7 relative (the least effort reached); the step from there is taken.

    units : (piece0 (P, W), unit piece (m, P, W), tip0 (12,), unit tip (m, 12)): the load
        channels at zero inputs and per unit input.
    goal : (target (3,), orientation (3, 3), weights w (t,)): t = 3 (position) or 6 (pose).
    bounds : (lower (n,), upper (n,), scales (n,)).
    settings : (tol, max_iterations, length, redundant: -1 unknown, 0, 1).
    warm : (flag (1,): 1.0 to take the warm step, tip state (12,), A (6, n), G (6, 1 + n),
        miss flag (1,), miss q (n,), miss x (6,), miss task step (t,)).
    out : (A (6, n), G (6, 1 + n), J (t, n), linear: x (6), q (n), its linear prediction
        (n), G (6, 1 + n), its task step (t,), the singular values of J s (min(t, n),)) at
        the end; linear is the warm step's.
    info : (outcome, iterations, redundant, warm step taken) on return.
    """
    n = q.size
    m = every.size
    t = goal[2].size
    tol, max_iterations, length = settings[0], int(settings[1]), settings[2]
    redundant = int(settings[3])
    piece0, unit_piece, tip0, unit_tip = units
    target, orientation, w = goal
    lower, upper, scales = bounds
    A, G, J, singular = out[0], out[1], out[2], out[4]
    scale = arm[7]
    P, W = piece0.shape
    piece = np.empty((P, W))
    tipv = np.empty(tip0.size)
    case = (piece, unit_piece, tipv, unit_tip)
    r = np.empty(6)
    x_shot = np.empty(6)
    Jfull = np.empty((6, 6 + m))
    y = np.empty(18 + W - PIECE_LOADS)
    T = np.empty((6 + m, 12 + W - PIECE_LOADS))
    E = np.empty((6, 6 + m))
    B = np.empty((6, 1 + n))
    work = np.empty((6, 7 + n))
    e = np.empty(t)
    rhs = np.empty(t)
    trial = np.empty(n)
    tip = np.empty(12)
    info[2] = redundant
    info[3] = 0.0
    warm_step = warm[0][0] > 0.0
    merit = np.inf
    iterations = 0
    while True:
        iterations += 1
        info[1] = iterations
        if iterations > max_iterations:
            info[0] = NEWTON_CAP
            return
        if warm_step:
            _copy(warm[1], tip)
            for i in range(6):
                for c in range(n):
                    A[i, c] = warm[2][i, c]
                for c in range(1 + n):
                    G[i, c] = warm[3][i, c]
            task_error(tip, target, orientation, length, e)
            for i in range(t):
                rhs[i] = e[i]
        else:
            for c in range(n):
                every[first + c] = q[c]
            for j in range(P):
                for i in range(W):
                    acc = piece0[j, i]
                    for k in range(m):
                        acc += every[k] * unit_piece[k, j, i]
                    piece[j, i] = acc
            for i in range(tip0.size):
                acc = tip0[i]
                for k in range(m):
                    acc += every[k] * unit_tip[k, i]
                tipv[i] = acc
            _copy(x, x_shot)
            shoot(x_shot, 0.0, steps, base, arm, act, case, r, Jfull, y, T)
            for c in range(6 + m):  # the tip's motion per column, spatial
                for i in range(3):
                    E[i, c] = T[c, _TP + i]
                    E[3 + i, c] = (y[_R + 3 * i] * T[c, _TT] + y[_R + 3 * i + 1] * T[c, _TT + 1]
                                   + y[_R + 3 * i + 2] * T[c, _TT + 2])
            for i in range(6):
                B[i, 0] = r[i]
                for c in range(n):
                    B[i, 1 + c] = Jfull[i, 6 + first + c]
            if not _small_solve(Jfull, B, np.int64(6), work, G):
                info[0] = NEWTON_SINGULAR
                return
            for i in range(6):
                for c in range(n):
                    acc = E[i, 6 + first + c]
                    for k in range(6):
                        acc -= E[i, k] * G[k, 1 + c]
                    A[i, c] = acc
            task_error(y, target, orientation, length, e)
            for i in range(t):
                acc = 0.0
                for k in range(6):
                    acc += E[i, k] * G[k, 0]
                rhs[i] = e[i] + w[i] * acc
        for i in range(t):
            for c in range(n):
                J[i, c] = w[i] * A[i, c]
        if redundant < 0:
            _scaled_singular_values(J, scales, singular)
            redundant = 1 if redundant_task(singular, n) else 0
            info[2] = redundant
        step = regularised_step(J, rhs, q, scales, 0.0, EFFORT if redundant else 0.0, lower,
                                upper, np.int64(100))
        for c in range(n):
            trial[c] = min(max(q[c] + step[c], lower[c]), upper[c])
        if warm_step:
            warm_step = False
            info[3] = 1.0
            linear = out[3]
            _copy(x, linear[0])
            _copy(q, linear[1])
            _copy(trial, linear[2])
            for i in range(6):
                for c in range(1 + n):
                    linear[3][i, c] = G[i, c]
            _copy(e, linear[4])
            factor = 0.0
            if warm[4][0] > 0.0:  # the second-order term carried over (f = α²)
                last = warm[7]
                norm = 0.0
                dot = 0.0
                for i in range(t):
                    norm += last[i] * last[i]
                    dot += e[i] * last[i]
                if norm > 0.0:
                    factor = (dot / norm) ** 2
                if not (0.0 < factor <= 4.0):
                    factor = 0.0
            for c in range(n):
                if factor > 0.0:
                    trial[c] = min(max(trial[c] + factor * warm[5][c], lower[c]), upper[c])
            for i in range(6):
                acc = factor * warm[6][i]
                for c in range(n):
                    acc -= G[i, 1 + c] * (trial[c] - q[c])
                x[i] += acc
            _copy(trial, q)
            continue
        size = _task_size(e)
        residual = _norm_scaled(r, scale)
        if not math.isfinite(size + residual):
            info[0] = NEWTON_SINGULAR
            return
        if size + residual > 2.0 * merit:
            info[0] = NEWTON_DIVERGED
            return
        merit = size + residual
        biggest_step, biggest_q = 0.0, 0.0
        for c in range(n):
            biggest_step = max(biggest_step, abs(trial[c] - q[c]) / scales[c])
            biggest_q = max(biggest_q, abs(q[c]) / scales[c])
        for i in range(6):
            acc = G[i, 0]
            for c in range(n):
                acc += G[i, 1 + c] * (trial[c] - q[c])
            x[i] -= acc
        _copy(trial, q)
        # stop at an integration that shows the task within tol, also as linearised to the
        # equilibrium, with the residual small enough for that linearisation (the step taken
        # from there only improves them; the solve at the answer checks). Not earlier: along
        # the inputs' weak direction (equal tensions compress the arm) the second-order terms
        # are large, and a step from a task error of 1e-4 was measured to leave 2e-7, not 1e-8
        if (size <= 0.5 * tol and _task_size(rhs) <= 0.5 * tol and residual <= 1e-6
                and (redundant == 0 or biggest_step <= 1e-7 * (1.0 + biggest_q))):
            _scaled_singular_values(J, scales, singular)  # (its condition, reported)
            info[0] = NEWTON_DONE
            return


# ------------------------------------------------------------------ multiple shooting
# Stiff problems (tension: k = √(T/EI), kL large). Single shooting's map x -> r(x) grows like
# e^{kL}; here [0, L] is cut into M intervals of kL/M <= _GROWTH each, the state at every
# interval start is an unknown, and continuity at the joins closes the system: a block-banded
# Newton system solved by banded Gaussian elimination with partial pivoting (never condensed
# back into a 6 × 6 transfer product, which would restore e^{kL}). README.md, "Multiple
# shooting"; docs/solver.md for users.
#
# Unknowns (scaled, n = 12 M - 6): the base reaction x (6, in units of the bending scale),
# then per interior node i = 1..M-1 the corrections (δn, δm, δp, δθ) of its state (forces in
# the bending scale, δp in L, δθ material, rad): the order of the tangent columns below.
# Equations: per join (12 rows, p, θ, n, m: the end of interval i minus node i + 1), then the
# tip residual (6). An interval from a node integrates 13 tangent columns: 0-5 δ(n; m) at the
# node, 6 the load factor, 7-9 δp, 10-12 δθ; columns 7-12 use the rate rows 1-6 of the
# case, which are zero (the homogeneous variational equations: the same _steps, no new
# compiled right-hand side).

_GROWTH = 5.0  # kL per shooting interval at most (the tangents grow by about e^5 across it)
_STIFF_STEPS = 0.6  # coarse RK4 steps per unit of kL at least: hk <= 1.7 (RK4 is stable for the
#                    decaying mode e^{-ks} up to hk = 2.78; the error estimate then decides)
# The smallest load-factor step of the stiff path: the path from the unloaded arm bends
# sharply near λ = 0 (k grows like √λ: the predicted lateral motion at λ = 0 is that of an
# arm without tension), so steps far below a single-shooting path's are needed there,
# doubling from then on.
_DLAM_MIN_STIFF = 1e-12
# With contact the branch guard is det's sign alone, and a step no longer than this crosses
# (the guard of before issue 42): the penalty's band switches on within a step at a
# touchdown, and J changes there by more than the eigenvalue test and the phase's step allow
# (a path that the old guard followed failed and widened the band). Contact is to be solved
# as a constraint instead (issue 39).
_DLAM_CROSS_CONTACT = 1e-3
# The corrector's contraction test with contact: Newton on a penalty contracts slowly until
# it is within the band of the answer (a contact that closes between prediction and answer).
_CONTRACTION_CONTACT = 0.9
# The Richardson estimate |p_2N - p_N| / 15 times this: at hk near 1 (a boundary layer of
# width 1/k resolved by a few steps) RK4 is not yet in its asymptotic regime, and the fine
# solution's error against the separatrix was measured up to 2.2 times |p_2N - p_N| / 15
# (a hard pull at 150°, kL = 1e4).
_STIFF_SAFETY = 2.0
_NODE_WEIGHT = 0.2
# The levels of the stiff path: each has 2^_LEVEL times the intervals of the one before
_LEVEL = 2  # the interior nodes' weight in the path's distance (_ms_distance)
_BAND = 17  # the Jacobian's lower and upper bandwidth (rows of a join, columns of two nodes)
_COLS = 13  # tangent columns of an interval from an interior node
# Chunk rows (_chunk_table): piece, start s, length, 1.0 if it starts its piece (the point
# wrench there is its own), the interval it belongs to.
_CJ, _CS, _CL, _CFIRST, _CI = 0, 1, 2, 3, 4


@_jit
def _stiffness_size(arm, act, w, loads):
    """kL estimated from the case's load size ``w`` (in EI/L² of the *stiffest* bending,
    :func:`_load_size`) with the softest bending stiffness of the arm: the growth exponent of
    single shooting under a tension of that size; with contact, the larger of that and the
    penalty's own, L max(√(k/GA), (k/EI)^¼) (the growth rates of a shearable rod on an
    elastic foundation of stiffness k times the case's scale, the channel CT of ``loads``
    (P, W): contact.md)."""
    soft = 0.0
    for j in range(arm[1].size):
        soft = max(soft, arm[2][j, 4, 4], arm[2][j, 5, 5])
    stiff = arm[7][3] * arm[6]  # the bending scale's EI
    kl = math.sqrt(max(w, 0.0) * stiff * soft)
    if act is not None and act[5].shape[0] > 0:
        for j in range(arm[1].size):
            C, k = arm[2][j], act[6][j, 2] * loads[j, _CT]
            shear = max(C[1, 1], C[2, 2])
            bending = max(C[4, 4], C[5, 5])
            kl = max(kl, arm[6] * max(math.sqrt(k * shear), (k * bending) ** 0.25))
    return kl


@_jit
def _chunk_table(arm, M, out):
    """Cut [0, L] at the interval starts i L / M and at the piece starts: out[c] = (piece,
    start, length, starts its piece, interval); returns (chunks, first chunk of each
    interval (M + 1,))."""
    piece_start, piece_len, length = arm[0], arm[1], arm[6]
    first = np.empty(M + 1, dtype=np.int64)
    c = 0
    for i in range(M):
        first[i] = c
        a = length * i / M
        b = length if i == M - 1 else length * (i + 1) / M
        for j in range(piece_len.size):
            s0 = piece_start[j]
            s1 = s0 + piece_len[j] if j < piece_len.size - 1 else length
            lo, hi = max(a, s0), min(b, s1)
            if hi > lo or (j == 0 and i == 0 and hi >= lo):
                out[c, _CJ] = j
                out[c, _CS] = lo
                out[c, _CL] = hi - lo
                out[c, _CFIRST] = 1.0 if lo == s0 else 0.0
                out[c, _CI] = i
                c += 1
    first[M] = c
    return c, first


@_jit
def _chunk_steps(chunks, nc, length, N, factor, mult, out):
    """Steps per chunk for a nominal N over the arm (at least one), times ``factor`` and its
    interval's multiplier ``mult[i]`` (the intervals refined for their local error)."""
    for c in range(nc):
        out[c] = factor * mult[int(chunks[c, _CI])] * max(
            1, math.floor(N * chunks[c, _CL] / length + 0.5))


@_jit
def _run_chunks(y, T, nt, c0, c1, chunks, csteps, arm, act, rate, scratch):
    """Integrate the chunks c0..c1-1 in place (state and the first nt tangent columns),
    with the point wrench at the start of every chunk that starts its piece."""
    work, twork, now, law = scratch[2], scratch[3], scratch[4], scratch[8]
    for c in range(c0, c1):
        j = int(chunks[c, _CJ])
        if chunks[c, _CFIRST] > 0.0:
            _jump(y, T, nt, now, rate, j, arm, act, law)
        n = csteps[c]
        _steps(y, T, nt, chunks[c, _CL] / n, chunks[c, _CS], n, arm, act, j, now, rate, work,
               twork, law)


@_jit
def _node_start(y, T, nt, Z, i):
    """The state at node i (Z[i]: p, R, n, m) and the tangents' initial values (columns 0-5
    δ(n; m), 6 the load factor (0), 7-9 δp, 10-12 δθ)."""
    for a in range(18):
        y[a] = Z[i, a]
    for a in range(18, y.size):
        y[a] = 0.0
    for d in range(nt):
        for a in range(T.shape[1]):
            T[d, a] = 0.0
    for d in range(min(nt, 6)):
        T[d, _TN + d] = 1.0
    for d in range(3):
        if nt > 7 + d:
            T[7 + d, _TP + d] = 1.0
            T[10 + d, _TT + d] = 1.0


@_jit
def _rotation_mismatch(Ra, y, A, out):
    """A = Raᵀ R (R: y's rotation), out = vee(skew A) (zero where R = Ra; near it the
    material rotation from Ra to R)."""
    for a in range(3):
        for b in range(3):
            acc = 0.0
            for k in range(3):
                acc += Ra[_R + 3 * k + a] * y[_R + 3 * k + b]
            A[a, b] = acc
    out[0] = 0.5 * (A[2, 1] - A[1, 2])
    out[1] = 0.5 * (A[0, 2] - A[2, 0])
    out[2] = 0.5 * (A[1, 0] - A[0, 1])


@_jit
def _unknown(i, d):
    """The unknown index of tangent column d (not 6) of the interval from node i."""
    if i == 0:
        return d
    return 6 + 12 * (i - 1) + (d if d < 6 else d - 1)


@_jit
def _band_set(B, row, col, value):
    B[row, col - row + _BAND] = value


@_jit
def _ms_evaluate(x, Z, M, lam, nt, chunks, first, csteps, base, arm, act, case, scratch,
                 colscale, rowscale, F, B, G, ends, lengths, Gq):
    """Integrate every interval at load factor λ: the scaled residual F (n), and with
    tangents (nt > 0) the scaled Jacobian in band storage B (n, 3 _BAND + 1) and its load
    factor column G (n). ``ends``: each interval's end state (M, width), for the tip and the
    output. Returns the scaled residual's largest component. ``lengths``: the tendons'
    lengths summed over the intervals. ``Gq``: None, or (n, inputs) the scaled residual's
    derivatives by the inputs (tangent columns _COLS.. along the case's rate rows 7..: every
    interval then integrates nt = _COLS + inputs columns, the first one's node columns
    unused)."""
    y, T = scratch[0], scratch[1]
    rate, tip_rate = case[1], case[3]
    now, tip_now, law = scratch[4], scratch[5], scratch[8]
    _set_loads(lam, case, now, tip_now)
    n = 12 * M - 6
    if nt > 0:
        for r_ in range(n):
            G[r_] = 0.0
            for c in range(B.shape[1]):
                B[r_, c] = 0.0
    A = np.empty((3, 3))
    mis = np.empty(3)
    J = np.empty((6, max(nt, _COLS)))
    r6 = np.empty(6)
    if Gq is not None:
        for r_ in range(n):
            for c in range(Gq.shape[1]):
                Gq[r_, c] = 0.0
    for a in range(lengths.size):
        lengths[a] = 0.0
    worst = 0.0
    for i in range(M):
        ni = 0 if nt == 0 else (7 if i == 0 else _COLS)
        if Gq is not None:
            ni = nt
        if i == 0:
            _start(y, T, ni, base, x)
        else:
            _node_start(y, T, ni, Z, i)
        _run_chunks(y, T, ni, first[i], first[i + 1], chunks, csteps, arm, act, rate, scratch)
        for a in range(y.size):
            ends[i, a] = y[a]
        for a in range(lengths.size):
            lengths[a] += y[18 + a]
        if i < M - 1:
            row = 12 * i
            _rotation_mismatch(Z[i + 1], y, A, mis)
            for k in range(3):
                F[row + k] = (y[_P + k] - Z[i + 1, _P + k]) / rowscale[row + k]
                F[row + 3 + k] = mis[k]
                F[row + 6 + k] = (y[_N + k] - Z[i + 1, _N + k]) / rowscale[row + 6 + k]
                F[row + 9 + k] = (y[_M + k] - Z[i + 1, _M + k]) / rowscale[row + 9 + k]
            for k in range(12):
                worst = max(worst, abs(F[row + k])) if math.isfinite(F[row + k]) else np.inf
            if nt == 0:
                continue
            trace = A[0, 0] + A[1, 1] + A[2, 2]
            for d in range(ni):
                t = T[d]
                if d == LAM:
                    for k in range(12):
                        G[row + k] = 0.0
                    for k in range(3):
                        G[row + k] = t[_TP + k] / rowscale[row + k]
                        G[row + 3 + k] = 0.5 * (trace * t[_TT + k] - A[k, 0] * t[_TT]
                                                - A[k, 1] * t[_TT + 1] - A[k, 2] * t[_TT + 2])
                        G[row + 6 + k] = t[_TN + k] / rowscale[row + 6 + k]
                        G[row + 9 + k] = t[_TM + k] / rowscale[row + 9 + k]
                    continue
                if Gq is not None and d >= _COLS:  # an input's column
                    for k in range(3):
                        Gq[row + k, d - _COLS] = t[_TP + k] / rowscale[row + k]
                        Gq[row + 3 + k, d - _COLS] = 0.5 * (
                            trace * t[_TT + k] - A[k, 0] * t[_TT] - A[k, 1] * t[_TT + 1]
                            - A[k, 2] * t[_TT + 2])
                        Gq[row + 6 + k, d - _COLS] = t[_TN + k] / rowscale[row + 6 + k]
                        Gq[row + 9 + k, d - _COLS] = t[_TM + k] / rowscale[row + 9 + k]
                    continue
                if i == 0 and d > LAM:  # (the base's interval has no node columns)
                    continue
                col = _unknown(i, d)
                cs = colscale[col]
                for k in range(3):
                    _band_set(B, row + k, col, t[_TP + k] / rowscale[row + k] * cs)
                    _band_set(B, row + 3 + k, col, 0.5 * cs * (
                        trace * t[_TT + k] - A[k, 0] * t[_TT] - A[k, 1] * t[_TT + 1]
                        - A[k, 2] * t[_TT + 2]))
                    _band_set(B, row + 6 + k, col, t[_TN + k] / rowscale[row + 6 + k] * cs)
                    _band_set(B, row + 9 + k, col, t[_TM + k] / rowscale[row + 9 + k] * cs)
            # the next node's own columns: -1 on p, n, m; -(tr A I - Aᵀ)/2 on θ
            nxt = 6 + 12 * i
            for k in range(3):
                _band_set(B, row + k, nxt + 6 + k, -colscale[nxt + 6 + k] / rowscale[row + k])
                _band_set(B, row + 6 + k, nxt + k, -colscale[nxt + k] / rowscale[row + 6 + k])
                _band_set(B, row + 9 + k, nxt + 3 + k,
                          -colscale[nxt + 3 + k] / rowscale[row + 9 + k])
                for m in range(3):
                    v = -0.5 * ((trace if k == m else 0.0) - A[m, k])
                    _band_set(B, row + 3 + k, nxt + 9 + m, v * colscale[nxt + 9 + m])
        else:
            _tip_residual(y, T, ni, tip_now, tip_rate, r6, J, arm, act, now, rate, law)
            row = 12 * (M - 1)
            for k in range(6):
                F[row + k] = r6[k] / rowscale[row + k]
                worst = max(worst, abs(F[row + k])) if math.isfinite(F[row + k]) else np.inf
            if nt == 0:
                continue
            for d in range(ni):
                for k in range(6):
                    if d == LAM:
                        G[row + k] = J[k, d] / rowscale[row + k]
                    elif Gq is not None and d >= _COLS:
                        Gq[row + k, d - _COLS] = J[k, d] / rowscale[row + k]
                    elif i == 0 and d > LAM:
                        continue
                    else:
                        col = _unknown(i, d)
                        _band_set(B, row + k, col, J[k, d] / rowscale[row + k] * colscale[col])
    return worst


@_jit
def _band_factor(B, n, kl, piv, Lm):
    """Gaussian elimination with partial pivoting of the band matrix B (n rows; row r holds
    columns r - kl .. r + 2 kl, the last kl for the fill of the row exchanges; the upper
    width is at most kl) in place: U in B, the multipliers in Lm, the exchanges in piv
    (LAPACK's gbtrf, written out). Returns the sign of the determinant, 0.0 if singular."""
    sign = 1.0
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
        right = min(n - 1, c + 2 * kl)
        piv[c] = p
        if p != c:
            sign = -sign
            for col in range(c, right + 1):
                a = B[c, col - c + kl]
                B[c, col - c + kl] = B[p, col - p + kl]
                B[p, col - p + kl] = a
        pivot = B[c, kl]
        if pivot < 0.0:
            sign = -sign
        for r in range(c + 1, last + 1):
            g = B[r, c - r + kl] / pivot
            Lm[c, r - c - 1] = g
            B[r, c - r + kl] = 0.0
            if g != 0.0:
                for col in range(c + 1, right + 1):
                    B[r, col - r + kl] -= g * B[c, col - c + kl]
    return sign


@_jit
def _band_solve(B, n, kl, piv, Lm, b):
    """b ← A⁻¹ b from :func:`_band_factor`'s factors. False if the result is not finite."""
    for c in range(n):
        p = piv[c]
        if p != c:
            a = b[c]
            b[c] = b[p]
            b[p] = a
        for r in range(c + 1, min(n - 1, c + kl) + 1):
            b[r] -= Lm[c, r - c - 1] * b[c]
    for c in range(n - 1, -1, -1):
        # four partial sums: one sum's chain of dependent additions is latency bound
        # (measured 88 -> 30 µs a solve of 726 unknowns, kl = 29)
        a0, a1, a2, a3 = b[c], 0.0, 0.0, 0.0
        last = min(n - 1, c + 2 * kl)
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


@_jit
def _ms_apply(x, Z, M, du, colscale, sign):
    """x, Z += sign × du (scaled unknowns): forces and positions added, node rotations
    R ← R exp(δθ~) (material)."""
    for k in range(6):
        x[k] += sign * du[k] * colscale[k]
    before = np.empty(Z.shape[1])
    for i in range(1, M):
        o = 6 + 12 * (i - 1)
        for k in range(3):
            Z[i, _N + k] += sign * du[o + k] * colscale[o + k]
            Z[i, _M + k] += sign * du[o + 3 + k] * colscale[o + 3 + k]
            Z[i, _P + k] += sign * du[o + 6 + k] * colscale[o + 6 + k]
        _copy(Z[i], before)
        _rotated(before, sign * du[o + 9] * colscale[o + 9], sign * du[o + 10] * colscale[o + 10],
                 sign * du[o + 11] * colscale[o + 11], Z[i])


@_jit
def _ms_motion(T, M, du, colscale, lam_rate, out):
    """The tip's displacement (out[0:3]) and rotation (out[3:6], material) for the scaled
    change du of the unknowns, from the last interval's tangents T (and ``lam_rate`` times
    its load-factor column)."""
    nt = 7 if M == 1 else _COLS
    for k in range(3):
        acc_p = lam_rate * T[LAM, _TP + k]
        acc_t = lam_rate * T[LAM, _TT + k]
        for d in range(nt):
            if d == LAM:
                continue
            col = _unknown(M - 1, d)
            acc_p += T[d, _TP + k] * du[col] * colscale[col]
            acc_t += T[d, _TT + k] * du[col] * colscale[col]
        out[k] = acc_p
        out[3 + k] = acc_t


@_jit
def _ms_distance(du, n, T, M, colscale, w, length, motion):
    """The size of a scaled change du of the unknowns: as single shooting measures it
    (:func:`_distance`), the largest of the base reaction's change relative to the case's
    load size 1 + w and of the tip motion it causes (L, rad), and the interior nodes'
    changes at a fifth of their weight (forces relative to 1 + w, positions in L, angles in
    rad). Under a hard oblique pull the clamp's boundary layer sweeps past node after node as
    k grows like √λ, turning each by up to the pull's angle: at full weight those turns held
    the path to 300 steps at kL = 1e4; without them it jumped to an arm wound the wrong way
    round (a node turning by more than π in one step)."""
    out = 0.0
    for k in range(n):
        force = k < 6 or (k - 6) % 12 < 6
        size = abs(du[k]) / (1.0 + w) if force else abs(du[k])
        out = max(out, size if k < 6 else _NODE_WEIGHT * size)
    _ms_motion(T, M, du, colscale, 0.0, motion)
    for k in range(6):
        out = max(out, abs(motion[k]) / (length if k < 3 else 1.0))
    if not math.isfinite(out):
        return np.inf
    return out


@_jit
def _ms_corrector(x, Z, M, lam, nt, chunks, first, csteps, base, arm, act, case, scratch, colscale,
                  rowscale, work, w, length, threshold, max_iterations, first_limit, loose, tip,
                  counter):
    """Newton at fixed λ on the block system from the prediction (x, Z), with
    :func:`_corrector`'s tests (the first step within ``first_limit``, every further one at
    most half the one before, converged at the threshold or at a step no larger than
    ``loose``, taken without integrating again). On success the band matrix holds the
    factors of the Jacobian at the last point integrated (for the tangent and det's sign),
    returned as (True, sign, the distance travelled); ``tip`` the tip position."""
    F, B, G, ends, lengths, piv, Lm, du, motion = work
    n = 12 * M - 6
    previous = np.inf
    travelled = 0.0
    for k in range(max_iterations + 1):
        res = _ms_evaluate(x, Z, M, lam, nt, chunks, first, csteps, base, arm, act, case, scratch,
                           colscale, rowscale, F, B, G, ends, lengths, None)
        counter[0] += 1
        for i in range(3):
            tip[i] = ends[M - 1, _P + i]
        if not math.isfinite(res):
            return False, 0.0, travelled
        sign = _band_factor(B, n, np.int64(_BAND), piv, Lm)
        if res <= threshold:
            return sign != 0.0, sign, travelled
        if k == max_iterations or sign == 0.0:
            return False, 0.0, travelled
        for i in range(n):
            du[i] = -F[i]
        if not _band_solve(B, n, np.int64(_BAND), piv, Lm, du):
            return False, 0.0, travelled
        size = _ms_distance(du, n, scratch[1], M, colscale, w, length, motion)
        if k == 0:
            if size > first_limit:
                return False, 0.0, travelled
        elif size > (_CONTRACTION_MAX if act is None or act[5].shape[0] == 0
                     else _CONTRACTION_CONTACT) * previous:
            return res <= _STALL * threshold, sign, travelled
        previous = size
        travelled += size
        if travelled > first_limit:
            return False, 0.0, travelled
        _ms_apply(x, Z, M, du, colscale, 1.0)
        if size <= loose:
            for i in range(3):
                tip[i] += motion[i]
            return True, sign, travelled
    return False, 0.0, travelled


@_jit
def _loose(act, length):
    """The corrector's tolerance on the way (a step no larger ends it): _LOOSE, or with
    contact a tenth of the thinnest contact distance (over L): a point on the way left
    _LOOSE L from the path lies far outside the band, and the next corrector, started
    there, does not find its way back into it."""
    loose = _LOOSE
    if act is not None and act[5].shape[0] > 0:
        for j in range(act[6].shape[0]):
            loose = min(loose, 0.1 * act[6][j, 1] / length)
    return loose


@_jit
def _ms_condensed(B, n, piv, Lm, v, P):
    """P (6 × 6): the block of B⁻¹ from the tip residual's rows to the base reaction's
    columns, i.e. the inverse of ∂r/∂x condensed onto the base reaction (single shooting's
    Jacobian, in the band's scaled units), by six band solves with B's factors. False if
    they fail. (Its eigenvalues' ratios between two points are the branch guard's
    :func:`_crossings`; formed only where the arm is not in strong tension, whose growing
    Jacobi fields make it ill-conditioned.)"""
    for k in range(6):
        for i in range(n):
            v[i] = 0.0
        v[n - 6 + k] = 1.0
        if not _band_solve(B, n, np.int64(_BAND), piv, Lm, v):
            return False
        for i in range(6):
            P[i, k] = v[i]
    return True


@_jit
def _ms_follow(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, colscale, rowscale,
               work, w, length, threshold, max_iterations, max_load_step, max_shootings, final,
               tip, counter, reached, lam0, end):
    """:func:`_follow` on the block system: the path from λ = lam0 (x, Z: the solution there,
    exact or close) to λ = ``end``, predicted along the tangent -J⁻¹ ∂F/∂λ, corrected by
    :func:`_ms_corrector`, with the same step control and branch guards: the sign of the
    whole banded Jacobian's determinant, the tip's direction of motion and, while the
    path's phase is at most _PHASE_TESTED (:func:`_phase`), the crossings of the condensed
    Jacobian (:func:`_ms_condensed`) and the phase's advance per step. True on success
    (x, Z at λ = end, the band factors there); else reached[0] is the last load factor
    reached."""
    B, G, piv, Lm, du, motion = work[1], work[2], work[5], work[6], work[7], work[8]
    n = 12 * M - 6
    nt = M - M + _COLS  # (a variable: one compiled version of the callees)
    reached[0] = lam0
    ok, sign, dist = _ms_corrector(x, Z, M, lam0, nt, chunks, first, csteps, base, arm, act, case,
                             scratch, colscale, rowscale, work, w, length, threshold,
                             max_iterations, _REFINE_MAX, _LOOSE, tip, counter)
    if not ok:
        return False
    bounds = np.empty(7)
    _path_bounds(arm, act, case, arm[7], bounds)
    touching = act is not None and act[5].shape[0] > 0
    guard = _guard_work()
    P_prev = np.empty((6, 6))
    P_new = np.empty((6, 6))
    v = np.empty(n)
    tested = (not touching and _phase(bounds, lam0) <= _PHASE_TESTED
              and _ms_condensed(B, n, piv, Lm, v, P_prev))
    t = np.empty(n)
    for i in range(n):
        t[i] = -G[i]
    if not _band_solve(B, n, np.int64(_BAND), piv, Lm, t):
        return False
    reached[1] = sign
    x_keep = np.empty(6)
    Z_keep = np.empty_like(Z)
    motion_prev = np.empty(6)
    motion_new = np.empty(6)
    _ms_motion(scratch[1], M, t, colscale, 1.0, motion_prev)
    moved = np.empty(n)
    lam = lam0
    loose = _loose(act, length)
    size = _ms_distance(t, n, scratch[1], M, colscale, w, length, motion)
    dl = max_load_step if size <= 0.0 else min(max_load_step, _FIRST_MOTION / size)
    while lam < end:
        if counter[0] > max_shootings:
            return False
        dl, target = _load_step(lam, dl if touching else _phase_limited(bounds, lam, dl), end)
        _copy(x, x_keep)
        _copy(Z, Z_keep)
        for i in range(n):
            moved[i] = (target - lam) * t[i]
        _ms_apply(x, Z, M, moved, colscale, 1.0)
        ok, new_sign, dist = _ms_corrector(x, Z, M, target, nt, chunks, first, csteps, base,
                                           arm, act, case, scratch, colscale, rowscale, work, w,
                                           length, threshold, max_iterations, _DIST_MAX,
                                           final if target == 1.0 else loose, tip, counter)
        if ok:
            for i in range(n):
                du[i] = -G[i]
            ok = _band_solve(B, n, np.int64(_BAND), piv, Lm, du)
        check = False  # the condensed Jacobian's crossings: only where it is well conditioned
        if ok:
            check = (tested and _phase(bounds, target) <= _PHASE_TESTED
                     and _ms_condensed(B, n, piv, Lm, v, P_new))
            _ms_motion(scratch[1], M, du, colscale, 1.0, motion_new)
            crossing = new_sign != sign or (
                check and _crossings(P_new, P_prev, np.int64(6), guard[2], guard[3], 0.0) != 0)
            # (with contact the tip turns where it touches: only det's sign guards)
            ok = dl <= (_DLAM_CROSS_CONTACT if touching else _cross_step(bounds, lam)) or (
                not crossing and (_cosine(motion_prev, motion_new) >= 0.5 or touching))
        if ok:
            sign = new_sign
            reached[1] = sign
            tested = check
            if check:
                _copy(P_new, P_prev)
            for i in range(3):
                motion_prev[i] = motion_new[i]
            # (dist: the corrector's distance from the prediction, the step control's measure)
            for i in range(n):
                t[i] = du[i]
            lam = target
            reached[0] = lam
            dl = _grown(dl, dist, max_load_step)
        else:
            _copy(x_keep, x)
            _copy(Z_keep, Z)
            dl *= 0.4
            if dl < min(_DLAM_MIN_STIFF, _smallest_step(bounds, lam)):
                return False
    return True


@_jit
def _ms_grid(arm, M, width):
    """The block system's grid with M intervals: (chunks, their count, each interval's first
    chunk, steps per chunk, work arrays, column scales, row scales)."""
    length, scale = arm[6], arm[7]
    chunks = np.empty((M + arm[1].size, 5))
    nc, first = _chunk_table(arm, M, chunks)
    n = 12 * M - 6
    colscale = np.empty(n)
    rowscale = np.empty(n)
    for k in range(6):
        colscale[k] = scale[k]
    for i in range(1, M):
        o = 6 + 12 * (i - 1)
        for k in range(6):
            colscale[o + k] = scale[k]
            colscale[o + 6 + k] = length if k < 3 else 1.0
    for i in range(M - 1):  # rows p, θ, n, m of join i
        o = 12 * i
        for k in range(3):
            rowscale[o + k] = length
            rowscale[o + 3 + k] = 1.0
            rowscale[o + 6 + k] = scale[k]
            rowscale[o + 9 + k] = scale[3 + k]
    for k in range(6):
        rowscale[n - 6 + k] = scale[k]
    return (chunks, nc, first, np.empty(nc, dtype=np.int64), _ms_work(M, width), colscale,
            rowscale)


@_jit
def _ms_fill_nodes(x, coarse, ratio, Z, M, chunks, first, csteps, base, arm, act, case,
                   scratch, lam):
    """The nodes Z (M) of a grid ``ratio`` times finer than a solution's (base reaction x,
    nodes ``coarse``) at load factor lam, to be corrected there: the coarse nodes where they
    fall (every ratio-th), the states between integrated from them on this grid (with ratio
    0, every node integrated from the clamp)."""
    y, T = scratch[0], scratch[1]
    none = M - M
    _set_loads(lam, case, scratch[4], scratch[5])
    _start(y, T, none, base, x)
    for i in range(M):
        if i > 0:
            if ratio > 0 and i % ratio == 0:
                _copy(coarse[i // ratio], y)
            _copy(y, Z[i])
        _run_chunks(y, T, none, first[i], first[i + 1], chunks, csteps, arm, act, case[1],
                    scratch)


@_jit
def _ms_path(x, Z, M, levels, kl, N, n_fixed, arm, act, base, case, scratch, w, threshold,
             max_iterations, max_load_step, budget, final_step, tip, counter, reached, chunks,
             first, csteps, work, colscale, rowscale):
    """The loading path from the unloaded arm to λ = 1 on the final grid (M intervals,
    ``csteps`` at N), in levels: k grows like √λ, so the path runs on M / 2^levels
    intervals and proportionally fewer steps while k√λ L <= _GROWTH times their number,
    then on four times as many, each finer grid's nodes the coarser's plus the states
    between (integrated on the finer grid from the coarser nodes, :func:`_ms_fill_nodes`,
    then corrected at that λ). The
    early load steps, most of the path's, cost a fraction of the last ones'. True on success,
    x and Z the solution at λ = 1 on the final grid (its band factors in ``work``)."""
    length = arm[6]
    y = scratch[0]
    lam = 0.0
    for k in range(6):
        x[k] = 0.0
    prev_Z = np.zeros((1, y.size))
    prev_M = 0
    for level in range(levels, -1, -1):
        Ml = M >> (_LEVEL * level)
        final = level == 0
        end = 1.0 if final or not kl > 0.0 else min(1.0, (_GROWTH * Ml / kl) ** 2)
        if final:
            g_chunks, g_first, g_csteps, g_work = chunks, first, csteps, work
            g_colscale, g_rowscale, Zl = colscale, rowscale, Z
        else:
            g_chunks, nc, g_first, g_csteps, g_work, g_colscale, g_rowscale = _ms_grid(
                arm, Ml, y.size)
            Zl = np.zeros((Ml, y.size))
            # steps in proportion to k at the level's end (N is the final grid's)
            Nl = N if n_fixed > 0 else max(nc, math.ceil(N * math.sqrt(end)))
            _chunk_steps(g_chunks, nc, length, Nl, np.int64(1), np.ones(Ml, dtype=np.int64),
                         g_csteps)
        # the nodes: the coarser level's (every fourth one) and the states between them,
        # integrated from those; on the first level the unloaded arm's (x = 0, λ = 0)
        _ms_fill_nodes(x, prev_Z, (1 << _LEVEL) if prev_M > 0 else 0, Zl, Ml, g_chunks,
                       g_first, g_csteps, base, arm, act, case, scratch, lam)
        if not _ms_follow(x, Zl, Ml, g_chunks, g_first, g_csteps, base, arm, act, case, scratch,
                          g_colscale, g_rowscale, g_work, w, length, threshold, max_iterations,
                          max_load_step, budget, final_step if final else _loose(act, length),
                          tip, counter,
                          reached, lam, end):
            return False
        lam = end
        if final:
            return True
        prev_Z = Zl
        prev_M = Ml
    return True


@_jit
def _ms_chord(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, colscale, rowscale,
              work, threshold, max_iterations, tip, counter):
    """The solution at λ = 1 on another grid by chord iterations from (x, Z) with the band
    factors left in ``work`` (a nearby grid's): :func:`_chord`'s tests (the first step a
    discretisation-sized change, the residual at least halved every iteration, a stall
    accepted at ``_STALL`` times the threshold). True if converged."""
    F, B, G, ends, lengths, piv, Lm, du = work[:8]
    n = 12 * M - 6
    none = M - M  # no tangents (a variable: one compiled version)
    previous = np.inf
    for _ in range(max_iterations):
        res = _ms_evaluate(x, Z, M, 1.0, none, chunks, first, csteps, base, arm, act, case,
                           scratch, colscale, rowscale, F, B, G, ends, lengths, None)
        counter[0] += 1
        for i in range(3):
            tip[i] = ends[M - 1, _P + i]
        if res <= threshold:
            return True
        if not res < 0.5 * previous:
            return res <= _STALL * threshold
        for i in range(n):
            du[i] = -F[i]
        if not _band_solve(B, n, np.int64(_BAND), piv, Lm, du):
            return False
        if not math.isfinite(previous):
            size = 0.0
            for i in range(n):
                size = max(size, abs(du[i]))
            if not size <= _REFINE_MAX:
                return False
        previous = res
        _ms_apply(x, Z, M, du, colscale, 1.0)
    return False


@_jit
def _ms_record(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, s_out, out, b,
               states, sens):
    """The output pass of the solution (x, Z) at λ = 1: each interval integrated from its
    start once more, and every station written (a station inside a step: the RK4 step from
    that step's start to the station; the tip station from the tip state). With ``states``
    (not None), the state itself at each station s_out instead (the stability sweep's grid).
    With ``sens`` (not None: (U, colscale, nt), :func:`_ms_sensitivities`), the tangents
    too (nt columns), and each station's compliance and actuation Jacobian into out[6][b],
    the tendons' lengths' into out[5][b] rows 6.. (:func:`_ms_motion_rows`)."""
    y, T, work, twork, now, tip_now, ys, Ts, law = scratch
    poses, strains, stresses, E = out[0][b], out[1][b], out[2][b], out[6][0]
    rate = case[1]
    one = np.int64(1)
    none = one - one
    nt = none if sens is None else sens[2]
    _set_loads(1.0, case, now, tip_now)
    ns = s_out.size
    k = 0
    lengths = out[8]
    for a in range(lengths.shape[1]):
        if states is None:
            lengths[b, a] = 0.0
    if sens is not None:
        for r_ in range(6, out[5].shape[1]):
            for c in range(out[5].shape[2]):
                out[5][b, r_, c] = 0.0
    for i in range(M):
        if i == 0:
            _start(y, T, nt, base, x)
        else:
            _node_start(y, T, nt, Z, i)
        for c in range(first[i], first[i + 1]):
            j = int(chunks[c, _CJ])
            if chunks[c, _CFIRST] > 0.0:
                _jump(y, T, nt, now, rate, j, arm, act, law)
            n = csteps[c]
            h = chunks[c, _CL] / n
            s0 = chunks[c, _CS]
            step = 0
            while step < n:
                run = n - step
                if k < ns:
                    run = min(run, max(int((s_out[k] - s0) / h) - 1 - step, 0))
                if run > 0:
                    _steps(y, T, nt, h, s0 + step * h, run, arm, act, j, now, rate, work,
                           twork, law)
                    step += run
                    continue
                t0 = s0 + step * h
                t1 = s0 + (step + 1) * h
                last = i == M - 1 and c == first[M] - 1 and step == n - 1
                while k < ns and s_out[k] < t1 and not (last and s_out[k] >= arm[6]):
                    _copy(y, ys)
                    _copy(T, Ts)
                    _steps(ys, Ts, nt, s_out[k] - t0, t0, one, arm, act, j, now, rate, work,
                           twork, law)
                    if states is not None:
                        _copy(ys, states[k])
                    else:
                        _write(ys, Ts, none, j, s_out[k], arm, act, now, law, poses[k],
                               strains[k], stresses[k], E[0])
                        if sens is not None:
                            _ms_motion_rows(ys, Ts, i, sens, out[6][b][k], np.int64(6))
                    k += 1
                _steps(y, T, nt, h, t0, one, arm, act, j, now, rate, work, twork, law)
                step += 1
        for a in range(lengths.shape[1]):
            if states is None:
                lengths[b, a] += y[18 + a]
        if sens is not None and out[5].shape[1] > 6:
            _ms_motion_rows(y, T, i, sens, out[5][b], -np.int64(6))
    for i in range(k, ns):
        if states is not None:
            _copy(y, states[i])
        else:
            _write(y, T, none, arm[1].size - 1, arm[6], arm, act, now, law, poses[i],
                   strains[i], stresses[i], E[0])
            if sens is not None:
                _ms_motion_rows(y, T, M - 1, sens, out[6][b][i], np.int64(6))
    if states is None:
        for i in range(6):
            out[7][b, i] = x[i]


@_jit
def _ms_motion_rows(y, T, i, sens, rows, which):
    """With the tangents T of interval i at a point: ``which`` = 6, the point's motion
    (δp; δθ spatial) per tip wrench and per input into rows (6, 6 + n), written; ``which``
    = -6, the tendons' lengths' (T's columns NT.., the interval's share) added into rows
    6.. of rows (6 + A, 6 + n). Through the unknowns' sensitivities U (scaled, per tip
    wrench component, then per input): Σ_d T[d] colscale U[unknown(i, d)], plus an input's
    own column."""
    U, colscale, nt = sens
    m = U.shape[1]
    count = 6 if which > 0 else T.shape[1] - NT
    for r_ in range(count):
        for c in range(m):
            acc = 0.0
            for d in range(min(nt, _COLS)):
                if d == LAM or (i == 0 and d > LAM):
                    continue
                col = _unknown(i, d)
                acc += _motion_entry(y, T, d, r_, which) * colscale[col] * U[col, c]
            if c >= 6:
                acc += _motion_entry(y, T, _COLS + c - 6, r_, which)
            if which > 0:
                rows[r_, c] = acc
            else:
                rows[6 + r_, c] += acc


@_jit
def _motion_entry(y, T, d, r_, which):
    """Row r_ of tangent column d: δp (r_ < 3) or δθ in spatial components (which = 6), or
    tendon r_'s length (which = -6)."""
    if which < 0:
        return T[d, NT + r_]
    if r_ < 3:
        return T[d, _TP + r_]
    i = r_ - 3
    return (y[_R + 3 * i] * T[d, _TT] + y[_R + 3 * i + 1] * T[d, _TT + 1]
            + y[_R + 3 * i + 2] * T[d, _TT + 2])


@_jit
def _ms_work(M, width):
    """Work arrays of the block system with M intervals: F, the band B, G, the interval end
    states, the tendons' lengths, pivots, multipliers, a step, a motion."""
    n = 12 * M - 6
    return (np.empty(n), np.empty((n, 3 * _BAND + 1)), np.empty(n), np.empty((M, width)),
            np.empty(width - 18), np.empty(n, dtype=np.int64), np.empty((n, _BAND)),
            np.empty(n), np.empty(6))


def _stiff_capability(args):
    key, text = _per_arm("stiff", "the multiple-shooting solver (stiff problems)", 2)(args)
    if _given(args[8]):
        key, text = key + "+jacobians", text + " with Jacobians"
    if _given(args[7]):
        key, text = key + "+verdict", text + " and its stability verdict"
    return key, text


@_entry(_stiff_capability, nogil=True)
def solve_stiff_cases(base, arm, act, loads, options, s_out, out, verdicts, inputs, chain):
    """Solve every load case of a flattened batch by multiple shooting, each from the
    unloaded arm (λ = 0) along its own loading path (the stiff route of
    :func:`solve_cases`: the same arguments where they exist, the same outputs), or, with
    ``chain`` on, from the last solution the chain holds (a chained Solver's quasi-static
    path: solver.py's ``_StiffChain``, docs/solver.md "Chained solves").

    The stages follow solve_cases': the path (in levels of intervals, :func:`_ms_path`),
    the solution at 2N (chord iterations with the factors at N, else Newton), the
    Richardson estimate |p_2N - p_N| / 15 times _STIFF_SAFETY against tol, the steps grown
    by the order-4 model until it is met (in the intervals whose local error calls for it,
    :func:`_ms_local_errors`; with one interval, N itself), the output pass. The intervals
    (kL/M <= _GROWTH, k from the case's load size) and their cut by the pieces are fixed per
    case; N spreads over them as over the arm.

    ``verdicts``: None, or (index (B,), conservative (B,)): each solved case's stability
    verdict (:func:`stability_cases`' Morse index on the grid of N steps per piece, its
    sweep taking the state at every grid point from this solution instead of integrating it
    backwards, where it would grow like e^{kL}). ``inputs``: None, or as solve_cases'
    (Jacobians): the compliances and actuation Jacobians by the implicit function theorem on
    the block system (:func:`_ms_sensitivities`), in solve_cases' outputs after its
    :func:`_implicit_function`. ``chain``: (x (6,), Z (cap, 18 + actuators), mult (cap,)
    int64, meta (4,), piece (pieces, width), tip (TIP_LOADS,)); meta[0] is 0 (off: neither
    read nor written), 1 (on, holding nothing) or 2 (holding a solution: meta[1] its M,
    meta[2] its N, meta[3] its error estimate, x, Z[:M] and mult[:M] its nodes on N steps,
    piece and tip its loads). A chain on holds each case's solution for the next (the
    batch is one path) and nothing after a case that failed.
    """
    piece_loads, tip_loads = loads
    nb = piece_loads.shape[0]
    npieces = arm[1].size
    length = arm[6]
    scale = arm[7]
    tol, max_iterations, max_load_step, n_fixed, n_max, budget = _read_options(options)
    info, status = out[3], out[4]
    width = piece_loads.shape[2]
    scratch = _scratch(npieces, width - PIECE_LOADS, _COLS)
    start = np.zeros((npieces, width))
    rate = np.zeros((7, npieces, width))  # rows 1-6: zero (the node columns 7-12)
    tip_start = np.zeros(TIP_LOADS)
    tip_rate = np.zeros((7, TIP_LOADS))
    case = (start, rate, tip_start, tip_rate)
    final_step = min(1e-3, math.sqrt(0.01 * tol / length)) if math.isfinite(tol) else 1e-9
    reached = np.zeros(2)
    counter = np.zeros(1, dtype=np.int64)
    x = np.zeros(6)
    x_f = np.zeros(6)
    tip_c = np.empty(3)
    tip_f = np.empty(3)
    y = scratch[0]
    chain_x, chain_Z, chain_mult, chain_meta, chain_piece, chain_tip = chain
    chained = chain_meta[0] > 0.0 and chain_Z.shape[1] == y.size and \
        chain_piece.shape[0] == npieces and chain_piece.shape[1] == width
    for b in range(nb):
        # from the chain's last solution when it holds one; a cold start if that fails
        warm = chained and chain_meta[0] == 2.0
        again = True
        while again:
            again = False
            counter[0] = 0
            for j in range(npieces):
                for i in range(width):
                    start[j, i] = chain_piece[j, i] if warm else 0.0
                    rate[0, j, i] = piece_loads[b, j, i] - start[j, i]
            for i in range(TIP_LOADS):
                tip_start[i] = chain_tip[i] if warm else 0.0
                tip_rate[0, i] = tip_loads[b, i] - tip_start[i]
            w, turning = _load_size(arm, act, scale, start, piece_loads[b], tip_start,
                                    tip_loads[b])
            threshold = 1e-12 * w + 1e-300
            kl = _stiffness_size(arm, act, w, piece_loads[b])
            # M = M_base 2^levels >= kL / _GROWTH (within 25 %): the path's levels halve it
            needed = max(1, min(math.ceil(kl / _GROWTH), n_max // 4))
            levels = 0
            while (needed >> (_LEVEL * (levels + 1))) >= 4:
                levels += 1
            M = ((needed + (1 << (_LEVEL * levels)) - 1) >> (_LEVEL * levels)) \
                << (_LEVEL * levels)
            ratio = 1  # a warm start's intervals per interval of the chain's grid
            if warm:
                # the chain's grid, on which its nodes were solved, or where the loads
                # stiffen past it (a raised penalty), that grid refined the fewest times
                # that hold them; a cold start where that is over twice the cold grid
                # (measured: refined 4 times at once, an inverse solve's raised penalties
                # took the finger's grid from 48 intervals to 3072) or the chain's grid is
                # over 8 times it (loads that soften: each shooting costs as many more)
                held = int(chain_meta[1])
                ratio = max(1, (needed + held - 1) // held)
                if held * ratio > 2 * M or held > 8 * M or held * ratio > n_max // 4 or \
                        held * ratio > chain_Z.shape[0]:
                    warm = False
                    again = True
                    continue
                M = held * ratio
                levels = 0
            chunks, nc, first, csteps, work, colscale, rowscale = _ms_grid(arm, M, y.size)
            n = 12 * M - 6
            Z = np.zeros((M, y.size))
            Z_f = np.zeros((M, y.size))
            mult = np.ones(M, dtype=np.int64)
            local = np.empty(M)
            if n_fixed > 0:
                N = n_fixed // 2
            else:
                N = max(_first_steps(arm, tol, turning), math.ceil(_STIFF_STEPS * kl))
            N = min(N, n_max // 2)
            path = True
            if warm:
                if n_fixed == 0:
                    # the chain's steps, half as many where its estimate allowed it (order
                    # 4: 16 times the error): a zone that moves on needs fewer again
                    held = int(chain_meta[2])
                    if chain_meta[3] <= tol / 32.0:
                        held = held // 2
                    N = min(n_max // 2, max(N, held))
                for i in range(M):
                    mult[i] = chain_mult[i // ratio]
            status[b] = OK
            estimate = np.inf
            failures = 0
            failed_at = -1.0
            done = False
            while not done:
                if path and warm:  # the path from the chain's solution, on N steps
                    _chunk_steps(chunks, nc, length, N, np.int64(1), mult, csteps)
                    _copy(chain_x, x)
                    if ratio == 1:
                        Z[:, :] = chain_Z[:M]
                    else:
                        _ms_fill_nodes(x, chain_Z, ratio, Z, M, chunks, first, csteps, base,
                                       arm, act, case, scratch, 0.0)
                    if not _ms_follow(x, Z, M, chunks, first, csteps, base, arm, act, case,
                                      scratch, colscale, rowscale, work, w, length, threshold,
                                      max_iterations, max_load_step, budget, final_step,
                                      tip_c, counter, reached, 0.0, 1.0):
                        status[b] = PATH_FAILED  # (then a cold start)
                        break
                    path = False
                if path:
                    _chunk_steps(chunks, nc, length, N, np.int64(1), mult, csteps)
                    if not _ms_path(x, Z, M, levels, kl, N, n_fixed, arm, act, base, case, scratch,
                                    w, threshold, max_iterations, max_load_step, budget,
                                    final_step, tip_c, counter, reached, chunks, first, csteps,
                                    work, colscale, rowscale):
                        if counter[0] > budget:
                            status[b] = BUDGET
                            break
                        if _retry_finer(n_fixed, N, n_max, failures, reached[0], failed_at):
                            failures += 1
                            failed_at = reached[0]
                            N = 2 * N
                            continue
                        status[b] = PATH_FAILED
                        break
                    path = False
                if counter[0] > budget:
                    status[b] = BUDGET
                    break
                # the fine solution at 2N: chord iterations with the factors at N, else Newton
                _copy(x, x_f)
                _copy(Z, Z_f)
                _chunk_steps(chunks, nc, length, N, np.int64(2), mult, csteps)
                if not _ms_chord(x_f, Z_f, M, chunks, first, csteps, base, arm, act, case, scratch,
                                 colscale, rowscale, work, threshold, max_iterations, tip_f,
                                 counter):
                    _copy(x, x_f)
                    _copy(Z, Z_f)
                    ok, _, _ = _ms_corrector(
                        x_f, Z_f, M, 1.0, M - M + _COLS, chunks, first, csteps, base, arm, act,
                        case, scratch, colscale, rowscale, work, w, length, threshold,
                        max_iterations, _REFINE_MAX, 1e-9, tip_f, counter)
                    if not ok:
                        if 4 * N > n_max or n_fixed > 0:
                            status[b] = NEWTON_FAILED
                            break
                        N = 2 * N
                        path = True
                        continue
                d2 = 0.0
                for i in range(3):
                    d2 += (tip_f[i] - tip_c[i]) ** 2
                estimate = _STIFF_SAFETY * math.sqrt(d2) / 15.0
                if estimate <= tol or n_fixed > 0:
                    done = True
                    break
                total = 0
                for c in range(nc):
                    total += csteps[c]  # (at 2N)
                if total >= n_max:
                    status[b] = TOO_MANY_STEPS
                    break
                grow = (estimate / (0.3 * tol)) ** 0.25
                if M > 1:
                    # refine where the error is made: the intervals whose local error (N against
                    # 2N from the same start) is within a factor 20 of the largest; a boundary
                    # layer (the clamp's, width 1/k) then gets the steps, not the whole arm
                    _ms_local_errors(x_f, Z_f, M, chunks, first, csteps, base, arm, act, case,
                                     scratch, colscale, rowscale, work, length, nc, N, mult,
                                     local)
                    largest = 0.0
                    for i in range(M):
                        largest = max(largest, local[i])
                    factor = max(2, math.ceil(grow))
                    for i in range(M):
                        if local[i] >= 0.05 * largest or not largest > 0.0:
                            mult[i] *= factor
                else:
                    N = min(n_max // 2, max(N + 1, math.ceil(N * grow)))
                _chunk_steps(chunks, nc, length, N, np.int64(1), mult, csteps)
                _copy(x_f, x)
                _copy(Z_f, Z)
                ok, _, _ = _ms_corrector(
                    x, Z, M, 1.0, M - M + _COLS, chunks, first, csteps, base, arm, act, case,
                    scratch, colscale, rowscale, work, w, length, threshold, max_iterations,
                    _REFINE_MAX, final_step, tip_c, counter)
                path = not ok
            if warm and status[b] != OK:  # a cold start, from the unloaded arm
                warm = False
                again = True
        info[b, 1] = estimate
        info[b, 2] = 1.0 if status[b] == OK else reached[0]
        info[b, 3] = counter[0]
        info[b, 4] = N
        F = work[0]
        residual = 0.0
        for i in range(6):  # the tip residual (N, N m), as solve_cases reports it
            v = abs(F[n - 6 + i]) * rowscale[n - 6 + i]
            if not v <= residual:
                residual = v
        info[b, 0] = residual
        if chained:  # the chain holds this solution (its nodes on N steps) for the next case
            chain_meta[0] = 1.0
            if status[b] == OK and M <= chain_Z.shape[0]:
                chain_x[:] = x
                chain_Z[:M] = Z
                chain_mult[:M] = mult
                chain_piece[:, :] = piece_loads[b]
                chain_tip[:] = tip_loads[b]
                chain_meta[1] = M
                chain_meta[2] = N
                chain_meta[3] = estimate
                chain_meta[0] = 2.0
        if status[b] != OK:
            continue
        _chunk_steps(chunks, nc, length, N, np.int64(2), mult, csteps)
        if inputs is None:
            _ms_record(x_f, Z_f, M, chunks, first, csteps, base, arm, act, case, scratch,
                       s_out, out, b, None, None)
        elif not _ms_sensitivities(x_f, Z_f, M, chunks, first, csteps, base, arm, act,
                                   piece_loads[b], tip_loads[b], inputs, colscale, rowscale,
                                   work, s_out, out, b):
            status[b] = SINGULAR
            continue
        if not math.isfinite(residual):
            status[b] = NOT_FINITE
        if verdicts is not None and status[b] == OK:
            _ms_verdict(x_f, Z_f, M, chunks, first, csteps, base, arm, act, case, scratch, N,
                        piece_loads[b], tip_loads[b], out, b, verdicts)


@_jit
def _ms_local_errors(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, colscale,
                     rowscale, work, length, nc, N, mult, local):
    """Each interval's local error ``local[i]`` (L, rad): its end state integrated from the
    solution's own start on N steps against on 2N (``work``'s ends: the last integration,
    at 2N, of this solution), in position / L and rotation. Leaves ``csteps`` at N."""
    F, B, G, ends, lengths = work[0], work[1], work[2], work[3], work[4]
    fine = ends.copy()
    _chunk_steps(chunks, nc, length, N, np.int64(1), mult, csteps)
    none = M - M
    _ms_evaluate(x, Z, M, 1.0, none, chunks, first, csteps, base, arm, act, case, scratch,
                 colscale, rowscale, F, B, G, ends, lengths, None)
    for i in range(M):
        e = 0.0
        for a in range(3):
            e = max(e, abs(ends[i, _P + a] - fine[i, _P + a]) / length)
        for a in range(9):
            e = max(e, abs(ends[i, _R + a] - fine[i, _R + a]))
        local[i] = e if math.isfinite(e) else np.inf


@_jit
def _ms_sensitivities(x, Z, M, chunks, first, csteps, base, arm, act, piece, tip, inputs,
                      colscale, rowscale, work, s_out, out, b):
    """The implicit function theorem on the block system at the solution (x, Z): the
    scaled unknowns' changes U per dead tip wrench component (J U = e_k / rowscale_k: the
    tip rows are n(L) - W) and per input (J U = -∂F/∂q), then the output pass with the
    tangents, which writes each station's compliance and actuation Jacobian and the
    tendons' lengths' (:func:`_ms_record`), and out[5][b] rows 0:6 = [∂x/∂W | -∂x/∂q], as
    solve_cases' :func:`_implicit_function` leaves them. False if J is singular."""
    F, B, G, ends, lengths, piv, Lm = work[:7]
    n = 12 * M - 6
    n_in = inputs[0].shape[0]
    npieces = arm[1].size
    width = piece.shape[1]
    nt = _COLS + n_in
    scratch = _scratch(npieces, width - PIECE_LOADS, nt)
    rate = np.zeros((7 + n_in, npieces, width))  # row 0 (λ) and the node rows 1-6: zero
    tip_rate = np.zeros((7 + n_in, TIP_LOADS))
    for q in range(n_in):
        for j in range(npieces):
            for i in range(width):
                rate[7 + q, j, i] = inputs[0][q, j, i]
        for i in range(TIP_LOADS):
            tip_rate[7 + q, i] = inputs[1][q, i]
    case = (piece, rate, tip, tip_rate)  # at λ = 1 the loads are piece, tip (rate 0 is zero)
    Gq = np.empty((n, max(n_in, 1)))
    _ms_evaluate(x, Z, M, 1.0, nt, chunks, first, csteps, base, arm, act, case, scratch,
                 colscale, rowscale, F, B, G, ends, lengths, Gq)
    if _band_factor(B, n, np.int64(_BAND), piv, Lm) == 0.0:
        return False
    U = np.zeros((n, 6 + n_in))
    column = np.empty(n)
    for c in range(6 + n_in):
        for i in range(n):
            column[i] = 0.0
        if c < 6:
            column[n - 6 + c] = 1.0 / rowscale[n - 6 + c]
        else:
            for i in range(n):
                column[i] = -Gq[i, c - 6]
        if not _band_solve(B, n, np.int64(_BAND), piv, Lm, column):
            return False
        for i in range(n):
            U[i, c] = column[i]
    _ms_record(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, s_out, out, b,
               None, (U, colscale, nt))
    jac = out[5][b]
    for i in range(6):
        for c in range(6 + n_in):
            jac[i, c] = U[i, c] * colscale[i] * (1.0 if c < 6 else -1.0)
    return True


@_jit
def _ms_verdict(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, N, piece, tip,
                out, b, verdicts):
    """Case b's stability verdict (see :func:`solve_stiff_cases`): the solution's state at
    every point of the sweep's grid (N steps spread over the pieces), then the sweep."""
    npieces = arm[1].size
    steps = np.empty(npieces, dtype=np.int64)
    _fill_steps(arm[6], arm[1], N, np.int64(1), steps)
    total = 0
    for j in range(npieces):
        total += steps[j]
    grid = np.empty(total + 1)
    k = 0
    for j in range(npieces):
        h = arm[1][j] / steps[j]
        for i in range(steps[j]):
            grid[k] = arm[0][j] + i * h
            k += 1
    grid[total] = arm[6]
    states = np.empty((total + 1, scratch[0].size))
    _ms_record(x, Z, M, chunks, first, csteps, base, arm, act, case, scratch, grid, out, b,
               states, None)
    nt = _tangent_columns(arm, act, piece)
    verdicts[1][b] = _conservative(piece, tip)
    one_case = (case[0], case[1][:1], case[2], case[3][:1])
    r = np.empty(6)
    J = np.empty((6, 7))
    t0 = np.zeros((nt, nt))
    verdicts[0][b] = _sweep(x, 1.0, steps, base, arm, act, one_case, scratch, nt, r, J,
                            np.empty((0, 1)), np.empty((0, 1, 1)), t0, np.empty((0, 1)), states)


# ==================================================================== dynamics (begin)
# One implicit time step of Cosserat rod dynamics is a boundary value problem in s (Till,
# Aloi & Rucker 2019). Node state (DYN = 24): centreline p (spatial), frame R (row-major),
# internal force n and moment m (material), velocity q and angular velocity ω (material).
# p and R sit where the statics' state has them (_P, _R), so _rotated and _dipole apply.
_DP, _DR, _DN, _DM, _DQ, _DW = _P, _R, 12, 15, 18, 21
DYN = 24
# Unknowns and rates per node (DUNK = 18): δp, δθ (material), δn, δm, δq, δω; a node's rate
# vector holds p', u, n', m', q', ω' in the same order.
DUNK = 18
_DYN_HALVINGS = 12  # the most halvings of a damped Newton step (contact, _dyn_newton)
_DKL = 29  # the band's lower width: rows of interval k meet node k's columns 29 back
# History per node (DHIST = 36): x = (ε (6), q, ω) at t - Δt, at t - 2Δt, and ẋ at t - Δt.
DHIST = 36
# Per-piece properties (DPROPS): K (36), B (36), (K + c0 B)⁻¹ (36), f⁰ (6), μ (1), ρJ (3).
# The loads are the statics' channels (PIECE_LOADS + actuators per piece, TIP_LOADS).
_PK, _PB, _PKD, _PF0, _PMU, _PRJ = 0, 36, 72, 108, 114, 115
DPROPS = 118
# BDF-α coefficients (DCOEF): c0, c1, c2, d1, Δt, α.
DCOEF = 6
# Statuses
DYN_OK, DYN_NEWTON, DYN_NOT_FINITE, DYN_INADMISSIBLE = 0, 1, 2, 3
# A step that took this many chord iterations asks for new factors at the next one: a
# factorisation costs about ten iterations, an aged factor one more iteration a step for
# tens of steps (measured: 3.0 -> 2.x iterations a step).
_DYN_REFRESH = 4


@_jit
def _mat_t_vec(R, o, x0, x1, x2, out, k):
    """out[k:k+3] = Rᵀ x with R row-major at R[o:o+9]."""
    out[k] = R[o] * x0 + R[o + 3] * x1 + R[o + 6] * x2
    out[k + 1] = R[o + 1] * x0 + R[o + 4] * x1 + R[o + 7] * x2
    out[k + 2] = R[o + 2] * x0 + R[o + 5] * x1 + R[o + 8] * x2


@_jit
def _log_relative(za, zb, out):
    """out = log(R_aᵀ R_b) (material components of a); returns its angle θ."""
    ra, rb = _DR, _DR
    m00 = za[ra] * zb[rb] + za[ra + 3] * zb[rb + 3] + za[ra + 6] * zb[rb + 6]
    m11 = za[ra + 1] * zb[rb + 1] + za[ra + 4] * zb[rb + 4] + za[ra + 7] * zb[rb + 7]
    m22 = za[ra + 2] * zb[rb + 2] + za[ra + 5] * zb[rb + 5] + za[ra + 8] * zb[rb + 8]
    m01 = za[ra] * zb[rb + 1] + za[ra + 3] * zb[rb + 4] + za[ra + 6] * zb[rb + 7]
    m10 = za[ra + 1] * zb[rb] + za[ra + 4] * zb[rb + 3] + za[ra + 7] * zb[rb + 6]
    m02 = za[ra] * zb[rb + 2] + za[ra + 3] * zb[rb + 5] + za[ra + 6] * zb[rb + 8]
    m20 = za[ra + 2] * zb[rb] + za[ra + 5] * zb[rb + 3] + za[ra + 8] * zb[rb + 6]
    m12 = za[ra + 1] * zb[rb + 2] + za[ra + 4] * zb[rb + 5] + za[ra + 7] * zb[rb + 8]
    m21 = za[ra + 2] * zb[rb + 1] + za[ra + 5] * zb[rb + 4] + za[ra + 8] * zb[rb + 7]
    c = min(1.0, max(-1.0, 0.5 * (m00 + m11 + m22 - 1.0)))
    x0, x1, x2 = 0.5 * (m21 - m12), 0.5 * (m02 - m20), 0.5 * (m10 - m01)  # sin θ · axis
    sn = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    th = math.atan2(sn, c)
    f = 1.0 + th * th / 6.0 if sn < 1e-4 else th / sn
    out[0] = f * x0
    out[1] = f * x1
    out[2] = f * x2
    return th


@_jit
def _inverse_jacobian(a0, a1, a2, sign, out):
    """out (3×3) = J_r⁻¹(sign · a) = I + sign a~/2 + β a~², β = 1/θ² - (1 + cos θ)/(2θ sin θ)."""
    th2 = a0 * a0 + a1 * a1 + a2 * a2
    th = math.sqrt(th2)
    if th < 1e-3:
        beta = 1.0 / 12.0 + th2 / 720.0
    else:
        beta = 1.0 / th2 - (1.0 + math.cos(th)) / (2.0 * th * math.sin(th))
    h = 0.5 * sign
    # a~ = [[0, -a2, a1], [a2, 0, -a0], [-a1, a0, 0]]; a~² = a aᵀ - θ² I
    out[0, 0] = 1.0 + beta * (a0 * a0 - th2)
    out[1, 1] = 1.0 + beta * (a1 * a1 - th2)
    out[2, 2] = 1.0 + beta * (a2 * a2 - th2)
    out[0, 1] = -h * a2 + beta * a0 * a1
    out[1, 0] = h * a2 + beta * a0 * a1
    out[0, 2] = h * a1 + beta * a0 * a2
    out[2, 0] = -h * a1 + beta * a0 * a2
    out[1, 2] = -h * a0 + beta * a1 * a2
    out[2, 1] = h * a0 + beta * a1 * a2


@_jit
def _node_rates(z, s, j, props, now, hist_h, coef, out, eps, act, actuation, lengths):
    """The node's rates (p', u, n', m', q', ω') on piece j (arc length s) with the step's
    history terms ``hist_h`` (ε_h, q_h, ω_h) and loads ``now`` (the statics' channels per
    piece); ``eps`` gets the strain f = (v; u). With actuators (``act``; ``actuation`` =
    the constitutive law's arm and scratch), (n, m) is the total wrench of rod, tendons and
    fluid and the strain solves the actuated law with the damping folded into its
    stiffness (:func:`_law`: K(ε - f⁰) + B ε̇ = (K + c0 B) ε - K f⁰ + B ε_h); ``lengths``
    gets each tendon's |w| = dℓ/ds."""
    c0 = coef[0]
    pr = props[j]
    sig = np.empty(6)
    for k in range(6):
        sig[k] = z[_DN + k]
    actuated = act is not None and _actuated(act, j)
    if act is not None and actuated:
        law_arm, law = actuation[0], actuation[1]
        K, f0s = pr[_PK:_PK + 36], law_arm[3]
        Kd = law_arm[2]
        for i in range(6):  # f⁰' = (K + c0 B)⁻¹ (K f⁰ - B ε_h)
            acc = 0.0
            for k in range(6):
                acc += K[6 * i + k] * pr[_PF0 + k] - pr[_PB + 6 * i + k] * hist_h[k]
            eps[i] = acc
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += Kd[j, i, k] * eps[k]
            f0s[j, i] = acc
        e0, e1, e2, e3, e4, e5, _ = _law(law_arm, act, j, s, now, law, np.int64(0), sig[0],
                                         sig[1], sig[2], sig[3], sig[4], sig[5])
        eps[0], eps[1], eps[2], eps[3], eps[4], eps[5] = e0, e1, e2, e3, e4, e5
        for a in range(lengths.size):
            lengths[a] = law[1][a, 3] if act[2][j, a] != 0.0 and act[1][a] == TENDON else 0.0
    else:
        rhs = np.empty(6)
        for i in range(6):
            acc = sig[i]
            for k in range(6):
                acc += (pr[_PK + 6 * i + k] * pr[_PF0 + k]
                        - pr[_PB + 6 * i + k] * hist_h[k])
            rhs[i] = acc
        for i in range(6):
            acc = 0.0
            for k in range(6):
                acc += pr[_PKD + 6 * i + k] * rhs[k]
            eps[i] = acc
    v0, v1, v2 = eps[0], eps[1], eps[2]
    u0, u1, u2 = eps[3], eps[4], eps[5]
    vt0 = c0 * v0 + hist_h[0]
    vt1 = c0 * v1 + hist_h[1]
    vt2 = c0 * v2 + hist_h[2]
    ut0 = c0 * u0 + hist_h[3]
    ut1 = c0 * u1 + hist_h[4]
    ut2 = c0 * u2 + hist_h[5]
    q0, q1, q2 = z[_DQ], z[_DQ + 1], z[_DQ + 2]
    w0, w1, w2 = z[_DW], z[_DW + 1], z[_DW + 2]
    qt0 = c0 * q0 + hist_h[6]
    qt1 = c0 * q1 + hist_h[7]
    qt2 = c0 * q2 + hist_h[8]
    wt0 = c0 * w0 + hist_h[9]
    wt1 = c0 * w1 + hist_h[10]
    wt2 = c0 * w2 + hist_h[11]
    n0, n1, n2 = sig[0], sig[1], sig[2]
    m0, m1, m2 = sig[3], sig[4], sig[5]
    # p' = R v
    for i in range(3):
        out[i] = z[_DR + 3 * i] * v0 + z[_DR + 3 * i + 1] * v1 + z[_DR + 3 * i + 2] * v2
    out[3] = u0
    out[4] = u1
    out[5] = u2
    # the loads per length, material: Rᵀ f_d + f_f, Rᵀ l_d + l_f (+ a magnetisation's)
    fd = np.empty(6)
    for k in range(3):
        fd[k] = now[j, _FD + k]
        fd[3 + k] = now[j, _LD + k]
    ma0 = ma1 = ma2 = 0.0
    if act is not None:
        ma0, ma1, ma2 = act[3][j, 0], act[3][j, 1], act[3][j, 2]
    if act is not None and (ma0 != 0.0 or ma1 != 0.0 or ma2 != 0.0):
        law = actuation[1]
        _dipole(z, law[2], np.int64(0), ma0, ma1, ma2, now[j], now[j], law[2][3])
        for k in range(6):
            fd[k] += law[2][3, k]
    if act is not None and act[5].shape[0] > 0 and now[j, _CT] != 0.0:
        _moving_contact(z, act[5], act[6][j], now[j, _CT], fd)
    fl = np.empty(6)
    _mat_t_vec(z, _DR, fd[0], fd[1], fd[2], fl, 0)
    _mat_t_vec(z, _DR, fd[3], fd[4], fd[5], fl, 3)
    for k in range(3):
        fl[k] += now[j, _FF + k]
        fl[3 + k] += now[j, _LF + k]
    mu = pr[_PMU]
    # n' = -u × n + μ (ω × q + q_t) - f
    out[6] = -(u1 * n2 - u2 * n1) + mu * (w1 * q2 - w2 * q1 + qt0) - fl[0]
    out[7] = -(u2 * n0 - u0 * n2) + mu * (w2 * q0 - w0 * q2 + qt1) - fl[1]
    out[8] = -(u0 * n1 - u1 * n0) + mu * (w0 * q1 - w1 * q0 + qt2) - fl[2]
    # m' = -u × m - v × n + ρJ ω_t + ω × ρJ ω - l
    j0, j1, j2 = pr[_PRJ], pr[_PRJ + 1], pr[_PRJ + 2]
    h0, h1, h2 = j0 * w0, j1 * w1, j2 * w2
    out[9] = (-(u1 * m2 - u2 * m1) - (v1 * n2 - v2 * n1) + j0 * wt0 + (w1 * h2 - w2 * h1)
              - fl[3])
    out[10] = (-(u2 * m0 - u0 * m2) - (v2 * n0 - v0 * n2) + j1 * wt1 + (w2 * h0 - w0 * h2)
               - fl[4])
    out[11] = (-(u0 * m1 - u1 * m0) - (v0 * n1 - v1 * n0) + j2 * wt2 + (w0 * h1 - w1 * h0)
               - fl[5])
    # q' = v_t - u × q + ω × v
    out[12] = vt0 - (u1 * q2 - u2 * q1) + (w1 * v2 - w2 * v1)
    out[13] = vt1 - (u2 * q0 - u0 * q2) + (w2 * v0 - w0 * v2)
    out[14] = vt2 - (u0 * q1 - u1 * q0) + (w0 * v1 - w1 * v0)
    # ω' = u_t - u × ω
    out[15] = ut0 - (u1 * w2 - u2 * w1)
    out[16] = ut1 - (u2 * w0 - u0 * w2)
    out[17] = ut2 - (u0 * w1 - u1 * w0)


@_jit
def _moving_contact(z, obstacles, params, scale, out):
    """Add the contact's force and moment per unit length (spatial) on the moving node z to
    out[0:6]: the statics' normal force (:func:`_contact`) and Coulomb friction at the
    surface point p - r n, regularised, f_t = -μ φ w / √(|w|² + w_ε²) with w the surface
    point's sliding velocity (its velocity R q + (R ω) × (-r n), less the normal part) and
    w_ε = ``params[4]`` (m/s): sliding where |w| >> w_ε, sticking as a creep of speed
    about w_ε |f_t| / (μ φ) below the friction cone (contact.md). ``params`` = the piece's
    (r, δ, k, μ, w_ε); ``scale`` the penalty's (the channel CT)."""
    px, py, pz = z[_DP], z[_DP + 1], z[_DP + 2]
    r, mu, slip = params[0], params[3], params[4]
    # the section's velocity and spin, spatial
    vx = z[_DR] * z[_DQ] + z[_DR + 1] * z[_DQ + 1] + z[_DR + 2] * z[_DQ + 2]
    vy = z[_DR + 3] * z[_DQ] + z[_DR + 4] * z[_DQ + 1] + z[_DR + 5] * z[_DQ + 2]
    vz = z[_DR + 6] * z[_DQ] + z[_DR + 7] * z[_DQ + 1] + z[_DR + 8] * z[_DQ + 2]
    wx = z[_DR] * z[_DW] + z[_DR + 1] * z[_DW + 1] + z[_DR + 2] * z[_DW + 2]
    wy = z[_DR + 3] * z[_DW] + z[_DR + 4] * z[_DW + 1] + z[_DR + 5] * z[_DW + 2]
    wz = z[_DR + 6] * z[_DW] + z[_DR + 7] * z[_DW + 1] + z[_DR + 8] * z[_DW + 2]
    for k in range(obstacles.shape[0]):
        d, n0, n1, n2, _, _, _, _ = _nearest(px, py, pz, obstacles[k])
        phi, _ = _pressure(d - r, params[1], params[2])
        phi *= scale
        if phi == 0.0:
            continue
        out[0] += phi * n0
        out[1] += phi * n1
        out[2] += phi * n2
        if mu == 0.0:
            continue
        a0, a1, a2 = -r * n0, -r * n1, -r * n2  # the surface point from the centreline
        s0 = vx + wy * a2 - wz * a1
        s1 = vy + wz * a0 - wx * a2
        s2 = vz + wx * a1 - wy * a0
        normal = s0 * n0 + s1 * n1 + s2 * n2
        s0, s1, s2 = s0 - normal * n0, s1 - normal * n1, s2 - normal * n2
        # (its own name: ``scale``, the penalty's, holds for the next obstacles)
        slide = -mu * phi / math.sqrt(s0 * s0 + s1 * s1 + s2 * s2 + slip * slip)
        t0, t1, t2 = slide * s0, slide * s1, slide * s2
        out[0] += t0
        out[1] += t1
        out[2] += t2
        out[3] += a1 * t2 - a2 * t1
        out[4] += a2 * t0 - a0 * t2
        out[5] += a0 * t1 - a1 * t0


@_jit
def _point_wrench(z, now, tip_now, j, act, actuation, out):
    """out = the point wrench (material) on the node z at the start of piece j, or with
    j = -1 at the tip: the dead (spatial) and follower channels, and a segment's dipole
    there (at its distal end), in the field of the piece channels ``now``."""
    d = np.empty(6)
    for k in range(6):
        d[k] = tip_now[_TD + k] if j < 0 else now[j, _JD + k]
    if act is not None:
        row = act[4].shape[0] - 1 if j < 0 else j
        m0, m1, m2 = act[4][row, 0], act[4][row, 1], act[4][row, 2]
        if m0 != 0.0 or m1 != 0.0 or m2 != 0.0:
            law = actuation[1]
            field = now[now.shape[0] - 1] if j < 0 else now[j]
            _dipole(z, law[2], np.int64(0), m0, m1, m2, field, field, law[2][3])
            for k in range(6):
                d[k] += law[2][3, k]
    _mat_t_vec(z, _DR, d[0], d[1], d[2], out, 0)
    _mat_t_vec(z, _DR, d[3], d[4], d[5], out, 3)
    for k in range(6):
        out[k] += tip_now[_TF + k] if j < 0 else now[j, _JF + k]


@_jit
def _dyn_column(k, c):
    """The unknown's column of node k's component c (node 0: only n, m are unknown)."""
    if k == 0:
        return c - 6
    return 6 + DUNK * (k - 1) + c


@_jit
def _dyn_residual(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, r, rates, eps,
                  lengths):
    """The scaled residual r (18 (G - 1) + 6) of the step's discrete equations: the
    trapezoidal rule in s on every interval (a joint of zero length: continuity, n and m
    jumping by the point wrench at the next piece's start), then the tip's boundary
    condition. ``grid`` = (interval lengths, piece of each node, s of each node).
    ``rates`` (G, 18), ``eps`` (G, 6) and ``lengths`` (G, tendons) get each node's rates,
    strains and dℓ/ds. Returns the largest |r|."""
    h, node_piece, node_s = grid
    G = Z.shape[0]
    for k in range(G):
        _node_rates(Z[k], node_s[k], node_piece[k], props, now, hh[k], coef, rates[k], eps[k],
                    act, actuation, lengths[k])
    lg = np.empty(3)
    jw = np.empty(6)
    worst = 0.0
    for k in range(G - 1):
        za, zb = Z[k], Z[k + 1]
        o = DUNK * k
        hk = h[k]
        _log_relative(za, zb, lg)
        for i in range(3):
            r[o + i] = zb[_DP + i] - za[_DP + i] - 0.5 * hk * (rates[k, i] + rates[k + 1, i])
            r[o + 3 + i] = lg[i] - 0.5 * hk * (rates[k, 3 + i] + rates[k + 1, 3 + i])
        for i in range(12):
            r[o + 6 + i] = (zb[_DN + i] - za[_DN + i]
                            - 0.5 * hk * (rates[k, 6 + i] + rates[k + 1, 6 + i]))
        if hk == 0.0:  # a joint: n and m jump by the point wrench at the next piece's start
            _point_wrench(za, now, tip_now, node_piece[k + 1], act, actuation, jw)
            for i in range(6):
                r[o + 6 + i] += jw[i]
        for i in range(DUNK):
            r[o + i] /= S[i]
            worst = max(worst, abs(r[o + i]))
    zt = Z[G - 1]
    o = DUNK * (G - 1)
    _point_wrench(zt, now, tip_now, np.int64(-1), act, actuation, jw)
    for i in range(6):
        r[o + i] = (zt[_DN + i] - jw[i]) / S[6 + i]
        worst = max(worst, abs(r[o + i]))
    return worst


@_jit
def _dyn_put(Bm, kl, row, col, value):
    Bm[row, col - row + kl] += value


@_jit
def _magnetised(act):
    """Whether any piece of the arm carries a magnetisation (act[3])."""
    for j in range(act[3].shape[0]):
        for i in range(3):
            if act[3][j, i] != 0.0:
                return True
    return False


@_jit
def _dyn_jacobian(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, rates, Gk, Bm,
                  kl):
    """The scaled Jacobian of :func:`_dyn_residual` in band storage (``rates`` as the
    residual left them). Each node's ∂(rates)/∂(unknowns) by forward differences; the
    rotation of the point wrenches at the joints and the tip is exact for the dead channels
    (a dipole's own turning is left out: the iteration is a chord iteration anyway)."""
    h, node_piece, node_s = grid
    G = Z.shape[0]
    Bm[:, :] = 0.0
    zp = np.empty(DYN)
    g1 = np.empty(DUNK)
    e1 = np.empty(6)
    l1 = np.empty(max(1, 0 if act is None else act[0].shape[0]))
    Ja = np.empty((3, 3))
    Jb = np.empty((3, 3))
    lg = np.empty(3)
    # the rates depend on the position p only through loads that depend on where the
    # section is: contact (the penalty's stiffness ∂f/∂p, the largest term of a touching
    # node's Jacobian: without it Newton crept and failed on touchdown, friction or a
    # start at rest on an obstacle) and a magnetisation in a field with a gradient
    placed = act is not None and (act[5].shape[0] > 0 or _magnetised(act))
    first = 0 if placed else 3
    for k in range(G):
        for c in range(first, DUNK):
            for i in range(DYN):
                zp[i] = Z[k, i]
            d = 1e-7 * S[c]
            if c < 3:
                zp[_DP + c] += d
            elif c < 6:
                a0 = d if c == 3 else 0.0
                a1 = d if c == 4 else 0.0
                a2 = d if c == 5 else 0.0
                _rotated(zp, a0, a1, a2, zp)
            else:
                zp[_DN + c - 6] += d
            _node_rates(zp, node_s[k], node_piece[k], props, now, hh[k], coef, g1, e1, act,
                        actuation, l1)
            for i in range(DUNK):
                Gk[k, i, c] = (g1[i] - rates[k, i]) / d
        for i in range(DUNK):
            for c in range(first):
                Gk[k, i, c] = 0.0
    jw = np.empty(6)
    for k in range(G - 1):
        za, zb = Z[k], Z[k + 1]
        row0 = DUNK * k
        hk = h[k]
        _log_relative(za, zb, lg)
        _inverse_jacobian(lg[0], lg[1], lg[2], -1.0, Ja)
        _inverse_jacobian(lg[0], lg[1], lg[2], 1.0, Jb)
        for side in range(2):
            node = k + side
            sgn = 1.0 if side == 1 else -1.0
            for c in range(DUNK):
                if node == 0 and (c < 6 or c >= 12):
                    continue
                col = _dyn_column(node, c)
                for i in range(DUNK):
                    v = -0.5 * hk * Gk[node, i, c]
                    if 3 <= i < 6 and 3 <= c < 6:
                        v += (Jb[i - 3, c - 3] if side == 1 else -Ja[i - 3, c - 3])
                    elif i == c and not (3 <= i < 6):
                        v += sgn
                    if v != 0.0:
                        _dyn_put(Bm, kl, row0 + i, col, v * S[c] / S[i])
        if hk == 0.0 and k > 0:  # the point wrench turns with the frame at the joint
            _point_wrench(za, now, tip_now, node_piece[k + 1], act, actuation, jw)
            for blk in range(2):  # (only the dead part turns: Rᵀ F_d)
                j1 = node_piece[k + 1]
                f0 = now[j1, _JF + 3 * blk]
                f1 = now[j1, _JF + 3 * blk + 1]
                f2 = now[j1, _JF + 3 * blk + 2]
                _dyn_skew_put(Bm, kl, row0 + 6 + 3 * blk, _dyn_column(k, 3),
                              jw[3 * blk] - f0, jw[3 * blk + 1] - f1, jw[3 * blk + 2] - f2,
                              1.0, S[6 + 3 * blk], S[3])
    zt = Z[G - 1]
    row0 = DUNK * (G - 1)
    _point_wrench(zt, now, tip_now, np.int64(-1), act, actuation, jw)
    for i in range(6):
        _dyn_put(Bm, kl, row0 + i, _dyn_column(G - 1, 6 + i), 1.0)
    if G - 1 > 0:
        for blk in range(2):
            _dyn_skew_put(Bm, kl, row0 + 3 * blk, _dyn_column(G - 1, 3),
                          jw[3 * blk] - tip_now[_TF + 3 * blk],
                          jw[3 * blk + 1] - tip_now[_TF + 3 * blk + 1],
                          jw[3 * blk + 2] - tip_now[_TF + 3 * blk + 2],
                          -1.0, S[6 + 3 * blk], S[3])


@_jit
def _dyn_skew_put(Bm, kl, row, col, w0, w1, w2, sign, srow, scol):
    """Bm[row:row+3, col:col+3] += sign · w~ (scaled)."""
    f = sign * scol / srow
    _dyn_put(Bm, kl, row, col + 1, -w2 * f)
    _dyn_put(Bm, kl, row, col + 2, w1 * f)
    _dyn_put(Bm, kl, row + 1, col, w2 * f)
    _dyn_put(Bm, kl, row + 1, col + 2, -w0 * f)
    _dyn_put(Bm, kl, row + 2, col, -w1 * f)
    _dyn_put(Bm, kl, row + 2, col + 1, w0 * f)


@_jit
def _dyn_apply(Z, dx, S):
    """Z -= the scaled correction dx (rotations R ← R exp(-δθ~))."""
    G = Z.shape[0]
    for k in range(G):
        for c in range(DUNK):
            if k == 0 and (c < 6 or c >= 12):
                continue
            if 3 <= c < 6:
                continue
            v = dx[_dyn_column(k, c)] * S[c]
            if c < 3:
                Z[k, _DP + c] -= v
            else:
                Z[k, _DN + c - 6] -= v
        if k > 0:
            o = _dyn_column(k, 3)
            _rotated(Z[k], -dx[o] * S[3], -dx[o + 1] * S[3], -dx[o + 2] * S[3], Z[k])


@_jit
def _set_base(Zw, row):
    """The base node of a step's guess: its pose and velocities from the base's row (18:
    p, R row-major, q, ω material)."""
    for i in range(3):
        Zw[0, _DP + i] = row[i]
        Zw[0, _DQ + i] = row[12 + i]
        Zw[0, _DW + i] = row[15 + i]
    for i in range(9):
        Zw[0, _DR + i] = row[3 + i]


@_jit
def _sum_squares(r):
    total = 0.0
    for i in range(r.size):
        total += r[i] * r[i]
    return total


# Friction's band on a step that does not solve (issue 39): Coulomb's law regularised with
# the speed w_ε (``slip_velocity``) has the slope μ φ / w_ε in the sliding velocity, steep at
# a touchdown (φ large, w from 0 to the arrival speed within a step), and Newton fails there
# from every guess (the docs' table drop, μ = 0.5, at the default 1e-4 m/s). The step is
# then solved along a continuation in w_ε: from the last state with the band widened 10×,
# 100×, ... (at most 10^_WIDENINGS) until it solves, then narrowed back towards the band
# given, each solve from the answer before, by a factor that is halved (in its logarithm)
# after a narrowing that fails and doubled again (up to 10) after one that solves. The
# step's answer is the law's own at the band given; it fails as before after _NARROWINGS
# failed narrowings.
_WIDENINGS = 4
_NARROWINGS = 12


@_jit
def _friction(params) -> bool:
    """Whether any piece has friction (μ > 0; ``params`` = act[6])."""
    for j in range(params.shape[0]):
        if params[j, 3] > 0.0:
            return True
    return False


@_jit
def _with_band(params, given, exponent):
    """act[6]'s w_ε column = the given bands × 10^exponent."""
    for j in range(params.shape[0]):
        params[j, 4] = given[j] if exponent == 0.0 else given[j] * 10.0 ** exponent


@_jit
def _dyn_widened(Zw, last, pose, grid, props, coef, S, now, tip_now, hh, act, actuation,
                 tol, max_iter, fac, kl, work):
    """A step with friction solved along a continuation in the friction's band (above):
    _dyn_newton's (code, residual, iterations, factorisations), the iterations summed.
    ``last`` the state before the step, ``pose`` the base's row. Writes act[6]'s w_ε column
    and restores it (``act`` is a thread's own where friction acts: _simulator)."""
    params = act[6]
    given = params[:, 4].copy()
    code, res, its, nf = DYN_NEWTON, np.inf, 0, 0
    exponent = 0.0  # the band is given × 10^exponent
    while code != DYN_OK and exponent < _WIDENINGS:
        exponent += 1.0
        _with_band(params, given, exponent)
        _copy(last, Zw)
        _set_base(Zw, pose)
        fac[3][0] = 0
        code, res, more, nf2 = _dyn_newton(Zw, grid, props, coef, S, now, tip_now, hh, act,
                                           actuation, tol, max_iter, fac, kl, work)
        its += more
        nf += nf2
    if code == DYN_OK:
        good = Zw.copy()  # the answer at the narrowest band solved so far
        step, failures = 1.0, 0
        while exponent > 0.0:
            trial = max(exponent - step, 0.0)
            _with_band(params, given, trial)
            fac[3][0] = 0
            code, res, more, nf2 = _dyn_newton(Zw, grid, props, coef, S, now, tip_now, hh,
                                               act, actuation, tol, max_iter, fac, kl, work)
            its += more
            nf += nf2
            if code == DYN_OK:
                _copy(Zw, good)
                exponent = trial
                step = min(2.0 * step, 1.0)
                continue
            failures += 1
            if failures > _NARROWINGS:
                break  # (code: the failure)
            _copy(good, Zw)
            step *= 0.5
    _with_band(params, given, 0.0)
    return code, res, its, nf


@_jit
def _dyn_newton(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, tol, max_iter,
                factors, kl, work):
    """Chord-Newton on one step's equations from the guess Z (the factors (Bm, Lm, piv,
    valid) are reused while ``valid[0]`` and the iteration contracts, refreshed
    otherwise). Returns (status, scaled residual, iterations, factorisations)."""
    Bm, Lm, piv, valid = factors
    r, dx, rates, eps, lengths, Gk = work
    n = r.size
    last = math.inf
    factored = 0
    # with contact, a Newton step on a fresh Jacobian that does not lower the residual is
    # halved until it does (a contact that opens or closes within the step changes the
    # equations' slope by the penalty's k: the full step overshoots deep into the obstacle)
    damped = act is not None and act[5].shape[0] > 0
    before_step = np.empty((Z.shape[0], Z.shape[1]) if damped else (1, 1))
    merit_before = 0.0
    worst = _dyn_residual(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, r, rates,
                          eps, lengths)
    for it in range(max_iter):
        if not math.isfinite(worst):
            return DYN_NOT_FINITE, worst, it, factored
        fresh = valid[0] == 0
        if valid[0] == 0:
            _dyn_jacobian(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, rates, Gk,
                          Bm, kl)
            if _band_factor(Bm, n, kl, piv, Lm) == 0.0:
                return DYN_NEWTON, worst, it, factored
            valid[0] = 1
            factored += 1
        for i in range(n):
            dx[i] = r[i]
        if not _band_solve(Bm, n, kl, piv, Lm, dx):
            valid[0] = 0
            continue
        step = 0.0
        for i in range(n):
            step = max(step, abs(dx[i]))
        if damped:
            _copy(Z, before_step)
            merit_before = _sum_squares(r)
        _dyn_apply(Z, dx, S)
        before = worst
        worst = _dyn_residual(Z, grid, props, coef, S, now, tip_now, hh, act, actuation, r,
                              rates, eps, lengths)
        halvings = 0
        if damped and fresh:  # (merit: the residual's 2-norm; the max norm can stall)
            merit = _sum_squares(r)
            while not (merit < merit_before) and halvings < _DYN_HALVINGS:
                halvings += 1
                _copy(before_step, Z)
                for i in range(n):
                    dx[i] *= 0.5
                step *= 0.5
                _dyn_apply(Z, dx, S)
                worst = _dyn_residual(Z, grid, props, coef, S, now, tip_now, hh, act,
                                      actuation, r, rates, eps, lengths)
                merit = _sum_squares(r)
        # converged when the residual is below tol and so is the error left, estimated
        # from the contraction ρ of the last two corrections: ρ/(1 - ρ) × this one
        rho = step / last if last < math.inf else 1.0
        if worst <= tol and (step <= tol or (rho < 0.5 and rho / (1.0 - rho) * step <= tol)):
            return DYN_OK, worst, it + 1, factored
        if not (worst < 0.25 * before) or step > last:
            valid[0] = 0  # slow or growing: a fresh Jacobian at the current iterate
        last = step
    return DYN_NEWTON, worst, max_iter, factored


@_jit
def _dyn_history_terms(H, coef, hh):
    """x_h = c1 x(t-Δt) + c2 x(t-2Δt) + d1 ẋ(t-Δt) for x = (ε, q, ω) at every node."""
    c1, c2, d1 = coef[1], coef[2], coef[3]
    for k in range(H.shape[0]):
        for i in range(12):
            hh[k, i] = c1 * H[k, i] + c2 * H[k, 12 + i] + d1 * H[k, 24 + i]


@_jit
def _dyn_energies(Z, h, node_piece, props, eps, hh, coef, gravity, out):
    """out = kinetic, elastic, gravity energy (J) and dissipation power (W) of the state,
    by the trapezoidal rule on the grid."""
    c0 = coef[0]
    kin = 0.0
    ela = 0.0
    grav = 0.0
    power = 0.0
    G = Z.shape[0]
    for k in range(G):
        wl = 0.0
        if k > 0:
            wl += 0.5 * h[k - 1]
        if k < G - 1:
            wl += 0.5 * h[k]
        if wl == 0.0:
            continue
        pr = props[node_piece[k]]
        z = Z[k]
        mu = pr[_PMU]
        e = kin
        for i in range(3):
            e += 0.5 * wl * (mu * z[_DQ + i] ** 2 + pr[_PRJ + i] * z[_DW + i] ** 2)
            grav -= wl * mu * gravity[i] * z[_DP + i]
        kin = e
        et = np.empty(6)
        for i in range(6):
            et[i] = c0 * eps[k, i] + hh[k, i]
        for i in range(6):
            for j in range(6):
                de_i = eps[k, i] - pr[_PF0 + i]
                de_j = eps[k, j] - pr[_PF0 + j]
                ela += 0.5 * wl * de_i * pr[_PK + 6 * i + j] * de_j
                power += wl * et[i] * pr[_PB + 6 * i + j] * et[j]
    out[0] = kin
    out[1] = ela
    out[2] = grav
    out[3] = power


@_jit
def _dyn_predict(Z, Z1, Z2):
    """Z ← the quadratic extrapolation of the states at t - 2Δt (Z2), t - Δt (Z1) and t
    (Z): 3 Z - 3 Z1 + Z2, the rotations R exp(2 a - b) with a = log(R1ᵀ R), b =
    log(R2ᵀ R1) (the last two increments)."""
    a = np.empty(3)
    b = np.empty(3)
    for k in range(Z.shape[0]):
        _log_relative(Z1[k], Z[k], a)
        _log_relative(Z2[k], Z1[k], b)
        for i in range(DYN):
            if not (_DR <= i < _DR + 9):
                Z[k, i] = 3.0 * Z[k, i] - 3.0 * Z1[k, i] + Z2[k, i]
        _rotated(Z[k], 2.0 * a[0] - b[0], 2.0 * a[1] - b[1], 2.0 * a[2] - b[2], Z[k])


def _dynamics(args):
    """dynamic_steps' capability: passive, or with actuators or magnets (``act``)."""
    actuated = _given(args[26])
    return ("dynamics" + "+actuated" * actuated,
            "the dynamics (implicit time steps)"
            + " for actuated, magnetic or touching arms" * actuated)


@_entry(_dynamics, nogil=True)
def dynamic_steps(Z, Zold, H, aux, props, loads, tip, grid, coef, S, options, base, gravity,
                  stations, first, last, factors, positions, rotations, velocities, spins,
                  strains, stresses, energy, info, status, act, actuation, inputs, tendons):
    """Advance the cases [first, last) by base.shape[1] implicit time steps each.

    Z (B, G, DYN), Zold (B, 2, G, DYN): the state now and one and two steps before (for
    the predictor); H (B, G,
    DHIST) the BDF-α history; aux (B, 2): the dissipated energy so far (J) and the last
    dissipation power (W). props (P, DPROPS) the pieces' properties; loads (B, P, W) and
    tip (B, TIP_LOADS) the statics' load channels (at zero inputs when ``inputs`` is
    given); grid = (interval lengths (G - 1; 0 at a joint between pieces), piece of each
    node, s of each node); coef (DCOEF,), S (18,) scales, options = (tol, max_iter). base
    (B or 1, T, 18): the base's p, R (row-major), q, ω (material) at each new step;
    gravity (B, 3) (for the energy); stations (S,) the recorded nodes; factors = (Bm, Lm,
    piv, valid): per case (B) or one shared (1; reused only by the first case of the call).
    Outputs per case and step: positions,
    rotations (9), velocities, spins (spatial), strains, stresses (material), energy
    (kinetic, elastic, gravity, dissipated), info (residual, iterations, factorisations,
    predictor - corrector distance / L); status (B,) is the number of steps done (= T on
    success): a failed step leaves Z, Zold, H and aux at the last solved step, and info's
    row at the failed step holds (residual, -1, ...); a case whose status is < 0 on entry
    is skipped (it failed before).

    Optional (None: compiled without): ``act`` the actuators and magnets (the statics'
    ``act``), with ``actuation`` = (the constitutive law's arm (the statics' arm with
    K + c0 B, its inverse and a scratch f⁰), the law's scratch); ``inputs``
    = (q (B or 1, T, n): the inputs at each step, unit piece channels (n, P, W), unit tip
    channels (n, TIP_LOADS)): the loads at step t are loads + Σᵢ qᵢ unitᵢ; ``tendons`` (B,
    T, A) the tendons' lengths (m) at each step.
    """
    tol = options[0]
    max_iter = int(options[1])
    length_scale = S[0]
    h, node_piece = grid[0], grid[1]
    G = Z.shape[1]
    T = base.shape[1]
    kl = np.int64(_DKL)
    n = DUNK * (G - 1) + 6
    A = 1 if act is None else max(1, act[0].shape[0])
    work = (np.empty(n), np.empty(n), np.empty((G, DUNK)), np.empty((G, 6)),
            np.zeros((G, A)), np.empty((G, DUNK, DUNK)))
    eps, lengths = work[3], work[4]
    hh = np.empty((G, 12))
    Zw = np.empty((G, DYN))
    Zp = np.empty((G, DYN))
    en = np.empty(4)
    c0 = coef[0]
    now = np.empty((loads.shape[1], loads.shape[2]))
    tip_now = np.empty(tip.shape[1])
    Bm_all, Lm_all, piv_all, valid_all = factors
    for b in range(first, last):
        if status[b] < 0:
            continue  # a case that failed in an earlier call: left where it stopped
        f = b if Bm_all.shape[0] > 1 else 0
        if Bm_all.shape[0] == 1 and b > first:
            valid_all[0] = 0  # (one shared factor storage: another case's factors)
        fac = (Bm_all[f], Lm_all[f], piv_all[f], valid_all[f:f + 1])
        bb = b if base.shape[0] > 1 else 0
        status[b] = 0
        for i in range(now.shape[0]):
            for c in range(now.shape[1]):
                now[i, c] = loads[b, i, c]
        for c in range(tip_now.size):
            tip_now[c] = tip[b, c]
        for t in range(T):
            if inputs is not None:  # the loads at this step's inputs
                q, unit, unit_tip = inputs
                qb = b if q.shape[0] > 1 else 0
                for i in range(now.shape[0]):
                    for c in range(now.shape[1]):
                        acc = loads[b, i, c]
                        for e in range(q.shape[2]):
                            acc += q[qb, t, e] * unit[e, i, c]
                        now[i, c] = acc
                for c in range(tip_now.size):
                    acc = tip[b, c]
                    for e in range(q.shape[2]):
                        acc += q[qb, t, e] * unit_tip[e, c]
                    tip_now[c] = acc
            _dyn_history_terms(H[b], coef, hh)
            # guess: the extrapolated state, the base's pose and velocity set
            for k in range(G):
                for i in range(DYN):
                    Zw[k, i] = Z[b, k, i]
            _dyn_predict(Zw, Zold[b, 0], Zold[b, 1])
            for k in range(G):
                for i in range(3):
                    Zp[k, i] = Zw[k, _DP + i]  # (the predicted centreline)
            _set_base(Zw, base[bb, t])
            code, res, its, nf = _dyn_newton(Zw, grid, props, coef, S, now, tip_now, hh, act,
                                             actuation, tol, max_iter, fac, kl, work)
            if code != DYN_OK and act is not None and act[5].shape[0] > 0:
                # contact: a contact that closes within the step can put the extrapolated
                # guess deep in an obstacle, outside Newton's reach; again from the last
                # state, with fresh factors
                for k in range(G):
                    for i in range(DYN):
                        Zw[k, i] = Z[b, k, i]
                _set_base(Zw, base[bb, t])
                fac[3][0] = 0
                code, res, again, nf2 = _dyn_newton(Zw, grid, props, coef, S, now, tip_now, hh,
                                                    act, actuation, tol, max_iter, fac, kl,
                                                    work)
                its += again
                nf += nf2
                if code != DYN_OK and _friction(act[6]):
                    code, res, again, nf2 = _dyn_widened(Zw, Z[b], base[bb, t], grid, props,
                                                         coef, S, now, tip_now, hh, act,
                                                         actuation, tol, max_iter, fac, kl,
                                                         work)
                    its += again
                    nf += nf2
            info[b, t, 0] = res
            info[b, t, 2] = nf
            for k in range(G):  # the model's limit: a section turned inside out (v₁ <= 0)
                if code == DYN_OK and not eps[k, 0] > 0.0:
                    code = DYN_INADMISSIBLE
            if code != DYN_OK:
                info[b, t, 1] = -1.0
                fac[3][0] = 0
                break
            moved = 0.0
            for k in range(G):
                for i in range(3):
                    moved = max(moved, abs(Zw[k, _DP + i] - Zp[k, i]))
            info[b, t, 1] = its
            info[b, t, 3] = moved / length_scale
            if its >= _DYN_REFRESH:
                fac[3][0] = 0  # the factors have aged: new ones for the next step
            # accept: shift the history, x_t = c0 x + x_h
            for k in range(G):
                for i in range(DYN):
                    Zold[b, 1, k, i] = Zold[b, 0, k, i]
                    Zold[b, 0, k, i] = Z[b, k, i]
                    Z[b, k, i] = Zw[k, i]
                for i in range(12):
                    x = eps[k, i] if i < 6 else Zw[k, _DQ + i - 6]
                    H[b, k, 12 + i] = H[b, k, i]
                    H[b, k, i] = x
                    H[b, k, 24 + i] = c0 * x + hh[k, i]
            _dyn_energies(Zw, h, node_piece, props, eps, hh, coef, gravity[b], en)
            aux[b, 0] += 0.5 * (aux[b, 1] + en[3]) * coef[4]
            aux[b, 1] = en[3]
            energy[b, t, 0] = en[0]
            energy[b, t, 1] = en[1]
            energy[b, t, 2] = en[2]
            energy[b, t, 3] = aux[b, 0]
            if tendons is not None:  # ℓ = ∫ |w| ds, the trapezoidal rule
                for a in range(tendons.shape[2]):
                    acc = 0.0
                    for k in range(G - 1):
                        acc += 0.5 * h[k] * (lengths[k, a] + lengths[k + 1, a])
                    tendons[b, t, a] = acc
            for si in range(stations.size):
                k = stations[si]
                z = Zw[k]
                pr = props[node_piece[k]]
                for i in range(3):
                    positions[b, t, si, i] = z[_DP + i]
                    velocities[b, t, si, i] = (z[_DR + 3 * i] * z[_DQ] + z[_DR + 3 * i + 1]
                                               * z[_DQ + 1] + z[_DR + 3 * i + 2] * z[_DQ + 2])
                    spins[b, t, si, i] = (z[_DR + 3 * i] * z[_DW] + z[_DR + 3 * i + 1]
                                          * z[_DW + 1] + z[_DR + 3 * i + 2] * z[_DW + 2])
                for i in range(9):
                    rotations[b, t, si, i] = z[_DR + i]
                for i in range(6):
                    strains[b, t, si, i] = eps[k, i] - pr[_PF0 + i]
                    stresses[b, t, si, i] = z[_DN + i]
            status[b] = t + 1
