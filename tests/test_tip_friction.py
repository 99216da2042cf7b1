"""Coulomb friction at a free tip held on an obstacle (issue 39; statics/tip_friction.py).

- a tip that sticks (μ above the stuck force's lean on the whole path: it needs 0.9 μ N at
  most) against an independent solve_bvp of the planar Reissner rod whose tip's cap rolls
  on the plane without sliding from where it first touched (tests/_tip_reference.py);
- a tip that slides (the stuck force would need 1.1 μ N at least) against the same rod with
  Coulomb's force μ N at the contact point;
- the contact wrench against the solve's global balance; the answer converging as tol
  shrinks, with no δ; a load across the bending plane (a slide that turns) converging as
  the path's steps are refined;
- a chained Solver follows the quasi-static path of its solves: loaded in steps it ends
  where one solve does (a slide's end does not depend on the way), and unloaded after the
  slide its tip sticks, rolling from where it slid to (the reference rolls from there);
- a stuck tip's compliance against central differences of chained solves; a batch equals
  its cases one by one; Jacobians where they are not built (a sliding tip) are refused,
  saying why.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest
from _tip_reference import tip_sliding_on_plane, tip_stuck_from, tip_stuck_on_plane

import softarm as sa
from softarm.case import parse_case, solve_case
from softarm.cli import _contact_line
from softarm.contact import balance
from softarm.statics import Solver, tip_friction

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

L = 0.5
RADIUS = 0.01
POINT, NORMAL = (0.0, -0.04), (0.0, 1.0)  # a floor 40 mm below the clamp (x, z)
FLOOR = sa.Plane((POINT[0], 0.0, POINT[1]), (NORMAL[0], 0.0, NORMAL[1]))


@pytest.fixture(scope="module")
def arm():
    return sa.Arm(L, sa.Circle(RADIUS), sa.Material(youngs_modulus=2e7, poisson_ratio=0.5,
                                                    density=1000.0))


@pytest.fixture(scope="module")
def stuck(arm):
    """The heavy arm's tip on the floor, rolling without sliding from its first touch."""
    rig = arm.rigidities
    return tip_stuck_on_plane(L, rig.EA, rig.GAy, rig.EIy, RADIUS,
                              arm.linear_density * 9.81, (0.0, 0.0), POINT, NORMAL)


def _lean(wrench):
    """|f_t| / f_n of the floor's force on the tip."""
    f = np.asarray(wrench)[..., :3]
    return np.hypot(f[..., 0], f[..., 1]) / f[..., 2]


def test_a_stuck_tip_matches_the_reissner_rod_rolling_on_the_floor(arm, stuck):
    # the path's stuck force leans 3.87-4.05 (measured), so with μ = max/0.9 the tip
    # sticks from its first touch to the full load
    mu = stuck.ratios.max() / 0.9
    eq = sa.solve(arm, [sa.Gravity(), sa.Contact(FLOOR, friction=mu)], s=101)
    assert eq.method == "numeric.tip_contact"
    assert np.abs(eq.positions - stuck.positions(eq.s)).max() < 1e-7 * L  # (5.4e-9 L)
    assert eq.contact_wrench[[0, 2]] == pytest.approx(stuck.reaction, rel=1e-6)
    assert _lean(eq.contact_wrench) == pytest.approx(0.9 * mu * stuck.ratios[-1]
                                                     / stuck.ratios.max(), rel=1e-6)
    # without friction the tip slides back where the stuck one is held: 0.5 mm further out
    smooth = sa.solve(arm, [sa.Gravity(), sa.Contact(FLOOR)], s=101)
    assert smooth.tip_position[0] - eq.tip_position[0] == pytest.approx(2.2e-4, rel=0.05)
    # friction is not conservative: the verdict is not decided, the held index 0
    assert not eq.stability.conservative
    assert eq.stability.index == 0
    assert "friction" in eq.stability.describe()
    assert "(stuck: tangential 3.039 N, 0.9 × μ × the normal 0.751 N)" in _contact_line(eq)


