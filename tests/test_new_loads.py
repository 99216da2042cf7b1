"""The load interface and the new loads of issue 13 §1: DistributedForce and DistributedMoment,
dead or follower, on the whole arm, a span [s0, s1] or one segment.

References, none of them the library's solver:

- a uniform distributed moment about a principal axis of a straight arm: the planar closed
  form m(s) = μ (L - s), κ = m/EI, θ(s) = ∫ κ, positions by Gauss–Legendre quadrature;
- ``scipy.integrate.solve_bvp`` on the Cosserat rod equations written here (one state per
  uniformly loaded piece, joined by continuity conditions), continued in load steps from the
  unloaded arm; it is first checked against today's solver on loads both support;
- global balance: the internal wrench at every station rebuilt from the loads on [s, L] and
  the returned poses.

``LOAD_KINDS`` lists every load kind once; the battery below runs over all of them (batched
equals looped, base pose, balance, case-file round trip, description). A new kind is covered
by adding one entry.
"""

from __future__ import annotations

import dataclasses
import itertools
import sys
from collections.abc import Callable
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson, solve_bvp, solve_ivp
from scipy.linalg import expm

import softarm
from softarm import (
    Arm,
    Circle,
    DistributedForce,
    Gravity,
    Material,
    PointLoad,
    SegmentedArm,
    TipLoad,
)
from softarm.case import arm_to_dict, loads_to_dict, parse_case

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10 only
    import tomli as tomllib


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def numeric(arm, loads, **options):
    return softarm.solve(arm, loads, method="numeric", **options)


def distributed_moment(*args, **kwargs):
    """softarm.DistributedMoment, looked up when called (a missing class fails one test)."""
    return softarm.DistributedMoment(*args, **kwargs)


SOFT = Material(1.0e6, poisson_ratio=0.45, density=1100.0)
#: A curved, twisted two-segment arm (L = 0.4 m, joint at 0.25 m) for the general cases.
ARM = SegmentedArm([Arm(0.25, Circle(0.012), SOFT, curvature=(0.5, 0.0, 2.0)),
                    Arm(0.15, Circle(0.008), SOFT, curvature=(0.0, -1.0, 0.0))])
SPAN = (0.1, 0.3)  # crosses the joint
#: Stations 1 mm apart: the joint, the span ends and the point load all fall on them.
DENSE = np.linspace(0.0, ARM.length, 401)


# ============================================================================================
# 1. A uniform distributed moment about a principal axis: the planar closed form
# ============================================================================================

def planar_distributed_moment(L, mu, stiffness, axis, s):
    """Straight arm along e1, clamped at the origin, uniform moment μ per length about the
    principal axis e_axis (dead, or follower: the same, the sections turn about e_axis).

    n = 0 everywhere (no force: no extension, no shear whatever EA, GA), so
    m(s) = μ (L - s) e_axis, κ = m/EI, θ(s) = μ (L s - s²/2)/EI and R(s) = exp(θ(s) ê_axis);
    p(s) = ∫₀ˢ R e1 dt by 40-point Gauss–Legendre quadrature on [0, s] (the integrand is
    entire: exact to round-off), with R e1 = cos θ e1 + sin θ e × e1 + (1 - cos θ)(e·e1) e
    (Rodrigues). Returns positions (S, 3), rotations (S, 3, 3), curvatures (S, 3).
    """
    e, e1 = np.eye(3)[axis], np.eye(3)[0]
    nodes, weights = np.polynomial.legendre.leggauss(40)

    def theta(t):
        return mu * (L * t - t**2 / 2) / stiffness

    def tangent(t):
        c, sn = np.cos(theta(t))[:, None], np.sin(theta(t))[:, None]
        return c * e1 + sn * np.cross(e, e1) + (1 - c) * (e @ e1) * e

    positions = np.array([0.5 * si * weights @ tangent(0.5 * si * (nodes + 1)) for si in s])
    rotations = np.array([expm(theta(si) * hat(e)) for si in s])
    curvatures = np.outer(mu * (L - s) / stiffness, e)
    return positions, rotations, curvatures


