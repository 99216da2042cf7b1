"""Seeded randomised invariants of ``softarm.solve`` (issue 12), independent of any closed form.

Random arms (1-3 segments, straight or precurved, circle/tube/rectangle sections; silicone
E 0.1-10 MPa, nitinol and steel) under random loads of every kind (dead and follower tip
loads, gravity, dead and follower distributed forces, point loads) up to k = PL²/EI = 50 and
qL³/EI = 500, EI the smallest bending stiffness of the arm and L its length. Each case comes
from ``np.random.default_rng([SEED, family, index])``, so a failure names a reproducible case.

Checks:

* global force and moment balance of every part [s, L], at every station, rebuilt from the
  returned stresses and the loads (tests/_equilibrium_checks.py);
* batched equals looped, in random permutations of the batch;
* the same answer across a ladder of ``tol`` and of ``max_load_step``;
* closed form equals numeric wherever an exact closed form applies;
* for conservative loads, the returned equilibrium is the one reached by a fine quasi-static
  continuation (the prepared Solver stepped through λ = 0.005, 0.01, ..., 1) and, on a few
  cases, by the independent solve_bvp continuation of tests/_reference_rod.py: same shape and
  same potential energy.

A ``ConvergenceError`` that names a fold (``load_factor`` in (0, 1)) is accepted for a random
case only if the solve_bvp continuation cannot reach λ = 1 either; otherwise it is a failure.
The folds met are listed by ``python tests/reference_scripts/invariant_folds.py``.

The CI run takes about a minute. Set ``SOFTARM_INVARIANTS_LARGE=1`` for the large run (about
ten times as many cases of every kind, and solve_bvp on many more).
"""

from __future__ import annotations

import functools
import os

import numpy as np
import pytest
from _equilibrium_checks import balance_errors, fine_stations, potential_energy
from _reference_rod import describe, reference_energy, solve_reference

import softarm
import softarm.analytic
import softarm.statics

LARGE = os.environ.get("SOFTARM_INVARIANTS_LARGE", "") == "1"
SEED = 20261129

N_BALANCE = 240 if LARGE else 24
N_BATCH_GROUPS = 40 if LARGE else 5
BATCH = 8
N_LADDER = 80 if LARGE else 8
N_CLOSED = 300 if LARGE else 30
N_ENERGY = 120 if LARGE else 12
#: energy cases also checked against solve_bvp (~5 s each); in CI two cases where softarm
#: 0.1 took a wrong branch from a cold solve (found with this suite)
REFERENCE_CASES = range(40) if LARGE else (3, 11)

TOL = 1e-8
#: balance of every part [s, L], relative to the case's own load scale (sum of |applied
#: force|, and of |applied moment| + force scale × L). The stresses of a tol = 1e-8 solution
#: carry relative errors ~1e-8 (the RK4 error is what tol bounds); the quadrature of the
#: distributed loads (12-point Gauss on 8 cells per piece, Legendre interpolant) is exact to
#: ~1e-12 on these shapes (measured: 3e-10 relative on the 1 m arm looping under its weight).
#: 1e-6 leaves two decades for the solver and still sees a copied station (1e-2) or a
#: dropped load (1).
BALANCE_RTOL = 1e-6
#: agreement of two answers on the same branch, × L: both within tol·L of the truth by
#: the solver's estimate; 20 tol leaves room for the estimate's own error
SAME = 20 * TOL


# ---------------------------------------------------------------------------------------------
# random arms and loads


def random_segment(rng, family, length):
    if family == "silicone":
        material = softarm.Material(youngs_modulus=float(np.exp(rng.uniform(np.log(1e5),
                                                                             np.log(1e7)))),
                                    poisson_ratio=float(rng.uniform(0.45, 0.5)),
                                    density=float(rng.uniform(1000.0, 1200.0)))
        size = rng.uniform(0.003, 0.02)
    elif family == "nitinol":
        material = softarm.Material(youngs_modulus=float(rng.uniform(40e9, 75e9)),
                                    poisson_ratio=0.33, density=6450.0)
        size = rng.uniform(0.0002, 0.002)
    else:
        material = softarm.Material(youngs_modulus=200e9, poisson_ratio=0.3, density=7850.0)
        size = rng.uniform(0.0005, 0.005)
    kind = rng.choice(["circle", "tube", "rectangle"], p=[0.5, 0.3, 0.2])
    if kind == "circle":
        section = softarm.Circle(float(size))
    elif kind == "tube":
        section = softarm.Tube(float(size), float(size * rng.uniform(0.3, 0.8)))
    else:
        section = softarm.Rectangle(float(size * 1.6), float(size * 1.6 / rng.uniform(1.0, 3.0)))
    return section, material


