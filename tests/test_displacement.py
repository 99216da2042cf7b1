"""Tendon lengths' exact Jacobian and displacement-controlled tendons (issue 16, item 4).

References, none of them the library's displacement solver:

- central finite differences of the tension-controlled solver (step count held fixed) for
  ∂ℓ/∂(inputs), and of the displacement-controlled solver for its Jacobians;
- the symmetry of ∂ℓ_a/∂τ_b for a conservative system (the Hessian of the complementary
  energy, whose gradient in τ is ℓ), and its sign (negative definite);
- the constant-strain closed form of straight tendons on an unloaded straight arm, written
  here: K (ε - f⁰) = -Σ_b τ_b (e1; r_b × e1) on each piece, so w_a = e1 (v1 + u × r_a)·e1
  and ℓ_a = Σ_pieces len · (1 - Σ_b τ_b c_ab), c_ab = 1/EA + z_a z_b/EI_y + y_a y_b/EI_z
  over the tendons b acting on the piece (affine in τ: its derivative is exact);
- scipy.optimize.fsolve / brentq on the tensions of tension-controlled solves (the way a
  user would do it without displacement control), written in the tests;
- examples/tendon_robot.toml solved under tension control, then given the tendons' reported
  length changes as displacements.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

import softarm
from softarm import Arm, Chamber, Gravity, MagneticField, Tendon, TipLoad
from softarm.case import load_case
from softarm.routing import Helix, Straight

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def numeric(arm, loads, **options):
    return softarm.solve(arm, loads, method="numeric", **options)


def _arm():
    return Arm.from_stiffness(0.3, EA=60.0, GAy=30.0, GAz=30.0, GJ=0.005, EIy=0.008,
                              EIz=0.006, mass_per_length=0.05, magnetization=(0.4, 0.0, 0.0))


# ============================================================================================
# ∂(tendon lengths)/∂(inputs)
# ============================================================================================

def test_tendon_length_jacobian_matches_central_differences_for_every_kind_of_input():
    arm = _arm()

    def loads(q):
        return [Gravity(), Tendon(q[0], Straight(0.0, 0.01)),
                Tendon(q[1], Helix(0.008, 1.5, phase=0.4), end=0.2),
                Chamber(q[2], 1e-5, Straight(0.006, 0.0)),
                Tendon(q[3], Straight(-0.007, -0.004)), MagneticField(q[4:7])]

    q = np.array([0.6, 0.3, 2e3, 0.2, 0.01, 0.02, -0.01])  # N, N, Pa, N, T, T, T
    eq = numeric(arm, loads(q), jacobians=True, steps=96)
    G = eq.tendon_length_jacobian
    assert G.shape == (3, 7)  # three tendons (not the chamber), seven inputs
    errors = []
    for i in range(7):
        h = 1e-4 * max(abs(q[i]), 1e-2)  # the lengths' round-off: 1e-6 would leave ~1e-6
        dq = np.zeros(7)
        dq[i] = h
        fd = (numeric(arm, loads(q + dq), steps=96).tendon_lengths
              - numeric(arm, loads(q - dq), steps=96).tendon_lengths) / (2 * h)
        errors.append(np.abs(G[:, i] - fd).max() / np.abs(fd).max())
    assert max(errors) <= 1e-6 and np.median(errors) <= 1e-7, errors


def test_tendon_length_jacobian_in_tensions_is_symmetric_and_negative_definite():
    # conservative loads (gravity, a dead tip force): ∂ℓ_a/∂τ_b is the Hessian of the
    # complementary energy, an independent check on each off-diagonal pair
    arm = _arm()
    loads = [Gravity(), TipLoad(force=[0.0, 0.02, -0.01]),
             Tendon(0.6, Straight(0.0, 0.01)), Tendon(0.3, Helix(0.008, 1.5, phase=0.4)),
             Tendon(0.2, Straight(-0.007, -0.004), end=0.2)]
    G = numeric(arm, loads, jacobians=True, steps=128).tendon_length_jacobian
    np.testing.assert_allclose(G, G.T, rtol=0, atol=1e-9 * np.abs(G).max())
    assert np.all(np.linalg.eigvalsh(0.5 * (G + G.T)) < 0.0)


def test_tendon_length_jacobian_of_straight_tendons_equals_the_closed_form():
    # tendon a to the tip at (y, z) = (0, z_a), tendon b to s = e at (y_b, z_b); no other
    # load: ∂ℓ_a/∂τ_a = -L c_aa, ∂ℓ_a/∂τ_b = ∂ℓ_b/∂τ_a = -e c_ab, ∂ℓ_b/∂τ_b = -e c_bb
    EA, EIy, EIz, L, e = 2e3, 4e-3, 3e-3, 0.25, 0.15
    arm = Arm.from_stiffness(L, EA=EA, GAy=EA, GAz=EA, GJ=EIy, EIy=EIy, EIz=EIz)
    r = {"a": (0.0, 0.006), "b": (0.005, -0.003)}

    def c(p, q):
        return 1 / EA + r[p][1] * r[q][1] / EIy + r[p][0] * r[q][0] / EIz

    exact = -np.array([[L * c("a", "a"), e * c("a", "b")], [e * c("b", "a"), e * c("b", "b")]])
    # and the lengths themselves: ℓ_a = e (1 - τ_a c_aa - τ_b c_ab) + (L - e)(1 - τ_a c_aa)
    tau = (0.8, 0.5)
    eq = numeric(arm, [Tendon(tau[0], Straight(*r["a"])), Tendon(tau[1], Straight(*r["b"]),
                                                                  end=e)],
                 jacobians=True, tol=1e-11)
    np.testing.assert_allclose(eq.tendon_length_jacobian, exact, rtol=1e-9)
    lengths = [e * (1 - tau[0] * c("a", "a") - tau[1] * c("a", "b"))
               + (L - e) * (1 - tau[0] * c("a", "a")),
               e * (1 - tau[0] * c("b", "a") - tau[1] * c("b", "b"))]
    np.testing.assert_allclose(eq.tendon_lengths, lengths, rtol=1e-12)


def test_passive_and_chamber_only_solves_have_no_tendon_length_jacobian():
    arm = _arm()
    eq = numeric(arm, [Gravity(), Chamber(1e3, 1e-5, Straight(0.006, 0.0))], jacobians=True)
    assert eq.tendon_length_jacobian is None and eq.tendon_slack is None
    assert eq.actuation_jacobian.shape == (6, 1)


# ============================================================================================
# Displacement-controlled tendons
# ============================================================================================

def _displaced(loads, changes):
    """The tension-controlled tendons among ``loads`` given by these length changes."""
    out, k = [], 0
    for load in loads:
        if isinstance(load, Tendon):
            out.append(Tendon(routing=load.routing, end=load.end, displacement=changes[k]))
            k += 1
        else:
            out.append(load)
    return out


def test_tendon_robot_round_trip_from_its_reported_length_changes():
    case = load_case(EXAMPLES / "tendon_robot.toml")
    by_tension = softarm.solve(case.arm, case.loads)
    by_length = softarm.solve(case.arm, _displaced(case.loads,
                                                   by_tension.tendon_length_changes))
    L = case.arm.length
    np.testing.assert_allclose(by_length.positions, by_tension.positions, rtol=0,
                               atol=1e-9 * L)
    np.testing.assert_allclose(by_length.tendon_tensions, by_tension.tendon_tensions,
                               rtol=0, atol=1e-6)  # 3, 1, 0 N
    np.testing.assert_allclose(by_length.tendon_length_changes,
                               by_tension.tendon_length_changes, rtol=0, atol=1e-10 * L)
    # the third tendon (0 N in the file) is exactly taut at its own length: τ = 0 at the bound
    assert by_length.tendon_tensions[2] == 0.0
    assert by_length.tendon_slack.tolist() == [False, False, True]
    assert isinstance(by_length.loads[2], Tendon) and by_length.loads[2].displacement_controlled
    # the same kind of result as any solve: its own stability verdict, no Jacobians unasked
    assert by_length.stability.index == by_tension.stability.index == 0
    assert by_length.actuation_jacobian is None and by_length.tip_compliance is None
    assert isinstance(by_length.residual, float) and by_length.poses.shape == (101, 4, 4)


def test_mixed_control_agrees_with_fsolve_over_tension_controlled_solves():
    # tendons 1 and 2 by displacement, tendon 3 by tension: scipy's fsolve finds the two
    # tensions whose tension-controlled solves give those length changes
    case = load_case(EXAMPLES / "tendon_robot.toml")
    arm, (gravity, t1, t2, t3) = case.arm, case.loads
    d = np.array([-0.004, 0.001])  # m
    steps = 160

    def gap(tau):
        eq = numeric(arm, [gravity, t1.replace(tension=tau[0]), t2.replace(tension=tau[1]),
                           t3.replace(tension=0.5)], steps=steps)
        return (eq.tendon_length_changes[:2] - d) * 1e3

    tau = fsolve(gap, [1.0, 1.0], xtol=1e-13)
    assert np.max(np.abs(gap(tau))) < 1e-10  # mm
    eq = numeric(arm, [gravity, Tendon(routing=t1.routing, displacement=d[0]),
                       Tendon(routing=t2.routing, displacement=d[1]), t3.replace(tension=0.5)],
                 steps=steps)
    np.testing.assert_allclose(eq.tendon_tensions, [*tau, 0.5], rtol=1e-7)
    np.testing.assert_allclose(eq.tendon_length_changes[:2], d, rtol=0, atol=1e-11)
    reference = numeric(arm, [gravity, t1.replace(tension=tau[0]),
                              t2.replace(tension=tau[1]), t3.replace(tension=0.5)], steps=steps)
    np.testing.assert_allclose(eq.positions, reference.positions, rtol=0,
                               atol=1e-8 * arm.length)
    assert not eq.tendon_slack.any()


def test_a_tendon_given_more_length_than_its_path_needs_is_slack():
    # two antagonistic tendons: the upper one pulled in 3 mm, the lower one paid out 5 mm
    # (more than bending lengthens its path): slack, τ = 0; the upper one's tension by brentq
    # over tension-controlled solves with the lower one at 0 N
    arm = Arm.from_stiffness(0.25, EA=50.0, GAy=25.0, GAz=25.0, GJ=0.004, EIy=0.006,
                             EIz=0.006, mass_per_length=0.04)
    up, down = Straight(0.0, 0.008), Straight(0.0, -0.008)
    steps = 128
    eq = numeric(arm, [Gravity(), Tendon(routing=up, displacement=-0.003),
                       Tendon(routing=down, displacement=0.005)], steps=steps)
    assert eq.tendon_slack.tolist() == [False, True]
    assert eq.tendon_tensions[1] == 0.0

    def change(tau):
        return numeric(arm, [Gravity(), Tendon(tau, up), Tendon(0.0, down)],
                       steps=steps).tendon_length_changes

    tau = brentq(lambda t: change(t)[0] + 0.003, 0.0, 3.0, xtol=1e-14, rtol=1e-14)
    np.testing.assert_allclose(eq.tendon_tensions[0], tau, rtol=1e-8)
    assert change(tau)[1] < 0.005  # the lower tendon's path is shorter than its length
    np.testing.assert_allclose(eq.tendon_length_changes[0], -0.003, rtol=0, atol=1e-12)
    assert eq.tendon_length_changes[1] < 0.005


def test_every_tendon_slack_is_the_arm_under_its_other_loads():
    arm = Arm.from_stiffness(0.25, EA=50.0, GAy=25.0, GAz=25.0, GJ=0.004, EIy=0.006,
                             EIz=0.006, mass_per_length=0.04)
    eq = numeric(arm, [Gravity(), Tendon(routing=Straight(0.0, 0.008), displacement=0.002)],
                 s=21)
    alone = numeric(arm, [Gravity(), Tendon(0.0, Straight(0.0, 0.008))], s=21)
    assert eq.tendon_slack.tolist() == [True] and eq.tendon_tensions.tolist() == [0.0]
    np.testing.assert_array_equal(eq.positions, alone.positions)


def test_batched_displacements_equal_looped():
    arm = Arm.from_stiffness(0.25, EA=50.0, GAy=25.0, GAz=25.0, GJ=0.004, EIy=0.006,
                             EIz=0.006, mass_per_length=0.04)
    d1 = np.array([[-0.004], [-0.001], [0.003]])  # (3, 1): the last one slack
    d2 = np.array([-0.002, 0.0])  # (2,)

    def loads(a, b, t):
        return [Gravity(), Tendon(routing=Straight(0.0, 0.008), displacement=a),
                Tendon(routing=Straight(0.007, -0.004), displacement=b),
                Tendon(t, Straight(-0.007, -0.004))]

    tension = np.array([0.2, 0.4])
    batch = numeric(arm, loads(d1, d2, tension), s=11, jacobians=True)
    assert batch.poses.shape == (3, 2, 11, 4, 4)
    assert batch.tendon_length_jacobian.shape == (3, 2, 3, 3)
    for i, j in np.ndindex(3, 2):
        one = numeric(arm, loads(d1[i, 0], d2[j], tension[j]), s=11, jacobians=True)
        np.testing.assert_allclose(batch.poses[i, j], one.poses, rtol=0, atol=1e-12)
        np.testing.assert_allclose(batch.tendon_tensions[i, j], one.tendon_tensions, rtol=0,
                                   atol=1e-10)
        np.testing.assert_array_equal(batch.tendon_slack[i, j], one.tendon_slack)
        np.testing.assert_allclose(batch.actuation_jacobian[i, j], one.actuation_jacobian,
                                   rtol=0, atol=1e-8 * np.abs(one.actuation_jacobian).max())
    assert batch.tendon_slack[2, :, 0].all() and not batch.tendon_slack[:2, :, 0].any()
    assert batch.stability.index.shape == batch.residual.shape == (3, 2)


def test_jacobians_in_displacement_inputs_match_central_differences():
    arm = _arm()
    steps = 96

    def loads(q):
        return [Gravity(), Tendon(routing=Straight(0.0, 0.01), displacement=q[0]),
                Tendon(q[1], Helix(0.008, 1.5, phase=0.4), end=0.2),
                Tendon(routing=Straight(-0.007, -0.004), displacement=q[2]),
                Tendon(routing=Straight(0.007, -0.004), displacement=q[3])]  # slack

    q = np.array([-0.003, 0.3, -0.005, -0.002])  # m, N, m, m
    eq = numeric(arm, loads(q), jacobians=True, steps=steps)
    assert eq.tendon_slack.tolist() == [False, False, False, True]
    A, G = eq.actuation_jacobian, eq.tendon_length_jacobian
    # a taut displacement-controlled tendon keeps its length: identity rows, zero elsewhere
    np.testing.assert_allclose(G[[0, 2]][:, [0, 2]], np.eye(2), rtol=0, atol=1e-9)
    np.testing.assert_allclose(G[[0, 2]][:, [1, 3]], 0.0, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(A[:, 3], 0.0)  # a slack tendon's displacement moves nothing
    R = eq.poses[-1, :3, :3]
    for i in range(3):
        h = 1e-4 * max(abs(q[i]), 1e-3)
        dq = np.zeros(4)
        dq[i] = h
        plus, minus = numeric(arm, loads(q + dq), steps=steps), \
            numeric(arm, loads(q - dq), steps=steps)
        dp = (plus.tip_position - minus.tip_position) / (2 * h)
        W = (plus.poses[-1, :3, :3] - minus.poses[-1, :3, :3]) / (2 * h) @ R.T
        fd = np.r_[dp, W[2, 1], W[0, 2], W[1, 0]]
        np.testing.assert_allclose(A[:, i], fd, rtol=0, atol=1e-6 * np.abs(fd).max())
        fd_lengths = (plus.tendon_lengths - minus.tendon_lengths) / (2 * h)
        np.testing.assert_allclose(G[:, i], fd_lengths, rtol=0,
                                   atol=1e-6 * np.abs(fd_lengths).max())


@pytest.mark.parametrize("kwargs, message", [
    ({}, "neither"), ({"tension": 1.0, "displacement": -0.001}, "both")])
def test_exactly_one_of_tension_and_displacement(kwargs, message):
    with pytest.raises(TypeError, match=f"tension.*displacement.*{message}"):
        Tendon(routing=Straight(0.0, 0.01), **kwargs)


def test_a_bad_displacement_is_named():
    with pytest.raises(ValueError, match=r"Tendon\.displacement"):
        Tendon(routing=Straight(0.0, 0.01), displacement=math.nan)


def test_routes_without_displacement_control_say_so():
    arm = _arm()
    tendon = Tendon(routing=Straight(0.0, 0.01), displacement=-0.001)
    with pytest.raises(ValueError, match="displacement-controlled"):
        softarm.statics.Solver(arm).shoot([tendon], np.zeros(6))


def test_a_failed_displacement_solve_is_a_convergence_error(monkeypatch):
    import softarm.statics.displacement as displacement

    monkeypatch.setattr(displacement, "MAX_ITERATIONS", 1)
    arm = _arm()
    with pytest.raises(softarm.ConvergenceError, match="prescribed length") as error:
        numeric(arm, [Gravity(), Tendon(routing=Straight(0.0, 0.01), displacement=-0.003)])
    assert error.value.residual > 1e-6  # m: the length error after one step


def test_displacement_tendons_in_a_case_file_round_trip(tmp_path):
    text = (EXAMPLES / "tendon_robot.toml").read_text()
    text = text.replace("tension = 3.0 ", "displacement = -0.006 ").replace(
        "tension = 1.0\n", "displacement = 0.001\n")
    path = tmp_path / "robot.toml"
    path.write_text(text)
    case = load_case(path)
    assert case.loads[1].displacement == -0.006 and case.loads[1].tension is None
    written = case.loads[2].to_case()
    assert written == {"kind": "tendon", "displacement": 0.001,
                       "routing": {"kind": "straight", "y": 0.006928, "z": -0.004}}
    eq = softarm.solve(case.arm, case.loads)
    python = softarm.solve(case.arm, [case.loads[0], Tendon(routing=Straight(0.0, 0.008),
                                                            displacement=-0.006),
                                      Tendon(routing=Straight(0.006928, -0.004),
                                             displacement=0.001), case.loads[3]])
    np.testing.assert_array_equal(eq.positions, python.positions)
    np.testing.assert_allclose(eq.tendon_length_changes[:2], [-0.006, 0.001], rtol=0,
                               atol=1e-12)


def test_the_cli_summary_reports_displacement_control_and_slack(tmp_path, capsys):
    from softarm import cli

    text = (EXAMPLES / "tendon_robot.toml").read_text()
    text = text.replace("tension = 3.0 ", "displacement = -0.004 ").replace(
        "tension = 1.0\n", "displacement = 0.004\n")  # the second one paid out: slack
    path = tmp_path / "robot.toml"
    path.write_text(text)
    assert cli.main(["solve", str(path)]) == 0
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if "tension" in line and "mm" in line]
    assert len(lines) == 3
    assert "displacement-controlled: set -4 mm)" in lines[0] and "SLACK" not in lines[0]
    assert "displacement-controlled: set +4 mm; SLACK" in lines[1]
    assert "tension 0 N" in lines[1]
    assert "displacement" not in lines[2]  # the third tendon is tension-controlled


def test_inverse_with_displacement_inputs_reaches_a_target_made_by_displacements():
    # the target: the tip of a displacement-controlled solve; the answer's displacements,
    # solved forward again by displacement control, put the tip there
    case = load_case(EXAMPLES / "tendon_robot.toml")
    arm, gravity = case.arm, case.loads[0]
    routes = [load.routing for load in case.loads[1:]]
    hidden = [Tendon(routing=r, displacement=d) for r, d in zip(routes, [-0.003, 0.001, 0.0],
                                                                   strict=True)]
    target = softarm.solve(arm, [gravity, *hidden]).tip_position
    guess = [Tendon(routing=r, displacement=0.0) for r in routes]
    answer = softarm.inverse(arm, guess, target, loads=[gravity], tol=1e-6)
    assert answer.reached and answer.error <= 1e-6
    forward = softarm.solve(arm, [gravity, *[Tendon(routing=r, displacement=d) for r, d in
                                             zip(routes, answer.inputs, strict=True)]])
    np.testing.assert_allclose(forward.tip_position, target, rtol=0, atol=2e-6 * arm.length)
    np.testing.assert_allclose(answer.equilibrium.tendon_length_changes, answer.inputs,
                               rtol=0, atol=1e-12)
    assert all(load.displacement_controlled for load in answer.equilibrium.loads[1:])
    # its Jacobian is per metre of displacement: a taut tendon's own length row is 1
    taut = ~answer.equilibrium.tendon_slack
    np.testing.assert_allclose(answer.equilibrium.tendon_length_jacobian[taut][:, taut],
                               np.eye(int(taut.sum())), rtol=0, atol=1e-9)
    with pytest.raises(ValueError, match="bounds on a displacement input"):
        softarm.inverse(arm, guess, target, loads=[gravity], bounds=(0.0, 10.0))
