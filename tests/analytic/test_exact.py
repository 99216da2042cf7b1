"""exact_closed_form: exact results where a closed form is exact, None everywhere else.

pytest runs with warnings as errors, so these tests also pin that it never warns.
"""

from __future__ import annotations

import numpy as np
import pytest

from softarm import Arm, DistributedForce, Gravity, PointLoad, SegmentedArm, TipLoad
from softarm.analytic import axial_force, elastica, exact_closed_form, tip_moment


def _arm(EIz=2.0, curvature=(0.0, 0.0, 0.0)):
    return Arm.from_stiffness(1.0, EA=1e4, GAy=5e3, GAz=6e3, GJ=0.5, EIy=1.0, EIz=EIz,
                              curvature=curvature, mass_per_length=0.1)


@pytest.mark.parametrize(("arm", "load", "method", "reference"), [
    (_arm(), TipLoad(moment=[0.0, 2.0, 0.0]), "analytic.tip_moment.principal",
     lambda a: tip_moment(a, [0.0, 2.0, 0.0])),
    (_arm(), TipLoad(moment=[0.0, 0.0, -1.0], follower=True), "analytic.tip_moment.principal",
     lambda a: tip_moment(a, [0.0, 0.0, -1.0], follower=True)),
    (_arm(EIz=1.0), TipLoad(moment=[1.0, 1.0, 0.0], follower=True), "analytic.tip_moment.helix",
     lambda a: tip_moment(a, [1.0, 1.0, 0.0], follower=True)),
    (_arm(curvature=(0.0, 0.5, 0.0)), TipLoad(moment=[0.0, 1.0, 0.0]),
     "analytic.tip_moment.principal", lambda a: tip_moment(a, [0.0, 1.0, 0.0])),
    (_arm(), TipLoad(force=[-3.0, 0.0, 0.0], follower=True), "analytic.axial_force",
     lambda a: axial_force(a, [-3.0, 0.0, 0.0])),
    (_arm(), TipLoad(force=[1.0, 0.0, -2.0]), "analytic.elastica",
     lambda a: elastica(a, [1.0, 0.0, -2.0])),
    (_arm(), TipLoad(), "analytic.tip_moment.principal", lambda a: tip_moment(a, [0, 0, 0])),
])
def test_exact_cases(arm, load, method, reference):
    eq = exact_closed_form(arm, [load], s=21)
    assert eq is not None and eq.exact and eq.method == method
    assert eq.loads == (load,)
    np.testing.assert_allclose(eq.poses, reference(arm).poses[::5], rtol=0, atol=1e-14)


@pytest.mark.parametrize(("arm", "loads"), [
    (_arm(), [TipLoad(moment=[1.0, 1.0, 0.0])]),  # not principal, EIy != EIz
    (_arm(EIz=1.0, curvature=(0.0, 0.5, 0.0)), [TipLoad(moment=[0.0, 0.0, 1.0])]),
    (_arm(), [TipLoad(force=[0.0, 1.0, 1.0])]),  # outside the principal planes
    (_arm(), [TipLoad(force=[0.0, 0.0, 1.0], follower=True)]),  # follower transverse force
    (_arm(), [TipLoad(force=[0.0, 0.0, 1.0], moment=[0.0, 1.0, 0.0])]),  # force and moment
    (_arm(curvature=(0.0, 0.5, 0.0)), [TipLoad(force=[1.0, 0.0, 0.0])]),  # curved arm
    (_arm(), [TipLoad(force=[0.0, 0.0, 1e6])]),  # beyond planar_elastica's range
    (_arm(), [TipLoad(force=[-2e4, 0.0, 0.0])]),  # compression beyond -EA
    (_arm(), [Gravity()]),
    (_arm(), [DistributedForce([0.0, 0.0, 1.0])]),
    (_arm(), [PointLoad(0.5, force=[0.0, 0.0, 1.0])]),
    (_arm(), [TipLoad(moment=[0.0, 1.0, 0.0]), Gravity()]),
    (_arm(), [TipLoad(moment=[0.0, 1.0, 0.0]), TipLoad(moment=[0.0, 1.0, 0.0], follower=True)]),
    (SegmentedArm([_arm(), _arm()]), [TipLoad(moment=[0.0, 1.0, 0.0])]),
    (_arm(), []),
])
def test_none_outside(arm, loads):
    assert exact_closed_form(arm, loads) is None


def test_batch_all_or_nothing():
    # One non-principal element makes the whole batch non-exact.
    moments = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 2.0], [1.0, 1.0, 0.0]])
    assert exact_closed_form(_arm(), TipLoad(moment=moments)) is None
    eq = exact_closed_form(_arm(), TipLoad(moment=moments[:2]))
    assert eq.batch_shape == (2,) and eq.exact
    # planes may differ per element
    forces = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    eq = exact_closed_form(_arm(), TipLoad(force=forces))
    assert eq.method == "analytic.elastica" and eq.batch_shape == (2,)


def test_tip_loads_in_one_frame_are_summed():
    loads = [TipLoad(moment=[0.0, 1.0, 0.0]), TipLoad(moment=[0.0, 0.5, 0.0])]
    eq = exact_closed_form(_arm(), loads)
    np.testing.assert_allclose(eq.poses, tip_moment(_arm(), [0.0, 1.5, 0.0]).poses, atol=0)
    assert eq.loads == tuple(loads)


def test_bad_inputs():
    with pytest.raises(TypeError, match="loads"):
        exact_closed_form(_arm(), "gravity")
    with pytest.raises(TypeError, match="arm"):
        exact_closed_form(None, [TipLoad()])
    with pytest.raises(ValueError, match="s must"):
        exact_closed_form(_arm(), [TipLoad()], s=[0.0, 3.0])
