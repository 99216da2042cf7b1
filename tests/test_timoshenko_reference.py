"""The cantilever frequency references of softarm/validation/_timoshenko.py against independent
values."""

import math

import numpy as np
import pytest

from softarm.validation._timoshenko import (
    cantilever_axial,
    cantilever_bending,
    cantilever_bending_fem,
    cantilever_bending_transfer,
    cantilever_torsion,
)

# Euler-Bernoulli clamped-free roots of cosh(βL) cos(βL) = -1: βL = 1.8751041, 4.6940911
# (e.g. Thomson, Theory of Vibration with Applications, appendix D.3: 1.8751, 4.6941)
EB_ROOTS = np.array([1.8751040687, 4.6940911330])


def test_slender_limit_is_euler_bernoulli():
    # r² = I/(A L²) = 1e-8 and s² = EI/(kGA L²) = 1e-8: corrections of relative order 1e-7
    omega = cantilever_bending(1.0, 1.0, 1e8, 1.0, 1e-8)
    np.testing.assert_allclose(omega, EB_ROOTS**2, rtol=1e-6)


def test_euler_bernoulli_scaling_with_units():
    # ω = (βL)² √(EI / (ρA L⁴)) for a steel-like slender rod, L = 2 m
    length, EI, rhoA = 2.0, 3.0e3, 7.8
    omega = cantilever_bending(length, EI, 1e12, rhoA, 1e-12)
    np.testing.assert_allclose(omega, EB_ROOTS**2 * math.sqrt(EI / (rhoA * length**4)), rtol=1e-6)


def test_shear_and_rotary_inertia_lower_the_frequencies():
    slender = cantilever_bending(1.0, 1.0, 1e8, 1.0, 1e-8)
    thick = cantilever_bending(1.0, 1.0, 100.0, 1.0, 1e-3)
    assert np.all(thick < slender)
    # the second mode (shorter wavelength) feels the corrections more
    assert thick[1] / slender[1] < thick[0] / slender[0]


@pytest.mark.parametrize(("kGA", "rhoI"), [(1e4, 1e-4), (100.0, 1e-3), (376.99, 1.3823e-4)])
def test_frequency_equation_agrees_with_matrix_exponential(kGA, rhoI):
    # the same boundary-value problem without the closed-form general solution
    omega = cantilever_bending(1.0, 1.0, kGA, 1.0, rhoI)
    np.testing.assert_allclose(cantilever_bending_transfer(1.0, 1.0, kGA, 1.0, rhoI), omega,
                               rtol=1e-7)


@pytest.mark.parametrize(("kGA", "rhoI"), [(1e4, 1e-4), (100.0, 1e-3)])
def test_frequency_equation_agrees_with_finite_elements(kGA, rhoI):
    # linear Timoshenko elements, O(h²): Richardson of 100 and 200 elements
    coarse = cantilever_bending_fem(1.0, 1.0, kGA, 1.0, rhoI, n_elements=100)
    fine = cantilever_bending_fem(1.0, 1.0, kGA, 1.0, rhoI, n_elements=200)
    omega = cantilever_bending(1.0, 1.0, kGA, 1.0, rhoI)
    assert np.all(np.abs(fine - omega) < np.abs(coarse - omega))  # converging
    np.testing.assert_allclose((4 * fine - coarse) / 3, omega, rtol=2e-6)


def test_swinging_arm_first_period():
    # helpers/swing.md quotes 1.48 s for the linear first period of the swinging arm
    r, youngs, rho = 0.02, 1.0e6, 1100.0
    area, inertia = math.pi * r**2, math.pi * r**4 / 4
    omega = cantilever_bending(0.5, youngs * inertia, 0.9 * youngs / 3 * area, rho * area,
                               rho * inertia)
    assert 2 * math.pi / omega[0] == pytest.approx(1.48, abs=0.01)


def test_quarter_wave_frequencies():
    # torsion: circle r = 0.02 m, G = 1e6/3 Pa, ρ = 1100 kg/m³: ω = (π/2L) √(G/ρ)
    r = 0.02
    polar = math.pi * r**4 / 2
    omega = cantilever_torsion(0.5, 1e6 / 3 * polar, 1100.0 * polar)
    assert omega == pytest.approx(math.pi / 1.0 * math.sqrt(1e6 / 3 / 1100.0), rel=1e-14)
    # axial: a steel bar, c = √(E/ρ) = 5064 m/s, L = 1 m: f = c / 4L = 1266 Hz
    area = 1e-4
    omega = cantilever_axial(1.0, 2.0e11 * area, 7800.0 * area)
    assert omega / (2 * math.pi) == pytest.approx(math.sqrt(2.0e11 / 7800.0) / 4.0, rel=1e-14)


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="kGA"):
        cantilever_bending(1.0, 1.0, -1.0, 1.0, 1e-3)
