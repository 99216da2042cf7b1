"""The layouts shared by the kernels and by Python (statics/solver.py builds the arrays): the
statuses returned per case, the state and tangent rows, the load channels per piece and at
the tip, the solver's options and the memory of a chained solve."""

from __future__ import annotations

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