@pytest.mark.parametrize("follower", [False, True], ids=["dead", "follower"])
@pytest.mark.parametrize("axis", [1, 2, 0], ids=["about_y", "about_z", "about_x_twist"])
def test_uniform_distributed_moment_planar_closed_form(axis, follower):
    # Soft in extension and shear on purpose: n = 0 must leave them unstrained.
    L = 0.8
    K = dict(EA=20.0, GAy=8.0, GAz=12.0, GJ=0.7, EIy=1.0, EIz=1.6)
    arm = Arm.from_stiffness(L, **K)
    stiffness = [K["GJ"], K["EIy"], K["EIz"]][axis]
    mu = 3.0 * stiffness / L**2  # θ(L) = μ L²/2EI = 1.5 rad
    moment = np.zeros(3)
    moment[axis] = mu
    s = np.linspace(0.0, L, 17)
    eq = numeric(arm, distributed_moment(moment, follower=follower), s=s, tol=1e-11)
    p, R, kappa = planar_distributed_moment(L, mu, stiffness, axis, s)
    np.testing.assert_allclose(eq.positions, p, rtol=0, atol=1e-9 * L)
    np.testing.assert_allclose(eq.rotations, R, rtol=0, atol=1e-9)
    np.testing.assert_allclose(eq.strains[:, 3:], kappa, rtol=0, atol=1e-9 * mu * L / stiffness)
    np.testing.assert_allclose(eq.stresses[:, :3], 0.0, rtol=0, atol=1e-10 * mu)
    np.testing.assert_allclose(eq.strains[:, :3], 0.0, rtol=0, atol=1e-10 * mu / K["GAy"])
    np.testing.assert_allclose(eq.stresses[:, 3 + axis], mu * (L - s), rtol=0,
                               atol=1e-10 * mu * L)


# ============================================================================================
# 2. A second method: scipy.integrate.solve_bvp on the rod equations
# ============================================================================================

@dataclass(frozen=True)
class Piece:
    """A uniformly loaded piece [a, b] of one segment (loads per unit length, N/m, N m/m)."""

    a: float
    b: float
    compliance: np.ndarray  # K⁻¹ of the segment
    reference_strain: np.ndarray  # f⁰ = (1, 0, 0, κ⁰)
    force_dead: np.ndarray  # spatial
    force_follower: np.ndarray  # material
    moment_dead: np.ndarray
    moment_follower: np.ndarray


def rod_rhs(piece: Piece, lam: float, Y: np.ndarray) -> np.ndarray:
    """d/ds of Y = (p, R row-major, n, m) (18, k), n and m spatial (Simo–Reissner rod):

        p' = R v,  R' = R û,  (v; u) = f⁰ + K⁻¹ (Rᵀ n; Rᵀ m),
        n' = -(f_dead + R f_follower),  m' = -p' × n - (l_dead + R l_follower).
    """
    p_dot_scale = piece.b - piece.a  # the piece is mapped onto τ ∈ [0, 1]
    R = Y[3:12].reshape(3, 3, -1)
    n, m = Y[12:15], Y[15:18]
    stress = np.concatenate([np.einsum("jik,jk->ik", R, n), np.einsum("jik,jk->ik", R, m)])
    strain = piece.reference_strain[:, None] + piece.compliance @ stress
    v, u = strain[:3], strain[3:]
    dp = np.einsum("ijk,jk->ik", R, v)
    u_hat = np.zeros((3, 3, Y.shape[1]))
    u_hat[0, 1], u_hat[0, 2], u_hat[1, 2] = -u[2], u[1], -u[0]
    u_hat[1, 0], u_hat[2, 0], u_hat[2, 1] = u[2], -u[1], u[0]
    dR = np.einsum("ijk,jlk->ilk", R, u_hat)
    dn = -lam * (piece.force_dead[:, None] + np.einsum("ijk,j->ik", R, piece.force_follower))
    dm = -np.cross(dp, n, axis=0) - lam * (piece.moment_dead[:, None]
                                           + np.einsum("ijk,j->ik", R, piece.moment_follower))
    return p_dot_scale * np.concatenate([dp, dR.reshape(9, -1), dn, dm])


def pieces_of(arm, cuts, load_on: Callable[[float, float, int], dict]) -> list[Piece]:
    """The arm cut at its joints and at ``cuts``; ``load_on(a, b, segment)`` gives the
    nonzero load densities of the piece [a, b] (keys force_dead, force_follower, ...)."""
    bounds = np.array(arm.boundaries)
    edges = np.unique(np.concatenate([bounds, np.asarray(cuts, dtype=float)]))
    pieces = []
    for a, b in itertools.pairwise(edges):
        k = min(int(np.searchsorted(bounds, 0.5 * (a + b))) - 1, len(arm.segments) - 1)
        seg = arm.segments[k]
        loads = dict(force_dead=np.zeros(3), force_follower=np.zeros(3),
                     moment_dead=np.zeros(3), moment_follower=np.zeros(3))
        loads.update({key: np.asarray(v, dtype=float) for key, v in load_on(a, b, k).items()})
        pieces.append(Piece(float(a), float(b), np.linalg.inv(seg.stiffness),
                            seg.reference_strain, **loads))
    return pieces


