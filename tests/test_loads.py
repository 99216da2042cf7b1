"""Loads: stored as read-only float64 copies, batch shapes, and input checks naming the field."""

from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest

from softarm import DistributedForce, Gravity, PointLoad, TipLoad
from softarm.loads import as_loads, batch_shape

# (class, field, the other required arguments)
VECTOR_FIELDS = [
    (TipLoad, "force", {}),
    (TipLoad, "moment", {}),
    (Gravity, "acceleration", {}),
    (DistributedForce, "force", {}),
    (PointLoad, "force", {"s": 0.1}),
    (PointLoad, "moment", {"s": 0.1}),
]
IDS = [f"{cls.__name__}.{field}" for cls, field, _ in VECTOR_FIELDS]


def test_defaults():
    tip = TipLoad()
    assert np.array_equal(tip.force, np.zeros(3)) and np.array_equal(tip.moment, np.zeros(3))
    assert tip.follower is False
    assert np.array_equal(Gravity().acceleration, [0.0, 0.0, -9.81])  # standard gravity, m/s²
    point = PointLoad(0.2)
    assert point.s == 0.2 and np.array_equal(point.force, np.zeros(3))


@pytest.mark.parametrize(("cls", "field", "extra"), VECTOR_FIELDS, ids=IDS)
def test_vectors_are_read_only_float64_copies(cls, field, extra):
    given = np.array([1, 2, 3])  # integers: converted
    load = cls(**extra, **{field: given})
    stored = getattr(load, field)
    assert stored.dtype == np.float64 and np.array_equal(stored, [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="read-only"):
        stored[0] = 5.0
    floats = np.array([1.0, 2.0, 3.0])
    stored = getattr(cls(**extra, **{field: floats}), field)
    floats[0] = 7.0  # the caller's array stays theirs: writable, and not aliased by the load
    assert stored[0] == 1.0


@pytest.mark.parametrize(("cls", "field", "extra"), VECTOR_FIELDS, ids=IDS)
@pytest.mark.parametrize("bad", [[1.0, 2.0], np.zeros((2, 4)), 5.0, np.zeros((3, 3, 2))],
                         ids=["(2,)", "(2,4)", "()", "(3,3,2)"])
def test_wrong_shape_names_field_and_shapes(cls, field, extra, bad):
    name = f"{cls.__name__}.{field}"
    message = f"{name} must have shape (..., 3), got shape {np.shape(bad)}"
    with pytest.raises(ValueError, match=re.escape(message)):
        cls(**extra, **{field: bad})


@pytest.mark.parametrize(("cls", "field", "extra"), VECTOR_FIELDS, ids=IDS)
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_non_finite_names_field(cls, field, extra, value):
    with pytest.raises(ValueError, match=rf"^{cls.__name__}\.{field} must be finite"):
        cls(**extra, **{field: [0.0, value, 0.0]})


@pytest.mark.parametrize(("cls", "field", "extra"), VECTOR_FIELDS, ids=IDS)
def test_non_numeric_names_field(cls, field, extra):
    with pytest.raises(TypeError, match=rf"^{cls.__name__}\.{field} must be numeric"):
        cls(**extra, **{field: ["a", "b", "c"]})


@pytest.mark.parametrize("follower", [1, 0, "yes", None, 1.0])
def test_follower_must_be_bool(follower):
    with pytest.raises(TypeError, match=r"TipLoad\.follower must be True or False"):
        TipLoad(force=[0.0, 0.0, 1.0], follower=follower)


@pytest.mark.parametrize("follower", [True, False, np.True_, np.False_])
def test_follower_accepts_bools(follower):
    assert TipLoad(follower=follower).follower == follower


def test_point_load_station():
    assert PointLoad(np.float64(0.25)).s == 0.25 and type(PointLoad(0.25).s) is float
    with pytest.raises(ValueError, match=r"PointLoad\.s must be a single arc length in m"):
        PointLoad([0.1, 0.2])
    with pytest.raises(ValueError, match=r"PointLoad\.s must be finite"):
        PointLoad(math.nan)
    with pytest.raises(TypeError, match=r"PointLoad\.s must be numeric"):
        PointLoad("end")


def test_batch_shapes_broadcast():
    tip = TipLoad(force=np.zeros((4, 1, 3)), moment=np.zeros((5, 3)))
    assert tip.batch_shape == (4, 5)
    assert Gravity().batch_shape == ()
    assert DistributedForce(np.zeros((2, 3))).batch_shape == (2,)
    assert PointLoad(0.1, moment=np.zeros((7, 3))).batch_shape == (7,)
    assert batch_shape([tip, Gravity(), DistributedForce(np.zeros((4, 1, 3)))]) == (4, 5)
    assert batch_shape(Gravity()) == ()
    assert batch_shape([]) == ()


def test_batch_shapes_that_do_not_broadcast():
    with pytest.raises(ValueError, match=r"loads have batch shapes \[\(2,\), \(3,\)\] that do "
                                         r"not broadcast"):
        batch_shape([TipLoad(force=np.zeros((2, 3))), Gravity(np.zeros((3, 3)))])
    # Within one load the check happens at construction.
    with pytest.raises(ValueError, match=re.escape("TipLoad.force and TipLoad.moment must have "
                                                   "batch shapes that broadcast, got shapes "
                                                   "(2, 3) and (3, 3)")):
        TipLoad(force=np.zeros((2, 3)), moment=np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"PointLoad\.force and PointLoad\.moment"):
        PointLoad(0.1, force=np.zeros((2, 3)), moment=np.zeros((3, 3)))


def test_as_loads():
    tip, gravity = TipLoad(), Gravity()
    assert as_loads(tip) == (tip,)
    assert as_loads([tip, gravity]) == (tip, gravity)
    assert as_loads(x for x in (gravity,)) == (gravity,)
    for bad in (None, 3.0, [tip, "gravity"], {"tip": tip}):
        with pytest.raises(TypeError, match=r"loads must be (a )?softarm\.Load"):
            as_loads(bad)


def test_loads_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        TipLoad().force = np.ones(3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        Gravity().acceleration = np.ones(3)


def _applied_cases():
    import softarm as sa
    from softarm.routing import Straight

    soft = sa.Material(youngs_modulus=1e6, poisson_ratio=0.5, density=1000.0)
    arm = sa.Arm(0.5, sa.Circle(0.01), soft)
    two = sa.SegmentedArm([sa.Arm(0.3, sa.Circle(0.012), sa.Material(
        youngs_modulus=2e6, poisson_ratio=0.5, density=1000.0)), sa.Arm(0.2, sa.Circle(0.008),
        sa.Material(youngs_modulus=1e6, poisson_ratio=0.5, density=3000.0))])
    magnet = sa.Arm(0.5, sa.Circle(0.01), soft, magnetization=(0.5, 0.0, 0.0),
                    tip_magnet=(0.01, 0.02, 0.0))
    gradient = [[0.1, 0.2, 0.0], [0.2, -0.3, 0.05], [0.0, 0.05, 0.2]]
    base = np.eye(4)
    base[:3, 3] = (0.1, 0.2, 0.3)
    base[:3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    return {
        "gravity, tip follower, base pose": (arm, [Gravity(), TipLoad(
            (0.1, 0.2, 0.0), (0.0, 0.01, 0.0), follower=True)], base),
        "point and distributed follower": (arm, [PointLoad(0.2, (0.1, 0.0, 0.3)),
                                                 DistributedForce((0.0, 0.3, 0.0),
                                                                  follower=True)], None),
        "two segments of two densities": (two, [Gravity(), DistributedForce((0, 0.2, 0))],
                                          None),
        "magnets in a field gradient": (magnet, [sa.MagneticField((0.01, 0.02, 0.0),
                                                                  gradient)], None),
        "tendon and chamber (internal)": (arm, [Gravity(), sa.Tendon(0.3, Straight(0.006, 0.0),
                                                                     0.4),
                                                sa.Chamber(2000.0, 1e-5, Straight(0.0, 0.005),
                                                           0.1, 0.45)], None),
        "a batch": (arm, [Gravity(), TipLoad([[0.1, 0.0, 0.0], [0.0, 0.0, 0.1]])], None),
    }


@pytest.mark.parametrize("name", list(_applied_cases()))
def test_applied_wrench_balances_the_solvers_base_wrench(name):
    """loads.applied_wrench (each load's resultant from the equilibrium's poses, the base
    of Equilibrium.contact_wrench) against a second method, the solver's base reaction:
    without contact they are the same wrench (forces applied to the arm and their moment
    about the origin) to 1e-8 of the loads."""
    import softarm as sa
    from softarm.loads import applied_wrench

    arm, loads, base = _applied_cases()[name]
    cuts = np.concatenate([np.asarray(load.cuts(arm), float) for load in loads]
                          + [np.asarray(arm.boundaries, float)])
    s = np.union1d(np.linspace(0.0, arm.length, 201), cuts)
    eq = sa.solve(arm, loads, s=s, method="numeric", base=base)
    force = eq.base_wrench[..., :3]
    moment = eq.base_wrench[..., 3:] + np.cross(eq.positions[..., 0, :], force)
    balance = np.concatenate([force, moment], -1) - applied_wrench(arm, tuple(loads), s,
                                                                   eq.poses)
    scale = np.abs(eq.base_wrench).max() + 1e-3
    assert np.abs(balance).max() < 1e-8 * scale
