"""Output stations between RK4 steps (``_record`` in the kernel): each is interpolated on
its step, cubic Hermite on the state and tangents and on the rotation vector from the step's
start for R. Reference: the same arm solved at tol = 1e-13 (discretisation error far below
what is checked), at the same stations. The stations' error must be of the order of the
tip's, which the solver's error estimate controls: within 3 tol in position (units of L)
and rotation (rad); and R a rotation as exactly as the steps' own (each RK4 step ends with one
Björck step: 1e-11 at tol 1e-5, round-off at tight tolerances)."""

from __future__ import annotations

import numpy as np
import pytest

import softarm
from softarm.lie import so3
from softarm.routing import Straight


def _soft_arm():
    arm = softarm.Arm(0.3, softarm.Circle(0.01), softarm.Material(1.0e6, poisson_ratio=0.45,
                                                                   density=1100.0))
    return arm, [softarm.Gravity([0.0, 0.0, -9.81]), softarm.TipLoad([0.0, 0.02, 0.01])]


def _cantilever():  # the Mattiasson cantilever, k = 5 (EI = L = 1)
    arm = softarm.Arm.from_stiffness(1.0, EA=1e9, GAy=1e9, GAz=1e9, GJ=1.0, EIy=1.0, EIz=1.0)
    return arm, [softarm.TipLoad([0.0, 0.0, 5.0])]


def _tendon_robot():
    nitinol = softarm.Material(6.0e10, poisson_ratio=0.33, density=6450.0)
    arm = softarm.Arm(0.25, softarm.Circle(0.0006), nitinol, mass_per_length=0.02)
    offsets = [(0.0, 0.008), (0.006928, -0.004), (-0.006928, -0.004)]
    return arm, [softarm.Gravity([0.0, 0.0, -9.81])] + [
        softarm.Tendon(t, Straight(*o)) for t, o in zip((3.0, 1.0, 0.0), offsets, strict=True)]


@pytest.mark.parametrize("case", [_soft_arm, _cantilever, _tendon_robot])
@pytest.mark.parametrize("tol", [1e-5, 1e-7])
def test_stations_between_steps_are_as_accurate_as_the_tip(case, tol):
    arm, loads = case()
    L = arm.length
    s = np.sort(np.random.default_rng(3).uniform(0.0, L, 157))
    eq = softarm.solve(arm, loads, method="numeric", tol=tol, s=s)
    ref = softarm.solve(arm, loads, method="numeric", tol=1e-13, s=s)
    position = np.linalg.norm(eq.positions - ref.positions, axis=-1) / L
    rotation = np.array([np.linalg.norm(so3.log(a @ b.T))
                         for a, b in zip(eq.rotations, ref.rotations, strict=True)])
    assert position.max() <= 3.0 * tol
    assert rotation.max() <= 3.0 * tol
    assert position.max() > 1e-3 * tol  # (the reference is distinct: the check can fail)
    gram = eq.rotations @ np.swapaxes(eq.rotations, -1, -2)
    assert np.abs(gram - np.eye(3)).max() <= (1e-10 if tol > 1e-6 else 1e-13)