def random_arm(rng, straight=False):
    family = rng.choice(["silicone", "nitinol", "steel"], p=[0.6, 0.2, 0.2])
    length = {"silicone": rng.uniform(0.1, 1.0), "nitinol": rng.uniform(0.1, 1.0),
              "steel": rng.uniform(0.2, 2.0)}[family]
    count = int(rng.integers(1, 4))
    parts = rng.dirichlet(np.full(count, 3.0)) * length
    segments = []
    for part in parts:
        section, material = random_segment(rng, family, part)
        curvature = (0.0, 0.0, 0.0)
        if not straight and rng.random() < 0.5:
            # up to 1.5 rad of turn over the whole arm, some twist
            curvature = tuple(float(c) for c in rng.normal(size=3) * 1.5 / length / np.sqrt(3)
                              * np.array([0.3, 1.0, 1.0]))
        segments.append(softarm.Arm(float(part), section, material, curvature))
    return segments[0] if count == 1 else softarm.SegmentedArm(segments)


def bending_scale(arm):
    """EI (smallest bending stiffness over the segments, N m²) and L (m)."""
    EI = min(min(seg.stiffness[4, 4], seg.stiffness[5, 5]) for seg in arm.segments)
    return float(EI), float(arm.length)


def unit(rng, shape=()):
    v = rng.normal(size=(*shape, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def log_uniform(rng, low, high, shape=()):
    return np.exp(rng.uniform(np.log(low), np.log(high), size=shape))


def random_loads(rng, arm, batch=(), conservative=False):
    """1-3 load kinds, magnitudes up to k = 50 (forces), qL³/EI = 500 (distributed)."""
    EI, L = bending_scale(arm)
    kinds = ["tip", "gravity", "distributed", "point"] if conservative else \
        ["tip", "tip_follower", "gravity", "distributed", "distributed_follower", "point"]
    chosen = rng.choice(kinds, size=int(rng.integers(1, 4)), replace=False)
    loads = []
    for kind in chosen:
        if kind in ("tip", "tip_follower"):
            force = unit(rng, batch) * log_uniform(rng, 0.05, 50.0, batch)[..., None] * EI / L**2
            moment = np.zeros_like(force)
            if not conservative and rng.random() < 0.5:
                moment = unit(rng, batch) * log_uniform(rng, 0.05, 3.0, batch)[..., None] * EI / L
            loads.append(softarm.TipLoad(force=force, moment=moment,
                                         follower=kind == "tip_follower"))
        elif kind == "gravity":
            mu = max(seg.linear_density for seg in arm.segments)
            q = mu * 9.81 * L**3 / EI   # this arm's own qL³/EI at 1 g
            scale = min(1.0, rng.uniform(5.0, 500.0) / q)   # at most 1 g, at most 500
            loads.append(softarm.Gravity(unit(rng, batch) * 9.81 * scale))
        elif kind in ("distributed", "distributed_follower"):
            q = unit(rng, batch) * log_uniform(rng, 0.5, 500.0, batch)[..., None] * EI / L**3
            if kind == "distributed":
                loads.append(softarm.DistributedForce(q))
            else:
                loads.append(softarm.DistributedForce(q, follower=True))
        else:
            s = float(np.round(rng.uniform(0.05, 0.95) * L, 6))
            force = unit(rng, batch) * log_uniform(rng, 0.05, 30.0, batch)[..., None] * EI / L**2
            moment = np.zeros_like(force)
            if not conservative and rng.random() < 0.3:
                moment = unit(rng, batch) * log_uniform(rng, 0.05, 2.0, batch)[..., None] * EI / L
            loads.append(softarm.PointLoad(s, force=force, moment=moment))
    if rng.random() < 0.15:
        # issue 12, reproducer 4: tiny loads (down to 1e-12 of the above) are not dropped
        factor = 10.0 ** -rng.uniform(3.0, 12.0)
        loads = [scaled(load, factor) for load in loads]
    return loads


def scaled(load, factor):
    """``load`` with every vector multiplied by ``factor``."""
    if isinstance(load, softarm.Gravity):
        return softarm.Gravity(load.acceleration * factor)
    if isinstance(load, softarm.TipLoad):
        return softarm.TipLoad(force=load.force * factor, moment=load.moment * factor,
                               follower=load.follower)
    if isinstance(load, softarm.DistributedForce):
        if getattr(load, "follower", False):
            return softarm.DistributedForce(load.force * factor, follower=True)
        return softarm.DistributedForce(load.force * factor)
    return softarm.PointLoad(load.s, force=load.force * factor, moment=load.moment * factor)


STREAMS = {"balance": 1, "ladder": 5, "energy": 6}


@functools.cache
def case(family: str, index: int, conservative=False):
    rng = np.random.default_rng([SEED, STREAMS[family], index])
    arm = random_arm(rng)
    return arm, random_loads(rng, arm, conservative=conservative)


# ---------------------------------------------------------------------------------------------
# folds: accepted only where the independent continuation stops too

FOLDS: dict = {}


@functools.cache
def reference_of(key, arm, loads):
    """solve_bvp continuation (λ steps ≤ 0.1, collocation tolerance 1e-4), cached per case."""
    return solve_reference(arm, list(loads), lam_step=0.1, tol=1e-4, nodes=41)


#: the solver's fold and the λ where the reference stops must agree this well (the
#: reference's natural-parameter steps shrink to 1e-4 at a fold, but solve_bvp may give up a
#: little before it)
FOLD_LAMBDA_ATOL = 0.05


def check_fold(key, arm, loads, error):
    """A ConvergenceError for this case: pass only for a fold the reference meets too."""
    lam = getattr(error, "load_factor", None)
    assert lam is not None and 0.0 < lam < 1.0, f"{key}: not a fold: {error!r}"
    assert f"{lam:.3g}" in str(error) or f"{lam:.2f}" in str(error) or "load factor" in \
        str(error), f"{key}: the message does not name the load factor: {error}"
    ref = reference_of(key, arm, tuple(loads))
    FOLDS[key] = (lam, ref.lam)
    assert not ref.complete, (f"{key}: the solver stops at a fold λ = {lam:.4g}, the solve_bvp "
                              f"continuation reaches λ = 1: {error}")
    assert abs(ref.lam - lam) <= FOLD_LAMBDA_ATOL, (
        f"{key}: the solver's fold λ = {lam:.4g}, the reference stops at λ = {ref.lam:.4g}")


def solve_or_fold(key, arm, loads, **kwargs):
    """The equilibrium, or None after a fold the reference confirms."""
    try:
        return softarm.solve(arm, loads, **kwargs)
    except softarm.ConvergenceError as error:
        check_fold(key, arm, loads, error)
        return None


# ---------------------------------------------------------------------------------------------
# balance at every station


@pytest.mark.parametrize("index", range(N_BALANCE))
def test_balance_at_every_station(index):
    arm, loads = case("balance", index)
    eq = solve_or_fold(("balance", index), arm, loads, s=fine_stations(arm, loads), tol=TOL)
    if eq is None:
        return
    force_err, moment_err, force_scale, moment_scale = balance_errors(eq)
    assert force_err <= BALANCE_RTOL * force_scale, (force_err, force_scale)
    assert moment_err <= BALANCE_RTOL * moment_scale, (moment_err, moment_scale)
    # every station holds its own state: the default 101 stations (s = L among them) agree
    # with the same stations solved among the fine ones
    default = softarm.solve(arm, loads, tol=TOL)
    assert default.s[-1] == arm.length
    both = softarm.solve(arm, loads, s=np.union1d(default.s, eq.s), tol=TOL)
    rows = np.searchsorted(both.s, default.s)
    np.testing.assert_allclose(default.positions, both.positions[rows], rtol=0,
                               atol=SAME * arm.length)
    np.testing.assert_allclose(both.positions[np.searchsorted(both.s, eq.s)], eq.positions,
                               rtol=0, atol=SAME * arm.length)


# ---------------------------------------------------------------------------------------------
# batched equals looped


def batch_group(index):
    rng = np.random.default_rng([SEED, 2, index])
    arm = random_arm(rng)
    return arm, random_loads(rng, arm, batch=(BATCH,))


def take(loads, rows):
    """The loads with their batch axis indexed by ``rows`` (an index array or an int)."""
    out = []
    for load in loads:
        if isinstance(load, softarm.Gravity):
            out.append(softarm.Gravity(load.acceleration[rows]))
        elif isinstance(load, softarm.TipLoad):
            out.append(softarm.TipLoad(force=load.force[rows], moment=load.moment[rows],
                                       follower=load.follower))
        elif isinstance(load, softarm.DistributedForce):
            follower = getattr(load, "follower", False)
            out.append(softarm.DistributedForce(load.force[rows], follower=True) if follower
                       else softarm.DistributedForce(load.force[rows]))
        else:
            out.append(softarm.PointLoad(load.s, force=load.force[rows],
                                         moment=load.moment[rows]))
    return out


@pytest.mark.parametrize("index", range(N_BATCH_GROUPS))
def test_batched_equals_looped_in_any_order(index):
    arm, loads = batch_group(index)
    L = arm.length
    looped = {}
    for row in range(BATCH):
        eq = solve_or_fold(("batch", index, row), arm, take(loads, row), tol=TOL)
        if eq is not None:
            looped[row] = eq.poses
    rows = np.array(sorted(looped))
    if rows.size < BATCH:  # a batch with a fold in it fails as a whole
        with pytest.raises(softarm.ConvergenceError):
            softarm.solve(arm, loads, tol=TOL)
    if rows.size == 0:
        return
    rng = np.random.default_rng([SEED, 3, index])
    for order in (rows, rows[::-1], rng.permutation(rows), rng.permutation(rows)):
        batched = softarm.solve(arm, take(loads, order), tol=TOL)
        for j, row in enumerate(order):
            np.testing.assert_allclose(batched.poses[j][..., :3, 3], looped[row][..., :3, 3],
                                       rtol=0, atol=SAME * L, err_msg=f"row {row}")
            np.testing.assert_allclose(batched.poses[j][..., :3, :3], looped[row][..., :3, :3],
                                       rtol=0, atol=SAME * 10)


# ---------------------------------------------------------------------------------------------
# ladders of tol and max_load_step


@pytest.mark.parametrize("index", range(N_LADDER))
def test_same_answer_across_tol_and_load_step(index):
    arm, loads = case("ladder", index)
    L = arm.length
    finest = solve_or_fold(("ladder", index), arm, loads, tol=1e-10, method="numeric")
    if finest is None:
        return
    for tol in (1e-6, 1e-8):
        eq = softarm.solve(arm, loads, tol=tol, method="numeric")
        np.testing.assert_allclose(eq.positions, finest.positions, rtol=0, atol=10 * tol * L,
                                   err_msg=f"tol={tol}")
    for step in (1.0, 0.25, 0.05):
        eq = softarm.solve(arm, loads, tol=TOL, method="numeric", max_load_step=step)
        np.testing.assert_allclose(eq.positions, finest.positions, rtol=0, atol=SAME * L,
                                   err_msg=f"max_load_step={step}")


# ---------------------------------------------------------------------------------------------
# closed form equals numeric


def closed_form_case(index):
    """A straight or precurved single arm with tip loads that have an exact closed form."""
    rng = np.random.default_rng([SEED, 4, index])
    family = rng.choice(["silicone", "nitinol", "steel"], p=[0.6, 0.2, 0.2])
    length = float(rng.uniform(0.1, 1.0))
    section, material = random_segment(rng, family, length)
    kind = rng.choice(["moment", "moment_follower", "elastica", "axial"], p=[0.3, 0.2, 0.4, 0.1])
    if kind == "elastica":
        section = softarm.Circle(section.radius) if isinstance(section, softarm.Circle) else \
            softarm.Tube(section.outer_radius, section.inner_radius) \
            if isinstance(section, softarm.Tube) else section
        arm = softarm.Arm(length, section, material)
        EI, L = bending_scale(arm)
        k = float(log_uniform(rng, 0.05, 50.0))
        if isinstance(section, softarm.Rectangle):   # a principal plane: x-z
            direction = np.array([rng.normal(), 0.0, rng.normal()])
        else:
            direction = unit(rng)
        direction /= np.linalg.norm(direction)
        return arm, [softarm.TipLoad(force=direction * k * EI / L**2)]
    if kind == "axial":
        arm = softarm.Arm(length, section, material)
        EI, L = bending_scale(arm)
        # tension, or compression below 0.9 of the first Euler load (π²/4 EI/L²)
        k = float(rng.uniform(-0.9 * np.pi**2 / 4, 20.0))
        return arm, [softarm.TipLoad(force=(k * EI / L**2, 0.0, 0.0))]
    # a tip moment about a principal axis (possibly precurved about that axis), or any moment
    # on a straight arm with EIy = EIz (the helix)
    axis = int(rng.integers(0, 3))
    follower = kind == "moment_follower"
    if isinstance(section, softarm.Rectangle) or rng.random() < 0.5:
        curvature = np.zeros(3)
        curvature[axis] = rng.normal() * 1.0 / length
        arm = softarm.Arm(length, section, material, tuple(curvature))
        moment = np.zeros(3)
        moment[axis] = rng.choice([-1.0, 1.0]) * float(log_uniform(rng, 0.05, 6.0))
    else:
        arm = softarm.Arm(length, section, material)
        moment = unit(rng) * float(log_uniform(rng, 0.05, 6.0))
    EI, L = bending_scale(arm)
    return arm, [softarm.TipLoad(moment=moment * EI / L, follower=follower)]


@pytest.mark.parametrize("index", range(N_CLOSED))
def test_closed_form_equals_numeric(index):
    arm, loads = closed_form_case(index)
    L = arm.length
    closed = softarm.analytic.exact_closed_form(arm, loads)
    assert closed is not None, f"no closed form for {loads!r} on {arm!r}"
    auto = softarm.solve(arm, loads, tol=TOL)
    np.testing.assert_allclose(auto.poses, closed.poses, rtol=0, atol=1e-12 * max(L, 1.0))
    numeric = solve_or_fold(("closed", index), arm, loads, tol=TOL, method="numeric")
    assert numeric is not None, "a closed-form path has no fold"
    np.testing.assert_allclose(numeric.positions, closed.positions, rtol=0, atol=SAME * L)
    np.testing.assert_allclose(numeric.rotations, closed.rotations, rtol=0, atol=SAME * 10)


# ---------------------------------------------------------------------------------------------
# conservative loads: the energy and shape of a fine quasi-static continuation

CONTINUATION_STEPS = 200


def continued(arm, loads, s):
    """The prepared Solver driven through λ = 1/200, 2/200, ..., 1 (one batch, in order)."""
    lam = np.arange(1, CONTINUATION_STEPS + 1) / CONTINUATION_STEPS
    stepped = []
    for load in loads:
        if isinstance(load, softarm.Gravity):
            stepped.append(softarm.Gravity(lam[:, None] * load.acceleration))
        elif isinstance(load, softarm.TipLoad):
            stepped.append(softarm.TipLoad(force=lam[:, None] * load.force,
                                           moment=lam[:, None] * load.moment))
        elif isinstance(load, softarm.DistributedForce):
            stepped.append(softarm.DistributedForce(lam[:, None] * load.force))
        else:
            stepped.append(softarm.PointLoad(load.s, force=lam[:, None] * load.force))
    solver = softarm.statics.Solver(arm, s=s, tol=TOL)
    return solver.solve(stepped)


def energy_scale(loads, arm):
    rl = describe(loads)
    L = float(arm.length)
    mu = max(seg.linear_density for seg in arm.segments)
    force = (np.linalg.norm(rl.tip_force) + np.linalg.norm(mu * rl.gravity + rl.dist_force) * L
             + sum(np.linalg.norm(f) for _, f, _ in rl.points))
    return force * L


@pytest.mark.parametrize("index", range(N_ENERGY))
def test_conservative_equilibrium_is_the_continued_one(index):
    arm, loads = case("energy", index, conservative=True)
    L = arm.length
    s = fine_stations(arm, loads)
    eq = solve_or_fold(("energy", index), arm, loads, s=s, tol=TOL)
    if eq is None:
        return
    path = continued(arm, loads, s)
    last = path.poses[-1]
    np.testing.assert_allclose(eq.positions, last[..., :3, 3], rtol=0, atol=1e-6 * L)
    scale = energy_scale(loads, arm)
    energy = potential_energy(eq)
    path_eq = softarm.Equilibrium(s=path.s, poses=path.poses[-1], strains=path.strains[-1],
                                  stresses=path.stresses[-1], arm=arm, loads=tuple(loads),
                                  method=path.method, exact=path.exact)
    assert energy == pytest.approx(potential_energy(path_eq), abs=1e-6 * scale)


@pytest.mark.parametrize("index", REFERENCE_CASES)
@pytest.mark.slow
def test_conservative_equilibrium_is_the_solve_bvp_one(index):
    """Against the independent solve_bvp continuation: shape and potential energy."""
    arm, loads = case("energy", index, conservative=True)
    L = arm.length
    s = fine_stations(arm, loads)
    eq = solve_or_fold(("energy", index), arm, loads, s=s, tol=TOL)
    ref = reference_of(("energy", index), arm, tuple(loads))
    if eq is None:
        return
    assert ref.complete, f"the solve_bvp continuation stops at λ = {ref.lam}"
    p_ref = ref.state(eq.s)[0]
    # solve_bvp at collocation tolerance 1e-4: positions to ~5e-7 L on the 1 m arm and on
    # cases 3 and 11 against tolerance 1e-5 (measured)
    np.testing.assert_allclose(eq.positions, p_ref, rtol=0, atol=1e-5 * L)
    scale = energy_scale(loads, arm)
    assert potential_energy(eq) == pytest.approx(reference_energy(ref, describe(loads)),
                                                 abs=1e-5 * scale)
