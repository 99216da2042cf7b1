"""softarm.sweep: the sweep description and its execution, public, and still reachable under
the names softarm.case gave them first."""

from __future__ import annotations

import types

import numpy as np
import pytest

import softarm
import softarm.case
import softarm.sweep
from softarm import TipLoad
from softarm.sweep import Sweep


def test_public_module_and_old_names():
    assert isinstance(softarm.sweep, types.ModuleType)  # not shadowed by a function
    assert "sweep" in softarm.__all__ and softarm.sweep.__name__ == "softarm.sweep"
    assert softarm.case.solve_case is softarm.sweep.solve_case
    assert softarm.case.Sweep is softarm.sweep.Sweep
    from softarm._schema import arm_to_dict, loads_to_dict
    assert softarm.case.arm_to_dict is arm_to_dict
    assert softarm.case.loads_to_dict is loads_to_dict


@pytest.mark.parametrize(("direction", "unit"), [
    ((0.0, 0.0, 1e300), (0.0, 0.0, 1.0)),  # |v|² overflows (softarm 0.1 swept a zero force)
    ((3e300, 4e300, 0.0), (0.6, 0.8, 0.0)),  # 3-4-5 triangle
    ((0.0, 3e-320, 4e-320), (0.0, 0.6, 0.8)),  # subnormal: |v|² underflows to 0
    ((0.0, -2.0, 0.0), (0.0, -1.0, 0.0)),
])
def test_magnitude_sweep_keeps_the_direction(direction, unit):
    """A 'magnitude' sweep gives vectors of the swept length along the file's direction,
    whatever the scale of the direction vector (reference: the unit vectors written here)."""
    values = (0.0, 0.5, 2.0)
    sweep = Sweep(0, "tip", "force", "magnitude", values)
    (swept,) = sweep.apply([TipLoad(force=direction)])
    expected = np.asarray(values)[:, None] * np.asarray(unit)
    np.testing.assert_allclose(swept.force, expected, rtol=0, atol=1e-15)


def test_component_sweep_keeps_the_other_components():
    sweep = Sweep(0, "tip", "moment", "y", (1.0, -2.0))
    (swept,) = sweep.apply([TipLoad(force=[0.0, 0.0, 1.0], moment=[5.0, 7.0, 9.0])])
    np.testing.assert_array_equal(swept.moment, [[5.0, 1.0, 9.0], [5.0, -2.0, 9.0]])
    np.testing.assert_array_equal(swept.force, [0.0, 0.0, 1.0])
