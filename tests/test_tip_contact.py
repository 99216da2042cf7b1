"""A free tip held on obstacles, exactly (issue 39; softarm/statics/tip_contact.py).

- the held arm against an independent solve_bvp of the planar Reissner rod with the
  obstacle's reaction as an unknown (tests/_tip_reference.py), flat and tilted planes, with
  gravity, and a pin (a capsule across the bending plane);
- the verdict on a ball: a tip pulled against a ball ahead of it slides off (unstable) where
  the pull over the ball's radius exceeds the tip's lateral stiffness, a closed form;
- the propped cantilever with shear compliance (the force on the plane, no δ);
- the contact wrench against the solve's global balance;
- the held arm's Jacobians (compliance and actuation) against finite differences of solves;
- the cases the route does not hold (an arm lying on a table, a column held past its free
  buckling load) are the penalty's, and a batch of both equals its cases one by one.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from _tip_reference import tip_on_circle, tip_on_plane

import softarm as sa
from softarm.contact import balance
from softarm.routing import Straight

L = 0.5
RADIUS = 0.01


def _arm(E):
    return sa.Arm(L, sa.Circle(RADIUS), sa.Material(youngs_modulus=E, poisson_ratio=0.5,
                                                     density=1000.0))


def _plane(point, normal):  # (x, z) pairs: the planes of the x-z bending plane
    return sa.Plane((point[0], 0.0, point[1]), (normal[0], 0.0, normal[1]))


@pytest.mark.parametrize(("E", "gravity", "force", "point", "normal"), [
    (1e6, False, (0.0, -0.05), (0.0, -0.1), (0.0, 1.0)),   # the tip lands at 60° or so
    (2e7, True, (0.0, -0.2), (0.0, -0.04), (0.3, 1.0)),    # a heavy arm on a tilted plane
])
def test_a_held_tip_matches_the_reissner_rod_with_the_planes_reaction(E, gravity, force,
                                                                      point, normal):
    arm = _arm(E)
    rig = arm.rigidities
    weight = arm.linear_density * 9.81 if gravity else 0.0
    ref = tip_on_plane(L, rig.EA, rig.GAy, rig.EIy, RADIUS, weight, force, point, normal)
    loads = [sa.TipLoad(force=(force[0], 0.0, force[1]))] + ([sa.Gravity()] if gravity else [])
    eq = sa.solve(arm, [*loads, sa.Contact(_plane(point, normal))], s=101)
    assert eq.method == "numeric.tip_contact"
    assert np.abs(eq.positions - ref.positions(eq.s)).max() < 1e-7 * L  # (measured 1e-8 L)
    assert eq.contact_wrench[[0, 2]] == pytest.approx(ref.reaction, rel=1e-7, abs=1e-12)
    assert eq.contact_wrench[1] == 0.0
    # the contact wrench is the global balance: the base wrench less the other loads
    s = np.linspace(0.0, L, 2001)
    fine = sa.solve(arm, [*loads, sa.Contact(_plane(point, normal))], s=s)
    assert fine.contact_wrench == pytest.approx(
        balance(arm, loads, s, fine.poses, fine.base_wrench), abs=1e-9)
    # the tip's surface on the plane, and no station inside it
    assert fine.gaps[-1] == pytest.approx(0.0, abs=1e-2 * 1e-8 * L)
    assert fine.gaps.min() >= -1e-8 * L
    assert eq.stability.stable


def test_a_tip_held_on_a_pin_matches_the_reissner_rod_with_its_reaction():
    """A pin (a capsule across the bending plane) under the free tip's path: the reaction
    turns with the contact point, found along the load path from the first touch."""
    arm = _arm(1e6)
    rig = arm.rigidities
    centre, radius = (0.5, -0.25), 0.1
    ref = tip_on_circle(L, rig.EA, rig.GAy, rig.EIy, RADIUS, 0.0, (0.0, -0.05), centre,
                        radius)
    pin = sa.Capsule((centre[0], -0.1, centre[1]), (centre[0], 0.1, centre[1]), radius)
    eq = sa.solve(arm, [sa.TipLoad(force=(0.0, 0.0, -0.05)), sa.Contact(pin)], s=101)
    assert eq.method == "numeric.tip_contact"
    assert np.abs(eq.positions - ref.positions(eq.s)).max() < 1e-7 * L  # (measured 7e-9 L)
    assert eq.contact_wrench[[0, 2]] == pytest.approx(ref.reaction, rel=1e-6)
    assert eq.stability.stable


def test_a_reaction_past_the_free_arms_buckling_follows_the_contacts_path():
    """A tip pressed by 2 N onto a plane tilted 50° (rising ahead of it): the plane pushes
    it back towards the clamp with 2.4 N, past the free arm's buckling load π²/4 EI/L² =
    1.55 N. The free arm under that dead reaction, solved from the unloaded arm, ends on
    another branch whose tip is on the plane too (0.77 L away: it was returned, stable);
    the answer is the contact path's, as the Reissner rod's continuation finds it, with
    the out-of-plane direction in which the compressed arm, its tip free to slide along y,
    buckles (Morse index 1)."""
    arm = sa.Arm(L, sa.Circle(RADIUS), sa.Material(youngs_modulus=2e7, poisson_ratio=0.5,
                                                    density=1000.0))
    rig = arm.rigidities
    tilt = np.radians(50.0)
    normal = (-np.sin(tilt), np.cos(tilt))
    point = (L - RADIUS * normal[0], -0.01 - RADIUS * normal[1])
    ref = tip_on_plane(L, rig.EA, rig.GAy, rig.EIy, RADIUS, 0.0, (0.0, -2.0), point, normal)
    assert -ref.reaction @ np.array([1.0, 0.0]) > np.pi ** 2 / 4 * rig.EIy / L ** 2
    with pytest.warns(sa.StabilityWarning, match="Morse index 1"):
        eq = sa.solve(arm, [sa.TipLoad(force=(0.0, 0.0, -2.0)),
                            sa.Contact(_plane(point, normal))], s=101)
    assert eq.method == "numeric.tip_contact"
    assert np.abs(eq.positions - ref.positions(eq.s)).max() < 1e-7 * L  # (6.8e-11 L)
    assert eq.contact_wrench[[0, 2]] == pytest.approx(ref.reaction, rel=1e-7)
    assert eq.stability.index == 1 and eq.stability.conservative
    # its compliance (the normal held) against central differences of such solves
    h, plane = 1e-3, sa.Contact(_plane(point, normal))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sa.StabilityWarning)
        held = sa.solve(arm, [sa.TipLoad(force=(0.0, 0.0, -2.0)), plane], s=101,
                        jacobians=True)
        moved = [sa.solve(arm, [sa.TipLoad(force=(sign * h, 0.0, -2.0)), plane],
                          s=101).tip_position for sign in (1.0, -1.0)]
    column = (moved[0] - moved[1]) / (2 * h)
    assert held.tip_compliance[:3, 0] == pytest.approx(column, rel=1e-4,
                                                        abs=1e-4 * np.abs(column).max())


@pytest.mark.parametrize(("ratio", "index"), [(0.98, 2), (1.02, 0)])
def test_a_tip_pulled_against_a_ball_slides_off_where_the_closed_form_says(ratio, index):
    """A tip force P pulls the straight arm's tip against a ball ahead of it, whose centre
    lies ρ ahead of the tip's centreline: held, the arm carries no force (λ = P), and a
    lateral move δ of the tip turns the reaction by δ/ρ, a force P δ/ρ that pushes it on,
    against the tip's lateral stiffness 1/c, c = L³/(3 EI) + L/GA. It slides off (Morse
    index 2: both lateral directions of a round arm) where P c > ρ; a flat plane (ρ → ∞)
    would hold it."""
    arm = _arm(1e6)
    rig = arm.rigidities
    force = 0.05
    rho = ratio * force * (L**3 / (3.0 * rig.EIy) + L / rig.GAy)
    ball = sa.Sphere((L + rho, 0.0, 0.0), rho - RADIUS)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sa.StabilityWarning)
        eq = sa.solve(arm, [sa.TipLoad(force=(force, 0.0, 0.0)), sa.Contact(ball)])
    assert eq.method == "numeric.tip_contact"
    assert eq.contact_wrench[:3] == pytest.approx((-force, 0.0, 0.0), abs=1e-12)
    assert eq.stability.index == index


def test_a_tip_held_on_a_pin_has_the_jacobians_of_finite_differences():
    """The reaction turns with the tip on a pin: the held compliance has the term
    λ ∇²d of the contact's curvature (against central differences of held solves)."""
    arm = _arm(1e6)
    pin = sa.Contact(sa.Capsule((0.5, -0.1, -0.25), (0.5, 0.1, -0.25), 0.1))
    loads = [sa.TipLoad(force=(0.0, 0.0, -0.05))]
    eq = sa.solve(arm, [*loads, pin], jacobians=True)
    assert eq.method == "numeric.tip_contact"

    def tip(extra):
        held = sa.solve(arm, [*loads, sa.TipLoad(force=extra), pin], tol=1e-12,
                        stability=False)
        assert held.method == "numeric.tip_contact"
        return held.tip_position

    for j in range(3):
        column = _central(lambda e, j=j: tip(np.eye(3)[j] * e), 1e-4)
        assert eq.tip_compliance[:3, j] == pytest.approx(column, rel=1e-4, abs=1e-9)