class BvpReference:
    """The equilibrium of ``pieces`` by solve_bvp, continued from the unloaded arm.

    The unknown is the stacked state of every piece on τ ∈ [0, 1]; boundary conditions: the
    clamped base p = 0, R = I; continuity between pieces; the tip wrench
    (n; m)(L) = W_dead + (R(L) F_f; R(L) M_f). Load factor λ = 1/steps, 2/steps, ..., 1, each
    solve starting from the previous solution (the first from the unloaded arm, integrated
    with solve_ivp).
    """

    def __init__(self, pieces, tip_dead=(0.0,) * 6, tip_follower=(0.0,) * 6, steps=4,
                 tol=1e-8, nodes=30):
        self.pieces = pieces
        P = len(pieces)
        tip_dead, tip_follower = np.asarray(tip_dead, float), np.asarray(tip_follower, float)

        def fun(_, Y, lam):
            return np.concatenate([rod_rhs(pc, lam, Y[18 * k:18 * k + 18])
                                   for k, pc in enumerate(pieces)])

        def bc(Ya, Yb, lam):
            parts = [Ya[0:3], Ya[3:12] - np.eye(3).ravel()]
            parts += [Ya[18 * (k + 1):18 * (k + 2)] - Yb[18 * k:18 * (k + 1)]
                      for k in range(P - 1)]
            tip = Yb[18 * (P - 1):]
            R_tip = tip[3:12].reshape(3, 3)
            parts.append(tip[12:15] - lam * (tip_dead[:3] + R_tip @ tip_follower[:3]))
            parts.append(tip[15:18] - lam * (tip_dead[3:] + R_tip @ tip_follower[3:]))
            return np.concatenate(parts)

        tau = np.linspace(0.0, 1.0, nodes)
        Y = np.empty((18 * P, nodes))
        y0 = np.concatenate([np.zeros(3), np.eye(3).ravel(), np.zeros(6)])
        for k, pc in enumerate(pieces):  # the unloaded arm: n = m = 0 stays 0
            run = solve_ivp(lambda _, y, pc=pc: rod_rhs(pc, 0.0, y[:, None])[:, 0], (0.0, 1.0),
                            y0, t_eval=tau, rtol=1e-12, atol=1e-14)
            Y[18 * k:18 * k + 18] = run.y
            y0 = run.y[:, -1]
        for lam in np.linspace(0.0, 1.0, steps + 1)[1:]:
            sol = solve_bvp(lambda t, y, lam=lam: fun(t, y, lam),
                            lambda a, b, lam=lam: bc(a, b, lam), tau, Y, tol=tol,
                            bc_tol=1e-12, max_nodes=100_000)
            assert sol.status == 0, f"solve_bvp reference failed at λ = {lam}: {sol.message}"
            tau, Y = sol.x, sol.y
        self.sol = sol

    def at(self, s):
        """(positions (S, 3), rotations (S, 3, 3), n spatial (S, 3), m spatial (S, 3))."""
        s = np.asarray(s, dtype=float)
        out = np.empty((s.size, 18))
        for k, pc in enumerate(self.pieces):
            inside = (s >= pc.a) & (s <= pc.b)
            tau = (s[inside] - pc.a) / (pc.b - pc.a)
            out[inside] = self.sol.sol(tau)[18 * k:18 * k + 18].T
        return out[:, :3], out[:, 3:12].reshape(-1, 3, 3), out[:, 12:15], out[:, 15:18]


def assert_matches_reference(eq, reference, atol_length):
    p, R, n, m = reference.at(eq.s)
    L = eq.arm.length
    np.testing.assert_allclose(eq.positions, p, rtol=0, atol=atol_length)
    np.testing.assert_allclose(eq.rotations, R, rtol=0, atol=atol_length / L)
    n_scale, m_scale = np.max(np.abs(n)), np.max(np.abs(m))
    np.testing.assert_allclose(eq.forces_spatial, n, rtol=0, atol=atol_length / L * n_scale)
    np.testing.assert_allclose(eq.moments_spatial, m, rtol=0, atol=atol_length / L * m_scale)


# the loads of the references: N/m and N m/m on ARM (EI of the thin segment 3.2e-3 N m²)
F_DEAD = np.array([0.3, -0.4, -0.6])
F_FOLLOWER = np.array([0.0, 0.3, -0.5])
M_FOLLOWER = np.array([0.005, 0.02, -0.015])
F_SPAN = np.array([0.2, -0.5, -0.8])
M_SEGMENT = np.array([0.0, 0.02, 0.01])
STATIONS = np.linspace(0.0, ARM.length, 41)


def _inside(a, b, span):
    return span[0] <= a and b <= span[1]


