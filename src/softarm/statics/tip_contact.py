"""Hard contact at the free tip: exact, with no contact distance δ (issue 39).

Where a solve's Contact holds planes only and asks for no penalty of its own (neither
``distance`` nor ``stiffness`` given), the arm touching them with its free tip alone is
solved as a unilateral constraint, not through the penalty's stiff band:

    g(p(L)) = n̂ · (p(L) - a) - r >= 0,   λ >= 0,   λ g = 0,

g the gap between the tip's surface (the tube of radius r around the centreline, as for the
penalty) and the plane through a with outward normal n̂, λ the reaction the plane puts on
the tip, a force λ n̂ at the tip (frictionless; no moment about the centreline). With λ
given, the arm is a plain solve with one more dead tip force, so λ is found by Newton's
method on the one equation g = 0 with the solve's exact tip compliance C,
dg/dλ = n̂ᵀ C n̂, kept inside a bracket of the root. Every iterate is a solve of the smooth,
non-stiff problem: the answer does not depend on a δ, its gap is zero to 1 % of tol·L, and
its cost does not grow with how hard the tip is pressed (the penalty's stiffness made the
same case 100× slower).

The route answers a case only where it is the answer (the caller solves the others with the
penalty, case by case, so that a batch's answers are its cases' alone):

- the free arm (no contact) meets the obstacles, at 1/4, 1/2, 3/4 and all of the load, at
  its tip alone: on each plane the stations inside form a run ending at the tip, and on one
  plane only (an arm that lies on a table or dips into it mid-span needs contact zones);
- the solution with the tip held keeps every station of the solver's fine ones (the asked
  stations and CONTACT_STATIONS uniform ones, as the penalty's check) outside every plane to
  tol·L, and λ >= 0;
- where the solver gives verdicts, the free arm with the dead force λ n̂ is stable
  (conservative, Morse index 0);
- with ``jacobians``, no tendon (their length Jacobian would need the tendons' response to
  the tip's reaction, which the solve does not return).

Stability. The held arm's second variation is the free arm's with the dead force λ n̂,
restricted to the variations with n̂ · δp(L) >= 0 (= 0 where λ > 0); a plane has no
curvature, so the constraint adds no term of its own. A restriction removes directions
only: where the free arm with the dead force is stable, so is the held arm, and its verdict
is "stable". Where it is not, the held arm may still be stable (holding the tip of a column
raises its buckling load from π²/4 to 20.19 EI/L²), but the dead force's own loading path
from the unloaded arm then crosses a critical point and need not lead to the held
equilibrium: those cases are left to the penalty, whose path carries the contact from the
start (docs/contact.md).

Jacobians. An extra dead tip wrench W moves the tip by C_W W and the reaction by δλ n̂;
holding n̂ · δp(L) = 0 gives δλ = -n̂ᵀ C_W W / n̂ᵀ C n̂, and every station's compliance
becomes compliance - compliance[:, :3] n̂ (n̂ᵀ C_W) / (n̂ᵀ C n̂); the actuation Jacobians
likewise with the inputs' columns.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..loads import TipLoad

__all__ = ["METHOD", "solve_tip_contact"]

#: The gap (a fraction of tol·L) to which λ is solved.
GAP = 1e-2
#: Newton iterations on λ before the route gives the case to the penalty.
ITERATIONS = 60
#: The load factors at which the free arm's path is checked, besides the full load.
PATH = (0.25, 0.5, 0.75)
#: Uniform stations of the path's check and of the Newton iterations.
COARSE = 201
#: The route's name in ``Equilibrium.method``.
METHOD = "numeric.tip_contact"


def _planes(contact) -> np.ndarray | None:
    """(K, 2, 3): each plane's point and outward unit normal, or None where the route does
    not apply to this Contact (an obstacle other than a plane, or a penalty asked for)."""
    if contact.stiffness is not None or contact.distance is not None:
        return None
    if any(obstacle.kind != "plane" for obstacle in contact.obstacles):
        return None
    return np.array([(obstacle.point, obstacle.normal) for obstacle in contact.obstacles])


def _gaps(planes, positions, radii) -> np.ndarray:
    """(K, ..., S): the gap to each plane at centreline positions (..., S, 3) with surface
    radii (S,) (m)."""
    return np.stack([(positions - point) @ normal - radii for point, normal in planes])


def _at_tip_only(gaps, depth: float) -> np.ndarray:
    """(...) bool, from gaps (K, ..., S): whether the stations deeper than ``depth`` inside
    a plane are on one plane at most and form a run that ends at the last station."""
    inside = gaps < -depth
    runs = np.all(np.diff(inside.astype(np.int8), axis=-1) >= 0, axis=(0, -1))
    return runs & (inside.any(axis=-1).sum(axis=0) <= 1)


def _dot(a, b):
    return np.einsum("...j,...j->...", a, b)


def solve_tip_contact(solver, loads, shape, jacobians: bool, fine, asked):
    """(the Equilibrium of ``loads`` (checked, batch ``shape``, one Contact) with the arm's
    free tip held outside the Contact's planes (module docstring) at ``solver``'s
    stations, the cases it holds (``shape`` bool)), or None where the route applies to no
    case; the caller solves the others with the penalty. ``fine``, ``asked``: the solver's
    stations in contact and the index of each asked one among them
    (:func:`softarm.statics.solver._contact_stations`). A ConvergenceError of any case's
    solve (the free arm's path, a held iterate) is raised: the caller then tries the
    cases one by one."""
    contact = next(load for load in loads if load.kind == "contact")
    planes = _planes(contact)
    if planes is None or (jacobians and any(load.kind == "tendon" for load in loads)):
        return None
    free = tuple(load for load in loads if load.kind != "contact")
    depth = solver.tol * solver.length
    coarse = solver._with_stations(np.linspace(0.0, solver.length, COARSE), stability=False)
    radii = contact.station_radii(solver.arm, coarse.s)
    held = np.ones(shape, dtype=bool)  # the cases this route answers
    for factor in PATH:  # the free arm on its way to the full load
        eq = coarse._solve(tuple(load.scaled(factor) for load in free), chained=False,
                           jacobians=False, checked=True)
        held &= _at_tip_only(_gaps(planes, eq.positions, radii), depth)
    eq = coarse._solve(free, chained=False, jacobians=True, checked=True)
    gaps = _gaps(planes, eq.positions, radii)
    held &= _at_tip_only(gaps, depth)
    if not held.any():
        return None
    # Newton's method on λ, per case (0 where the free tip is outside every plane)
    touching = held & (gaps[..., -1].min(axis=0) < -depth)
    under = planes[np.argmin(gaps[..., -1], axis=0)]  # (*shape, 2, 3): the tip's plane
    point, normal = under[..., 0, :], under[..., 1, :]
    level = _dot(point, normal) + radii[-1]  # the gap is p(L) · n̂ - level
    lam, low, high = np.zeros(shape), np.zeros(shape), np.full(shape, np.inf)
    for _ in range(ITERATIONS):
        gap = _dot(eq.tip_position, normal) - level
        slope = _dot(normal, np.einsum("...ij,...j->...i", eq.tip_compliance[..., :3, :3],
                                       normal))
        # a case stops where it converged (its λ does not depend on its batch's), or where
        # the held tip's Newton step has no direction
        touching &= np.abs(gap) > GAP * depth
        held &= ~(touching & (slope <= 0.0))
        touching &= held
        if not touching.any():
            break
        # g(λ) rises with λ (slope > 0): a bracket [low, high] of the root, and Newton's
        # step inside it, else its middle (large deflections: the tip's height saturates at
        # ±L and plain Newton overshoots without end)
        low, high = np.where(gap < 0.0, lam, low), np.where(gap > 0.0, lam, high)
        step = lam - gap / np.where(touching, slope, 1.0)
        inside = (step > low) & (step < high)
        lam = np.where(touching, np.where(inside, step, 0.5 * (low + high)), lam)
        eq = coarse._solve((*free, TipLoad(force=lam[..., None] * normal)), chained=False,
                           jacobians=True, checked=False)
    held &= ~touching & (lam >= 0.0)
    lam = np.where(held, lam, 0.0)
    if not held.any():
        return None
    final = solver._with_stations(fine, stability=solver.stability)._solve(
        (*free, TipLoad(force=lam[..., None] * normal)), chained=False, jacobians=jacobians,
        checked=False)
    gaps = _gaps(planes, final.positions, contact.station_radii(solver.arm, fine))
    held &= np.all(gaps >= -depth, axis=(0, -1))  # (else contact zones: the penalty's)
    if solver.stability:  # (final's verdict: the free arm's with the dead force λ n̂)
        held &= np.asarray(final.stability.stable)
    if not held.any():
        return None
    changes = {}
    if jacobians:
        changes.update(_held_jacobians(final, asked, normal, lam > 0.0))
    force = lam[..., None] * normal
    wrench = np.concatenate([force, np.cross(final.tip_position, force)], axis=-1)
    return dataclasses.replace(
        final, s=solver.s, poses=final.poses[..., asked, :, :],
        strains=final.strains[..., asked, :], stresses=final.stresses[..., asked, :],
        loads=loads, method=METHOD, contact_resultant=wrench, **changes), held


def _held_jacobians(final, asked, normal, pressed) -> dict:
    """The Jacobians of ``final`` (the free arm with the tip's reaction as a dead force)
    with the pressed tips held on their planes (module docstring), at the asked stations."""
    tip, stations = final.tip_compliance, final.compliance[..., asked, :, :]
    # each station's motion per unit tip force along n̂ (spatial), and the tip's
    along = np.einsum("...ij,...j->...i", stations[..., :3], normal[..., None, :])
    tip_along = np.einsum("...ij,...j->...i", tip[..., :3], normal)
    slope = _dot(normal, tip_along[..., :3])
    # the reaction's change per unit column (wrench, then inputs): -n̂ᵀ C_col / n̂ᵀ C n̂
    scale = np.where(pressed, 1.0 / np.where(pressed, slope, 1.0), 0.0)[..., None]

    def held(columns, station_columns):
        reaction = -scale * np.einsum("...j,...jk->...k", normal, columns[..., :3, :])
        return (columns + tip_along[..., :, None] * reaction[..., None, :],
                station_columns + along[..., :, None] * reaction[..., None, None, :])

    out = dict(zip(("tip_compliance", "compliance"), held(tip, stations), strict=True))
    if final.actuation_jacobian is not None:
        out.update(zip(("actuation_jacobian", "station_actuation_jacobian"),
                       held(final.actuation_jacobian,
                            final.station_actuation_jacobian[..., asked, :, :]), strict=True))
    return out