def test_the_propped_cantilevers_force_needs_no_contact_distance():
    """The free tip 0.5 mm above a plane, pressed on it by 0.05 N: the propped cantilever
    with shear compliance (small deflection: the tip moves w = P c, c = L³/(3 EI) + L/GA,
    under the net P) puts F - w/c = 0.049906 N on the plane; its own error is O((w/L)²)
    = 1e-6. The penalty's answer was first order in δ (3.4e-4 off at δ = 1e-6 m)."""
    arm = _arm(1e6)
    rig = arm.rigidities
    force, gap = 0.05, 5e-4
    c = L**3 / (3.0 * rig.EIy) + L / rig.GAy
    plane = sa.Plane((0.0, 0.0, -(RADIUS + gap)), (0.0, 0.0, 1.0))
    eq = sa.solve(arm, [sa.TipLoad(force=(0.0, 0.0, -force)), sa.Contact(plane)])
    assert eq.method == "numeric.tip_contact"
    assert eq.contact_wrench[2] == pytest.approx(force - gap / c, rel=2e-6)
    assert eq.contact_wrench[4] == pytest.approx(-L * (force - gap / c), rel=2e-6)
    assert np.all(eq.contact_forces == 0.0)  # (a point force: no force per length)
    # a chained Solver (a quasi-static sweep, the app) holds it too, the same answer
    solver = sa.statics.Solver(arm)
    solver.solve([sa.TipLoad(force=(0.0, 0.0, -0.02)), sa.Contact(plane)])
    chained = solver.solve([sa.TipLoad(force=(0.0, 0.0, -force)), sa.Contact(plane)])
    assert chained.method == "numeric.tip_contact"
    assert np.array_equal(chained.positions, eq.positions)