#: The solve_bvp references by name (built on first use, once per module).
REFERENCE_RECIPES = {
    "dead_force": lambda: BvpReference(pieces_of(
        ARM, [], lambda a, b, k: dict(force_dead=F_DEAD))),
    "dead_force_cut": lambda: BvpReference(pieces_of(  # extra cuts that change nothing
        ARM, [0.07, 0.31], lambda a, b, k: dict(force_dead=F_DEAD))),
    "follower_tip": lambda: BvpReference(pieces_of(ARM, [], lambda a, b, k: {}),
                                         tip_follower=[0.0, 0.02, -0.03, 0.002, 0.0, 0.0]),
    "follower_force": lambda: BvpReference(pieces_of(
        ARM, [], lambda a, b, k: dict(force_follower=F_FOLLOWER))),
    "follower_moment": lambda: BvpReference(pieces_of(
        ARM, [], lambda a, b, k: dict(moment_follower=M_FOLLOWER))),
    # a dead force on SPAN and a follower moment on segment 1
    "span_dead_force_segment_follower_moment": lambda: BvpReference(pieces_of(
        ARM, SPAN, lambda a, b, k: dict(
            force_dead=F_SPAN if _inside(a, b, SPAN) else np.zeros(3),
            moment_follower=M_SEGMENT if k == 1 else np.zeros(3)))),
    # a follower force on SPAN and a dead moment on segment 0
    "span_follower_force_segment_dead_moment": lambda: BvpReference(pieces_of(
        ARM, SPAN, lambda a, b, k: dict(
            force_follower=F_FOLLOWER if _inside(a, b, SPAN) else np.zeros(3),
            moment_dead=M_SEGMENT if k == 0 else np.zeros(3)))),
}


@pytest.fixture(scope="module")
def references():
    """``references(name)``: the solve_bvp reference, computed once per module."""
    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = REFERENCE_RECIPES[name]()
        return cache[name]

    return get


# --- the reference validated on today's solver -----------------------------------------------

@pytest.mark.slow
def test_bvp_reference_reproduces_the_dead_distributed_force(references):
    # Today's solver and the reference agree to 2e-12 L (measured); asserted at 1e-9 L.
    eq = numeric(ARM, DistributedForce(F_DEAD), s=STATIONS, tol=1e-11)
    assert_matches_reference(eq, references("dead_force"), 1e-9 * ARM.length)
    assert_matches_reference(eq, references("dead_force_cut"), 1e-9 * ARM.length)


def test_bvp_reference_reproduces_the_follower_tip_load(references):
    # The R(L) F_follower boundary condition of the reference against today's follower tip load.
    eq = numeric(ARM, TipLoad(force=[0.0, 0.02, -0.03], moment=[0.002, 0.0, 0.0],
                              follower=True), s=STATIONS, tol=1e-11)
    assert_matches_reference(eq, references("follower_tip"), 1e-9 * ARM.length)


def test_bvp_reference_reproduces_the_planar_follower_moment():
    # The follower-moment term R l of the reference against the closed form above.
    L, EI = 0.8, 1.0
    arm = Arm.from_stiffness(L, EA=20.0, GAy=8.0, GAz=12.0, GJ=0.7, EIy=EI, EIz=1.6)
    mu = 3.0 * EI / L**2
    ref = BvpReference(pieces_of(arm, [], lambda a, b, k: dict(moment_follower=[0, mu, 0])))
    s = np.linspace(0.0, L, 9)
    p, R, _ = planar_distributed_moment(L, mu, EI, 1, s)
    p_ref, R_ref, _, _ = ref.at(s)
    np.testing.assert_allclose(p_ref, p, rtol=0, atol=1e-9 * L)
    np.testing.assert_allclose(R_ref, R, rtol=0, atol=1e-9)


# --- the new loads against the reference -----------------------------------------------------

def test_follower_distributed_force_equals_solve_bvp(references):
    eq = numeric(ARM, DistributedForce(F_FOLLOWER, follower=True), s=STATIONS, tol=1e-10)
    assert_matches_reference(eq, references("follower_force"), 1e-6 * ARM.length)


def test_follower_distributed_moment_equals_solve_bvp(references):
    eq = numeric(ARM, distributed_moment(M_FOLLOWER, follower=True), s=STATIONS, tol=1e-10)
    assert_matches_reference(eq, references("follower_moment"), 1e-6 * ARM.length)


@pytest.mark.slow
def test_span_and_segment_restrictions_equal_solve_bvp(references):
    loads = [DistributedForce(F_SPAN, span=SPAN),
             distributed_moment(M_SEGMENT, follower=True, segment=1)]
    eq = numeric(ARM, loads, s=STATIONS, tol=1e-10)
    assert_matches_reference(eq, references("span_dead_force_segment_follower_moment"),
                             1e-6 * ARM.length)
    loads = [DistributedForce(F_FOLLOWER, follower=True, span=SPAN),
             distributed_moment(M_SEGMENT, segment=0)]
    eq = numeric(ARM, loads, s=STATIONS, tol=1e-10)
    assert_matches_reference(eq, references("span_follower_force_segment_dead_moment"),
                             1e-6 * ARM.length)


