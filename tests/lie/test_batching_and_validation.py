"""Every public function of softarm.lie: batched equals looped, and bad input is refused clearly."""

from __future__ import annotations

import re

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from softarm import lie
from softarm.lie import se3, so3

# name -> (function, parameter name, input kind, input trailing shape, output trailing shape)
FUNCTIONS = {
    "so3.hat": (so3.hat, "w", "w", (3,), (3, 3)),
    "so3.vee": (so3.vee, "W", "skew", (3, 3), (3,)),
    "so3.exp": (so3.exp, "w", "w", (3,), (3, 3)),
    "so3.log": (so3.log, "R", "rotation", (3, 3), (3,)),
    "so3.jac_right": (so3.jac_right, "w", "w", (3,), (3, 3)),
    "so3.jac_right_inv": (so3.jac_right_inv, "w", "w", (3,), (3, 3)),
    "so3.jac_left": (so3.jac_left, "w", "w", (3,), (3, 3)),
    "so3.jac_left_inv": (so3.jac_left_inv, "w", "w", (3,), (3, 3)),
    "so3.to_quaternion": (so3.to_quaternion, "R", "rotation", (3, 3), (4,)),
    "so3.from_quaternion": (so3.from_quaternion, "q", "quaternion", (4,), (3, 3)),
    "se3.hat": (se3.hat, "h", "h", (6,), (4, 4)),
    "se3.vee": (se3.vee, "X", "twist_matrix", (4, 4), (6,)),
    "se3.exp": (se3.exp, "h", "h", (6,), (4, 4)),
    "se3.log": (se3.log, "H", "pose", (4, 4), (6,)),
    "se3.inverse": (se3.inverse, "H", "pose", (4, 4), (4, 4)),
    "se3.adjoint": (se3.adjoint, "H", "pose", (4, 4), (6, 6)),
    "se3.ad": (se3.ad, "h", "h", (6,), (6, 6)),
    "se3.jac_right": (se3.jac_right, "h", "h", (6,), (6, 6)),
    "se3.jac_right_inv": (se3.jac_right_inv, "h", "h", (6,), (6, 6)),
}
BATCH_SHAPES = [(), (1,), (3, 1, 2)]


def test_every_public_function_is_covered():
    public = {f"{module.__name__.rsplit('.', 1)[-1]}.{name}"
              for module in (lie.so3, lie.se3) for name in module.__all__}
    assert public == set(FUNCTIONS) | {"se3.from_rotation_translation"}  # two inputs: below
    assert set(lie.__all__) == {"so3", "se3"}


def rotation_vectors(rng, batch) -> np.ndarray:
    """Rotation vectors with angles mixed across regimes: 1e-9, middle, π - 1e-8, 0."""
    n = int(np.prod(batch, dtype=int))
    axes = rng.normal(size=(n, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    theta = np.array([1e-9, 1.3, np.pi - 1e-8, 0.0, 1e-5, 2.9])[np.arange(n) % 6]
    return (theta[:, None] * axes).reshape(*batch, 3)


def make_input(kind, rng, batch) -> np.ndarray:
    w = rotation_vectors(rng, batch)
    u = rng.uniform(-2, 2, size=w.shape)
    h = np.concatenate([u, w], axis=-1)
    return {
        "w": w,
        "skew": so3.hat(w),
        "rotation": so3.exp(w),
        "h": h,
        "twist_matrix": se3.hat(h),
        "pose": se3.exp(h),
        "quaternion": so3.to_quaternion(so3.exp(w)),
    }[kind]


@pytest.mark.parametrize("batch", BATCH_SHAPES, ids=str)
@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_batched_equals_looped(name, batch, rng):
    function, _, kind, in_shape, out_shape = FUNCTIONS[name]
    x = make_input(kind, rng, batch)
    assert x.shape == batch + in_shape
    out = function(x)
    assert out.shape == batch + out_shape
    assert out.dtype == np.float64
    for index in np.ndindex(*batch):
        assert_array_equal(out[index], function(x[index]))
    # Nested lists are accepted like arrays, and the input is left untouched.
    before = x.copy()
    assert_array_equal(function(x.tolist()), out)
    assert_array_equal(x, before)


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_wrong_trailing_shape_names_parameter_and_shapes(name):
    function, parameter, _, in_shape, _ = FUNCTIONS[name]
    expected = "(..., " + ", ".join(map(str, in_shape)) + ")"
    wrong = (*in_shape[:-1], in_shape[-1] + 1)
    for bad in (np.zeros(wrong), np.zeros((2, *wrong)), np.zeros((*in_shape[::-1], 1))):
        message = f"{parameter} must have shape {expected}, got shape {bad.shape}"
        with pytest.raises(ValueError, match=re.escape(message)):
            function(bad)
    with pytest.raises(ValueError, match=re.escape(f"got shape {()}")):
        function(1.0)  # a scalar has no trailing object axes


@pytest.mark.parametrize("bad_value", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_non_finite_input_names_parameter(name, bad_value, rng):
    function, parameter, kind, _, _ = FUNCTIONS[name]
    x = make_input(kind, rng, (2,))
    x[1, 0] = bad_value
    with pytest.raises(ValueError, match=rf"^{parameter} must be finite"):
        function(x)


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_non_numeric_input_names_parameter(name):
    function, parameter, _, _, _ = FUNCTIONS[name]
    with pytest.raises(TypeError, match=rf"^{parameter} must be numeric"):
        function("not an array")


@pytest.mark.parametrize("batch", BATCH_SHAPES, ids=str)
def test_from_rotation_translation_batched_equals_looped(batch, rng):
    h = make_input("h", rng, batch)
    H = se3.exp(h)  # an independent pose: its blocks must come back as they are
    out = se3.from_rotation_translation(H[..., :3, :3], H[..., :3, 3])
    assert out.shape == (*batch, 4, 4)
    assert_array_equal(out, H)
    for index in np.ndindex(*batch):
        assert_array_equal(out[index], se3.from_rotation_translation(H[index][:3, :3],
                                                                     H[index][:3, 3]))
    with pytest.raises(ValueError, match=r"p must have shape \(\.\.\., 3\), got shape \(2,\)"):
        se3.from_rotation_translation(np.eye(3), [1.0, 2.0])