def _central(solve, h):
    return (solve(h) - solve(-h)) / (2.0 * h)


def test_a_held_tips_jacobians_match_finite_differences():
    arm = _arm(2e7)
    plane = sa.Contact(_plane((0.0, -0.05), (0.2, 1.0)))
    chamber = sa.Chamber(5e4, 2e-5, Straight(0.0, -0.006))
    loads = [sa.Gravity(), sa.TipLoad(force=(0.0, 0.0, -0.05)), chamber]
    eq = sa.solve(arm, [*loads, plane], jacobians=True)
    assert eq.method == "numeric.tip_contact"
    assert eq.contact_wrench[2] > 0.01  # (pressed)

    def tip(extra=(0.0,) * 6, pressure=5e4):
        extra = np.asarray(extra)
        held = sa.solve(arm, [*loads[:2], chamber.replace(pressure=pressure),
                              sa.TipLoad(force=extra[:3], moment=extra[3:]), plane], tol=1e-12,
                        stability=False)  # (a dead couple has no verdict: not conservative)
        assert held.method == "numeric.tip_contact"
        R = held.tip[:3, :3]
        turned = R @ eq.tip[:3, :3].T  # the rotation vector of the small turn
        angle = 0.5 * np.array([turned[2, 1] - turned[1, 2], turned[0, 2] - turned[2, 0],
                                turned[1, 0] - turned[0, 1]])
        return np.concatenate([held.tip_position, angle])

    for j, h in enumerate((1e-4,) * 3 + (1e-5,) * 3):
        column = _central(lambda e, j=j: tip(np.eye(6)[j] * e), h)
        assert eq.tip_compliance[:, j] == pytest.approx(column, rel=1e-4, abs=1e-9)
    pressure = _central(lambda e: tip(pressure=5e4 + e), 10.0)
    assert eq.actuation_jacobian[:, 0] == pytest.approx(pressure, rel=1e-4, abs=1e-12)
    # held: the tip does not move along the plane's normal, whatever the wrench
    normal = np.array([0.2, 0.0, 1.0]) / np.hypot(0.2, 1.0)
    assert np.abs(normal @ eq.tip_compliance[:3]).max() < 1e-9 * np.abs(eq.tip_compliance).max()
    # every station's compliance ends in the tip's
    assert eq.compliance[-1] == pytest.approx(eq.tip_compliance, abs=1e-14)


