"""Hard contact at the free tip: exact, with no contact distance δ (issue 39).

Where a solve's Contact asks for no penalty of its own (neither ``distance`` nor
``stiffness`` given), an arm touching its obstacles with its free tip alone is solved as a
unilateral constraint, not through the penalty's stiff band:

    g = d(p(L)) - r >= 0,   λ >= 0,   λ g = 0,

g the gap between the tip's surface (the tube of radius r around the centreline, as for the
penalty) and the obstacle, d its signed distance, λ the reaction it puts on the tip: a
force λ n̂ at the tip along its outward normal n̂ = ∇d (frictionless; no moment about the
centreline). With λ and n̂ given, the arm is a plain solve with one more dead tip force, so
λ is found by Newton's method on the one equation g = 0 with the solve's exact tip
compliance C, dg/dλ = n̂ᵀ C n̂, kept inside a bracket of the root (at large deflections the
tip's height saturates and plain Newton overshoots without end); then n̂ is taken at the
new tip and λ corrected again, until n̂ stays (a plane's at once). On a ball or a capsule
the reaction is followed along the load path from the first touch (n̂ at a free tip deep
inside a pin points anywhere). Every iterate is a solve of the smooth, non-stiff problem:
the answer does not depend on a δ, its gap is zero to 1 % of tol·L, and its cost does not
grow with how hard the tip is pressed (the penalty's stiffness made the same cases 25-100×
slower).

The route answers a case only where it is the answer (the caller solves the others with the
penalty, case by case, so that a batch's answers are its cases' alone):

- the free arm (no contact) meets the obstacles, at 1/4, 1/2, 3/4 and all of the load
  (k/16 with a ball or a capsule, and between two of those states the straight way of
  every station that comes closer to it than half its move, on 33 points), at its tip
  alone: the stations inside form a run ending at the tip, in one obstacle (an arm
  that lies on a table or wraps a pin needs contact zones);
- the solution with the tip held keeps every station of the solver's fine ones (the asked
  stations and CONTACT_STATIONS uniform ones, as the penalty's check) outside every
  obstacle to tol·L, and λ >= 0;
- where the solver gives verdicts, the free arm with the dead force λ n̂ is stable
  (conservative, Morse index 0);
- where the reaction pushes the tip back towards the base with more than DOUBT of the free
  arm's buckling load, the answer agrees with the contact's own path from the first touch
  (tip_friction.py with μ = 0), else that path's answer is returned (the dead force's path
  from the unloaded arm may pass the buckling load onto another branch);
- with ``jacobians``, no tendon (their length Jacobian would need the tendons' response to
  the tip's reaction, which the solve does not return).

Stability. The held arm's second variation is the free arm's with the dead force λ n̂ (its
Hessian H, index 0 by the rule above), plus the reaction's own stiffness -λ ∇²d at the tip
(the force λ n̂(p) turns with the contact point: zero on a plane, -λ (I - n̂ n̂ᵀ)/ρ on a
ball whose centre is ρ from the tip), restricted to the variations with n̂ · δp(L) = 0.
With B the map from a variation to δp(L), C = B H⁻¹ Bᵀ, and S = K n̂ n̂ᵀ - λ ∇²d (K → ∞ for
the constraint) on its range, the inertia of [[H, Bᵀ], [B, -S⁻¹]] counted both ways gives
the held index: index(H + Bᵀ S B) = 0 + pos(S⁻¹ + C) - pos(S⁻¹) (pos: positive
eigenvalues). On a plane it is 0: holding a point removes directions. On a ball it is the
number of tangent directions in which λ/ρ exceeds the tip's lateral stiffness: a tip
pushed onto a small ball slides off (tests/test_tip_contact.py checks the closed form).
Where the free arm with the dead force is not stable the held arm may still be (holding
the tip of a column raises its buckling load from π²/4 to 20.19 EI/L²), but the dead
force's own loading path from the unloaded arm then crosses a critical point and need not
lead to the held equilibrium: those cases are left to the penalty, whose path carries the
contact from the start (docs/contact.md).

Jacobians. A column W (a tip wrench, an actuation input) moves the free tip by C_W W and
the reaction by δf = δλ n̂ + λ ∇²d δp(L); holding n̂ · δp(L) = 0 gives the 4 × 4 system of
:func:`_held_jacobians`, and every station's column gains its response to δf.
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np

from ..equilibrium import Stability
from ..errors import ConvergenceError
from ..loads import TipLoad
from .tip_friction import follow_on, held_columns, held_index, stuck_jacobians, with_friction

__all__ = ["METHOD", "solve_tip_contact"]

#: The gap (a fraction of tol·L) to which λ is solved.
GAP = 1e-2
#: Newton iterations on λ before the route gives the case to the penalty.
ITERATIONS = 60
#: The load factors at which the free arm's path is checked, besides the full load.
PATH = (0.25, 0.5, 0.75)
#: Uniform stations of the path's check and of the Newton iterations.
COARSE = 201
#: The load factors k/CURVED_PATH at which a path near a ball or a capsule is checked.
CURVED_PATH = 16
#: Points along a station's way between two of those factors where it passes close to one.
CHORD = 32
#: Turns of the reaction's direction n̂ (a curved obstacle's normal at the new tip) at most,
#: and the change of n̂ below which it has stopped turning.
TURNS = 20
TURNED = 1e-12
#: The step of the curvature's differences, as a fraction of the obstacle's radius.
CURVATURE_STEP = 1e-5
#: The part of the free arm's buckling load beyond which a reaction pushing the tip back
#: towards the base has its answer checked against the contact's path (solve_tip_contact).
DOUBT = 0.25
#: The route's name in ``Equilibrium.method``.
METHOD = "numeric.tip_contact"


def _gaps(obstacles, positions, radii) -> np.ndarray:
    """(K, ..., S): the gap to each obstacle at centreline positions (..., S, 3) with
    surface radii (S,) (m)."""
    return np.stack([obstacle.distance(positions)[0] - radii for obstacle in obstacles])


def _at_tip_only(gaps, depth: float, which) -> np.ndarray:
    """(...) bool, from gaps (K, ..., S): whether the stations deeper than ``depth`` inside
    an obstacle are all in the obstacle ``which`` (...) and form a run that ends at the
    last station."""
    inside = gaps < -depth
    runs = np.all(np.diff(inside.astype(np.int8), axis=-1) >= 0, axis=(0, -1))
    others = np.arange(len(gaps)).reshape((-1,) + (1,) * np.ndim(which)) != which
    return runs & ~np.any(inside.any(axis=-1) & others, axis=0)


def _dot(a, b):
    return np.einsum("...j,...j->...", a, b)


def _matvec(A, x):
    return np.einsum("...ij,...j->...i", A, x)


def _path(coarse, free, obstacles, radii, full, depth) -> tuple:
    """(the load factors of the free arm's path's check, its positions (..., S, 3) there,
    and the cases (bool) whose stations cannot have passed through a ball or a capsule
    unseen between two of them): PATH with planes only, else CURVED_PATH uniform factors,
    the same for every batch. ``full``: the positions at the full load. A station outside
    a curved obstacle at two factors, with gaps g₁, g₂, that moved by Δ between them stays
    outside on the straight way if min(g₁, g₂) >= Δ/2 (a distance changes by no more than
    the point moves); where it does not, CHORD + 1 points of the way are looked at, and a
    case where a station is inside at one of them is not held (what could still pass
    unseen is a clip of a ball of radius ρ (its own plus the arm's) between two of those
    points, at most (Δ/CHORD)²/(8ρ) deep: 0.2 µm for Δ = 13 mm and ρ = 0.11 m). The outside
    of a plane is convex: a straight way between two points outside stays outside."""
    curved = [obstacle for obstacle in obstacles if obstacle.kind != "plane"]
    factors = PATH if not curved else tuple(np.arange(1, CURVED_PATH) / CURVED_PATH)
    positions = [coarse._solve(tuple(load.scaled(factor) for load in free), chained=False,
                               jacobians=False, checked=True).positions
                 for factor in ((0.0,) if curved else ()) + tuple(factors)]
    if not curved:
        return factors, positions, True
    way = np.stack([*positions, full])  # (F + 1, ..., S, 3), from the unloaded arm
    moves = np.linalg.norm(np.diff(way, axis=0), axis=-1)
    gaps = _gaps(curved, way, radii)  # (K, F + 1, ..., S)
    outside = (gaps[:, :-1] >= -depth) & (gaps[:, 1:] >= -depth)
    unseen = outside & (np.minimum(gaps[:, :-1], gaps[:, 1:]) < 0.5 * moves)
    if unseen.any():  # those ways looked at closer: CHORD points, each Δ/CHORD apart
        which, *where = np.nonzero(unseen)
        start, end = way[:-1][tuple(where)], way[1:][tuple(where)]  # (n, 3)
        t = np.linspace(0.0, 1.0, CHORD + 1)[:, None]
        points = start[:, None] + t * (end - start)[:, None]  # (n, CHORD + 1, 3)
        closest = np.stack([o.distance(points)[0] for o in curved])[
            which, np.arange(which.size)].min(axis=-1) - radii[where[-1]]
        unseen[(which, *where)] = closest < -depth
    return factors, positions[1:], ~np.any(unseen, axis=(0, 1, -1))


def _curvature(obstacle, p, h) -> np.ndarray:
    """(..., 3, 3): ∇²d of the obstacle's signed distance at points p (..., 3), from
    central differences of its normal with step h (m): zero for a plane, (I - n̂ n̂ᵀ)/ρ on
    a ball (ρ the distance from its centre)."""
    columns = [(obstacle.distance(p + h * e)[1] - obstacle.distance(p - h * e)[1]) / (2 * h)
               for e in np.eye(3)]
    hessian = np.stack(columns, axis=-1)
    return 0.5 * (hessian + np.swapaxes(hessian, -1, -2))


def solve_tip_contact(solver, loads, shape, jacobians: bool, fine, asked, last=None):
    """(the Equilibrium of ``loads`` (checked, batch ``shape``, one Contact that asks for no
    penalty: neither ``distance`` nor ``stiffness`` given, Solver._held_at_tip) with the arm's
    free tip held outside the Contact's obstacles (module docstring) at ``solver``'s
    stations, the cases it holds (``shape`` bool)), or None where the route applies to no
    case; the caller solves the others with the penalty. ``fine``, ``asked``: the solver's
    stations in contact and the index of each asked one among them
    (:func:`softarm.statics.solver._contact_stations`). A ConvergenceError of any case's
    solve (the free arm's path, a held iterate) is raised: the caller then tries the
    cases one by one. ``last``: a chained Solver's last answer held with friction
    (Solver._friction), from which a single case with the same Contact goes on."""
    contact = next(load for load in loads if load.kind == "contact")
    obstacles = contact.obstacles
    if jacobians and not contact.friction and any(load.kind == "tendon" for load in loads):
        return None  # (their length Jacobians would need their response to the reaction)
    free = tuple(load for load in loads if load.kind != "contact")
    depth = solver.tol * solver.length
    coarse = solver._with_stations(np.linspace(0.0, solver.length, COARSE), stability=False)
    if contact.friction > 0.0 and last is not None and last[0] == _key(contact):
        return _with_friction(solver, coarse, loads, free, contact, last[1], shape, depth,
                              jacobians, fine, asked, last=last)
    radii = contact.station_radii(solver.arm, coarse.s)
    # the free arm at the full load (an arm that lies on an obstacle is left at once), then
    # on its way there
    eq = coarse._solve(free, chained=False, jacobians=True, checked=True)
    gaps = _gaps(obstacles, eq.positions, radii)
    which = np.argmin(gaps[..., -1], axis=0)  # (*shape): the obstacle under the tip
    held = np.array(_at_tip_only(gaps, depth, which))  # the cases this route answers
    if not held.any():
        return None
    curved = any(obstacle.kind != "plane" for obstacle in obstacles)
    touches = gaps[..., -1].min(axis=0) < -depth
    factors, path, seen = _path(coarse, free, obstacles, radii, eq.positions, depth)
    held &= seen
    for positions in path:
        on_the_way = _gaps(obstacles, positions, radii)
        held &= _at_tip_only(on_the_way, depth, which)
        if not curved:  # (a plane met on the way and left again: no held answer follows it)
            held &= touches | np.all(on_the_way >= -depth, axis=(0, -1))
    if not held.any():
        return None
    single = math.prod(shape) == 1
    if contact.friction > 0.0 or single:
        case = (0,) * len(shape)
        bracket = [(t, obstacles[which[case]].distance(positions[case][-1])[0] - radii[-1])
                   for t, positions in zip([*factors, 1.0], [*path, eq.positions],
                                           strict=True)]
    if contact.friction > 0.0:  # (a single case: Solver._held_at_tip)
        return _with_friction(solver, coarse, loads, free, contact, int(which[case]), shape,
                              depth, jacobians, fine, asked, bracket=bracket)
    eligible = held.copy()
    try:
        answer = _frictionless(solver, coarse, loads, free, contact, which, held, depth,
                               factors, curved, eq, jacobians, fine, asked)
    except ConvergenceError:
        if not single:
            raise
        answer = None
    held = answer[1] if answer is not None else np.zeros(shape, dtype=bool)
    doubtful = eligible & ~held
    if answer is not None:  # (the reaction's compression against the free arm's buckling)
        tangent = answer[0].poses[..., -1, :3, 0]
        pushed = -np.einsum("...j,...j->...", answer[0].contact_wrench[..., :3], tangent)
        lateral = np.linalg.eigvalsh(eq.tip_compliance[..., :3, :3])[..., -1]
        doubtful |= held & (pushed > DOUBT * np.pi ** 2 / 12.0 * solver.length / lateral)
    if not doubtful.any():
        return answer
    # The dead reaction's solves start from the unloaded arm: where the reaction pushes the
    # arm back towards its base with a good part of the free arm's buckling load (π²/4
    # EI/L² for a uniform one, estimated from its lateral tip compliance c as π²L/12c),
    # that path may pass it and end on another branch than the contact's path from the
    # first touch (a tip on a plane tilted 50° under 2 N, E 20 MPa: 0.77 L away, the
    # right one having an unstable direction), or fail. Such a case is held along the
    # contact's path (tip_friction.py with μ = 0), one case at a time: the answer where
    # the two agree to tol·L, else the path's
    if not single:
        raise ConvergenceError("a reaction near the free arm's buckling: case by case", 0.0)
    path_answer = _with_friction(solver, coarse, loads, free, contact, int(which[case]),
                                 shape, depth, jacobians, fine, asked, bracket=bracket,
                                 mu=0.0)
    if path_answer is None:
        return None if not held.any() else answer
    if held.any() and np.abs(path_answer[0].positions - answer[0].positions).max() <= depth:
        return answer
    return path_answer


def _frictionless(solver, coarse, loads, free, contact, which, held, depth, factors, curved,
                  eq, jacobians, fine, asked):
    """solve_tip_contact's answer without friction: Newton's method on λ over solves of the
    free arm with the dead reaction (module docstring)."""
    obstacles, shape = contact.obstacles, held.shape
    radii = contact.station_radii(solver.arm, coarse.s)
    lam, normal, held = _normal_reaction(coarse, free, obstacles, radii, which, held, depth,
                                         factors, curved, eq)
    held &= lam >= 0.0
    lam = np.where(held, lam, 0.0)
    if not held.any():
        return None
    final = solver._with_stations(fine, stability=solver.stability)._solve(
        (*free, TipLoad(force=lam[..., None] * normal)), chained=False,
        jacobians=jacobians or (curved and solver.stability), checked=False)
    gaps = _gaps(obstacles, final.positions, contact.station_radii(solver.arm, fine))
    held &= np.all(gaps >= -depth, axis=(0, -1))  # (else contact zones: the penalty's)
    pressed = held & (lam > 0.0)
    # the constraint's curvature: the reaction λ n̂(p) turns with the tip (∇²d, zero on a
    # plane), a stiffness -λ ∇²d at the tip
    tip = final.tip_position
    bent = np.zeros((*shape, 3, 3))
    for k, obstacle in enumerate(obstacles):
        if obstacle.kind != "plane":
            mine = pressed & (which == k)
            bent[mine] = -lam[mine][..., None, None] * _curvature(
                obstacle, tip[mine], CURVATURE_STEP * obstacle.radius)
    changes = {}
    if solver.stability:  # (final's verdict: the free arm's with the dead force λ n̂)
        held &= np.asarray(final.stability.stable)
        index = _held_index(final.tip_compliance, normal, bent) if curved else 0
        changes["stability"] = Stability.of(np.where(pressed, index, 0), True, shape)
    if not held.any():
        return None
    if jacobians:
        changes.update(_held_jacobians(final, asked, normal, bent, pressed))
    else:  # (the compliance was the verdict's)
        changes.update(dict.fromkeys(("tip_compliance", "compliance", "actuation_jacobian",
                                      "station_actuation_jacobian",
                                      "tendon_length_jacobian")))
    force = lam[..., None] * normal
    return _answer(final, solver, asked, loads, tip, force, changes), held


def _answer(final, solver, asked, loads, point, force, changes):
    """The held arm's Equilibrium from ``final`` (the arm with the reaction as a dead load
    on the solver's fine stations) at the asked stations, the reaction ``force`` acting at
    ``point`` (spatial, N and m) its contact wrench."""
    wrench = np.concatenate([force, np.cross(point, force)], axis=-1)
    return dataclasses.replace(
        final, s=solver.s, poses=final.poses[..., asked, :, :],
        strains=final.strains[..., asked, :], stresses=final.stresses[..., asked, :],
        loads=loads, method=METHOD, contact_resultant=wrench, **changes)


def _key(contact) -> str:
    """What a chained solve with friction needs unchanged: the obstacles, μ, the radius."""
    return repr(([o.to_case() for o in contact.obstacles], contact.friction, contact.radius))


def _with_friction(solver, coarse, loads, free, contact, which, shape, depth, jacobians,
                   fine, asked, *, bracket=None, last=None, mu=None):
    """solve_tip_contact's answer with Coulomb friction (tip_friction.py) for a single
    case (batch shape () or (1,): a batch is held case by case, Solver._held_at_tip), its
    tip on the obstacle ``which``: along the loads' path from the unloaded arm (the free
    arm's tip's gaps ``bracket`` on it), or from a chained Solver's ``last`` answer. Sets
    ``solver._friction_found``: the answer a chained solve goes on from. ``mu``: the
    contact's μ by default; 0 for a frictionless tip held along its path (past the free
    arm's buckling load: solve_tip_contact), a case left to the penalty where it fails."""
    mu = contact.friction if mu is None else mu
    case = (0,) * len(shape)
    obstacle = contact.obstacles[which]
    radius = contact.station_radii(solver.arm, np.array([solver.length]))[-1]
    one = tuple(load.part(shape, case) for load in free)
    fine_solver = solver._with_stations(fine, stability=solver.stability)
    try:
        if last is None:
            found = with_friction(coarse, fine_solver, one, obstacle, mu, radius, depth,
                                  GAP * depth, bracket, jacobians)
        else:
            found = follow_on(coarse, fine_solver, last[2:], one, obstacle, mu, radius,
                              depth, GAP * depth, jacobians)
    except ConvergenceError as error:
        if not mu:
            return None
        warnings.warn(f"Contact.friction: the tip's path with friction did not solve "
                      f"({error}); solved frictionless, with the penalty", stacklevel=5)
        return None
    if found is None:  # (the free tip never touches: the free arm, the penalty's answer)
        return None
    final = found.final
    gaps = _gaps(contact.obstacles, final.positions, contact.station_radii(solver.arm, fine))
    if np.any(gaps < -depth):  # (the held arm lies on an obstacle: contact zones)
        return None
    tip = final.poses[-1, :3, 3]
    changes = dict.fromkeys(("tip_compliance", "compliance", "actuation_jacobian",
                             "station_actuation_jacobian", "tendon_length_jacobian"))
    if not mu:  # (the normal held: the reaction's turn with the tip, -λ ∇²d, as above)
        normal = obstacle.distance(tip)[1]
        bent = np.zeros((3, 3)) if obstacle.kind == "plane" else -float(
            found.force @ normal) * _curvature(obstacle, tip, CURVATURE_STEP * obstacle.radius)
    if jacobians and mu:
        changes.update(_frictional_jacobians(final, asked, found, obstacle, loads))
    elif jacobians:  # (as _held_jacobians for a batch of one)
        columns = _held_jacobians(_batched(final, (1,)), asked, normal[None], bent[None],
                                  np.array([True]))
        changes.update({name: value[0] for name, value in columns.items()})
    if solver.stability and not mu:  # (the free arm's index less what holding the normal
        # takes away: module docstring, "Stability")
        index = int(final.stability.index) + int(_held_index(
            final.tip_compliance[None], normal[None], bent[None])[0])
        changes["stability"] = Stability.of(index, final.stability.conservative, ())
    elif solver.stability:  # (friction is not conservative: the index with the friction
        # force taken as dead; the verdict undecided where the obstacle pushes)
        index = held_index(final.stability.index, final.tip_compliance, found.arm)
        pushes = np.any(found.force != 0.0)
        changes["stability"] = Stability.of(index, bool(final.stability.conservative)
                                            and not pushes, ())
    answer = _answer(final, solver, asked, loads if not shape else
                     tuple(load.part(shape, case) for load in loads), tip + found.arm,
                     found.force, changes)
    if mu:
        solver._friction_found = (_key(contact), which, one, found)
    return (_batched(answer, shape) if shape else answer), np.ones(shape, dtype=bool)


def _frictional_jacobians(final, asked, found, obstacle, loads) -> dict:
    """A tip held with friction: its Jacobians while it sticks on a plane (the cap's point
    held: tip_friction.stuck_jacobians); a ValueError where they are not built."""
    why = ("the tip slides (a sliding contact's response is one-sided)" if found.sliding
           else "the obstacle is curved (the contact point's turn is not built)"
           if obstacle.kind != "plane" else "a tendon's length Jacobian would need its "
           "response to the tip's force" if any(load.kind == "tendon" for load in loads)
           else None)
    if why is not None:
        raise ValueError(f"solve(..., jacobians=True) with Contact.friction > 0 holds a "
                         f"stuck tip on a plane only: here {why} (docs/contact.md, "
                         f"\"Friction\"); give jacobians=False or friction=0")
    return stuck_jacobians(final, asked, found.arm)


def _batched(eq, shape):
    """The unbatched Equilibrium ``eq`` as a batch of ``shape`` (one case)."""
    changes = {}
    for field in dataclasses.fields(eq):
        value = getattr(eq, field.name)
        if field.name in ("s", "loads", "method", "exact"):
            continue
        if isinstance(value, Stability):
            changes[field.name] = Stability.of(np.reshape(value.index, shape),
                                               np.reshape(value.conservative, shape), shape)
        elif isinstance(value, np.ndarray):
            changes[field.name] = value.reshape(*shape, *value.shape)
        elif isinstance(value, (float, np.floating)):
            changes[field.name] = np.full(shape, value)
    return dataclasses.replace(eq, **changes)


def _normal_reaction(coarse, free, obstacles, radii, which, held, depth, factors, curved,
                     eq):
    """(λ, n̂, the cases held) of the frictionless reaction λ n̂ at the tip (module
    docstring): ``eq`` the free arm at the full load at ``coarse``'s stations, ``factors``
    the path's check's load factors below 1."""
    shape = held.shape
    held = held.copy()
    # Newton's method on λ, per case (0 where the free tip is outside every obstacle), the
    # reaction's direction n̂ frozen; then n̂ at the new tip, until it stays (a plane's at
    # once). On a curved obstacle the reaction is followed along the path's factors from
    # where the tip first touches: n̂ at a free tip deep inside a pin points anywhere

    def nearest(tip):  # (gap (*shape), n̂ (*shape, 3)) to each case's obstacle
        found = [obstacle.distance(tip) for obstacle in obstacles]
        d = np.choose(which, [f[0] for f in found])
        n = np.stack([f[1] for f in found])[(which, *np.indices(shape))]
        return d - radii[-1], n

    def solve(loads, lam, normal, low):
        """(the held iterate, its λ, the least λ that failed (inf if none)): λ is moved
        towards ``low`` where the plain solve fails."""
        failed = np.full(shape, np.inf)
        for _ in range(ITERATIONS):
            try:
                return coarse._solve((*loads, TipLoad(force=lam[..., None] * normal)),
                                     chained=False, jacobians=True, checked=False), lam, failed
            except ConvergenceError:
                # a reaction the plain solve cannot follow from the unloaded arm (one far
                # too large: it turns the arm over): back towards the bracket's low end. A
                # batch is tried case by case (Solver._held_at_tip).
                if shape:
                    raise
                failed, lam = lam, 0.5 * (low + lam)
        raise ConvergenceError("no held iterate could be solved", float("nan"))

    lam, normal = np.zeros(shape), nearest(eq.tip_position)[1]
    for factor in (*([f for f in factors if f < 1.0] if curved else ()), 1.0):
        loads_at = free if factor == 1.0 else tuple(load.scaled(factor) for load in free)
        if factor < 1.0 or curved:
            eq, lam, _ = solve(loads_at, lam, normal, np.zeros(shape))
        gap, turned = nearest(eq.tip_position)
        touching = held & ((lam > 0.0) | (gap < -depth))
        normal = np.where((touching & (lam == 0.0))[..., None], turned, normal)
        for _ in range(TURNS):
            low, high = np.zeros(shape), np.full(shape, np.inf)
            active = touching.copy()
            for _ in range(ITERATIONS):
                slope = _dot(normal, _matvec(eq.tip_compliance[..., :3, :3], normal))
                # a case stops where it converged (its λ does not depend on its batch's),
                # or where the held tip's Newton step has no direction
                active &= np.abs(gap) > GAP * depth
                held &= ~(active & (slope <= 0.0))
                active &= held
                if not active.any():
                    break
                # g(λ) rises with λ (slope > 0): a bracket [low, high] of the root, and
                # Newton's step inside it, else its middle (large deflections: the tip's
                # height saturates at ±L and plain Newton overshoots without end)
                low, high = np.where(gap < 0.0, lam, low), np.where(gap > 0.0, lam, high)
                step = lam - gap / np.where(active, slope, 1.0)
                inside = (step > low) & (step < high)
                lam = np.where(active, np.where(inside, step, 0.5 * (low + high)), lam)
                eq, lam, failed = solve(loads_at, lam, normal, low)
                high = np.minimum(high, failed)
                gap = nearest(eq.tip_position)[0]
            held &= ~active  # (not converged)
            gap, turned = nearest(eq.tip_position)
            moved = touching & held & (np.linalg.norm(turned - normal, axis=-1) > TURNED)
            if not moved.any():
                break
            normal = np.where(moved[..., None], turned, normal)
            eq, lam, _ = solve(loads_at, lam, normal, np.zeros(shape))
            gap = nearest(eq.tip_position)[0]
        else:
            held &= ~moved
    return lam, normal, held


def _held_index(compliance, normal, bent) -> np.ndarray:
    """The Morse index of the held arm where the free arm with the dead reaction is stable
    (module docstring, "Stability"): the positive eigenvalues of S_r⁻¹ + C_r less those of
    S_r⁻¹, S = K n̂ n̂ᵀ + ``bent`` (K → ∞) on its range, C the tip's position compliance."""
    C = compliance[..., :3, :3]
    index = np.zeros(normal.shape[:-1], dtype=np.int64)
    for case in np.ndindex(index.shape):
        n, B = normal[case], bent[case]
        values, vectors = np.linalg.eigh(B)
        keep = np.abs(values) > 1e-9 * max(1.0, np.abs(values).max())
        keep &= np.abs(vectors.T @ n) < 0.5  # (n̂ is in ∇²d's null space)
        U = np.column_stack([n, vectors[:, keep]])
        scale = np.abs(C[case]).max()
        inverse = np.diag([1e-12 * scale, *(1.0 / values[keep])])
        bordered = inverse + U.T @ C[case] @ U
        positive = np.sum(np.linalg.eigvalsh(0.5 * (bordered + bordered.T)) > 0.0)
        index[case] = positive - 1 - np.sum(values[keep] > 0.0)
    return index


def _held_jacobians(final, asked, normal, bent, pressed) -> dict:
    """The Jacobians of ``final`` (the free arm with the tip's reaction as a dead force)
    with the pressed tips held on their obstacles (module docstring), at the asked
    stations. ``bent`` is the reaction's stiffness -λ ∇²d at the tip: a column W (a tip
    wrench, an input) moves the free tip by C_W W and the reaction by
    δf = δλ n̂ - bent·δp, so (I + C bent) δp - C n̂ δλ = C_W W with n̂ · δp = 0."""
    tip, stations = final.tip_compliance, final.compliance[..., asked, :, :]
    C = tip[..., :3, :3]
    shape = normal.shape[:-1]
    system = np.zeros((*shape, 4, 4))
    system[..., :3, :3] = np.eye(3) + C @ bent
    system[..., :3, 3] = -_matvec(C, normal)
    system[..., 3, :3] = normal
    system[~pressed] = np.eye(4)  # (a free case: no reaction)

    def held(columns, station_columns):
        right = np.zeros((*shape, 4, columns.shape[-1]))
        right[..., :3, :] = np.where(pressed[..., None, None], columns[..., :3, :], 0.0)
        solved = np.linalg.solve(system, right)  # (δp; δλ) per column
        reaction = normal[..., :, None] * solved[..., 3:, :] - bent @ solved[..., :3, :]
        return (columns + tip[..., :, :3] @ reaction,
                station_columns + stations[..., :, :3] @ reaction[..., None, :, :])

    return held_columns(final, asked, held)