def test_a_sliding_tip_matches_the_reissner_rod_with_coulombs_force(arm, stuck):
    mu = stuck.ratios.min() / 1.1  # the stuck force would lean 1.1 μ at least: it slides
    rig = arm.rigidities
    side = np.sign(stuck.reaction[0])  # (friction holds the tip back as the stuck force)
    ref = tip_sliding_on_plane(L, rig.EA, rig.GAy, rig.EIy, RADIUS,
                               arm.linear_density * 9.81, (0.0, 0.0), POINT, NORMAL, mu,
                               side)
    eq = sa.solve(arm, [sa.Gravity(), sa.Contact(FLOOR, friction=mu)], s=101)
    assert eq.method == "numeric.tip_contact"
    assert np.abs(eq.positions - ref.positions(eq.s)).max() < 1e-7 * L  # (1.3e-9 L)
    assert eq.contact_wrench[[0, 2]] == pytest.approx(ref.reaction, rel=1e-6)
    assert _lean(eq.contact_wrench) == pytest.approx(mu, rel=1e-9)  # |f_t| = μ N
    assert "(sliding: tangential 2.437 N, 1 × μ × the normal 0.6927 N)" in _contact_line(eq)
    # the contact wrench is the global balance: the base wrench less the weight
    s = np.linspace(0.0, L, 2001)
    fine = sa.solve(arm, [sa.Gravity(), sa.Contact(FLOOR, friction=mu)], s=s)
    assert fine.contact_wrench == pytest.approx(
        balance(arm, [sa.Gravity()], s, fine.poses, fine.base_wrench), abs=1e-9)
    assert fine.gaps[-1] == pytest.approx(0.0, abs=1e-2 * 1e-8 * L)
    assert fine.gaps.min() >= -1e-8 * L


def test_the_stuck_tip_converges_as_tol_shrinks_with_no_contact_distance(arm, stuck):
    mu = stuck.ratios.max() / 0.9
    errors = []
    for tol in (1e-6, 1e-8, 1e-10):
        eq = sa.solve(arm, [sa.Gravity(), sa.Contact(FLOOR, friction=mu)], s=101, tol=tol)
        errors.append(np.abs(eq.positions - stuck.positions(eq.s)).max() / L)
        assert errors[-1] < 10 * tol
    assert errors[2] < errors[0] / 100  # (measured 5.4e-9 L at 1e-8, 3.5e-11 L at 1e-10)


@pytest.mark.slow
def test_a_slide_across_the_bending_plane_converges_as_the_paths_steps_are_refined(
        arm, monkeypatch):
    """A tip force across the bending plane turns the slide's direction on the way: the
    answer at the path's own step count (32, BDF2's way) against the path in 128 steps."""
    loads = [sa.Gravity(), sa.TipLoad(force=(0.0, 0.05, 0.0)), sa.Contact(FLOOR,
                                                                           friction=0.3)]
    eq = sa.solve(arm, loads, s=101)
    assert eq.method == "numeric.tip_contact"
    assert -0.05 < eq.contact_wrench[1] < 0.0  # (the friction holds the tip against the pull)
    assert _lean(eq.contact_wrench) == pytest.approx(0.3, rel=1e-9)
    monkeypatch.setattr(tip_friction, "FRICTION_STEPS", (64, 128))
    refined = sa.solve(arm, loads, s=101)
    assert np.abs(eq.positions - refined.positions).max() < 2e-8 * L  # (1.1e-9 L)


@pytest.mark.slow
def test_a_chained_solver_follows_the_path_of_its_solves(arm, stuck):
    mu = stuck.ratios.min() / 1.1
    rig, weight = arm.rigidities, arm.linear_density * 9.81
    side = np.sign(stuck.reaction[0])
    contact = sa.Contact(FLOOR, friction=mu)
    solver = Solver(arm, s=np.linspace(0.0, L, 101))
    for g in (0.6, 0.8, 1.0):  # loaded in steps: the slide ends where one solve's does
        loaded = solver.solve([sa.Gravity().scaled(g), contact])
    once = sa.solve(arm, [sa.Gravity(), contact], s=101)
    assert np.abs(loaded.positions - once.positions).max() < 1e-8 * L  # (9.4e-10 L)
    assert _lean(loaded.contact_wrench) == pytest.approx(mu, rel=1e-9)
    # unloaded to 0.7 of the weight: the stuck force leans less than μ, and the cap rolls
    # on the floor from where the slide left it (a path no single solve takes)
    slid = tip_sliding_on_plane(L, rig.EA, rig.GAy, rig.EIy, RADIUS, weight, (0.0, 0.0),
                                POINT, NORMAL, mu, side)
    ref = tip_stuck_from(L, rig.EA, rig.GAy, rig.EIy, RADIUS, weight, (0.0, 0.0), POINT,
                         NORMAL, slid, 1.0, 0.7)
    assert ref.ratios.max() < mu  # (the reference sticks on the way: 0.906 μ at the end)
    unloaded = solver.solve([sa.Gravity().scaled(0.7), contact])
    assert np.abs(unloaded.positions - ref.positions(unloaded.s)).max() < 1e-7 * L  # 7.5e-10
    assert unloaded.contact_wrench[[0, 2]] == pytest.approx(ref.reaction, rel=1e-6)
    assert "stuck" in _contact_line(unloaded)
    # a single solve at 0.7 slides there from its first touch: another equilibrium
    fresh = sa.solve(arm, [sa.Gravity().scaled(0.7), contact], s=101)
    assert abs(fresh.tip_position[0] - unloaded.tip_position[0]) > 1e-5  # (1.8e-5 m)
    # a reset chain starts from the unloaded arm again
    solver.reset()
    again = solver.solve([sa.Gravity().scaled(0.7), contact])
    assert np.abs(again.positions - fresh.positions).max() < 1e-8 * L


