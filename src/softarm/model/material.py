"""Linear elastic, isotropic materials."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .._validate import format_value, nonnegative, positive, real

__all__ = ["Material"]


@dataclass(frozen=True)
class Material:
    """A linear elastic isotropic material (SI units).

    Give exactly one of ``poisson_ratio`` and ``shear_modulus``; the other follows from
    G = E / (2 (1 + ν)) (Grazioso et al. 2018, after eq. 12).

    Parameters
    ----------
    youngs_modulus : float
        E in Pa.
    poisson_ratio : float, optional
        ν, in (-1, 0.5].
    shear_modulus : float, optional
        G in Pa; must give ν = E/2G - 1 in (-1, 0.5].
    density : float, optional
        ρ in kg/m³, >= 0, needed for gravity (0: a massless rod, on which gravity acts on
        nothing).

    Examples
    --------
    >>> silicone = Material(youngs_modulus=1.0e6, poisson_ratio=0.5, density=1100.0)
    >>> round(silicone.G, 3)
    333333.333
    """

    youngs_modulus: float
    poisson_ratio: float | None = None
    shear_modulus: float | None = None
    density: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "youngs_modulus",
                           positive(self.youngs_modulus, "Material.youngs_modulus", "Pa"))
        if (self.poisson_ratio is None) == (self.shear_modulus is None):
            raise ValueError(
                "Material needs exactly one of poisson_ratio and shear_modulus, got "
                f"poisson_ratio={format_value(self.poisson_ratio)}, "
                f"shear_modulus={format_value(self.shear_modulus)}"
            )
        if self.shear_modulus is not None:
            object.__setattr__(self, "shear_modulus",
                               positive(self.shear_modulus, "Material.shear_modulus", "Pa"))
        if self.poisson_ratio is not None:  # any real number, numpy scalars of any width too
            try:
                object.__setattr__(self, "poisson_ratio",
                                   real(self.poisson_ratio, "Material.poisson_ratio"))
            except TypeError:
                raise TypeError(f"Material.poisson_ratio must be a number, got "
                                f"{format_value(self.poisson_ratio)}") from None
            except ValueError:  # not finite: reported by the range check below
                pass
        nu = self.nu
        if not (math.isfinite(nu) and -1.0 < nu <= 0.5):
            what = (
                f"poisson_ratio={format_value(self.poisson_ratio)}"
                if self.poisson_ratio is not None
                else f"shear_modulus={format_value(self.shear_modulus)} (ν = E/2G - 1 = "
                f"{format_value(nu)})"
            )
            raise ValueError(f"Material.poisson_ratio must lie in (-1, 0.5], got {what}")
        if self.density is not None:
            object.__setattr__(self, "density",
                               nonnegative(self.density, "Material.density", "kg/m³"))

    @property
    def E(self) -> float:
        """Young's modulus in Pa."""
        return float(self.youngs_modulus)

    @property
    def G(self) -> float:
        """Shear modulus in Pa (given, or E / 2(1 + ν))."""
        if self.shear_modulus is not None:
            return float(self.shear_modulus)
        return self.E / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def nu(self) -> float:
        """Poisson's ratio (given, or E/2G - 1)."""
        if self.poisson_ratio is not None:
            return float(self.poisson_ratio)
        return self.E / (2.0 * self.shear_modulus) - 1.0