def test_whole_arm_span_and_every_segment_equal_the_unrestricted_load():
    whole = numeric(ARM, DistributedForce(F_FOLLOWER, follower=True), s=11, tol=1e-10)
    span = numeric(ARM, DistributedForce(F_FOLLOWER, follower=True, span=(0.0, ARM.length)),
                   s=11, tol=1e-10)
    split = numeric(ARM, [DistributedForce(F_FOLLOWER, follower=True, segment=0),
                          DistributedForce(F_FOLLOWER, follower=True, segment=1)],
                    s=11, tol=1e-10)
    for eq in (span, split):
        np.testing.assert_allclose(eq.poses, whole.poses, rtol=0, atol=1e-9)
        np.testing.assert_allclose(eq.stresses, whole.stresses, rtol=0,
                                   atol=1e-9 * np.max(np.abs(whole.stresses)))


# ============================================================================================
# 3. Global balance, rebuilt from the loads on [s, L]
# ============================================================================================

@dataclass(frozen=True)
class Distributed:
    """Densities on [a, b]: force (N/m) and moment (N m/m), spatial or material components."""

    a: float
    b: float
    force: np.ndarray
    moment: np.ndarray
    material: bool


@dataclass(frozen=True)
class Point:
    """A force and moment at station s (s = L: the tip), spatial or material components."""

    s: float
    force: np.ndarray
    moment: np.ndarray
    material: bool


def rebuilt_wrench(eq, terms):
    """The internal wrench (n, m) at every station, spatial, from the loads on [s, L]:

        n(s) = Σ F_j + ∫ₛᴸ f,   m(s) = Σ (M_j + (p_j - p(s)) × F_j) + ∫ₛᴸ (l + (p - p(s)) × f),

    material densities turned by the returned R(t); integrals by cumulative Simpson over the
    stations of each smooth interval: a term is split at the joints, where R and p have kinks
    (the ends and the joints must fall on stations). A station at an interior point load holds
    the side towards the tip (the load not included).
    """
    s, P, R = eq.s, eq.positions, eq.rotations
    n, m = np.zeros_like(P), np.zeros_like(P)
    L = eq.arm.length
    joints = eq.arm.boundaries[1:-1]
    smooth = []
    for term in terms:
        if isinstance(term, Point):
            smooth.append(term)
            continue
        cuts = [term.a, *[j for j in joints if term.a < j < term.b], term.b]
        smooth += [dataclasses.replace(term, a=a, b=b) for a, b in itertools.pairwise(cuts)]
    for term in smooth:
        if isinstance(term, Point):
            (j,) = np.flatnonzero(np.isclose(s, term.s, rtol=0, atol=1e-12))
            F = R[j] @ term.force if term.material else np.asarray(term.force)
            M = R[j] @ term.moment if term.material else np.asarray(term.moment)
            on = s < term.s if term.s < L else np.ones(s.size, bool)
            n[on] += F
            m[on] += M + np.cross(P[j] - P[on], F)
            continue
        inside = (s >= term.a - 1e-12) & (s <= term.b + 1e-12)
        i = np.flatnonzero(inside)
        assert np.isclose(s[i[0]], term.a, atol=1e-12) and np.isclose(s[i[-1]], term.b,
                                                                     atol=1e-12)
        turn = R[i] if term.material else np.eye(3)
        f = np.einsum("...ij,j->...i", turn, term.force) * np.ones((i.size, 1))
        lm = np.einsum("...ij,j->...i", turn, term.moment) * np.ones((i.size, 1))
        integrand = np.concatenate([f, lm + np.cross(P[i], f)], axis=1)
        forward = cumulative_simpson(integrand, x=s[i], axis=0, initial=0.0)
        to_b = forward[-1] - forward  # ∫ₜᵇ at the stations in [a, b]
        tail = np.zeros((s.size, 6))
        tail[i] = to_b
        tail[s < term.a - 1e-12] = forward[-1]
        n += tail[:, :3]
        m += tail[:, 3:] - np.cross(P, tail[:, :3])
    return n, m


def assert_balanced(eq, terms, rtol=1e-8):
    """The returned stresses (material (n; m)), turned to spatial by the returned R, equal
    the wrench rebuilt from the loads, to rtol of its largest component."""
    n, m = rebuilt_wrench(eq, terms)
    n_solved = np.einsum("sij,sj->si", eq.rotations, eq.stresses[:, :3])
    m_solved = np.einsum("sij,sj->si", eq.rotations, eq.stresses[:, 3:])
    n_scale = max(np.max(np.abs(n)), 1e-300)
    m_scale = max(np.max(np.abs(m)), 1e-300)
    np.testing.assert_allclose(n_solved, n, rtol=0, atol=rtol * n_scale)
    np.testing.assert_allclose(m_solved, m, rtol=0, atol=rtol * m_scale)


# ============================================================================================
# 4. One battery over every load kind
# ============================================================================================

