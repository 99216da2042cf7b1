"""Equilibrium: the result type's views slice the poses correctly and every array is read-only."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose

from softarm import Arm, Circle, Equilibrium, Material, TipLoad
from softarm.lie import se3

ARM = Arm(1.0, Circle(0.01), Material(1e6, poisson_ratio=0.5))
EPS = np.finfo(np.float64).eps


def arc(kappa_y: float, n: int = 11) -> dict:
    """A circular arc in the x-z plane, H(s) = exp(s (e1; κ e2)), with a constant internal force
    (1, 2, 3) N and moment (0, κ EI, 0) in the material frame."""
    s = np.linspace(0.0, 1.0, n)
    poses = se3.exp(s[:, None] * np.array([1.0, 0.0, 0.0, 0.0, kappa_y, 0.0]))
    strains = np.tile([0.0, 0.0, 0.0, 0.0, kappa_y, 0.0], (n, 1))
    stresses = np.tile([1.0, 2.0, 3.0, 0.0, kappa_y * 7.85e-3, 0.0], (n, 1))
    return dict(s=s, poses=poses, strains=strains, stresses=stresses, arm=ARM,
                loads=[TipLoad()], method="test.arc", exact=True)


def test_views_slice_the_poses():
    kappa = 1.5
    result = Equilibrium(**arc(kappa))
    s = result.s
    # The arc of curvature κ about +y bends towards -z (Grazioso et al. 2018, eqs. 37-38):
    # p(s) = (sin κs / κ, 0, -(1 - cos κs)/κ), R(s) = [[c, 0, sn], [0, 1, 0], [-sn, 0, c]].
    expected_p = np.stack([np.sin(kappa * s) / kappa, 0 * s, -(1 - np.cos(kappa * s)) / kappa], -1)
    c, sn = np.cos(kappa * s), np.sin(kappa * s)
    expected_R = np.zeros((s.size, 3, 3))
    expected_R[:, 0, 0], expected_R[:, 0, 2], expected_R[:, 1, 1] = c, sn, 1.0
    expected_R[:, 2, 0], expected_R[:, 2, 2] = -sn, c
    assert result.positions.shape == (11, 3)
    assert result.rotations.shape == (11, 3, 3)
    assert_allclose(result.positions, expected_p, rtol=0, atol=4 * EPS)
    assert_allclose(result.rotations, expected_R, rtol=0, atol=4 * EPS)
    assert result.tip.shape == (4, 4)
    assert np.array_equal(result.tip, result.poses[-1])
    assert np.array_equal(result.tip_position, result.positions[-1])
    assert_allclose(result.tip_position, [np.sin(1.5) / 1.5, 0.0, -(1 - np.cos(1.5)) / 1.5],
                    rtol=0, atol=4 * EPS)
    assert result.batch_shape == ()


def test_spatial_resultants_rotate_material_components():
    result = Equilibrium(**arc(1.5))
    R = result.rotations
    n_material = result.stresses[..., :3]
    assert_allclose(result.forces_spatial, np.einsum("nij,nj->ni", R, n_material), rtol=1e-15)
    # At the tip the material e1 (the arm axis) is the first column of R.
    assert_allclose(result.forces_spatial[-1],
                    1.0 * R[-1, :, 0] + 2.0 * R[-1, :, 1] + 3.0 * R[-1, :, 2], rtol=1e-14)
    assert_allclose(result.moments_spatial[:, 1], 1.5 * 7.85e-3, rtol=1e-14)  # m ∥ e2 = y


def test_arrays_are_read_only_copies():
    fields = arc(0.7)
    given = fields["poses"]
    result = Equilibrium(**fields)
    given[0, 0, 3] = 99.0  # the caller's array is theirs to change
    assert result.poses[0, 0, 3] == 0.0
    for name in ("s", "poses", "strains", "stresses"):
        array = getattr(result, name)
        assert array.dtype == np.float64
        with pytest.raises(ValueError, match="read-only"):
            array[..., 0] = 1.0
    for view in (result.positions, result.rotations, result.tip, result.tip_position):
        with pytest.raises(ValueError, match="read-only"):
            view[..., 0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.method = "other"
    assert isinstance(result.loads, tuple)


def test_batched_result():
    one, two = arc(0.5), arc(-2.0)
    fields = dict(one)
    for name in ("poses", "strains", "stresses"):
        fields[name] = np.stack([one[name], two[name]])
    result = Equilibrium(**fields)
    assert result.batch_shape == (2,)
    assert result.positions.shape == (2, 11, 3)
    assert result.tip.shape == (2, 4, 4)
    assert result.tip_position.shape == (2, 3)
    for k, single in enumerate((one, two)):
        alone = Equilibrium(**single)
        assert np.array_equal(result.positions[k], alone.positions)
        assert np.array_equal(result.tip[k], alone.tip)
        assert np.array_equal(result.forces_spatial[k], alone.forces_spatial)
    assert "batch (2,)" in repr(result)


def test_repr_names_method_and_tip():
    text = repr(Equilibrium(**arc(1.0)))
    assert text.startswith("Equilibrium(method='test.arc', exact=True, stations=11")
    assert "tip_position=[" in text


@pytest.mark.parametrize("name", ["poses", "strains", "stresses"])
def test_mismatched_arrays_are_refused(name):
    fields = arc(1.0)
    fields[name] = fields[name][:-1]  # one station short
    with pytest.raises(ValueError, match=r"Equilibrium arrays disagree: s \(11,\)"):
        Equilibrium(**fields)


def test_writable_inputs_are_copied_and_isolated():
    fields = arc(0.7)
    given = {name: fields[name] for name in ("s", "poses", "strains", "stresses")}
    kept = {name: array.copy() for name, array in given.items()}
    result = Equilibrium(**fields)
    for name, array in given.items():
        assert array.flags.writeable  # the caller's array is left writable
        assert not np.shares_memory(getattr(result, name), array)
        array[...] = -1.0  # later writes do not reach the result
        assert np.array_equal(getattr(result, name), kept[name])


def test_read_only_inputs_are_taken_without_copy():
    fields = arc(0.7)
    for name in ("s", "poses", "strains", "stresses"):
        fields[name] = np.array(fields[name])  # owns its memory (linspace's s is a view)
        fields[name].setflags(write=False)
    # A constant field as a zero-stride read-only view of a frozen array.
    row = np.array([[0.0, 0.0, 0.0, 0.0, 0.7, 0.0]])
    row.setflags(write=False)
    fields["strains"] = np.broadcast_to(row, (11, 6))
    result = Equilibrium(**fields)
    for name in ("s", "poses", "stresses"):
        assert getattr(result, name) is fields[name]
    assert result.strains is fields["strains"] and np.shares_memory(result.strains, row)


def test_read_only_view_of_a_writable_array_is_copied():
    fields = arc(0.7)
    writable = fields["poses"]
    fields["poses"] = writable.view()
    fields["poses"].setflags(write=False)
    fields["strains"] = fields["strains"].astype(np.float32)  # another dtype: converted
    fields["strains"].setflags(write=False)
    result = Equilibrium(**fields)
    assert not np.shares_memory(result.poses, writable)
    assert result.strains.dtype == np.float64 and not result.strains.flags.writeable
    writable[0, 0, 3] = 99.0
    assert result.poses[0, 0, 3] == 0.0