def test_cases_the_tip_cannot_hold_are_the_penaltys_and_a_batch_equals_its_cases():
    """A batch of a held tip, a free arm that does not reach the plane, and an arm that lies
    on it (contact zones: the penalty's): each case equals its own solve to the bit."""
    arm = _arm(1e6)
    plane = sa.Contact(sa.Plane((0.0, 0.0, -0.1 - RADIUS), (0.0, 0.0, 1.0)))
    forces = np.array([[0.0, 0.0, -0.05], [0.0, 0.01, -0.01], [0.0, 0.0, 0.0]])
    weights = np.array([[0.0, 0.0, -0.5], [0.0, 0.0, 0.0], [0.0, 0.0, -2.0]])  # (N/m)
    s = np.linspace(0.0, L, 21)
    batch = sa.solve(arm, [sa.TipLoad(force=forces), sa.DistributedForce(force=weights),
                           plane], s=s)
    methods = []
    for b, (force, weight) in enumerate(zip(forces, weights, strict=True)):
        one = sa.solve(arm, [sa.TipLoad(force=force), sa.DistributedForce(force=weight),
                             plane], s=s)
        methods.append(one.method)
        assert np.array_equal(batch.positions[b], one.positions)
        assert np.array_equal(batch.contact_wrench[b], one.contact_wrench)
        assert np.array_equal(batch.contact_forces[b], one.contact_forces)
    assert methods == ["numeric.tip_contact", "numeric.tip_contact", "numeric.shooting"]
    assert batch.contact_wrench[1] == pytest.approx(np.zeros(6), abs=0.0)
    # the lying arm: pressure along a zone (the penalty's), and on the held tip none
    assert np.count_nonzero(np.abs(batch.contact_forces[2]).max(-1)) >= 3
    assert not np.any(batch.contact_forces[:2])


def test_pictures_draw_a_held_tips_reaction_at_the_tip():
    from softarm.geometry import contact_arrows

    arm = _arm(1e6)
    eq = sa.solve(arm, [sa.TipLoad(force=(0.0, 0.0, -0.05)),
                        sa.Contact(_plane((0.0, -0.1), (0.0, 1.0)))], s=21)
    arrow = contact_arrows(eq)
    assert arrow.unit == "N" and arrow.label == "contact force at the tip"
    assert arrow.origins == pytest.approx(eq.tip_position[None], abs=0.0)
    assert arrow.vectors[0] == pytest.approx(eq.contact_wrench[:3], abs=0.0)
    # a penalty's (the same contact with δ given): forces per length, at their stations
    penalty = sa.solve(arm, [sa.TipLoad(force=(0.0, 0.0, -0.05)),
                             sa.Contact(_plane((0.0, -0.1), (0.0, 1.0)), distance=1e-3)],
                       s=np.linspace(0.0, L, 2001))
    arrow = contact_arrows(penalty)
    assert arrow.unit == "N/m" and len(arrow.origins) >= 1



def test_the_cli_says_the_held_tips_reaction(capsys):
    """``softarm solve`` on examples/probe_on_surface.toml: the summary's contact line is the
    tip's reaction, the solve's contact wrench (its digits)."""
    from pathlib import Path

    from softarm import cli
    from softarm.case import load_case

    path = Path(__file__).resolve().parents[1] / "examples" / "probe_on_surface.toml"
    assert cli.main(["solve", str(path)]) == 0
    line = next(line for line in capsys.readouterr().out.splitlines()
                if line.startswith("contact"))
    case = load_case(path)
    eq = sa.solve(case.arm, case.loads, s=int(case.solve.stations))
    printed = [float(v) for v in line.split("(")[1].split(")")[0].split(",")]
    assert line.startswith("contact   the tip held exactly: reaction (")
    assert printed == pytest.approx(eq.contact_wrench[:3], rel=1e-4, abs=1e-9)


def test_a_free_path_through_a_thin_pin_is_not_held():
    """The free arm sweeps down through a thin pin under its middle (it ends below it, the
    pin untouched) and lands its tip on a floor: held at the tip alone, the arm would have
    passed through the pin. The path's check sees it (the arm's surface is given 0.5 mm
    thin, the pin 0.5 mm: the sampled states straddle it) and leaves the case to the
    penalty; without the pin the tip is held."""
    from softarm.statics import Solver
    from softarm.statics.solver import _contact_stations
    from softarm.statics.tip_contact import solve_tip_contact

    arm = _arm(1e6)
    pin = sa.Capsule((0.2, -0.1, -0.0011), (0.2, 0.1, -0.0011), 0.0005)
    floor = sa.Plane((0.0, 0.0, -0.15), (0.0, 0.0, 1.0))
    solver = Solver(arm)
    fine, asked = _contact_stations(solver._s_kernel, L, np.array([L]))
    for obstacles, held in (([pin, floor], False), ([floor], True)):
        loads, shape = solver.check_loads([sa.TipLoad(force=(0.0, 0.0, -0.05)),
                                           sa.Contact(obstacles, radius=0.0005)])
        found = solve_tip_contact(solver, loads, shape, False, fine, asked)
        assert (found is not None) == held
    # the free arm does pass through the pin's place and end below it, clear of it
    free = sa.solve(arm, [sa.TipLoad(force=(0.0, 0.0, -0.05))], s=201, method="numeric")
    assert sa.Contact(pin).gaps(free.positions, 0.0005)[0].min() > 0.01
