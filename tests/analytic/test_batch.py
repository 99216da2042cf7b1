"""Every closed form: a batch of loads equals the loop over its elements."""

from __future__ import annotations

import numpy as np
import pytest

from softarm import Arm
from softarm.analytic import (
    axial_force,
    elastica,
    exact_closed_form,
    linear,
    shear_force,
    tip_moment,
)
from softarm.loads import TipLoad

ARM = Arm.from_stiffness(0.8, EA=500.0, GAy=200.0, GAz=300.0, GJ=0.6, EIy=1.0, EIz=1.0)
CURVED = Arm.from_stiffness(0.8, EA=500.0, GAy=200.0, GAz=300.0, GJ=0.6, EIy=1.0, EIz=1.5,
                            curvature=(0.2, 0.9, -0.3))
AXIAL = np.array([1.0, 0.0, 0.0])
Z = np.array([0.0, 0.0, 1.0])

CASES = {
    "tip_moment helix dead": lambda v: tip_moment(ARM, v),
    "tip_moment helix follower": lambda v: tip_moment(ARM, v, follower=True),
    "axial_force": lambda v: axial_force(ARM, v * AXIAL),
    "shear_force": lambda v: shear_force(ARM, v),
    "linear": lambda v: linear(CURVED, force=v, moment=v[..., ::-1], s=17),
    "elastica": lambda v: elastica(ARM, v * [1.0, 0.0, 1.0]),
    "elastica inextensible": lambda v: elastica(ARM, v * [1.0, 1.0, 0.0], extensible=False),
    "exact_closed_form": lambda v: exact_closed_form(ARM, [TipLoad(force=v * Z)]),
}


@pytest.mark.parametrize("shape", [(), (1,), (3, 1, 2)])
@pytest.mark.parametrize("name", list(CASES))
def test_batched_equals_looped(name, shape, rng):
    solve = CASES[name]
    values = rng.normal(scale=0.8, size=(*shape, 3))
    batched = solve(values)
    n = batched.s.size
    assert batched.poses.shape == (*shape, n, 4, 4)
    assert batched.strains.shape == batched.stresses.shape == (*shape, n, 6)
    for index in np.ndindex(*shape):
        single = solve(values[index])
        for field in ("poses", "strains", "stresses"):
            np.testing.assert_allclose(getattr(batched, field)[index], getattr(single, field),
                                       rtol=1e-13, atol=1e-14)
        assert single.exact == batched.exact or not batched.exact


def test_no_nan_for_extreme_finite_input():
    # Zero, tiny and huge loads stay finite.
    for v in (0.0, 1e-300, 1e-12):
        for eq in (tip_moment(ARM, [v, v, 0.0]), linear(CURVED, force=[v, v, v]),
                   shear_force(ARM, [v, v, v]), elastica(ARM, [v, 0.0, v]),
                   axial_force(ARM, [v, 0.0, 0.0])):
            assert np.all(np.isfinite(eq.poses)) and np.all(np.isfinite(eq.strains))
    assert np.all(np.isfinite(tip_moment(ARM, [1e6, -1e6, 3e5]).poses))
    assert np.all(np.isfinite(elastica(ARM, [0.0, 0.0, 5e4], extensible=False).poses))


@pytest.mark.parametrize("threads", ["2", "3"])
@pytest.mark.parametrize("name", ["tip_moment helix dead", "tip_moment helix follower",
                                  "axial_force"])
def test_threaded_split_equals_one_thread(name, threads, rng, monkeypatch):
    # The pose kernel splits large batches over threads; with the per-thread minimum lowered,
    # a batch of 7 is split (unevenly for 3 threads, and a lone arm leaves empty ranges).
    # Every arm must come out bit for bit as in one thread, and as when solved alone to
    # rounding (one load takes the compiled screw of analytic/_compiled.py: the same closed
    # form, summed in another order).
    from softarm.analytic import _common

    solve = CASES[name]
    values = rng.normal(scale=0.8, size=(7, 3))
    monkeypatch.setenv(_common.THREADS_VARIABLE, "1")
    serial = solve(values)
    monkeypatch.setattr(_common, "_PER_THREAD", 1)
    monkeypatch.setenv(_common.THREADS_VARIABLE, threads)
    assert _common.thread_count(7 * serial.s.size) == int(threads)
    split = solve(values)
    for field in ("poses", "strains", "stresses"):
        np.testing.assert_array_equal(getattr(split, field), getattr(serial, field))
    for index in range(values.shape[0]):
        np.testing.assert_allclose(solve(values[index]).poses, serial.poses[index], rtol=0,
                                   atol=4 * np.finfo(np.float64).eps)


@pytest.mark.parametrize("setting", ["0", "-2", "two", "1.5"])
def test_bad_thread_setting_names_the_variable(setting, monkeypatch):
    monkeypatch.setenv("SOFTARM_NUM_THREADS", setting)
    with pytest.raises(ValueError, match=rf"SOFTARM_NUM_THREADS.*positive integer.*{setting}"):
        tip_moment(ARM, [0.0, 1.0, 0.0])
