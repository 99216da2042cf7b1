"""The two independent routes agree: every exact closed form against the numerical solver.

``softarm.analytic`` and ``softarm.statics`` never import each other; here each exact closed
form (an ``Equilibrium`` with ``exact=True``) is compared, station by station, with
``softarm.solve(method="numeric")`` on the same arm and loads: poses, strains and stresses.
"""

from __future__ import annotations

import numpy as np
import pytest

import softarm
from softarm import analytic

TOL = 1e-10  # solver tolerance on the tip position / L

SILICONE = softarm.Material(1.0e6, poisson_ratio=0.5, density=1100.0)
ROUND = softarm.Arm(0.3, softarm.Circle(0.01), SILICONE)  # EIy = EIz: the helix applies
FLAT = softarm.Arm(0.3, softarm.Rectangle(0.02, 0.01), SILICONE)  # EIy != EIz
TWISTED = softarm.Arm(0.3, softarm.Circle(0.01), SILICONE, curvature=(2.0, 0.0, 0.0))
PRECURVED = softarm.Arm(0.3, softarm.Rectangle(0.02, 0.01), SILICONE, curvature=(0.0, 3.0, 0.0))
EI = ROUND.rigidities.EIy

CASES = {
    # pure bending about a principal axis: eqs. 30-38
    "principal moment": (analytic.tip_moment, FLAT, dict(moment=[0.0, 0.004, 0.0])),
    "principal moment, precurved": (analytic.tip_moment, PRECURVED,
                                    dict(moment=[0.0, -0.003, 0.0])),
    # C4 (docs/closed-forms.md): helix under any end moment, dead and follower
    "helix, dead": (analytic.tip_moment, ROUND, dict(moment=[0.01, 0.03, -0.015])),
    "helix, follower": (analytic.tip_moment, ROUND,
                        dict(moment=[0.01, 0.03, -0.015], follower=True)),
    "helix, twisted arm": (analytic.tip_moment, TWISTED, dict(moment=[0.002, 0.003, 0.004])),
    # constant axial strain F/EA
    "axial force": (analytic.axial_force, ROUND, dict(force=[20.0, 0.0, 0.0])),
    # the extensible, shearable elastica in either principal plane, k = P L²/EI up to 8
    "elastica x-z": (analytic.elastica, ROUND, dict(force=[0.0, 0.0, -5.0 * EI / 0.09])),
    "elastica x-y, oblique": (analytic.elastica, FLAT,
                              dict(force=[0.3, -0.5, 0.0])),
    "elastica, large load": (analytic.elastica, ROUND, dict(force=[-0.2, 0.0, 8.0 * EI / 0.09])),
}


def _loads(function, kwargs):
    if function is analytic.tip_moment:
        return softarm.TipLoad(moment=kwargs["moment"], follower=kwargs.get("follower", False))
    return softarm.TipLoad(force=kwargs["force"])


@pytest.mark.parametrize("name", list(CASES))
def test_exact_closed_form_equals_the_solver(name):
    function, arm, kwargs = CASES[name]
    closed = function(arm, s=41, **kwargs)
    assert closed.exact, f"{name}: the closed form must be exact here"
    numeric = softarm.solve(arm, _loads(function, kwargs), method="numeric", s=41, tol=TOL)
    L = arm.length
    np.testing.assert_allclose(numeric.positions, closed.positions, rtol=0, atol=1e-8 * L)
    np.testing.assert_allclose(numeric.rotations, closed.rotations, rtol=0, atol=1e-8)
    # strains: dimensionless (γ) and 1/m (κ); stresses: compare at the scale of the load
    kappa_scale = max(1.0 / L, float(np.max(np.abs(closed.strains[:, 3:]))))
    np.testing.assert_allclose(numeric.strains[:, 3:], closed.strains[:, 3:], rtol=0,
                               atol=1e-7 * kappa_scale)
    np.testing.assert_allclose(numeric.strains[:, :3], closed.strains[:, :3], rtol=0,
                               atol=1e-9)
    scale = float(np.max(np.abs(closed.stresses)))
    np.testing.assert_allclose(numeric.stresses, closed.stresses, rtol=0, atol=1e-7 * scale)


@pytest.mark.parametrize("name", list(CASES))
def test_auto_takes_the_exact_closed_form(name):
    function, arm, kwargs = CASES[name]
    auto = softarm.solve(arm, _loads(function, kwargs), s=41)
    assert auto.method.startswith("analytic."), auto.method
    closed = function(arm, s=41, **kwargs)
    np.testing.assert_array_equal(auto.poses, closed.poses)
