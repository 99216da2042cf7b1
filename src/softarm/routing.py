"""Paths of tendons and pneumatic chambers through the arm's cross-sections.

A routing gives r(s) = (0, y(s), z(s)): where the tendon (or the chamber's centroid) crosses
the section at arc length s, in m, in the section's material frame (e2, e3). s is the arm's
arc length from the base (not a segment-local one). Every routing is a power series in s
plus a helix,

    y(s) = Σ_k a_k s^k + ρ cos(φ + 2π n s),   z(s) = Σ_k b_k s^k + ρ sin(φ + 2π n s),

so r, r' and r'' are exact (:meth:`Routing.position`, :meth:`Routing.derivative`,
:meth:`Routing.second_derivative`), and the solver evaluates the same series.

Examples
--------
>>> Straight(0.01, 0.0).position(0.2)
array([0.  , 0.01, 0.  ])
>>> h = Helix(0.01, turns_per_metre=2.0)
>>> np.round(h.position(0.125), 6)   # a quarter turn
array([0.  , 0.  , 0.01])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validate import format_value, real

__all__ = ["Helix", "Polynomial", "Routing", "Straight"]


class Routing:
    """Base of the routings: the coefficients of the series above.

    Subclasses set ``y_coefficients`` and ``z_coefficients`` (a_k, b_k in m/m^k, from k = 0)
    and ``helix`` = (ρ in m, n in turns per metre, φ in rad).
    """

    y_coefficients: tuple[float, ...] = (0.0,)
    z_coefficients: tuple[float, ...] = (0.0,)
    helix: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def _series(self, s, order: int) -> np.ndarray:
        s = np.asarray(s, dtype=np.float64)
        out = np.zeros((*s.shape, 3))
        for axis, coefficients in ((1, self.y_coefficients), (2, self.z_coefficients)):
            c = np.polynomial.polynomial.polyder(np.asarray(coefficients, float), order) \
                if order else np.asarray(coefficients, float)
            out[..., axis] = np.polynomial.polynomial.polyval(s, c) if c.size else 0.0
        radius, turns, phase = self.helix
        if radius:
            w = 2.0 * np.pi * turns
            angle = phase + w * s
            scale = radius * w**order
            # the k-th derivative of (cos, sin) is a rotation by k quarter turns
            out[..., 1] += scale * np.cos(angle + order * np.pi / 2)
            out[..., 2] += scale * np.sin(angle + order * np.pi / 2)
        return out

    def position(self, s) -> np.ndarray:
        """r(s) = (0, y, z) in m, material frame, shape (..., 3)."""
        return self._series(s, 0)

    def derivative(self, s) -> np.ndarray:
        """r'(s) = dr/ds (m/m), shape (..., 3)."""
        return self._series(s, 1)

    def second_derivative(self, s) -> np.ndarray:
        """r''(s) (1/m), shape (..., 3)."""
        return self._series(s, 2)

    def bound(self, length: float) -> float:
        """An upper bound of |r(s)| on [0, length] (m)."""
        total = abs(self.helix[0])
        for coefficients in (self.y_coefficients, self.z_coefficients):
            total += sum(abs(c) * max(length, 1.0) ** k for k, c in enumerate(coefficients))
        return float(total)

    def kernel_row(self, degree: int, length: float) -> np.ndarray:
        """The solver's routing row (see ``softarm/kernels/rod.py``) on an arm of this length:
        the bound of |r|, helix radius, angular rate 2π n, phase, then ``degree``
        coefficients of y and of z."""
        row = np.zeros(4 + 2 * degree)
        row[0] = self.bound(length)
        row[1] = self.helix[0]
        row[2] = 2.0 * np.pi * self.helix[1]
        row[3] = self.helix[2]
        row[4:4 + len(self.y_coefficients)] = self.y_coefficients
        row[4 + degree:4 + degree + len(self.z_coefficients)] = self.z_coefficients
        return row

    @property
    def degree(self) -> int:
        """The number of power-series coefficients (the longer of y and z)."""
        return max(len(self.y_coefficients), len(self.z_coefficients))

    def to_case(self) -> dict:
        """The routing's case-file table."""
        raise NotImplementedError


