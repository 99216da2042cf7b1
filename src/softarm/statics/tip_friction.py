"""Coulomb friction at a free tip held on an obstacle: the quasi-static path (issue 39).

The frictionless route (tip_contact.py) holds the tip with a normal reaction alone. With
Coulomb's μ > 0 (``Contact.friction``) the obstacle's force at the tip may lean:

    f = f_n n̂ + f_t,   f_n >= 0,   |f_t| <= μ f_n,

acting at the contact point q = p(L) - r n̂ of the tip's cap (the ball of the section's
radius r about p(L) whose gap d(p(L)) - r the contact measures), so that it carries the
moment (q - p(L)) × f about the centreline. Sticking, the cap rolls on the obstacle
without sliding; sliding, f_t = -μ f_n ŝ, ŝ the direction in which the cap's material
point in contact slides.

Friction makes the answer depend on the way to it. softarm's is the one reached along the
proportional load path from the unloaded arm (as a frictionless solve answers the
equilibrium connected to the unloaded arm), in steps of the load factor t:

- the free arm is followed to its first touch t₀, the root of its tip's gap on the path
  (regula falsi, Illinois' variant, inside the bracket of the path's check);
- each step from t₀ to 1 first tries the stuck tip, then, where that force leaves the
  cone, the tip sliding over the step (backward Euler, ŝ the way the material point in
  contact has moved over the step: the return map of plasticity), and where f_n < 0 the
  free arm, until the gap closes again;
- each of these is Newton's method on the arm's base reaction x and the force f together:
  a shooting from x (``Solver.shooter``, on the grid of the solve at the first touch)
  must meet the tip's loads with f at q added, and the tip must lie on the obstacle with
  its slide (stuck: none; sliding: the law), the derivatives in x exact (the shooting's),
  those of the closed forms in the tip's pose by central differences. The held arm is the
  unknown, not the free arm under a dead f: a held tip carries a force far beyond the free
  arm's buckling load (a column held at its tip: 20.19 EI/L² against π²/4 EI/L²), where
  the free arm's own path from the unloaded arm would snap elsewhere;
- the answer at the full load is solved again on the solver's stations to its tolerance
  (``Solver.solve_near`` from x with f as a dead load), and the full load's Newton is run
  again on that solve's grid until the tip's gap stays within the gap's tolerance.

The slide over a step is that of the cap's material point in contact: the centre moves by
Δp, the cap turns by θ = log(R R₀ᵀ) about it, the contact point is at -r m̂ (m̂ the normal
halfway between the step's ends), so it slides by Δw = P (Δp - r θ × m̂), P the projection
on the tangent plane: rolling in the bending plane on a plane is exact, the rest second
order in the step.

The whole path is done with 2, 4, 8, ... steps until two answers agree to tol·L. A path
that sticks (rolling in the bending plane), or slides one way, ends where the continuous
path does at any step count (its end state depends only on where it touched, or on the
slide's direction), so it is done at the first comparison; a slide whose direction turns
(a load across the bending plane) converges at backward Euler's first order.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ..errors import ConvergenceError
from ..loads import TipLoad

__all__ = ["FRICTION_STEPS", "FrictionalTip", "follow_on", "held_columns", "held_index",
           "stuck_jacobians", "with_friction"]

#: The path's steps after the first touch: doubled from the first until two answers agree.
FRICTION_STEPS = (2, 4, 8, 16, 32, 64, 128)
#: Newton iterations of one state (stuck, sliding, free), and of the first touch's root.
ITERATIONS = 30
#: Halvings of a Newton step whose residual grows, at most (then the load step is halved).
HALVINGS = 6
#: Halvings of a load step that does not solve, at most.
SPLITS = 6
#: Central differences of the contact's residual in the tip's pose: the step, as a
#: fraction of the slide over the step (at least the gap's tolerance).
DIFFERENCE = 1e-4
#: Paths at most: on the first touch's grid, then on the grid of the answer's solve.
GRIDS = 3
#: Solves on the solver's stations at the full load, at most (each followed by the full
#: load's Newton on its grid where the tip's gap is off).
REFINEMENTS = 4


class FrictionalTip(NamedTuple):
    """:func:`with_friction`'s answer for its one case."""

    force: np.ndarray  # (3,): the obstacle's force on the tip, spatial, N
    arm: np.ndarray  # (3,): where it acts, from the tip's centre, spatial, m
    sliding: bool  # whether the tip slid over the path's last step
    final: object  # the Equilibrium on the solver's stations (unbatched)
    state: object  # the path's _State there (on the answer's grid): a chain goes on from it


