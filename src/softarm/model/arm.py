"""The arm: a Cosserat rod with constant section, material and initial curvature."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .._validate import MAX_STEPS, as_vectors, format_value, length, nonnegative
from .material import Material
from .sections import Circle, Rectangle, Rigidities, Section, StiffnessMatrix, Tube

__all__ = ["Arm", "SegmentedArm"]

_SECTION_KINDS = (Circle, Tube, Rectangle, Section, Rigidities, StiffnessMatrix)


@dataclass(frozen=True)
class Arm:
    """A uniform Cosserat rod: length, cross-section, material and constant initial curvature.

    The arm axis is the material e1. The reference (stress-free) strain is
    f⁰ = (1, 0, 0, κ⁰₁, κ⁰₂, κ⁰₃): unit stretch along e1 and the initial twist/curvature κ⁰
    (1/m, material frame). Strains are measured from it, ε = f - f⁰, and the stress resultants
    are σ = K ε with K = diag(EA, GAy, GAz, GJ, EIy, EIz) (Grazioso et al. 2018, eqs. 3, 9-12).

    Parameters
    ----------
    length : float
        L in m.
    section : Circle, Tube, Rectangle or Section
        Cross-section.
    material : Material
        Material (its density gives the weight, if given).
    curvature : array_like, shape (3,)
        κ⁰ = (twist, curvature about y, curvature about z) in 1/m, material frame.
    mass_per_length : float, optional
        kg/m, >= 0; overrides ρ A (e.g. for an arm with embedded parts). 0 is a massless rod:
        gravity acts on nothing (a magnetic rod whose weight is negligible).
    magnetization : array_like, shape (3,), optional
        A hard magnetisation per unit length (A m²/m = A m), material components, fixed in
        the material (it turns with the section): acted on by a
        :class:`~softarm.MagneticField`.
    tip_magnet : array_like, shape (3,), optional
        A dipole (A m²), material components, at the arm's distal end (on a segment of a
        :class:`SegmentedArm`, at that segment's distal end).
    inertia_per_length : array_like, shape (3,), optional
        Rotary inertia per length ρ (J_p, Iy, Iz) in kg m (about the material e1, e2, e3;
        J_p = Iy + Iz is the section's polar moment): for dynamics
        (:func:`softarm.simulate`). Default: from the section and the density, scaled to
        ``mass_per_length`` if that is given.

    Examples
    --------
    >>> arm = Arm(0.3, Circle(0.01), Material(1.0e6, poisson_ratio=0.5, density=1100.0))
    >>> round(arm.rigidities.EIy, 9)
    0.007853982
    >>> arm.reference_strain
    array([1., 0., 0., 0., 0., 0.])
    """

    length: float
    section: Circle | Tube | Rectangle | Section | Rigidities
    material: Material | None = None
    curvature: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mass_per_length: float | None = None
    magnetization: tuple[float, float, float] | None = None
    tip_magnet: tuple[float, float, float] | None = None
    inertia_per_length: tuple[float, float, float] | None = None

    def __post_init__(self):
        object.__setattr__(self, "length", length(self.length, "Arm.length"))
        if not isinstance(self.section, _SECTION_KINDS):
            raise TypeError(
                "Arm.section must be a Circle, Tube, Rectangle, Section or Rigidities, got "
                f"{format_value(self.section)}"
            )
        if isinstance(self.section, (Rigidities, StiffnessMatrix)):
            if self.material is not None:
                raise ValueError(
                    "Arm.material must be None when the section is given by its Rigidities "
                    f"(use Arm.from_stiffness), got {format_value(self.material)}"
                )
        elif not isinstance(self.material, Material):
            raise TypeError(f"Arm.material must be a softarm.Material, got "
                            f"{format_value(self.material)}")
        curvature = as_vectors(self.curvature, "Arm.curvature", 3)
        if curvature.shape != (3,):
            raise ValueError(f"Arm.curvature must have shape (3,), got shape {curvature.shape}")
        object.__setattr__(self, "curvature", tuple(float(c) for c in curvature))
        _check_turning(float(np.linalg.norm(curvature)) * self.length, "Arm.curvature",
                       f"|κ⁰| = {float(np.linalg.norm(curvature)):.3g} 1/m on L = "
                       f"{self.length:.3g} m")
        if self.mass_per_length is not None:
            object.__setattr__(self, "mass_per_length",
                               nonnegative(self.mass_per_length, "Arm.mass_per_length",
                                           "kg/m"))
        for name in ("magnetization", "tip_magnet", "inertia_per_length"):
            value = getattr(self, name)
            if value is not None:
                vector = as_vectors(value, f"Arm.{name}", 3)
                if vector.shape != (3,):
                    raise ValueError(f"Arm.{name} must have shape (3,), got shape "
                                     f"{vector.shape}")
                object.__setattr__(self, name, tuple(float(c) for c in vector))
        if self.inertia_per_length is not None and min(self.inertia_per_length) < 0.0:
            raise ValueError(f"Arm.inertia_per_length must be >= 0 kg m, got "
                             f"{self.inertia_per_length!r}")

    @classmethod
    def from_stiffness_matrix(cls, length, K, curvature=(0.0, 0.0, 0.0), mass_per_length=None,
                              magnetization=None, tip_magnet=None,
                              inertia_per_length=None) -> Arm:
        """An arm with a full symmetric positive-definite 6 × 6 stiffness K (N, N m, N m²;
        linear part first), coupling extension, shear, twist and bending (a fibre-reinforced
        actuator). ValueError for a K that is not symmetric positive definite.

        Examples
        --------
        >>> K = np.diag([1e4, 1e4, 1e4, 0.5, 1.0, 1.0]); K[0, 3] = K[3, 0] = 20.0
        >>> Arm.from_stiffness_matrix(0.2, K).stiffness[0, 3]
        np.float64(20.0)
        """
        return cls(length, StiffnessMatrix(K), None, curvature, mass_per_length,
                   magnetization, tip_magnet, inertia_per_length)

    @classmethod
    def from_stiffness(cls, length, EA, GAy, GAz, GJ, EIy, EIz, curvature=(0.0, 0.0, 0.0),
                       mass_per_length=None, magnetization=None, tip_magnet=None,
                       inertia_per_length=None) -> Arm:
        """An arm known only by its stiffnesses (N for EA, GAy, GAz; N m² for GJ, EIy, EIz).

        Examples
        --------
        >>> arm = Arm.from_stiffness(1.0, EA=1e6, GAy=1e6, GAz=1e6, GJ=1.0, EIy=1.0, EIz=1.0)
        >>> arm.stiffness[4, 4]
        np.float64(1.0)
        """
        return cls(length, Rigidities(EA, GAy, GAz, GJ, EIy, EIz), None, curvature,
                   mass_per_length, magnetization, tip_magnet, inertia_per_length)

    @functools.cached_property
    def rigidities(self) -> Rigidities:
        """The six stiffnesses EA, GAy, GAz, GJ, EIy, EIz (computed once per arm)."""
        if isinstance(self.section, Rigidities):
            return self.section
        if isinstance(self.section, StiffnessMatrix):
            return self.section.rigidities
        return self.section.rigidities(self.material)

    @property
    def stiffness(self) -> np.ndarray:
        """K, the 6×6 stiffness matrix of eqs. 10-12 (N and N m²), linear part first."""
        if isinstance(self.section, StiffnessMatrix):
            return np.array(self.section.matrix)
        return self.rigidities.matrix

    @property
    def reference_strain(self) -> np.ndarray:
        """f⁰ = (1, 0, 0, κ⁰), shape (6,): the stress-free strain (eq. 3)."""
        return np.concatenate([[1.0, 0.0, 0.0], self.curvature])

    @property
    def linear_density(self) -> float | None:
        """Mass per unit length in kg/m (``mass_per_length``, else ρ A), or None if unknown."""
        if self.mass_per_length is not None:
            return float(self.mass_per_length)
        if self.material is None or self.material.density is None:
            return None
        return self.material.density * self.section.area

    @property
    def rotary_inertia(self) -> np.ndarray | None:
        """Rotary inertia per length ρ (J_p, Iy, Iz) in kg m, material axes e1, e2, e3
        (``inertia_per_length``, else from the section and the density, scaled to
        ``mass_per_length`` if given), or None if unknown."""
        if self.inertia_per_length is not None:
            return np.array(self.inertia_per_length)
        if isinstance(self.section, (Rigidities, StiffnessMatrix)):
            return None
        mu = self.linear_density
        if mu is None:
            return None
        section = self.section.properties(self.material.nu)
        per_area = mu / section.area  # ρ, or the density that gives mass_per_length
        return per_area * np.array([section.Iy + section.Iz, section.Iy, section.Iz])

    @property
    def radius(self) -> float | None:
        """Radius used to draw the arm as a tube (m), None if only stiffnesses are known."""
        if isinstance(self.section, (Rigidities, StiffnessMatrix)):
            return None
        return self.section.envelope_radius

    @property
    def segments(self) -> tuple[Arm, ...]:
        """``(self,)``: an Arm is a segmented arm with one segment."""
        return (self,)

    @property
    def boundaries(self) -> tuple[float, ...]:
        """``(0, L)``: the base and the tip (as :attr:`SegmentedArm.boundaries`), in m."""
        return (0.0, float(self.length))


@dataclass(frozen=True)
class SegmentedArm:
    """Uniform segments joined rigidly end to end (a multi-section soft arm).

    Each segment starts where the previous one ends, tangent to it: the material frame is
    continuous across a joint, only the section, material and initial curvature change.

    Parameters
    ----------
    segments : sequence of Arm
        From the base to the tip.

    Examples
    --------
    >>> soft = Material(1.0e6, poisson_ratio=0.5, density=1100.0)
    >>> arm = SegmentedArm([Arm(0.25, Circle(0.012), soft), Arm(0.125, Circle(0.008), soft)])
    >>> arm.length, arm.boundaries
    (0.375, (0.0, 0.25, 0.375))
    """

    segments: tuple[Arm, ...]

    def __post_init__(self):
        try:
            segments = tuple(self.segments) if not isinstance(self.segments, Arm) else ()
        except TypeError:  # not iterable (e.g. None): reported below, naming the parameter
            segments = ()
        if not segments or not all(isinstance(a, Arm) for a in segments):
            raise TypeError(
                "SegmentedArm.segments must be a non-empty sequence of Arm, got "
                f"{format_value(self.segments)}"
            )
        object.__setattr__(self, "segments", segments)
        turning = sum(float(np.linalg.norm(a.curvature)) * a.length for a in segments)
        _check_turning(turning, "SegmentedArm.segments' curvatures",
                       "Σ |κ⁰| L over the segments")

    @property
    def length(self) -> float:
        """Total length in m."""
        return float(sum(a.length for a in self.segments))

    @property
    def boundaries(self) -> tuple[float, ...]:
        """Arc length of each joint, base (0) and tip (L) included, in m."""
        bounds = np.concatenate([[0.0], np.cumsum([a.length for a in self.segments])])
        bounds[-1] = self.length  # the same float as ``length``
        return tuple(float(b) for b in bounds)


def _check_turning(turning: float, name: str, how: str) -> None:
    """ValueError if the unloaded arm turns by more than MAX_STEPS rad (``turning``, its
    own curvature's, |κ⁰| L): no step count softarm takes resolves it (docs/solver.md,
    "Out-of-range inputs")."""
    if turning > MAX_STEPS:
        raise ValueError(
            f"{name}: the unloaded arm turns by {turning:.3g} rad ({how}), more than the "
            f"{MAX_STEPS} rad softarm can resolve: its solver and stability verdict take at "
            f"most {MAX_STEPS} RK4 steps along the arm, and a step turns a section by a "
            "radian at most")