SWEEP = """
name = "floor_sweep"
[arm]
length = 0.5
section = { kind = "circle", radius = 0.01 }
material = { E = 2.0e7, nu = 0.5, density = 1000.0 }
[[load]]
kind = "gravity"
[[load]]
kind = "tip"
force = [0.02, 0.0, -0.1]
[[obstacle]]
kind = "plane"
point = [0.0, 0.0, -0.04]
normal = [0.0, 0.0, 1.0]
[contact]
friction = %s
[solve]
stations = 21
[sweep]
load = 2
field = "force"
component = "magnitude"
start = 0.0
stop = 0.2
steps = 3
"""


@pytest.mark.parametrize("mu", [0.0, 1.0])
def test_a_case_files_sweep_over_a_held_tip_is_its_steps_solved_one_by_one(arm, mu):
    """A [sweep] whose every step is a tip held exactly (it failed when no step had a
    penalty: the sweep's contact law had no stiffness to report)."""
    case = parse_case(tomllib.loads(SWEEP % mu), "sweep.toml")
    swept = solve_case(case)
    assert swept.method == "numeric.tip_contact"
    assert swept.loads[-1].stiffness is None  # (no penalty: "hard at a free tip")
    for k in range(3):  # (each step's own loads, as the case file gives them)
        one = sa.solve(arm, [load.take(k) if load.batch_shape else load
                             for load in case.batched_loads], s=21)
        assert np.array_equal(swept.positions[k], one.positions)
        assert np.array_equal(swept.contact_wrench[k], one.contact_wrench)
    assert np.linalg.norm(swept.contact_wrench[-1, :3]) > 0.1  # (the tip pressed, held)


def test_a_batch_with_friction_equals_its_cases_one_by_one(arm, stuck):
    mu = stuck.ratios.min() / 1.1
    pulls = np.array([[0.0, 0.0, 0.0], [0.02, 0.0, 0.0]])
    contact = sa.Contact(FLOOR, friction=mu)
    batch = sa.solve(arm, [sa.Gravity(), sa.TipLoad(force=pulls), contact], s=51)
    for case, pull in enumerate(pulls):
        one = sa.solve(arm, [sa.Gravity(), sa.TipLoad(force=pull), contact], s=51)
        assert np.array_equal(batch.positions[case], one.positions)
        assert np.array_equal(batch.contact_wrench[case], one.contact_wrench)


def test_a_stuck_tips_compliance_is_the_chained_solves_finite_differences(arm, stuck):
    """The stuck tip's compliance (the cap's point held: δp + δθ × a = 0) against central
    differences of a chained Solver moved by ±h of extra tip force from the same answer
    (the quasi-static response: the tip stays stuck; a solve from the unloaded arm would
    touch elsewhere)."""
    mu = stuck.ratios.max() / 0.9
    contact = sa.Contact(FLOOR, friction=mu)
    s = np.linspace(0.0, L, 51)
    eq = sa.solve(arm, [sa.Gravity(), contact], s=s, jacobians=True)
    assert "stuck" in _contact_line(eq)
    solver, h = Solver(arm, s=s), 1e-2
    for k in range(3):
        moved = []
        for sign in (1.0, -1.0):
            solver.reset()
            solver.solve([sa.Gravity(), contact])
            moved.append(solver.solve([sa.Gravity(), sa.TipLoad(force=sign * h * np.eye(3)[k]),
                                       contact]).tip_position)
        column = (moved[0] - moved[1]) / (2 * h)
        assert eq.tip_compliance[:3, k] == pytest.approx(  # (agree to 1e-8 of the largest)
            column, rel=1e-4, abs=1e-4 * np.abs(eq.tip_compliance[:3, :3]).max())
    # held: the cap's point in contact (offset -r n̂) does not move, to first order
    offset = -RADIUS * np.array([0.0, 0.0, 1.0])
    point_motion = eq.tip_compliance[:3, :] + np.cross(eq.tip_compliance[3:, :].T, offset).T
    assert np.abs(point_motion).max() < 1e-9 * np.abs(eq.tip_compliance).max()


def test_jacobians_with_friction_where_they_are_not_built_are_refused(arm, stuck):
    mu = stuck.ratios.min() / 1.1  # (it slides)
    with pytest.raises(ValueError, match=r"jacobians=True\) with Contact\.friction > 0 "
                                         r"holds a stuck tip on a plane only: here the tip "
                                         r"slides"):
        sa.solve(arm, [sa.Gravity(), sa.Contact(FLOOR, friction=mu)], jacobians=True)