@dataclass(frozen=True)
class _State:
    """The arm on the path at one load factor: its base reaction x (N, N m, spatial) on the
    grid of ``steps`` (Solver.last_solution's N), the tip's pose (centre p, rotation R,
    spatial), the obstacle's normal n̂ there, the force f on the tip (spatial, N; zero
    while free), whether it touches and whether it slid over the last step, and the rate of
    (x, f) in the load factor over the last step (the next step's predictor)."""

    x: np.ndarray
    steps: int
    p: np.ndarray
    R: np.ndarray
    normal: np.ndarray
    force: np.ndarray
    touching: bool
    sliding: bool = False
    rate: np.ndarray | None = None
    #: The last step: its length in the load factor, and the cap's slide Δw over it
    #: (spatial, m; None unless it slid): the next slide's second-order direction.
    size: float | None = None
    slid: np.ndarray | None = None


def with_friction(coarse, fine, free, obstacle, mu, radius, depth, gap_tol, bracket,
                  jacobians) -> FrictionalTip | None:
    """The one case ``free`` (its loads, unbatched, less the Contact) along its proportional
    path with its tip on ``obstacle`` with Coulomb's ``mu`` (module docstring): the path at
    ``coarse``'s stations, the answer at ``fine``'s (a Solver with the verdict if asked),
    or None where the free tip never reaches the obstacle. ``radius``: the tip's surface
    radius (m); ``depth``: tol·L (m), to which the path's answers must agree; ``gap_tol``:
    the gap and the slide solved to (m); ``bracket``: the load factors where the free arm's
    tip was checked and its gaps there, (t, gap) pairs in increasing t. ConvergenceError
    where a step or the answer does not solve or the steps do not converge."""
    start = _first_touch(coarse, free, obstacle, radius, gap_tol, bracket)
    if start is None:
        return None
    # the path's grid: the finer of the free arm's at the full load and at the first touch
    # (the held arm bends less than the free one; _finished checks it)
    grids = []
    for factor in (1.0, start):
        coarse.reset()
        coarse._solve(tuple(load.scaled(factor) for load in free), chained=True,
                      jacobians=False, checked=False, outputs=False)
        last = coarse.last_solution()
        if last is None:  # (multiple shooting's chain: no single shooting from x)
            raise ConvergenceError("the path with friction needs single shooting, and this "
                                   "arm is solved by multiple shooting", float("nan"))
        grids.append(last[1])
    shooter = coarse.shooter(free)
    shots = _Shots(lambda x, t, steps: shooter(x, load_factor=t, steps=steps), obstacle,
                   radius, mu, gap_tol, jacobians)
    x, steps = last
    if grids[0] > steps:
        x, steps = shots.solve(_Grid(grids[0]), start, None, "free", x, None).x, grids[0]
    return _on_grids(shots, fine, free, shots.state(x, steps, start, np.zeros(3), True),
                     start, depth)


def follow_on(coarse, fine, last, free, obstacle, mu, radius, depth, gap_tol,
              jacobians) -> FrictionalTip:
    """The one case ``free`` (unbatched loads less the Contact) reached from a chained
    Solver's last answer ``last`` (its loads, the FrictionalTip) along the straight way
    between their loads, the tip on ``obstacle`` with Coulomb's ``mu`` (the quasi-static
    path of a chain of solves: the app's slider, a quasi-static sweep). The rest as
    :func:`with_friction`."""
    before, found = last
    shooters = {}

    def shoot(x, t, steps):  # (the loads on the way: before's (1 - t) and free's t)
        if t not in shooters:
            shooters[t] = coarse.shooter((*(load.scaled(1.0 - t) for load in before),
                                          *(load.scaled(t) for load in free)))
        return shooters[t](x, steps=steps)

    shots = _Shots(shoot, obstacle, radius, mu, gap_tol, jacobians)
    return _on_grids(shots, fine, free, found.state, 0.0, depth)


