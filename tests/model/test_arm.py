"""Arm and SegmentedArm: stiffness matrix, reference strain, density, and input checks."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from softarm import Arm, Circle, Material, Rectangle, Rigidities, SegmentedArm, Tube

SILICONE = Material(1.0e6, poisson_ratio=0.5, density=1100.0)


def test_stiffness_of_a_circular_arm_by_hand():
    # K = diag(EA, k G A, k G A, G J, E I, E I) (Grazioso et al. 2018, eqs. 11-12) for r = 0.01 m,
    # E = 1 MPa, ν = 0.5: G = E/3, A = π 1e-4, I = π 1e-8/4, J = π 1e-8/2, and Cowper's
    # k = 6(1 + ν)/(7 + 6ν) = 9/10 (Cowper 1966, Table 1).
    arm = Arm(0.3, Circle(0.01), SILICONE)
    pi = math.pi
    EA = 1e6 * pi * 1e-4  # 314.159... N
    kGA = 0.9 * (1e6 / 3) * pi * 1e-4  # 94.2477... N
    GJ = (1e6 / 3) * pi * 1e-8 / 2  # 5.23598...e-3 N m²
    EI = 1e6 * pi * 1e-8 / 4  # 7.85398...e-3 N m²
    expected = np.diag([EA, kGA, kGA, GJ, EI, EI])
    K = arm.stiffness
    assert K.shape == (6, 6) and K.dtype == np.float64
    np.testing.assert_allclose(K, expected, rtol=1e-14, atol=0)
    assert arm.rigidities.EIy == pytest.approx(EI, rel=1e-14)


def test_stiffness_of_a_rectangular_arm_follows_the_axes():
    # Width along y: EIy = E w h³/12 is the weak (flapwise) stiffness of a flat strip.
    arm = Arm(1.0, Rectangle(width=0.03, height=0.01), Material(2e9, poisson_ratio=0.3))
    assert arm.rigidities.EIy == pytest.approx(2e9 * 0.03 * 0.01**3 / 12, rel=1e-14)  # 5 N m²
    assert arm.rigidities.EIz == pytest.approx(2e9 * 0.01 * 0.03**3 / 12, rel=1e-14)  # 45 N m²


def test_from_stiffness():
    arm = Arm.from_stiffness(0.5, EA=1e6, GAy=2e5, GAz=3e5, GJ=0.4, EIy=0.5, EIz=0.6,
                             curvature=(0.0, 1.0, 0.0), mass_per_length=0.2)
    assert np.array_equal(arm.stiffness, np.diag([1e6, 2e5, 3e5, 0.4, 0.5, 0.6]))
    assert arm.material is None
    assert arm.rigidities == Rigidities(1e6, 2e5, 3e5, 0.4, 0.5, 0.6)
    assert arm.length == 0.5
    assert arm.linear_density == 0.2
    assert arm.radius is None
    assert np.array_equal(arm.reference_strain, [1.0, 0.0, 0.0, 0.0, 1.0, 0.0])


def test_reference_strain_with_curvature():
    # f⁰ = (1, 0, 0, κ⁰): unit stretch along e1, then twist and curvatures (eq. 3).
    arm = Arm(0.2, Circle(0.01), SILICONE, curvature=[0.5, -2.0, 3.0])
    f0 = arm.reference_strain
    assert f0.shape == (6,) and f0.dtype == np.float64
    assert np.array_equal(f0, [1.0, 0.0, 0.0, 0.5, -2.0, 3.0])
    assert arm.curvature == (0.5, -2.0, 3.0)
    assert all(type(c) is float for c in arm.curvature)
    assert np.array_equal(Arm(0.2, Circle(0.01), SILICONE).reference_strain, [1, 0, 0, 0, 0, 0])


def test_linear_density():
    # μ = ρ A = 1100 kg/m³ · π (0.01 m)² = 0.345575... kg/m; an explicit value overrides it.
    assert Arm(0.3, Circle(0.01), SILICONE).linear_density == pytest.approx(
        1100 * math.pi * 1e-4, rel=1e-15)
    assert Arm(0.3, Tube(0.02, 0.01), SILICONE).linear_density == pytest.approx(
        1100 * math.pi * (4e-4 - 1e-4), rel=1e-14)
    assert Arm(0.3, Circle(0.01), SILICONE, mass_per_length=0.5).linear_density == 0.5
    assert Arm(0.3, Circle(0.01), Material(1e6, poisson_ratio=0.5)).linear_density is None
    assert Arm.from_stiffness(1.0, 1, 1, 1, 1, 1, 1).linear_density is None


def test_radius_and_segments():
    arm = Arm(0.3, Tube(0.02, 0.01), SILICONE)
    assert arm.radius == 0.02
    assert arm.segments == (arm,)


def test_segmented_arm_length_and_boundaries():
    parts = [Arm(0.25, Circle(0.012), SILICONE), Arm(0.125, Circle(0.008), SILICONE),
             Arm(0.1, Circle(0.006), SILICONE, curvature=(0, 2.0, 0))]
    arm = SegmentedArm(parts)
    assert arm.segments == tuple(parts)
    assert arm.length == pytest.approx(0.475, rel=1e-15)
    assert arm.boundaries == pytest.approx((0.0, 0.25, 0.375, 0.475), rel=1e-15)
    assert isinstance(arm.boundaries, tuple) and all(type(b) is float for b in arm.boundaries)
    single = SegmentedArm((parts[0],))
    assert single.length == 0.25 and single.boundaries == (0.0, 0.25)


def test_arms_are_frozen():
    arm = Arm(0.3, Circle(0.01), SILICONE)
    with pytest.raises(dataclasses.FrozenInstanceError):
        arm.length = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        SegmentedArm([arm]).segments = ()


# ---------------------------------------------------------------------------------------------
# Invalid input: each error names the parameter.


@pytest.mark.parametrize("length", [0.0, -0.3, math.nan, math.inf])
def test_length_must_be_positive_and_finite(length):
    with pytest.raises(ValueError, match=r"Arm\.length must be a positive finite value in m"):
        Arm(length, Circle(0.01), SILICONE)
    with pytest.raises(ValueError, match=r"Arm\.length"):
        Arm.from_stiffness(length, 1, 1, 1, 1, 1, 1)


@pytest.mark.parametrize("length", ["0.3", None, False])
def test_length_must_be_a_number(length):
    with pytest.raises(TypeError, match=r"Arm\.length"):
        Arm(length, Circle(0.01), SILICONE)


def test_section_must_be_a_section():
    with pytest.raises(TypeError, match=r"Arm\.section must be a Circle, Tube, Rectangle"):
        Arm(0.3, 0.01, SILICONE)


def test_material_is_required_for_a_shape():
    with pytest.raises(TypeError, match=r"Arm\.material must be a softarm\.Material"):
        Arm(0.3, Circle(0.01))
    with pytest.raises(TypeError, match=r"Arm\.material"):
        Arm(0.3, Circle(0.01), 1.0e6)


def test_material_with_rigidities_is_refused():
    with pytest.raises(ValueError, match=r"Arm\.material must be None when the section is given "
                                         r"by its Rigidities"):
        Arm(0.3, Rigidities(1, 1, 1, 1, 1, 1), SILICONE)


@pytest.mark.parametrize("curvature", [(1.0, 2.0), (1.0, 2.0, 3.0, 4.0), [[0.0, 1.0, 0.0]], 1.0])
def test_curvature_must_be_a_3_vector(curvature):
    with pytest.raises(ValueError, match=r"Arm\.curvature must have shape"):
        Arm(0.3, Circle(0.01), SILICONE, curvature=curvature)


@pytest.mark.parametrize("value", [math.nan, math.inf])
def test_curvature_must_be_finite(value):
    with pytest.raises(ValueError, match=r"Arm\.curvature must be finite"):
        Arm(0.3, Circle(0.01), SILICONE, curvature=(0.0, value, 0.0))


@pytest.mark.parametrize("value", [-1.0, math.nan])  # 0 is a massless arm (test_massless_arm)
def test_mass_per_length_must_be_non_negative(value):
    with pytest.raises(ValueError, match=r"Arm\.mass_per_length"):
        Arm(0.3, Circle(0.01), SILICONE, mass_per_length=value)


@pytest.mark.parametrize("segments", [[], (), [Circle(0.01)], Arm(0.3, Circle(0.01), SILICONE),
                                      None])
def test_segmented_arm_needs_arms(segments):
    with pytest.raises(TypeError, match=r"SegmentedArm\.segments must be a non-empty sequence "
                                        r"of Arm"):
        SegmentedArm(segments)
