"""Cross-sections: area, second moments, torsion constant and shear correction factors.

The material frame is (e1, e2, e3) = (axis, y, z). ``Iy`` = ∫ z² dA is the second moment for
bending about y (EI_y, curvature κ_y), ``Iz`` = ∫ y² dA for bending about z. Shear correction
factors are Cowper's (G. R. Cowper, "The shear coefficient in Timoshenko's beam theory",
J. Appl. Mech. 33:335-340, 1966, Table 1); they depend on Poisson's ratio ν, so every section
turns into stiffnesses only together with a :class:`~softarm.model.Material`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validate import format_value, length, positive
from .material import Material

__all__ = ["Circle", "Rectangle", "Rigidities", "Section", "StiffnessMatrix", "Tube"]


@dataclass(frozen=True)
class Rigidities:
    """The six cross-section stiffnesses of a rod (the diagonal of K, eqs. 11-12).

    Parameters
    ----------
    EA : float
        Axial stiffness in N.
    GAy, GAz : float
        Shear stiffnesses along material y and z in N (shear correction included).
    GJ : float
        Torsional stiffness in N m².
    EIy, EIz : float
        Bending stiffnesses about material y and z in N m².
    """

    EA: float
    GAy: float
    GAz: float
    GJ: float
    EIy: float
    EIz: float

    def __post_init__(self):
        for name, unit in (("EA", "N"), ("GAy", "N"), ("GAz", "N"), ("GJ", "N m²"),
                           ("EIy", "N m²"), ("EIz", "N m²")):
            object.__setattr__(self, name, positive(getattr(self, name), f"Rigidities.{name}",
                                                    unit))

    @property
    def matrix(self) -> np.ndarray:
        """K = diag(EA, GAy, GAz, GJ, EIy, EIz), shape (6, 6) (eqs. 10-12)."""
        return np.diag([self.EA, self.GAy, self.GAz, self.GJ, self.EIy, self.EIz]).astype(float)


@dataclass(frozen=True)
class StiffnessMatrix:
    """A section known by a full symmetric positive-definite 6 × 6 stiffness K (linear part
    first: (n; m) = K (γ; κ)), e.g. a fibre-reinforced actuator whose bending, twist and
    extension are coupled. Use :meth:`softarm.Arm.from_stiffness_matrix`.

    ``matrix`` is stored as a tuple of rows (an arm stays hashable); :attr:`rigidities` are
    its diagonal, for the places that need a scale (the closed forms do not apply).
    """

    matrix: tuple

    def __post_init__(self):
        try:
            K = np.array(self.matrix, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError(f"the stiffness matrix K must be a 6 × 6 array of numbers, got "
                            f"{format_value(self.matrix)}") from None
        if K.shape != (6, 6) or not np.all(np.isfinite(K)):
            raise ValueError(f"the stiffness matrix K must be a finite 6 × 6 array, got shape "
                             f"{K.shape}")
        if not np.allclose(K, K.T, rtol=1e-12, atol=0.0):
            raise ValueError("the stiffness matrix K must be symmetric (largest asymmetry "
                             f"{np.max(np.abs(K - K.T)):.3g})")
        smallest = float(np.min(np.linalg.eigvalsh(K)))
        if not smallest > 0.0:
            raise ValueError(f"the stiffness matrix K must be positive definite, got smallest "
                             f"eigenvalue {smallest:.3g}")
        object.__setattr__(self, "matrix", tuple(tuple(float(x) for x in row) for row in K))

    @property
    def rigidities(self) -> Rigidities:
        """The diagonal of K as :class:`Rigidities`."""
        return Rigidities(*np.diagonal(np.array(self.matrix)))


@dataclass(frozen=True)
class Section:
    """A general cross-section given by its properties (principal axes along y and z).

    Parameters
    ----------
    area : float
        A in m².
    Iy, Iz : float
        Second moments of area about material y and z in m⁴.
    J : float
        Torsion constant in m⁴ (equal to the polar moment only for circular sections).
    shear_factor_y, shear_factor_z : float
        Shear correction factors k (GA_eff = k G A); 1 means no correction.
    """

    area: float
    Iy: float
    Iz: float
    J: float
    shear_factor_y: float = 1.0
    shear_factor_z: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "area", positive(self.area, "Section.area", "m²"))
        for name in ("Iy", "Iz", "J"):
            object.__setattr__(self, name, positive(getattr(self, name), f"Section.{name}", "m⁴"))
        for name in ("shear_factor_y", "shear_factor_z"):
            value = positive(getattr(self, name), f"Section.{name}", "(dimensionless)")
            if value > 1.0:
                raise ValueError(f"Section.{name} must lie in (0, 1], got {value!r}")
            object.__setattr__(self, name, value)

    def properties(self, poisson_ratio: float) -> Section:
        """This section's properties (the shear factors were given, so ν is not used)."""
        return self

    @property
    def envelope_radius(self) -> float:
        """Radius of the circle of the same area (m), used to draw the arm as a tube."""
        return math.sqrt(self.area / math.pi)

    def rigidities(self, material: Material) -> Rigidities:
        """Stiffnesses of this section made of ``material`` (eqs. 11-12)."""
        if not isinstance(material, Material):
            raise TypeError(f"material must be a softarm.Material, got {format_value(material)}")
        p = self.properties(material.nu)
        E, G = material.E, material.G
        return Rigidities(
            EA=E * p.area,
            GAy=p.shear_factor_y * G * p.area,
            GAz=p.shear_factor_z * G * p.area,
            GJ=G * p.J,
            EIy=E * p.Iy,
            EIz=E * p.Iz,
        )