@dataclass(frozen=True)
class Kind:
    """A load kind for the battery.

    build(fields) -> the load; sample(rng, shape) -> its vector fields with that batch shape;
    spatial: the fields given in spatial components (rotated by Rᵀ for a base frame R);
    terms(fields) -> the applied loads of ONE case as Distributed / Point terms on ARM.
    """

    name: str
    build: Callable[[dict], object]
    sample: Callable[[np.random.Generator, tuple], dict]
    spatial: tuple[str, ...]
    terms: Callable[[dict], list]
    follower: bool = False


def _vectors(**scales):
    def sample(rng, shape):
        return {name: scale * rng.normal(size=(*shape, 3)) for name, scale in scales.items()}
    return sample


def _zero():
    return np.zeros(3)


def _segment_span(k):
    return ARM.boundaries[k], ARM.boundaries[k + 1]


def _gravity_terms(f):
    return [Distributed(*_segment_span(k), seg.linear_density * np.asarray(f["acceleration"]),
                        _zero(), False) for k, seg in enumerate(ARM.segments)]


L_ARM = ARM.length
LOAD_KINDS = [
    Kind("tip_dead", lambda f: TipLoad(force=f["force"], moment=f["moment"]),
         _vectors(force=0.02, moment=1e-3), ("force", "moment"),
         lambda f: [Point(L_ARM, f["force"], f["moment"], False)]),
    Kind("tip_follower", lambda f: TipLoad(force=f["force"], moment=f["moment"], follower=True),
         _vectors(force=0.02, moment=1e-3), (),
         lambda f: [Point(L_ARM, f["force"], f["moment"], True)], follower=True),
    Kind("gravity", lambda f: Gravity(f["acceleration"]), _vectors(acceleration=2.0),
         ("acceleration",), _gravity_terms),
    Kind("point", lambda f: PointLoad(0.15, force=f["force"], moment=f["moment"]),
         _vectors(force=0.03, moment=1e-3), ("force", "moment"),
         lambda f: [Point(0.15, f["force"], f["moment"], False)]),
    Kind("distributed_force_dead", lambda f: DistributedForce(f["force"]),
         _vectors(force=0.3), ("force",),
         lambda f: [Distributed(0.0, L_ARM, f["force"], _zero(), False)]),
    Kind("distributed_force_dead_span", lambda f: DistributedForce(f["force"], span=SPAN),
         _vectors(force=0.15), ("force",),
         lambda f: [Distributed(*SPAN, f["force"], _zero(), False)]),
    Kind("distributed_force_follower",
         lambda f: DistributedForce(f["force"], follower=True),
         _vectors(force=0.1), (),
         lambda f: [Distributed(0.0, L_ARM, f["force"], _zero(), True)], follower=True),
    Kind("distributed_force_follower_span",
         lambda f: DistributedForce(f["force"], follower=True, span=SPAN),
         _vectors(force=0.15), (),
         lambda f: [Distributed(*SPAN, f["force"], _zero(), True)], follower=True),
    Kind("distributed_moment_dead", lambda f: distributed_moment(f["moment"]),
         _vectors(moment=5e-3), ("moment",),
         lambda f: [Distributed(0.0, L_ARM, _zero(), f["moment"], False)]),
    Kind("distributed_moment_dead_segment",
         lambda f: distributed_moment(f["moment"], segment=0),
         _vectors(moment=5e-3), ("moment",),
         lambda f: [Distributed(*_segment_span(0), _zero(), f["moment"], False)]),
    Kind("distributed_moment_follower",
         lambda f: distributed_moment(f["moment"], follower=True),
         _vectors(moment=5e-3), (),
         lambda f: [Distributed(0.0, L_ARM, _zero(), f["moment"], True)], follower=True),
    Kind("distributed_moment_follower_segment",
         lambda f: distributed_moment(f["moment"], follower=True, segment=1),
         _vectors(moment=5e-3), (),
         lambda f: [Distributed(*_segment_span(1), _zero(), f["moment"], True)],
         follower=True),
]
KIND_IDS = [kind.name for kind in LOAD_KINDS]


def _base_pose():
    H = np.eye(4)
    H[:3, :3] = expm(hat([0.4, -0.9, 0.3]))
    H[:3, 3] = [0.05, -0.1, 0.2]
    return H


@pytest.mark.parametrize("kind", LOAD_KINDS, ids=KIND_IDS)
def test_is_a_load_with_its_batch_shape(kind, rng):
    for shape in [(), (3,), (2, 1, 2)]:
        load = kind.build(kind.sample(rng, shape))
        assert isinstance(load, softarm.Load)
        assert load.batch_shape == shape


