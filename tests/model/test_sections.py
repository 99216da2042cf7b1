"""Cross-section properties against textbook values and a second numerical method."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.sparse as sparse
import scipy.sparse.linalg as sparse_linalg

from softarm import Circle, Material, Rectangle, Rigidities, Section, Tube

STEEL = Material(210e9, poisson_ratio=0.3)


# ---------------------------------------------------------------------------------------------
# Circle and tube: A, I, J in closed form (any strength-of-materials text, e.g. Roark's Formulas
# for Stress and Strain, 7th ed., Table A.1 and Table 10.1 case 1: J of a circle = polar moment).


def test_circle_properties():
    r = 0.01
    p = Circle(r).properties(0.3)
    assert p.area == pytest.approx(3.141592653589793e-4, rel=1e-15)  # π r²
    assert p.Iy == pytest.approx(7.853981633974483e-9, rel=1e-15)  # π r⁴/4
    assert p.Iz == p.Iy
    assert p.J == pytest.approx(1.5707963267948966e-8, rel=1e-15)  # π r⁴/2
    assert Circle(r).area == p.area
    assert Circle(r).envelope_radius == r


def test_tube_properties():
    ro, ri = 0.02, 0.015
    p = Tube(ro, ri).properties(0.3)
    assert p.area == pytest.approx(math.pi * (0.02**2 - 0.015**2), rel=1e-14)  # 5.4978e-4 m²
    assert p.Iy == pytest.approx(math.pi * (0.02**4 - 0.015**4) / 4, rel=1e-14)
    assert p.Iz == p.Iy
    assert p.J == pytest.approx(math.pi * (0.02**4 - 0.015**4) / 2, rel=1e-14)
    assert Tube(ro, ri).envelope_radius == ro
    # The tube is the circle minus the hole.
    outer, hole = Circle(ro).properties(0.3), Circle(ri).properties(0.3)
    assert p.J == pytest.approx(outer.J - hole.J, rel=1e-14)


# ---------------------------------------------------------------------------------------------
# Rectangle: width along material y, height along z.


def test_rectangle_second_moments_follow_the_axes():
    w, h = 0.03, 0.01
    p = Rectangle(width=w, height=h).properties(0.3)
    assert p.area == pytest.approx(3e-4, rel=1e-15)
    assert p.Iy == pytest.approx(w * h**3 / 12, rel=1e-15)  # ∫z² dA, bending about y: 2.5e-9
    assert p.Iz == pytest.approx(h * w**3 / 12, rel=1e-15)  # ∫y² dA, bending about z: 2.25e-8
    assert p.Iy < p.Iz  # a flat strip is weak about y
    turned = Rectangle(width=h, height=w).properties(0.3)
    assert (turned.Iy, turned.Iz) == pytest.approx((p.Iz, p.Iy), rel=1e-15)
    assert turned.J == p.J
    assert Rectangle(w, h).envelope_radius == w / 2


# Torsion constant J = β a b³ of an a × b rectangle, a >= b: the table of β (k₁) in
# Timoshenko & Goodier, Theory of Elasticity, 3rd ed. (1970), §109, as reproduced in the Oasys
# GSA theory manual, "Rectangular sections" (docs.oasys-software.com/structural/gsa/
# references-theory/rectangular-sections.html): printed to 3 digits. The issue (#2) quotes the
# first two to 4 digits (0.1406, 0.1958); they are held to half a unit of their last digit.
TORSION_TABLE = [
    (1.0, 0.1406, 5e-5),
    (1.5, 0.1958, 5e-5),
    (2.0, 0.229, 5e-4),
    (3.0, 0.263, 5e-4),
    (4.0, 0.281, 5e-4),
    (10.0, 0.312, 5e-4),
]


@pytest.mark.parametrize(("ratio", "beta", "half_unit"), TORSION_TABLE)
def test_rectangle_torsion_constant_against_table(ratio, beta, half_unit):
    b = 0.01
    a = ratio * b
    for section in (Rectangle(width=a, height=b), Rectangle(width=b, height=a)):
        J = section.properties(0.3).J
        assert abs(J / (a * b**3) - beta) <= half_unit
    # Below Iy + Iz (the polar moment, right only for circles).
    p = Rectangle(a, b).properties(0.3)
    assert J < p.Iy + p.Iz


def test_rectangle_torsion_constant_thin_strip_limit():
    # Narrow rectangle: J → (a b³/3)(1 - (192/π⁵) Σ_odd n⁻⁵ · b/a) = (a b³/3)(1 - 0.630 b/a)
    # (Timoshenko & Goodier, §109), with an error exponentially small in a/b (tanh → 1).
    odd_zeta5 = 31 / 32 * 1.0369277551433699  # Σ_odd n⁻⁵ = (1 - 2⁻⁵) ζ(5), ζ(5): OEIS A013663
    assert 192 / math.pi**5 * odd_zeta5 == pytest.approx(0.630, abs=5e-4)
    b = 0.001
    for ratio in (10.0, 20.0, 100.0):
        a = ratio * b
        J = Rectangle(a, b).properties(0.3).J
        assert J == pytest.approx(a * b**3 / 3 * (1 - 192 / math.pi**5 * odd_zeta5 / ratio),
                                  rel=1e-12)


def prandtl_torsion_constant(a: float, b: float, n: int) -> float:
    """J = 2 ∫ φ dA with ∇²φ = -2 in the a × b rectangle, φ = 0 on its edge (Prandtl's stress
    function, Timoshenko & Goodier §104), by the 5-point finite-difference Laplacian on an n × m
    grid of equal spacing; a second method, independent of the series in sections.py."""
    m = round(n * a / b)
    hx, hy = a / m, b / n

    def second_difference(k, h):
        ones = np.ones(k - 2)
        return sparse.diags([ones, -2 * np.ones(k - 1), ones], [-1, 0, 1]) / h**2

    laplacian = sparse.kronsum(second_difference(m, hx), second_difference(n, hy), format="csc")
    phi = sparse_linalg.spsolve(laplacian, -2 * np.ones(laplacian.shape[0]))
    return 2 * phi.sum() * hx * hy


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_rectangle_torsion_constant_against_finite_differences(ratio):
    b = 1.0
    a = ratio * b
    coarse, fine = prandtl_torsion_constant(a, b, 40), prandtl_torsion_constant(a, b, 80)
    richardson = (4 * fine - coarse) / 3  # the 5-point scheme is second order
    J = Rectangle(a, b).properties(0.3).J
    assert J == pytest.approx(richardson, rel=5e-6)  # measured 1.0e-6 (a/b = 1), 3.2e-7 (2)
    assert abs(J - fine) < abs(J - coarse)  # the grid converges towards it


# ---------------------------------------------------------------------------------------------
# Shear correction factors: G. R. Cowper, "The shear coefficient in Timoshenko's beam theory",
# J. Appl. Mech. 33:335-340 (1966), Table 1.


def test_cowper_circle():
    # 6(1 + ν)/(7 + 6ν) = 7.8/8.8 at ν = 0.3; 6/7 at ν = 0.
    assert Circle(0.01).properties(0.3).shear_factor_y == pytest.approx(0.8863636363636364,
                                                                       rel=1e-15)
    assert Circle(0.01).properties(0.0).shear_factor_z == pytest.approx(6 / 7, rel=1e-15)


def test_cowper_rectangle():
    # 10(1 + ν)/(12 + 11ν) = 13/15.3 at ν = 0.3; 5/6 at ν = 0.
    p = Rectangle(0.02, 0.01).properties(0.3)
    assert p.shear_factor_y == pytest.approx(0.8496732026143791, rel=1e-15)
    assert p.shear_factor_z == p.shear_factor_y
    assert Rectangle(0.02, 0.01).properties(0.0).shear_factor_y == pytest.approx(5 / 6, rel=1e-15)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.5])
def test_cowper_tube_limits(nu):
    # Thin-walled round tube: 2(1 + ν)/(4 + 3ν); a pinhole: the solid circle, 6(1 + ν)/(7 + 6ν).
    thin = Tube(1.0, 1.0 - 1e-7).properties(nu).shear_factor_y
    assert thin == pytest.approx(2 * (1 + nu) / (4 + 3 * nu), rel=1e-12)
    pinhole = Tube(1.0, 1e-7).properties(nu).shear_factor_y
    assert pinhole == pytest.approx(6 * (1 + nu) / (7 + 6 * nu), rel=1e-12)


# ---------------------------------------------------------------------------------------------
# Section and Rigidities


def test_general_section_passes_through():
    section = Section(area=2e-4, Iy=1e-9, Iz=3e-9, J=2e-9, shear_factor_y=0.8, shear_factor_z=0.7)
    assert section.properties(0.3) is section
    assert section.envelope_radius == pytest.approx(math.sqrt(2e-4 / math.pi), rel=1e-15)
    K = section.rigidities(Material(1e6, shear_modulus=4e5))
    # EA = E A, GA = k G A, GJ = G J, EI = E I (Grazioso et al. 2018, eqs. 11-12), by hand.
    assert np.allclose(K.matrix, np.diag([200.0, 64.0, 56.0, 8e-4, 1e-3, 3e-3]), rtol=1e-14,
                       atol=0)


def test_rigidities_matrix_order():
    K = Rigidities(EA=1.0, GAy=2.0, GAz=3.0, GJ=4.0, EIy=5.0, EIz=6.0).matrix
    assert K.shape == (6, 6) and K.dtype == np.float64
    assert np.array_equal(K, np.diag([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]))


def test_sections_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        Circle(0.01).radius = 0.02


# ---------------------------------------------------------------------------------------------
# Invalid input: each error names the parameter.

BAD_LENGTHS = [0.0, -1.0, math.nan, math.inf]


@pytest.mark.parametrize("value", BAD_LENGTHS)
def test_circle_radius_must_be_positive_and_finite(value):
    with pytest.raises(ValueError, match=r"Circle\.radius must be a positive finite value in m"):
        Circle(value)


@pytest.mark.parametrize("value", BAD_LENGTHS)
def test_tube_radii_must_be_positive_and_finite(value):
    with pytest.raises(ValueError, match=r"Tube\.outer_radius"):
        Tube(value, 0.001)
    with pytest.raises(ValueError, match=r"Tube\.inner_radius"):
        Tube(0.02, value)


@pytest.mark.parametrize("inner", [0.02, 0.03])
def test_tube_inner_radius_must_be_smaller(inner):
    with pytest.raises(ValueError, match=r"Tube\.inner_radius must be smaller than "
                                         r"Tube\.outer_radius.*inner_radius=0\.0[23]"):
        Tube(0.02, inner)


@pytest.mark.parametrize("value", BAD_LENGTHS)
def test_rectangle_sides_must_be_positive_and_finite(value):
    with pytest.raises(ValueError, match=r"Rectangle\.width"):
        Rectangle(value, 0.01)
    with pytest.raises(ValueError, match=r"Rectangle\.height"):
        Rectangle(0.01, value)


@pytest.mark.parametrize("value", [True, "0.01", None])
def test_dimensions_must_be_numbers(value):
    with pytest.raises(TypeError, match=r"Circle\.radius must be a positive number"):
        Circle(value)


@pytest.mark.parametrize("name", ["EA", "GAy", "GAz", "GJ", "EIy", "EIz"])
@pytest.mark.parametrize("value", [0.0, -2.0, math.nan, math.inf])
def test_rigidities_must_be_positive(name, value):
    values = dict(EA=1.0, GAy=1.0, GAz=1.0, GJ=1.0, EIy=1.0, EIz=1.0)
    values[name] = value
    with pytest.raises(ValueError, match=rf"Rigidities\.{name} must be a positive finite"):
        Rigidities(**values)


@pytest.mark.parametrize("name", ["shear_factor_y", "shear_factor_z"])
@pytest.mark.parametrize("value", [0.0, -0.5, 1.5, math.nan])
def test_section_shear_factors_in_unit_interval(name, value):
    with pytest.raises(ValueError, match=rf"Section\.{name}"):
        Section(area=1e-4, Iy=1e-9, Iz=1e-9, J=2e-9, **{name: value})


def test_section_rigidities_needs_a_material():
    with pytest.raises(TypeError, match=r"material must be a softarm\.Material"):
        Circle(0.01).rigidities(210e9)
