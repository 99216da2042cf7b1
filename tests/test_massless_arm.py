"""A massless arm (issue 30): ``mass_per_length = 0`` (or ``density = 0``) is a valid model, on
which gravity acts on nothing; a negative or non-finite mass stays an error.

References: the unloaded shape of an arm of constant reference strain f⁰ is
p(s) = exp(s f⁰^) (scipy.linalg.expm of the 4 × 4 twist, independent of softarm.lie); with a
tip force, the same arm without the gravity load, solved by the other route.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

import softarm
from softarm import cli

CURVATURE = (0.0, 2.0, 0.5)  # 1/m: a precurved arm, so that "unloaded" is not a straight line
PLAIN = softarm.Material(1.5e6, poisson_ratio=0.49)
GRAVITY = softarm.Gravity([0.0, 0.0, -9.81])


def unloaded_poses(length: float, curvature, s) -> np.ndarray:
    """exp(s f⁰^) for f⁰ = (1, 0, 0, κ⁰): the stress-free arm (4 × 4 poses along s)."""
    k1, k2, k3 = curvature
    twist = np.array([[0.0, -k3, k2, 1.0], [k3, 0.0, -k1, 0.0], [-k2, k1, 0.0, 0.0],
                      [0.0, 0.0, 0.0, 0.0]])
    return np.array([expm(si * twist) for si in s])


@pytest.mark.parametrize("make", [
    lambda: softarm.Arm(0.3, softarm.Circle(0.01), PLAIN, CURVATURE, mass_per_length=0.0),
    lambda: softarm.Arm(0.3, softarm.Circle(0.01), softarm.Material(1.5e6, poisson_ratio=0.49,
                                                                   density=0.0), CURVATURE),
    lambda: softarm.Arm.from_stiffness_matrix(0.3, np.diag([1e4, 1e4, 1e4, 0.5, 1.0, 1.0]),
                                              CURVATURE, mass_per_length=0.0),
], ids=["mass_per_length", "density", "stiffness_matrix"])
@pytest.mark.parametrize("method", ["auto", "numeric"])
def test_gravity_on_a_massless_arm_leaves_it_unloaded(make, method):
    arm = make()
    assert arm.linear_density == 0.0
    eq = softarm.solve(arm, [GRAVITY], method=method, tol=1e-12)
    reference = unloaded_poses(arm.length, CURVATURE, eq.s)
    np.testing.assert_allclose(eq.poses, reference, rtol=0.0, atol=1e-11)
    np.testing.assert_allclose(eq.stresses, 0.0, atol=1e-12)


def test_gravity_on_a_massless_arm_adds_nothing_to_a_tip_force():
    """Gravity and a tip force on a massless straight arm: the closed form applies (gravity
    acts on nothing) and matches the numerical solve of the tip force alone."""
    arm = softarm.Arm(0.3, softarm.Circle(0.01), PLAIN, mass_per_length=0.0)
    tip = softarm.TipLoad(force=[0.0, 0.0, -0.02])
    auto = softarm.solve(arm, [GRAVITY, tip])
    numeric = softarm.solve(arm, [tip], method="numeric", tol=1e-12)
    assert auto.method == "analytic.elastica" and auto.exact
    np.testing.assert_allclose(auto.positions, numeric.positions, rtol=0.0, atol=1e-10)
    numeric = softarm.solve(arm, [GRAVITY, tip], method="numeric", tol=1e-12)
    np.testing.assert_allclose(numeric.positions, auto.positions, rtol=0.0, atol=1e-10)


@pytest.mark.parametrize("bad", [-1e-9, -1.0, np.inf, np.nan])
def test_a_negative_or_non_finite_mass_is_still_refused(bad):
    with pytest.raises(ValueError, match=r"Arm\.mass_per_length must be a finite value >= 0 "
                                         r"in kg/m, got "):
        softarm.Arm(0.3, softarm.Circle(0.01), PLAIN, mass_per_length=bad)
    with pytest.raises(ValueError, match=r"Material\.density must be a finite value >= 0"):
        softarm.Material(1.5e6, poisson_ratio=0.49, density=bad)


def test_a_case_file_with_mass_zero_solves(tmp_path, capsys):
    path = tmp_path / "massless.toml"
    path.write_text(f"""\
name = "magnetic rod, gravity off"
[arm]
length = 0.3
curvature = {list(CURVATURE)}
mass_per_length = 0.0
section = {{ kind = "circle", radius = 0.01 }}
material = {{ E = 1.5e6, nu = 0.49 }}
[[load]]
kind = "gravity"
""", encoding="utf-8")
    case = softarm.load_case(path)
    assert case.arm.mass_per_length == 0.0
    eq = softarm.solve(case.arm, case.loads, tol=1e-12)
    np.testing.assert_allclose(eq.poses, unloaded_poses(0.3, CURVATURE, eq.s), atol=1e-11)
    out = tmp_path / "massless.csv"
    assert cli.main(["solve", str(path), "-o", str(out)]) == 0
    saved = softarm.io.load_saved(out)
    assert saved.case.arm.mass_per_length == 0.0
    # the command solves to the file's default tolerance, 1e-8 L
    np.testing.assert_allclose(saved.result.poses, eq.poses, rtol=0.0, atol=1e-8 * 0.3)
    capsys.readouterr()
