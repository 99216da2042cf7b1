"""Quaternion conversions against scipy's Rotation (an independent implementation)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm.lie import so3


def _scipy_wxyz(R):
    xyzw = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat()
    wxyz = np.concatenate([xyzw[:, 3:], xyzw[:, :3]], axis=-1)
    return np.where(wxyz[:, :1] < 0, -wxyz, wxyz)  # the same hemisphere, w >= 0


@pytest.mark.parametrize("angle", [0.0, 1e-9, 1e-4, 0.7, 2.0, np.pi - 1e-8])
def test_to_quaternion_matches_scipy(rng, angle):
    axes = rng.normal(size=(20, 3))
    w = angle * axes / np.linalg.norm(axes, axis=-1, keepdims=True)
    R = so3.exp(w)
    np.testing.assert_allclose(so3.to_quaternion(R), _scipy_wxyz(R), rtol=0, atol=2e-15)


def test_quaternion_round_trip_and_batch(rng):
    w = rng.normal(size=(3, 1, 2, 3))
    R = so3.exp(w)
    q = so3.to_quaternion(R)
    assert q.shape == (3, 1, 2, 4)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(so3.from_quaternion(q), R, rtol=0, atol=2e-15)
    # any non-zero norm: the quaternion is normalised first
    np.testing.assert_allclose(so3.from_quaternion(3.0 * q), R, rtol=0, atol=2e-15)


def test_from_quaternion_rejects_zero_and_bad_shape():
    with pytest.raises(ValueError, match="non-zero"):
        so3.from_quaternion([0.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"q must have shape \(\.\.\., 4\), got shape \(3,\)"):
        so3.from_quaternion([1.0, 0.0, 0.0])