def _on_grids(shots, fine, free, start_state, start, depth) -> FrictionalTip:
    """The path from ``start_state`` at the load factor ``start`` to the full load, and its
    answer on ``fine``'s stations; the path again on the answer's grid where that solve
    needed a finer one than the path's (a path on a coarser grid is off by its RK4 error)."""
    counts = FRICTION_STEPS
    for _ in range(GRIDS):
        state, count = _followed(shots, start_state, start, depth, counts)
        found, grid = _finished(shots, fine, free, state)
        if grid <= start_state.steps:
            return found
        mode = ("stick" if shots.mu else "normal") if start_state.touching else "free"
        x = shots.solve(replace(start_state, steps=grid), start, start_state, mode,
                        start_state.x, start_state.force).x
        start_state = replace(start_state, x=x, steps=grid)
        counts = tuple(c for c in FRICTION_STEPS if c >= count // 2)
    return found


def _followed(shots, touched, start, depth, counts):
    """(the state at the full load, the load steps it took): the path from the first
    touch ``touched`` at the load factor ``start`` in ``counts`` equal steps, the count
    doubled until two answers agree to ``depth`` (m)."""
    previous = None
    for count in counts:
        state = touched
        factors = start + (1.0 - start) * np.arange(count + 1) / count
        for before, after in itertools.pairwise(factors):
            state = _advance(shots, state, before, after, SPLITS)
        if previous is not None and np.linalg.norm(state.p - previous) <= depth:
            return state, count
        previous = state.p
    raise ConvergenceError(
        f"the path with friction at the tip did not converge in {counts[-1]} load steps "
        f"(the tip moved by {np.linalg.norm(state.p - previous):.3g} m between the last "
        f"two)", float(np.linalg.norm(state.p - previous)))


def _finished(shots, fine, free, state) -> tuple:
    """(the answer at the full load on ``fine``'s stations, the grid (N) of its solve):
    solved from the path's x with its force as a dead load, and the full load's state
    solved again on that solve's grid while the tip's gap there is off by more than the
    gap's tolerance."""
    arm = -shots.radius * state.normal if state.touching else np.zeros(3)
    for _ in range(REFINEMENTS):
        tip = TipLoad(force=state.force, moment=np.cross(arm, state.force) if shots.mu
                      else np.zeros(3))  # (frictionless: along the normal, through p(L))
        final = fine._solve_near((*free, tip), state.x, 2 * state.steps,
                                 jacobians=fine.stability or shots.jacobians)
        x, steps = fine.last_solution()
        p, R = final.poses[-1, :3, 3], final.poses[-1, :3, :3]
        if not state.touching or abs(shots.gap(p)) <= shots.gap_tol:
            state = replace(state, x=x, steps=steps, p=p, R=R,
                            normal=shots.obstacle.distance(p)[1], rate=None, size=None,
                            slid=None)  # (a chain's next path starts afresh from here)
            return FrictionalTip(state.force, arm, state.sliding, final, state), steps
        state = replace(shots.solve(replace(state, x=x, steps=steps), 1.0, state,
                                    _held_mode(shots, state), x, state.force,
                                    onward=False), sliding=state.sliding)
        arm = -shots.radius * state.normal
    raise ConvergenceError("the held tip's gap on the solver's stations did not settle",
                           float(shots.gap(p)))


def _held_mode(shots, state) -> str:
    """The mode in which ``state`` is solved again (on a finer grid)."""
    return "normal" if not shots.mu else "slide" if state.sliding else "stick"


class _Grid(NamedTuple):
    """A grid for :meth:`_Shots.solve`'s ``base`` where only the grid matters (the free
    arm)."""

    steps: int


def _first_touch(coarse, free, obstacle, radius, gap_tol, bracket):
    """The load factor t₀ where the free tip first touches, or None where it does not at
    the factors checked."""

    def gap_at(t):
        eq = coarse._solve(tuple(load.scaled(t) for load in free), chained=False,
                           jacobians=False, checked=False)
        return obstacle.distance(eq.poses[-1, :3, 3])[0] - radius

    low, g_low = 0.0, gap_at(0.0)
    if g_low <= gap_tol:
        return 0.0
    for high, g_high in bracket:
        if g_high < 0.0:
            break
        low, g_low = high, g_high
    else:
        return None
    # regula falsi with Illinois' halving of the stale end's gap
    side = 0
    for _ in range(ITERATIONS):
        t = (low * g_high - high * g_low) / (g_high - g_low)
        g = gap_at(t)
        if abs(g) <= gap_tol:
            return t
        if g > 0.0:
            low, g_low = t, g
            g_high *= 0.5 if side == 1 else 1.0
            side = 1
        else:
            high, g_high = t, g
            g_low *= 0.5 if side == -1 else 1.0
            side = -1
    raise ConvergenceError("the free tip's first touch was not found", float(g))


def _advance(shots, state, before, after, splits) -> _State:
    """The state at the load factor ``after`` from ``state`` at ``before``: one step, or,
    where it does not solve, two halves (``splits`` more times at most)."""
    try:
        new = _step(shots, state, after, after - before)
        change = np.concatenate([new.x - state.x, new.force - state.force])
        return replace(new, rate=change / (after - before), size=after - before)
    except ConvergenceError:
        if not splits:
            raise
    middle = 0.5 * (before + after)
    state = _advance(shots, state, before, middle, splits - 1)
    return _advance(shots, state, middle, after, splits - 1)


def _step(shots, state, t, size) -> _State:
    """The state at the load factor ``t`` from ``state`` one step (``size``) before:
    stuck, sliding, or free (module docstring)."""
    x, force = state.x, state.force
    if state.rate is not None:  # (the last step's rate: the predictor)
        x, force = x + size * state.rate[:6], force + size * state.rate[6:]
    if not state.touching:  # free: until the tip's gap closes again
        free = shots.solve(state, t, state, "free", x, np.zeros(3))
        if shots.gap(free.p) >= -shots.gap_tol:
            return free
        force = np.zeros(3)  # (closed within the step: touching where it began)
        state = replace(state, touching=True)
    if not shots.mu:  # (frictionless: the normal force alone)
        held = shots.solve(state, t, state, "normal", x, force)
        if held.force @ held.normal >= 0.0:
            return held
        free = shots.solve(state, t, state, "free", held.x, np.zeros(3))
        if shots.gap(free.p) >= -shots.gap_tol:
            return replace(free, touching=False)
        raise ConvergenceError("the tip pulls on the obstacle and its free arm is inside it",
                               float(shots.gap(free.p)))
    stuck = shots.solve(state, t, state, "stick", x, force)
    normal = stuck.force @ stuck.normal
    along = stuck.force - normal * stuck.normal
    if normal < 0.0:  # pulled off the obstacle: free, if the free tip stays outside
        free = shots.solve(state, t, state, "free", stuck.x, np.zeros(3))
        if shots.gap(free.p) >= -shots.gap_tol:
            return replace(free, touching=False)
    elif np.linalg.norm(along) <= shots.mu * normal:
        return stuck
    # beyond the cone: the tip slides over the step, against the stuck force's lean (the
    # guess; the slide's way is solved for). Its way at the step's end is the slide's
    # rate there: BDF2's from this slide and the last one where the tip slid over the
    # last step too (second order in the step: a slide whose way turns converges in
    # fewer steps), else this slide (backward Euler: where a slide starts, the way has a
    # kink anyway)
    history = None
    if state.slid is not None:
        last = state.size
        history = ((2 * size + last) / (size + last),
                   size * size / (last * (size + last)) * state.slid)
    slid = shots.solve(state, t, state, "slide", stuck.x, stuck.force, history=history)
    return replace(slid, sliding=True, slid=shots.slide(state, slid.p, slid.R))


def _skew(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def _rotated(R, theta):
    """exp(θ̃) R (a spatial turn θ)."""
    angle = np.linalg.norm(theta)
    if angle == 0.0:
        return R
    k = _skew(theta / angle)
    return (np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k) @ R


def _turn(R):
    """The rotation vector θ of R = exp(θ̃) (|θ| < π)."""
    axis = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    sine = 0.5 * np.linalg.norm(axis)
    angle = np.arctan2(sine, 0.5 * (np.trace(R) - 1.0))
    return axis * (0.5 if sine < 1e-8 else angle / (2.0 * sine))


def _cross(a, b):
    """a × b of two 3-vectors (numpy's cross costs 30 µs a call in the Newton's loops)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _tangents(n):
    """(3, 2): an orthonormal basis of the plane normal to n."""
    t1 = _cross(n, np.eye(3)[np.argmin(np.abs(n))])
    t1 /= np.linalg.norm(t1)
    return np.column_stack([t1, _cross(n, t1)])


class _Shots:
    """Newton's method on the held arm's base reaction x and the contact's unknowns
    (module docstring), through ``shoot`` (x, the load factor t, the grid) -> the free
    loads' shooting at t (Solver.shooter's). The unknowns after x, per mode:

    - "free": none (the free arm);
    - "normal": the normal force f_n (frictionless, f = f_n n̂), the condition the gap;
    - "stick": the force f (3), the contact conditions the gap and the slide Δw (m);
    - "slide": the normal force f_n, the slide's angle φ in the tangent plane of the last
      state's normal (ŝ = cos φ t̂₁ + sin φ t̂₂) and its length w, with f = f_n (n̂ - μ ŝ)
      and the conditions the gap and Δw = w ŝ: smooth where the slide starts (w = 0),
      where ŝ = Δw/|Δw| is not.
    """

    def __init__(self, shoot, obstacle, radius, mu, gap_tol, jacobians):
        self.shoot, self.obstacle = shoot, obstacle
        self.radius, self.mu, self.gap_tol = radius, mu, gap_tol
        self.jacobians = jacobians  # (the answer's solve: with its compliance)
        # (:meth:`solve`'s: the slide's rate's ``history``, the tangent plane's basis)
        self.history = self.basis = None

    def gap(self, p) -> float:
        return float(self.obstacle.distance(p)[0]) - self.radius

    def state(self, x, steps, t, force, touching) -> _State:
        pose = self.shoot(x, t, ("solution", steps)).tip_pose
        p = pose[:3, 3]
        return _State(x, steps, p, pose[:3, :3], self.obstacle.distance(p)[1], force,
                      touching)

    def guess(self, before, mode, force):
        """The contact's unknowns for ``mode`` from a force f (a slide: against its
        tangential part, from w = 0)."""
        if mode == "free":
            return np.zeros(0)
        if mode == "stick":
            return np.array(force, dtype=float)
        if mode == "normal":
            return np.array([force @ before.normal])
        n = before.normal
        along = _tangents(n).T @ (force - (force @ n) * n)
        return np.array([max(force @ n, 0.0), np.arctan2(-along[1], -along[0]), 0.0])

    def closed(self, before, mode, unknowns, p, R, near=None):
        """(the force f on the tip (3,), the contact's conditions (m)) at the tip's pose;
        ``near``: the obstacle's (d, n̂) at p, if known."""
        if mode == "free":
            return np.zeros(3), np.zeros(0)
        d, n = self.obstacle.distance(p) if near is None else near
        if mode == "normal":
            return unknowns[0] * n, np.array([d - self.radius])
        slide = self.slide(before, p, R, n)
        basis = self.basis
        if mode == "stick":
            return unknowns, np.concatenate([[d - self.radius], basis.T @ slide])
        normal, angle, length = unknowns
        way = basis @ np.array([np.cos(angle), np.sin(angle)])
        way -= (way @ n) * n  # (in the tangent plane where the tip is)
        force = normal * (n - self.mu * way / np.linalg.norm(way))
        if self.history is not None:  # (the slide's rate at the step's end, BDF2)
            slide = self.history[0] * slide - self.history[1]
        return force, np.concatenate([[d - self.radius],
                                      basis.T @ slide - length * basis.T @ way])

    def slide(self, before, p, R, n=None) -> np.ndarray:
        """(3,) spatial, m: the slide Δw of the cap's material point in contact from
        ``before`` to the pose (p, R) (module docstring); ``n``: the normal at p, if
        known."""
        m = before.normal + (self.obstacle.distance(p)[1] if n is None else n)
        m /= np.linalg.norm(m)
        return p - before.p - self.radius * _cross(_turn(R @ before.R.T), m)

    def _parts(self, before, mode, unknowns, p, R):
        """The residual's closed-form rows: -(f; arm × f) (its wrench on the tip, at the
        contact point) and the contact's conditions."""
        near = self.obstacle.distance(p)
        force, conditions = self.closed(before, mode, unknowns, p, R, near)
        arm = -self.radius * near[1]
        return np.concatenate([-force, -_cross(arm, force), conditions])

    def _residual(self, base, t, before, mode, z):
        """(the residual, the shooting's result, the merit in m)."""
        shot = self.shoot(z[:6], t, ("solution", base.steps))
        p, R = shot.tip_pose[:3, 3], shot.tip_pose[:3, :3]
        e = self._parts(before, mode, z[6:], p, R)
        e[:6] += shot.residual
        # the tip's compliance to the residual's wrench: its error in m (and the turn's at
        # the cap's surface)
        miss = shot.tip_motion_x @ np.linalg.solve(shot.jacobian_x, e[:6])
        miss[3:] *= self.radius
        return e, shot, float(np.linalg.norm(np.concatenate([miss, e[6:]])))

    def _jacobian(self, before, mode, z, shot):
        """The residual's derivatives: the shooting's in x; those of the closed-form rows
        in the tip's pose (central differences) through the shooting's tip motion, and in
        the contact's unknowns (central differences)."""
        p, R = shot.tip_pose[:3, 3], shot.tip_pose[:3, :3]
        unknowns = z[6:]
        jacobian = np.zeros((6 + unknowns.size, z.size))
        jacobian[:6, :6] = shot.jacobian_x
        if mode == "free":
            return jacobian
        h = DIFFERENCE * max(np.linalg.norm(p - before.p), self.gap_tol)
        in_pose = np.empty((jacobian.shape[0], 6))
        for k, unit in enumerate(np.eye(3)):
            in_pose[:, k] = (self._parts(before, mode, unknowns, p + h * unit, R)
                             - self._parts(before, mode, unknowns, p - h * unit, R)) / (2 * h)
            turn = h / self.radius * unit
            in_pose[:, 3 + k] = (self._parts(before, mode, unknowns, p, _rotated(R, turn))
                                 - self._parts(before, mode, unknowns, p, _rotated(R, -turn))
                                 ) / (2 * h / self.radius)
        jacobian[:, :6] += in_pose @ shot.tip_motion_x
        for k in range(unknowns.size):
            step = 1e-6 * max(abs(unknowns[k]), 1e-3 if mode == "stick" else 1e-6)
            up, down = unknowns.copy(), unknowns.copy()
            up[k] += step
            down[k] -= step
            jacobian[:, 6 + k] = (self._parts(before, mode, up, p, R)
                                  - self._parts(before, mode, down, p, R)) / (2 * step)
        return jacobian

    def solve(self, base, t, before, mode, x, force, *, onward=True,
              history=None) -> _State:
        """The state at the load factor ``t`` on ``base``'s grid, ``mode`` "stick",
        "slide", "normal" or "free", from the guess (x, f), ``before`` the state one step back (the
        slide's start; ``onward``: a slide must go its way, w >= 0, not where a state is
        solved again on a finer grid; ``history``: (a, b Δw₀) of the slide's rate at the
        step's end, a Δw - b Δw₀, Δw₀ the last step's slide, or None for Δw): Newton's
        method, its step halved while the merit grows or the shooting fails."""
        self.history = history
        self.basis = None if before is None else _tangents(before.normal)
        z = np.concatenate([x, self.guess(before, mode, force)])
        step, best, halvings = None, np.inf, 0
        for _ in range(ITERATIONS):
            trial = z if step is None else z + step
            try:
                e, shot, merit = self._residual(base, t, before, mode, trial)
                finite = np.isfinite(merit)
            except (np.linalg.LinAlgError, FloatingPointError):
                finite = False
            if not finite or (step is not None and merit >= best):
                if step is None or halvings == HALVINGS:
                    break
                step, halvings = 0.5 * step, halvings + 1
                continue
            z, best, halvings = trial, merit, 0
            if best <= self.gap_tol:
                p, R = shot.tip_pose[:3, 3], shot.tip_pose[:3, :3]
                if onward and mode == "slide" and z[8] < -self.gap_tol:
                    break  # (it slid against the friction's way: not this slide)
                force = self.closed(before, mode, z[6:], p, R)[0]
                return _State(z[:6], base.steps, p, R, self.obstacle.distance(p)[1], force,
                              mode != "free")
            try:
                step = -np.linalg.solve(self._jacobian(before, mode, z, shot), e)
            except np.linalg.LinAlgError:
                break
        raise ConvergenceError(f"the tip's state ({mode}) did not converge at load factor "
                               f"{t:.6g}", best)


def stuck_jacobians(final, asked, arm) -> dict:
    """The Jacobians of ``final`` (the free arm with the tip's force as a dead load, its
    compliance computed) with the tip stuck: the cap rolls without sliding, so to first
    order its material point at ``arm`` from the centre stays, Gᵀ δx = δp + δθ × arm = 0
    (G = [I; arm~], δx the tip's (δp; δθ)), and the force changes by δf at it: a column W
    (a tip wrench, an input) moves the tip by C_W W + C G δf with
    δf = -(Gᵀ C G)⁻¹ Gᵀ C_W W, every station by its own columns likewise. On a plane the
    point's offset -r n̂ does not turn; the asked stations ``asked``."""
    G = _at_point(arm)
    C, stations = final.tip_compliance, final.compliance[..., asked, :, :]
    solve = np.linalg.inv(G.T @ C @ G) @ G.T

    def held(columns, station_columns):
        change = -solve @ columns  # δf per column (3, n)
        return columns + C @ G @ change, station_columns + stations @ G @ change

    return held_columns(final, asked, held)


def held_columns(final, asked, held) -> dict:
    """The Jacobian fields of ``final`` (the free arm with the tip's force as a dead load)
    with the tip held: ``held`` (the tip's columns, the asked stations' columns) -> the
    same held, applied to the compliances and the actuation Jacobians."""
    out = dict(zip(("tip_compliance", "compliance"),
                   held(final.tip_compliance, final.compliance[..., asked, :, :]),
                   strict=True))
    if final.actuation_jacobian is not None:
        out.update(zip(("actuation_jacobian", "station_actuation_jacobian"),
                       held(final.actuation_jacobian,
                            final.station_actuation_jacobian[..., asked, :, :]), strict=True))
    return out


def held_index(free_index, compliance, arm) -> int:
    """The Morse index of the arm with its tip held at the contact point, from the free
    arm's ``free_index`` under the tip's force and couple as dead loads and its tip
    compliance C (6, 6): holding the point (G = [I; arm~], the contact point's
    three directions) takes away as many unstable directions as Gᵀ C G has negative
    eigenvalues (the inertia of the bordered matrix, tip_contact.py's "Stability", with
    the constraint's stiffness K → ∞; the force's turn with the tip, O(r |f|), left out).

    With friction it is the verdict's index while the tip sticks, and a lower bound after
    a slide: the tip at rest on the cone's edge is held against every motion but the
    slide's going on, which friction does not resist beyond μ N. An index above 0 is an
    unstable direction with the tip held where it is, the most friction can do."""
    G = _at_point(arm)
    reduced = G.T @ compliance @ G
    negative = np.sum(np.linalg.eigvalsh(0.5 * (reduced + reduced.T)) < 0.0)
    return max(int(free_index) - int(negative), 0)


def _at_point(arm) -> np.ndarray:
    """(6, 3) G: the tip wrench (f; arm × f) of a force f at ``arm`` (spatial, m) from the
    tip's centre; Gᵀ (δp; δθ) = δp + δθ × arm is that point's motion."""
    return np.vstack([np.eye(3), _skew(arm)])