class _Shape:
    """Mixin for named shapes: their properties depend on ν through the shear factors."""

    def rigidities(self, material: Material) -> Rigidities:
        return Section.rigidities(self, material)

    @property
    def area(self) -> float:
        return self.properties(0.0).area


@dataclass(frozen=True)
class Circle(_Shape):
    """Solid circular cross-section.

    A = π r², Iy = Iz = π r⁴/4, J = π r⁴/2 (exact, Saint-Venant), shear factor
    6(1 + ν)/(7 + 6ν) (Cowper 1966).

    Parameters
    ----------
    radius : float
        r in m.
    """

    radius: float

    def __post_init__(self):
        object.__setattr__(self, "radius", length(self.radius, "Circle.radius"))

    def properties(self, poisson_ratio: float) -> Section:
        r, nu = self.radius, poisson_ratio
        k = 6 * (1 + nu) / (7 + 6 * nu)
        return Section(math.pi * r**2, math.pi * r**4 / 4, math.pi * r**4 / 4,
                       math.pi * r**4 / 2, k, k)

    @property
    def envelope_radius(self) -> float:
        return self.radius


@dataclass(frozen=True)
class Tube(_Shape):
    """Hollow circular cross-section (thick or thin walled).

    A = π (ro² - ri²), Iy = Iz = π (ro⁴ - ri⁴)/4, J = π (ro⁴ - ri⁴)/2 (exact), shear factor
    6(1 + ν)(1 + m²)² / ((7 + 6ν)(1 + m²)² + (20 + 12ν) m²) with m = ri/ro (Cowper 1966).

    Parameters
    ----------
    outer_radius, inner_radius : float
        ro > ri > 0 in m.
    """

    outer_radius: float
    inner_radius: float

    def __post_init__(self):
        for name in ("outer_radius", "inner_radius"):
            object.__setattr__(self, name, length(getattr(self, name), f"Tube.{name}"))
        if self.inner_radius >= self.outer_radius:
            raise ValueError(
                "Tube.inner_radius must be smaller than Tube.outer_radius, got "
                f"inner_radius={self.inner_radius!r} >= outer_radius={self.outer_radius!r}"
            )

    def properties(self, poisson_ratio: float) -> Section:
        ro, ri, nu = self.outer_radius, self.inner_radius, poisson_ratio
        m2 = (ri / ro) ** 2
        k = 6 * (1 + nu) * (1 + m2) ** 2 / ((7 + 6 * nu) * (1 + m2) ** 2 + (20 + 12 * nu) * m2)
        i = math.pi * (ro**4 - ri**4) / 4
        return Section(math.pi * (ro**2 - ri**2), i, i, 2 * i, k, k)

    @property
    def envelope_radius(self) -> float:
        return self.outer_radius


def _rectangle_torsion_constant(a: float, b: float) -> float:
    """Saint-Venant torsion constant of an a × b rectangle, a >= b (Timoshenko & Goodier,
    Theory of Elasticity, 3rd ed., §109): J = (a b³/3)[1 - (192 b / π⁵ a) Σ_odd n⁻⁵ tanh(nπa/2b)].
    """
    n = np.arange(1, 200, 2, dtype=float)
    series = np.sum(np.tanh(n * math.pi * a / (2 * b)) / n**5)
    return float(a * b**3 / 3 * (1 - 192 * b / (math.pi**5 * a) * series))


@dataclass(frozen=True)
class Rectangle(_Shape):
    """Solid rectangular cross-section, ``width`` along material y and ``height`` along z.

    A = w h, Iy = w h³/12 (bending about y), Iz = h w³/12, J from the Saint-Venant series
    (not Iy + Iz), shear factor 10(1 + ν)/(12 + 11ν) (Cowper 1966) on both axes.

    Parameters
    ----------
    width, height : float
        In m.
    """

    width: float
    height: float

    def __post_init__(self):
        object.__setattr__(self, "width", length(self.width, "Rectangle.width"))
        object.__setattr__(self, "height", length(self.height, "Rectangle.height"))

    def properties(self, poisson_ratio: float) -> Section:
        w, h, nu = self.width, self.height, poisson_ratio
        k = 10 * (1 + nu) / (12 + 11 * nu)
        J = _rectangle_torsion_constant(max(w, h), min(w, h))
        return Section(w * h, w * h**3 / 12, h * w**3 / 12, J, k, k)

    @property
    def envelope_radius(self) -> float:
        return 0.5 * max(self.width, self.height)