@dataclass(frozen=True)
class Straight(Routing):
    """A path parallel to the centreline at a constant offset (y, z) in m, material frame.

    Examples
    --------
    >>> Straight(y=0.0, z=-0.012).derivative(0.1)
    array([0., 0., 0.])
    """

    y: float = 0.0
    z: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "y", real(self.y, "Straight.y"))
        object.__setattr__(self, "z", real(self.z, "Straight.z"))

    @property
    def y_coefficients(self):
        return (self.y,)

    @property
    def z_coefficients(self):
        return (self.z,)

    def describe(self) -> str:
        return f"straight at (y, z) = ({self.y:.4g}, {self.z:.4g}) m"

    def to_case(self) -> dict:
        return {"kind": "straight", "y": self.y, "z": self.z}


@dataclass(frozen=True)
class Helix(Routing):
    """A helix about the centreline: r(s) = radius (0, cos(phase + 2π n s), sin(...)).

    Parameters
    ----------
    radius : float
        Distance from the centreline in m (> 0).
    turns_per_metre : float
        n, turns per metre of arc length (signed: positive turns from e2 towards e3).
    phase : float
        φ in rad: the angle from e2 at s = 0.
    """

    radius: float
    turns_per_metre: float
    phase: float = 0.0

    def __post_init__(self):
        radius = real(self.radius, "Helix.radius")
        if not radius > 0.0:
            raise ValueError(f"Helix.radius must be > 0 m, got {format_value(self.radius)}")
        object.__setattr__(self, "radius", radius)
        object.__setattr__(self, "turns_per_metre",
                           real(self.turns_per_metre, "Helix.turns_per_metre"))
        object.__setattr__(self, "phase", real(self.phase, "Helix.phase"))

    @property
    def helix(self):
        return (self.radius, self.turns_per_metre, self.phase)

    def describe(self) -> str:
        return (f"helix of radius {self.radius:.4g} m, {self.turns_per_metre:.4g} turns/m, "
                f"phase {self.phase:.4g} rad")

    def to_case(self) -> dict:
        return {"kind": "helix", "radius": self.radius,
                "turns_per_metre": self.turns_per_metre, "phase": self.phase}


@dataclass(frozen=True)
class Polynomial(Routing):
    """A path given by power series in the arm's arc length s (m): y(s) = Σ y[k] s^k,
    z(s) = Σ z[k] s^k (coefficients in m/m^k).

    Examples
    --------
    >>> float(Polynomial(y=[0.01, -0.02], z=[0.0]).position(0.25)[1])  # tapering inwards
    0.005
    """

    y: tuple[float, ...] = (0.0,)
    z: tuple[float, ...] = (0.0,)

    def __post_init__(self):
        for name in ("y", "z"):
            values = np.atleast_1d(np.asarray(getattr(self, name), dtype=object))
            try:
                coefficients = tuple(real(v, f"Polynomial.{name}") for v in values.ravel())
            except (TypeError, ValueError) as error:
                raise type(error)(f"Polynomial.{name} must be a list of power-series "
                                  f"coefficients in m/m^k, got "
                                  f"{format_value(getattr(self, name))}"
                                  ) from None
            if values.ndim != 1 or not coefficients:
                raise ValueError(f"Polynomial.{name} must be a non-empty list of "
                                 f"coefficients, got {format_value(getattr(self, name))}")
            object.__setattr__(self, name, coefficients)

    @property
    def y_coefficients(self):
        return self.y

    @property
    def z_coefficients(self):
        return self.z

    def describe(self) -> str:
        return f"polynomial y = {list(self.y)}, z = {list(self.z)} (m/m^k)"

    def to_case(self) -> dict:
        return {"kind": "polynomial", "y": list(self.y), "z": list(self.z)}


#: Routing kinds by their case-file name (``kind = ...`` in a ``routing`` table).
ROUTINGS = {"straight": Straight, "helix": Helix, "polynomial": Polynomial}
