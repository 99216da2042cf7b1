"""Closed forms against an independent shooting solution of the full Cosserat equations.

The reference below is written here from the strong form (Grazioso et al. 2018, eq. 20 with
H' = H f~, eq. 2) in spatial variables, integrated by scipy's solve_ivp and shot with
scipy.optimize.root; it shares no code with softarm.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import root

from softarm import Arm
from softarm.analytic import elastica, tip_moment

E1 = np.array([1.0, 0.0, 0.0])


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def shoot(stiffness, kappa0, length, force, moment, follower, s):
    """Clamped-free rod, tip force/moment; returns positions (N, 3) and rotations (N, 3, 3).

    Unknowns: the spatial internal force N (constant: no distributed load) and the spatial
    moment M(0) at the clamp. ODE: p' = R (e1 + Kuu⁻¹ Rᵀ N), R' = R (κ⁰ + Kωω⁻¹ Rᵀ M)~,
    M' = -p' × N. Tip: N = F, M(L) = M (dead) or Rᵀ N = F, Rᵀ M = M (follower).
    """
    k = np.asarray(stiffness, dtype=float)
    kappa0 = np.asarray(kappa0, dtype=float)

    def rhs(_, y):
        R = y[3:12].reshape(3, 3)
        N, M = y[12:15], y[15:18]
        dp = R @ (E1 + R.T @ N / k[:3])
        dR = R @ _skew(kappa0 + R.T @ M / k[3:])
        return np.concatenate([dp, dR.ravel(), np.zeros(3), -np.cross(dp, N)])

    def run(x, t_eval=None):
        y0 = np.concatenate([np.zeros(3), np.eye(3).ravel(), x])
        return solve_ivp(rhs, (0.0, length), y0, method="DOP853", rtol=1e-12, atol=1e-13,
                         t_eval=t_eval)

    def residual(x):
        y = run(x).y[:, -1]
        R, N, M = y[3:12].reshape(3, 3), y[12:15], y[15:18]
        if follower:
            return np.concatenate([R.T @ N - force, R.T @ M - moment])
        return np.concatenate([N - force, M - moment])

    guess = np.concatenate([force, moment + length * np.cross(E1, force)])
    solution = root(residual, guess, method="hybr", options={"xtol": 1e-14})
    # hybr may stop "without progress" at roundoff level: judge by the residual itself.
    assert np.max(np.abs(residual(solution.x))) < 1e-10, solution.message
    y = run(solution.x, t_eval=s).y
    return y[:3].T, y[3:12].T.reshape(-1, 3, 3)


def _arm(L=1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0, curvature=(0, 0, 0)):
    return Arm.from_stiffness(L, EA=EA, GAy=GAy, GAz=GAz, GJ=GJ, EIy=EIy, EIz=EIz,
                              curvature=curvature)


@pytest.mark.parametrize("follower", [False, True])
@pytest.mark.parametrize("twist", [0.0, 0.7])
def test_helix_matches_shooting(follower, twist):
    # The arm of C4 in docs/closed-forms.md (GJ = 1/1.3, EI = 1), moment (1, 1, 0); twist 0.7 1/m
    # checks the extension to an initially twisted straight arm (c = κ⁰₁ + M₁ (1/GJ - 1/B)).
    arm = _arm(GJ=1 / 1.3, curvature=(twist, 0.0, 0.0))
    s = np.linspace(0.0, 1.0, 11)
    eq = tip_moment(arm, [1.0, 1.0, 0.0], follower=follower, s=s)
    assert eq.exact and eq.method == "analytic.tip_moment.helix"
    p, R = shoot(np.diagonal(arm.stiffness), arm.curvature, 1.0, np.zeros(3),
                 np.array([1.0, 1.0, 0.0]), follower, s)
    np.testing.assert_allclose(eq.positions, p, atol=1e-10)
    np.testing.assert_allclose(eq.rotations, R, atol=1e-10)


def test_principal_moment_on_curved_arm_matches_shooting():
    # Initial curvature about y, moment about y (parallel): constant strain is exact (C2).
    arm = _arm(GJ=0.4, EIy=2.0, EIz=0.5, curvature=(0.0, 1.5, 0.0))
    s = np.linspace(0.0, 1.0, 7)
    eq = tip_moment(arm, [0.0, -1.0, 0.0], s=s)
    assert eq.exact
    p, R = shoot(np.diagonal(arm.stiffness), arm.curvature, 1.0, np.zeros(3),
                 np.array([0.0, -1.0, 0.0]), False, s)
    np.testing.assert_allclose(eq.positions, p, atol=1e-10)
    np.testing.assert_allclose(eq.rotations, R, atol=1e-10)


@pytest.mark.parametrize("force", [[0.0, 0.0, 3.0], [-1.0, 0.0, 2.0], [0.5, -2.0, 0.0]])
def test_extensible_elastica_matches_shooting(force):
    # Soft axial and shear stiffness (EA = 40 N, GA = 15 N against EI = 1 N m², L = 1 m) so
    # that extension and shear change the answer by percents, not by roundoff.
    arm = _arm(EA=40.0, GAy=15.0, GAz=25.0, GJ=0.8, EIy=1.0, EIz=1.3)
    s = np.linspace(0.0, 1.0, 9)
    eq = elastica(arm, force, s=s)
    assert eq.exact
    p, R = shoot(np.diagonal(arm.stiffness), (0, 0, 0), 1.0, np.array(force, float),
                 np.zeros(3), False, s)
    np.testing.assert_allclose(eq.positions, p, atol=1e-10)
    np.testing.assert_allclose(eq.rotations, R, atol=1e-10)
    inextensible = elastica(arm, force, s=s, extensible=False)
    assert np.max(np.abs(inextensible.positions - p)) > 1e-3  # the compliance matters here