@pytest.mark.parametrize("shape", [(3,), (2, 1, 2)])
@pytest.mark.parametrize("kind", LOAD_KINDS, ids=KIND_IDS)
def test_batched_equals_looped(kind, shape, rng):
    fields = kind.sample(rng, shape)
    # a second load broadcasting against it: (2, 1, 2) with (3, 1) gives (2, 3, 2)
    background = 0.01 * rng.normal(size=(*((3, 1) if len(shape) > 1 else shape), 3))
    loads = [kind.build(fields), TipLoad(force=background)]
    batched = numeric(ARM, loads, s=9, tol=1e-10)
    full = np.broadcast_shapes(shape, background.shape[:-1])
    assert batched.poses.shape == (*full, 9, 4, 4)
    tip = np.broadcast_to(background, (*full, 3))
    for index in np.ndindex(*full):
        own = index[-len(shape):] if shape else ()
        own = tuple(i if n > 1 else 0 for i, n in zip(own, shape, strict=True))
        one = numeric(ARM, [kind.build({k: v[own] for k, v in fields.items()}),
                            TipLoad(force=tip[index])], s=9, tol=1e-10)
        np.testing.assert_allclose(batched.poses[index], one.poses, rtol=0, atol=1e-10)
        np.testing.assert_allclose(batched.stresses[index], one.stresses, rtol=0,
                                   atol=1e-10 * max(np.max(np.abs(one.stresses)), 1e-12))


@pytest.mark.parametrize("kind", LOAD_KINDS, ids=KIND_IDS)
def test_base_pose_moves_the_solution_rigidly(kind, rng):
    # Clamped at H = (R0, p0), a dead load with spatial components v is the load Rᵀ v in the
    # base frame; follower components are unchanged. Then solve(base=H) = H · solve.
    H = _base_pose()
    R0 = H[:3, :3]
    fields = kind.sample(rng, ())
    load = kind.build(fields)
    local_fields = {k: (R0.T @ v if k in kind.spatial else v) for k, v in fields.items()}
    moved = numeric(ARM, load, base=H, s=9, tol=1e-10)
    at_identity = numeric(ARM, kind.build(local_fields), s=9, tol=1e-10)
    np.testing.assert_allclose(moved.poses, H @ at_identity.poses, rtol=0, atol=1e-10)
    np.testing.assert_allclose(moved.stresses, at_identity.stresses, rtol=0,
                               atol=1e-10 * np.max(np.abs(at_identity.stresses)))
    # the load's own re-expression agrees with the one above
    own = numeric(ARM, load.in_base_frame(R0), s=9, tol=1e-10)
    np.testing.assert_allclose(own.poses, at_identity.poses, rtol=0, atol=1e-12)


@pytest.mark.parametrize("kind", LOAD_KINDS, ids=KIND_IDS)
def test_global_balance(kind, rng):
    fields = kind.sample(rng, ())
    eq = numeric(ARM, kind.build(fields), s=DENSE, tol=1e-10)
    assert_balanced(eq, kind.terms(fields))


def test_global_balance_of_every_kind_together(rng):
    loads, terms = [], []
    for kind in LOAD_KINDS:
        fields = kind.sample(rng, ())
        loads.append(kind.build(fields))
        terms += kind.terms(fields)
    eq = numeric(ARM, loads, s=DENSE, tol=1e-10)
    assert_balanced(eq, terms)


@pytest.mark.parametrize(("name", "terms"), [
    ("follower_force", [Distributed(0.0, L_ARM, F_FOLLOWER, _zero(), True)]),
    ("follower_moment", [Distributed(0.0, L_ARM, _zero(), M_FOLLOWER, True)]),
    ("span_dead_force_segment_follower_moment",
     [Distributed(*SPAN, F_SPAN, _zero(), False),
      Distributed(*_segment_span(1), _zero(), M_SEGMENT, True)]),
    ("span_follower_force_segment_dead_moment",
     [Distributed(*SPAN, F_FOLLOWER, _zero(), True),
      Distributed(*_segment_span(0), _zero(), M_SEGMENT, False)]),
], ids=["follower_force", "follower_moment", "span_dead_force_segment_follower_moment",
        "span_follower_force_segment_dead_moment"])
def test_balance_reference_reproduces_the_bvp_solutions(references, name, terms):
    # The two references check each other on today's code: the wrench rebuilt from the loads
    # on [s, L] and the solve_bvp poses equals the solve_bvp wrench (to its accuracy).
    p, R, n, m = references(name).at(DENSE)
    stresses = np.concatenate([np.einsum("sji,sj->si", R, n), np.einsum("sji,sj->si", R, m)],
                              axis=1)  # material components, Rᵀ n and Rᵀ m
    state = SimpleNamespace(s=DENSE, positions=p, rotations=R, arm=ARM, stresses=stresses)
    assert_balanced(state, terms)


def _toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise TypeError(f"loads_to_dict gave {value!r}, which a TOML file cannot hold")


def _toml_loads(tables) -> str:
    """The [[load]] tables as TOML text (a minimal writer: numbers, bools, strings, lists)."""
    return "".join("[[load]]\n" + "".join(f"{key} = {_toml_value(v)}\n" for key, v in t.items())
                   for t in tables)


