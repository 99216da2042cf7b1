"""Material: the isotropic relation G = E / 2(1 + ν) and input checks."""

from __future__ import annotations

import dataclasses
import math

import pytest

from softarm import Material


@pytest.mark.parametrize(("nu", "ratio"), [(0.5, 1 / 3), (0.3, 1 / 2.6), (0.0, 0.5),
                                            (-0.5, 1.0)])
def test_shear_modulus_from_poisson_ratio(nu, ratio):
    # G = E / 2(1 + ν) (isotropic elasticity; Grazioso et al. 2018, after eq. 12).
    material = Material(1.0e6, poisson_ratio=nu)
    assert material.G == pytest.approx(ratio * 1.0e6, rel=1e-15)
    assert material.nu == nu
    assert material.E == 1.0e6


def test_poisson_ratio_from_shear_modulus():
    # ν = E/2G - 1: steel, E = 210 GPa, G = 80.77 GPa → ν = 0.3.
    material = Material(210e9, shear_modulus=210e9 / 2.6)
    assert material.nu == pytest.approx(0.3, rel=1e-14)
    assert material.G == 210e9 / 2.6


def test_density_is_optional():
    assert Material(1e6, poisson_ratio=0.5).density is None
    assert Material(1e6, poisson_ratio=0.5, density=1100.0).density == 1100.0


def test_material_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        Material(1e6, poisson_ratio=0.5).youngs_modulus = 2e6


@pytest.mark.parametrize("value", [0.0, -1e6, math.nan, math.inf])
def test_youngs_modulus_must_be_positive_and_finite(value):
    with pytest.raises(ValueError, match=r"Material\.youngs_modulus must be a positive finite "
                                         r"value in Pa"):
        Material(value, poisson_ratio=0.3)


@pytest.mark.parametrize("value", ["1e6", None, True])
def test_youngs_modulus_must_be_a_number(value):
    with pytest.raises(TypeError, match=r"Material\.youngs_modulus"):
        Material(value, poisson_ratio=0.3)


@pytest.mark.parametrize("nu", [-1.0, -1.5, 0.5000001, 0.6, math.nan, math.inf])
def test_poisson_ratio_range(nu):
    # ν in (-1, 0.5]: -1 and above 0.5 are not positive-definite isotropic materials.
    with pytest.raises(ValueError, match=r"Material\.poisson_ratio must lie in \(-1, 0\.5\]"):
        Material(1e6, poisson_ratio=nu)


@pytest.mark.parametrize("nu", [-0.999, 0.5])
def test_poisson_ratio_range_ends(nu):
    assert Material(1e6, poisson_ratio=nu).nu == nu


def test_poisson_ratio_must_be_a_number():
    with pytest.raises(TypeError, match=r"Material\.poisson_ratio must be a number"):
        Material(1e6, poisson_ratio="0.3")


def test_shear_modulus_must_give_valid_poisson_ratio():
    # ν = E/2G - 1 > -1 for every G > 0, but G < E/3 gives ν > 0.5.
    with pytest.raises(ValueError, match=r"Material\.poisson_ratio must lie in .*"
                                         r"shear_modulus=330000\.0"):
        Material(1e6, shear_modulus=3.3e5)
    assert Material(1e6, shear_modulus=1e7).nu == pytest.approx(-0.95, rel=1e-15)


@pytest.mark.parametrize("value", [0.0, -1.0, math.nan, math.inf])
def test_shear_modulus_must_be_positive_and_finite(value):
    with pytest.raises(ValueError, match=r"Material\.shear_modulus"):
        Material(1e6, shear_modulus=value)


def test_exactly_one_of_poisson_ratio_and_shear_modulus():
    with pytest.raises(ValueError, match=r"exactly one of poisson_ratio and shear_modulus.*"
                                         r"poisson_ratio=0\.3, shear_modulus=400000\.0"):
        Material(1e6, poisson_ratio=0.3, shear_modulus=4e5)
    with pytest.raises(ValueError, match=r"exactly one of poisson_ratio and shear_modulus.*"
                                         r"poisson_ratio=None, shear_modulus=None"):
        Material(1e6)


@pytest.mark.parametrize("value", [-1000.0, math.nan])  # 0: a massless arm
def test_density_must_be_non_negative(value):
    with pytest.raises(ValueError, match=r"Material\.density"):
        Material(1e6, poisson_ratio=0.5, density=value)