@pytest.mark.parametrize("kind", LOAD_KINDS, ids=KIND_IDS)
def test_case_file_round_trip(kind, rng):
    load = kind.build(kind.sample(rng, ()))
    tables = loads_to_dict([load])
    data = tomllib.loads(_toml_loads(tables))
    case = parse_case({"name": "round trip", **arm_to_dict(ARM), **data})
    assert len(case.loads) == 1 and type(case.loads[0]) is type(load)
    assert loads_to_dict(case.loads) == tables
    np.testing.assert_array_equal(numeric(ARM, case.loads, s=5).poses,
                                  numeric(ARM, load, s=5).poses)


@pytest.mark.parametrize("kind", LOAD_KINDS, ids=KIND_IDS)
def test_describe_is_one_line(kind, rng):
    text = kind.build(kind.sample(rng, ())).describe()
    assert isinstance(text, str) and text.strip() and "\n" not in text
    assert ("follower" in text.lower()) == kind.follower


def test_descriptions_tell_the_kinds_apart():
    fields = {"force": np.array([0.0, 0.0, -1.0]), "moment": np.array([0.0, 1.0, 0.0]),
              "acceleration": np.array([0.0, 0.0, -9.81])}
    texts = [kind.build({k: fields[k] for k in kind.sample(np.random.default_rng(0), ())})
             .describe() for kind in LOAD_KINDS]
    assert len(set(texts)) == len(texts), texts


def test_an_undeclared_load_kind_fails_closed():
    # Issue 13: a kind registered without its kernel contribution was silently dropped. A
    # subclass of Load that declares nothing must be refused (at construction or at solve),
    # never solved as if it were absent.
    class Probe(softarm.Load):
        pass

    arm = Arm(0.3, Circle(0.01), SOFT)
    with pytest.raises((TypeError, NotImplementedError)):
        softarm.solve(arm, [Gravity(), Probe()])
    with pytest.raises((TypeError, NotImplementedError)):
        loads_to_dict([Probe()])


@pytest.mark.parametrize("make", [
    lambda: TipLoad([0.0, 0.0, 1.0], [0.0, 0.0, 0.0], True),
    lambda: DistributedForce([0.0, 0.0, 1.0], True),
    lambda: distributed_moment([0.0, 0.0, 1.0], True),
], ids=["TipLoad", "DistributedForce", "DistributedMoment"])
def test_follower_is_keyword_only(make):
    # issue 13 §4: ``follower`` is keyword-only everywhere
    with pytest.raises(TypeError):
        make()


@pytest.mark.parametrize("bad", [object(), "gravity", {"kind": "tip"}, 3.0],
                         ids=["object", "str", "dict", "float"])
def test_a_non_load_is_a_type_error_naming_it(bad):
    # "naming it": its type or its repr appears in the message
    arm = Arm(0.3, Circle(0.01), SOFT)
    for loads in (bad, [Gravity(), bad]):
        with pytest.raises(TypeError) as info:
            softarm.solve(arm, loads)
        message = str(info.value)
        assert type(bad).__name__ in message or repr(bad) in message, message


# ============================================================================================
# 5. Bad input
# ============================================================================================

@pytest.mark.parametrize("cls", ["DistributedForce", "DistributedMoment"])
@pytest.mark.parametrize(("restriction", "parameter", "errors"), [
    (dict(span=(0.3, 0.1)), "span", ValueError),              # backward
    (dict(span=(-0.05, 0.1)), "span", ValueError),            # starts before the base
    (dict(span=(0.1, 0.45)), "span", ValueError),             # ends beyond the tip (L = 0.4)
    (dict(span=(0.1, 0.2, 0.3)), "span", (ValueError, TypeError)),  # not a pair
    (dict(span=(0.1, np.nan)), "span", ValueError),           # not finite
    (dict(segment=2), "segment", ValueError),                 # ARM has segments 0 and 1
    (dict(segment=0.5), "segment", (ValueError, TypeError)),  # not an index
    (dict(span=(0.1, 0.2), segment=0), "span", ValueError),   # both given
], ids=["backward", "negative", "beyond_tip", "triple", "nan", "segment_out_of_range",
        "segment_not_int", "span_and_segment"])
def test_bad_restriction_is_an_error_naming_the_parameter(cls, restriction, parameter, errors):
    # The error may come from the constructor or from solve (which knows the arm).
    with pytest.raises(errors, match=parameter) as info:
        load = getattr(softarm, cls)([0.0, 0.0, 0.1], **restriction)
        numeric(ARM, load, s=3)
    message = str(info.value)
    assert "unexpected keyword" not in message, message  # the keyword itself must exist
    if "segment" in restriction:
        assert "segment" in message
