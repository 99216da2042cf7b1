"""Contact with rigid obstacles fixed in space: :class:`Plane`, :class:`Sphere`,
:class:`Capsule`, and the load :class:`Contact` that lets the arm's surface touch them.

The method (docs/contact.md): a free tip that alone touches an obstacle is held exactly,
its reaction found by Newton's method over plain solves (statics/tip_contact.py); elsewhere a
penalty on the gap g between the arm's surface (a tube of radius r around the centreline)
and each obstacle, a force per unit length along the obstacle's outward normal through the
centreline,

    f = φ(g) n,   φ(g) = 0 for g >= δ,   k δ (t³ - t⁴/2) with t = (δ - g)/δ for 0 < g < δ,
    φ(g) = k (δ/2 - g) for g <= 0,

twice continuously differentiable, so that the shooting solver keeps its order; δ the
contact distance (default 1e-5 L), k a stiffness (N/m per m of arm) that the solver chooses
so that the largest pressure is carried within the band g ∈ [0, δ] (k δ/2 above it). The
shape is then within δ of the hard-contact solution's, and no point penetrates beyond tol·L
(the solver checks it at the stations and raises k where it must).

Frictionless: the force passes through the centreline, so it has no moment about it.
Friction (``friction`` = μ > 0) acts in the dynamics (softarm.simulate) and, in statics, at a
free tip held exactly (statics/tip_friction.py: the quasi-static path from the unloaded arm,
the tip sticking or sliding); the penalty's contact zones in statics return the frictionless
equilibrium (a Coulomb equilibrium for any μ, with zero tangential force; not necessarily
the one a quasi-static path with friction would reach: docs/contact.md, "Friction").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from ._validate import MAX_STEPS, as_array, format_value, real
from .loads import Key, Load, applied_wrench

__all__ = ["Capsule", "Contact", "Obstacle", "Plane", "Sphere", "along_the_arm", "balance",
           "penalty_energy", "pressure", "resultant"]

# The kernel's obstacle kinds (kernels/rod.py: PLANE, SPHERE, CAPSULE, one row of 8).
_PLANE, _SPHERE, _CAPSULE = 0, 1, 2
#: The default contact distance δ, as a fraction of the arm's length.
DISTANCE = 1e-5


def _point(value, name: str) -> np.ndarray:
    """A finite 3-vector (m), read-only."""
    array = as_array(value, name)
    if array.shape != (3,):
        raise ValueError(f"{name} must be a 3-vector (m, spatial), got shape {array.shape}: "
                         f"{format_value(value)}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite, got {format_value(value)}")
    array = array.copy()
    array.setflags(write=False)
    return array


def _radius(value, name: str) -> float:
    r = real(value, name, "m")
    if not (math.isfinite(r) and r > 0.0):
        raise ValueError(f"{name} must be a positive finite radius in m, got "
                         f"{format_value(value)}")
    return r


class Obstacle:
    """A rigid obstacle fixed in space (spatial frame, m). :meth:`distance` is the signed
    distance of points from its surface and the outward normal there."""

    kind: ClassVar[str]

    def distance(self, points) -> tuple[np.ndarray, np.ndarray]:
        """(d (...), n (..., 3)) for points (..., 3), m, spatial: the signed distance from
        the surface (negative inside) and the outward unit normal at the nearest surface
        point (∇d)."""
        return _distance(self.kernel_row(), np.asarray(points, dtype=np.float64))

    def kernel_row(self) -> np.ndarray:
        """The solver's row (8,): kind, two points or a point and a direction, radius
        (kernels/rod.py's ``_nearest``: a plane's point and normal, a ball's surface
        point and outward normal there, a capsule's axis ends)."""
        raise NotImplementedError

    def moved(self, R, origin) -> Obstacle:
        """The same obstacle in a frame rotated by R at ``origin``: x → Rᵀ (x - origin)."""
        raise NotImplementedError

    def to_case(self) -> dict:
        """The obstacle's ``[[obstacle]]`` table."""
        raise NotImplementedError


@dataclass(frozen=True, eq=False)
class Plane(Obstacle):
    """The half-space behind a plane: the solid is on the side opposite to ``normal``.

    Parameters
    ----------
    point : (3,) array_like
        A point of the plane, m, spatial.
    normal : (3,) array_like
        Its outward normal (pointing out of the solid), any non-zero length; stored unit.
    """

    point: np.ndarray
    normal: np.ndarray
    kind: ClassVar[str] = "plane"

    def __post_init__(self):
        object.__setattr__(self, "point", _point(self.point, "Plane.point"))
        normal = _point(self.normal, "Plane.normal")
        largest = float(np.max(np.abs(normal)))
        if not largest > 0.0:
            raise ValueError(f"Plane.normal must be a non-zero vector, got "
                             f"{format_value(self.normal)}")
        # scaled by its largest component first: |n| of (0, 0, 1e300) overflows and that of
        # (1e-320, 0, 0) underflows, where n / max|nᵢ| (components in [-1, 1]) does neither
        normal = normal / largest
        normal = normal / float(np.linalg.norm(normal))
        normal.setflags(write=False)
        object.__setattr__(self, "normal", normal)

    def kernel_row(self):
        return np.array([_PLANE, *self.point, *self.normal, 0.0])

    def moved(self, R, origin):
        return Plane(R.T @ (self.point - origin), R.T @ self.normal)

    def to_case(self):
        return {"kind": "plane", "point": self.point.tolist(), "normal": self.normal.tolist()}


@dataclass(frozen=True, eq=False)
class Sphere(Obstacle):
    """A solid ball.

    Parameters
    ----------
    center : (3,) array_like
        m, spatial.
    radius : float
        m, > 0.
    """

    center: np.ndarray
    radius: float
    kind: ClassVar[str] = "sphere"

    def __post_init__(self):
        object.__setattr__(self, "center", _point(self.center, "Sphere.center"))
        object.__setattr__(self, "radius", _radius(self.radius, "Sphere.radius"))

    def kernel_row(self):
        # the surface point q nearest the spatial origin (near the arm) and the outward
        # normal m there, the centre being q - R m: the gap of a point p is computed from
        # p - q, precise to round-off of the gap itself, however large the ball (_distance)
        size = float(np.linalg.norm(self.center))
        normal = -self.center / size if size > 0.0 else np.array([0.0, 0.0, 1.0])
        return np.array([_SPHERE, *(self.center + self.radius * normal), *normal,
                         self.radius])

    def moved(self, R, origin):
        return Sphere(R.T @ (self.center - origin), self.radius)

    def to_case(self):
        return {"kind": "sphere", "center": self.center.tolist(), "radius": self.radius}


@dataclass(frozen=True, eq=False)
class Capsule(Obstacle):
    """A solid cylinder of radius ``radius`` around the segment from ``a`` to ``b``, with
    hemispherical ends: a pin, a rod, a finger, a vessel's wall seen from outside.

    Parameters
    ----------
    a, b : (3,) array_like
        The ends of its axis, m, spatial (distinct).
    radius : float
        m, > 0.
    """

    a: np.ndarray
    b: np.ndarray
    radius: float
    kind: ClassVar[str] = "capsule"

    def __post_init__(self):
        object.__setattr__(self, "a", _point(self.a, "Capsule.a"))
        object.__setattr__(self, "b", _point(self.b, "Capsule.b"))
        object.__setattr__(self, "radius", _radius(self.radius, "Capsule.radius"))
        if not np.linalg.norm(self.b - self.a) > 0.0:
            raise ValueError(f"Capsule.a and Capsule.b must be distinct points, got "
                             f"{format_value(self.a)} twice")

    def kernel_row(self):
        return np.array([_CAPSULE, *self.a, *self.b, self.radius])

    def moved(self, R, origin):
        return Capsule(R.T @ (self.a - origin), R.T @ (self.b - origin), self.radius)

    def to_case(self):
        return {"kind": "capsule", "a": self.a.tolist(), "b": self.b.tolist(),
                "radius": self.radius}


#: Every obstacle kind by its case-file name.
OBSTACLE_KINDS = {cls.kind: cls for cls in (Plane, Sphere, Capsule)}


def _distance(row: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's ``_nearest`` in numpy, for points p (..., 3): (d, n)."""
    kind = int(row[0])
    if kind == _PLANE:
        normal = row[4:7]
        return (p - row[1:4]) @ normal, np.broadcast_to(normal, p.shape).copy()
    if kind == _SPHERE:  # (a surface point, its normal m, R: Sphere.kernel_row)
        w, radius = p - row[1:4], row[7]
        u = w + radius * row[4:7]
        r = np.linalg.norm(u, axis=-1)
        with np.errstate(invalid="ignore", divide="ignore"):
            n = np.where(r[..., None] > 0.0, u / r[..., None], 0.0)
        return (2.0 * radius * (w @ row[4:7]) + (w * w).sum(-1)) / (r + radius), n
    q = np.broadcast_to(row[1:4], p.shape)
    if kind == _CAPSULE:
        axis = row[4:7] - row[1:4]
        t = np.clip(((p - row[1:4]) @ axis) / (axis @ axis), 0.0, 1.0)
        q = row[1:4] + t[..., None] * axis
    offset = p - q
    r = np.linalg.norm(offset, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        n = np.where(r[..., None] > 0.0, offset / r[..., None], 0.0)
    return r - row[7], n


def pressure(gap, distance: float, stiffness: float) -> np.ndarray:
    """The contact law φ(g) (N/m per unit arm length) at gaps ``gap`` (m): the kernel's
    ``_pressure`` (module docstring)."""
    g = np.asarray(gap, dtype=np.float64)
    t = np.clip((distance - g) / distance, 0.0, 1.0)
    inside = stiffness * (0.5 * distance - np.minimum(g, 0.0))
    return np.where(g <= 0.0, inside, stiffness * distance * t**3 * (1.0 - 0.5 * t))


def _stiffness(value):
    """None, a positive finite float, or a read-only array of them (one per case)."""
    if value is None:
        return None
    if np.ndim(value) == 0:
        return _optional_positive(value, "Contact.stiffness", "N/m²")
    array = np.array(value, dtype=np.float64)
    if not np.all(np.isfinite(array) & (array > 0.0)):
        raise ValueError(f"Contact.stiffness must be positive and finite (N/m²), got "
                         f"{format_value(value)}")
    array.setflags(write=False)
    return array


def penalty_energy(gap, distance: float, stiffness) -> np.ndarray:
    """The law's stored energy per unit length Φ(g) = ∫_g^δ φ (J/m) at gaps ``gap`` (m):
    k δ² (t⁴/4 - t⁵/10) in the band, 0.15 k δ² + k (g²/2 - δ g/2) inside (−Φ' = φ)."""
    g = np.asarray(gap, dtype=np.float64)
    t = np.clip((distance - g) / distance, 0.0, 1.0)
    band = stiffness * distance**2 * (t**4 / 4.0 - t**5 / 10.0)
    inside = 0.15 * stiffness * distance**2 + stiffness * (0.5 * g * g - 0.5 * distance * g)
    return np.where(g <= 0.0, inside, band)


def _obstacles(value) -> tuple[Obstacle, ...]:
    items = (value,) if isinstance(value, Obstacle) else value
    try:
        items = tuple(items)
    except TypeError:
        raise TypeError(f"obstacles must be an obstacle (softarm.Plane, Sphere, Capsule) or "
                        f"a sequence of them, got {format_value(value)}") from None
    for k, item in enumerate(items):
        if not isinstance(item, Obstacle):
            raise TypeError(f"obstacles[{k}] must be a softarm.Plane, Sphere or Capsule, got "
                            f"{format_value(item)}")
    if not items:
        raise ValueError("obstacles must name at least one obstacle, got none")
    return items


def _optional_positive(value, name: str, unit: str) -> float | None:
    if value is None:
        return None
    number = real(value, name, unit)
    if not (math.isfinite(number) and number > 0.0):
        raise ValueError(f"{name} must be a positive finite number in {unit} or None, got "
                         f"{format_value(value)}")
    return number


@dataclass(frozen=True, eq=False)
class Contact(Load):
    """The arm's surface touches rigid obstacles fixed in space (a :class:`Load`; module
    docstring and docs/contact.md for the method and its accuracy).

    Parameters
    ----------
    obstacles : Obstacle or sequence of Obstacle
        :class:`Plane`, :class:`Sphere`, :class:`Capsule` (spatial frame, m).
    friction : float
        Coulomb's μ >= 0: in the dynamics, and in statics at a free tip held exactly (the
        tip sticks or slides along the loads' path from the unloaded arm); a statics
        contact zone (the penalty's) is frictionless (docs/contact.md, "Friction").
    distance : float or None
        The contact distance δ (m) of the penalty: forces act only where the gap is below
        it. Default 1e-5 L. The shape is within about δ of the hard-contact solution.
        Without ``distance`` and ``stiffness``, a free tip that alone touches an obstacle
        is held exactly, with no δ (``softarm.solve``, ``Solver.solve``; docs/contact.md,
        "A free tip held exactly"); giving either asks for the penalty everywhere.
    radius : float or None
        The arm's surface radius (m). Default: the section's (``Arm.radius``, per segment);
        required for an arm given by its stiffnesses.
    stiffness : float or None
        The penalty's k (N/m per m of arm, the force per length per m of penetration
        beyond the band). Default: chosen by the solver from the loads, and raised where a
        solution penetrates beyond tol·L (the values used, one per case where they differ,
        are on ``eq.loads``).
    slip_velocity : float
        Dynamics with friction: the sliding speed w_ε (m/s) below which Coulomb's law is
        regularised (a sticking contact creeps at about that speed; docs/contact.md).

    Examples
    --------
    >>> import softarm
    >>> table = softarm.Plane(point=(0, 0, -0.05), normal=(0, 0, 1))
    >>> print(softarm.Contact(table).describe())
    contact with 1 obstacle (plane), frictionless, hard at a free tip, else contact distance 1e-05 L
    """

    obstacles: tuple
    friction: float = 0.0
    distance: float | None = None
    radius: float | None = None
    stiffness: float | None = None
    slip_velocity: float = 1e-4
    #: Hard contact zones ((obstacle index, s_a, s_b), ...): on each, the pressure that
    #: keeps the gap's second derivative at zero (kernels/rod.py, ``_zone_pressure``), and
    #: the penalty off everywhere. Groundwork of issue 39, not a user setting: nothing in
    #: softarm.solve places zones yet (docs/contact.md, "Hard contact").
    zones: tuple = field(default=(), repr=False)
    kind: ClassVar[str] = "contact"
    schema: ClassVar = (Key("friction", "number"), Key("distance", "number", "m"),
                        Key("radius", "number", "m"), Key("stiffness", "number", "N/m²"),
                        Key("slip_velocity", "number", "m/s"))

    def __post_init__(self):
        object.__setattr__(self, "obstacles", _obstacles(self.obstacles))
        mu = real(self.friction, "Contact.friction", "")
        if not (math.isfinite(mu) and mu >= 0.0):
            raise ValueError(f"Contact.friction must be a finite number >= 0 (Coulomb's μ), "
                             f"got {format_value(self.friction)}")
        object.__setattr__(self, "friction", mu)
        for name, unit in (("distance", "m"), ("radius", "m"), ("slip_velocity", "m/s")):
            object.__setattr__(self, name, _optional_positive(getattr(self, name),
                                                              f"Contact.{name}", unit))
        object.__setattr__(self, "stiffness", _stiffness(self.stiffness))
        if self.slip_velocity is None:
            raise ValueError("Contact.slip_velocity must be a positive speed in m/s, got None")
        zones = tuple((int(k), float(a), float(b)) for k, a, b in self.zones)
        if any(not (0 <= k < len(self.obstacles) and 0.0 <= a < b) for k, a, b in zones):
            raise ValueError(f"Contact.zones must be (obstacle index, s_a, s_b) with "
                             f"0 <= s_a < s_b, got {self.zones!r}")
        object.__setattr__(self, "zones", zones)

    def cuts(self, arm) -> tuple[float, ...]:
        return tuple(s for _, a, b in self.zones for s in (a, b) if 0.0 < s < arm.length)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return np.shape(self.stiffness)  # (per case where the solver raised it)

    def apply(self, target) -> None:
        target.contact(self)

    def scaled(self, factor) -> Contact:
        return self  # (obstacles are geometry, not a load magnitude)

    def in_base_frame(self, R, origin=None) -> Contact:
        origin = np.zeros(3) if origin is None else np.asarray(origin, dtype=np.float64)
        return self.replace(obstacles=tuple(o.moved(np.asarray(R), origin)
                                            for o in self.obstacles))

    def _with_checked_stiffness(self, stiffness) -> Contact:
        """A copy with ``stiffness`` (an array of any shape) set without validation."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        object.__setattr__(new, "stiffness", stiffness)
        return new

    def take(self, index) -> Contact:
        if np.ndim(self.stiffness) == 0:
            return self
        return self.replace(stiffness=self.stiffness[index])

    def describe(self, swept=None) -> str:
        kinds = ", ".join(o.kind for o in self.obstacles)
        count = len(self.obstacles)
        friction = f"μ = {self.friction:g}" if self.friction else "frictionless"
        if self.distance is not None:
            distance = f"contact distance {self.distance:g} m"
        elif self.stiffness is None:
            distance = f"hard at a free tip, else contact distance {DISTANCE:g} L"
        else:
            distance = f"contact distance {DISTANCE:g} L"
        return (f"contact with {count} obstacle{'s' * (count != 1)} ({kinds}), {friction}, "
                f"{distance}")

    def check(self, arm) -> None:
        self.surface_radii(arm)
        # The representable range (docs/contact.md, "Limits"): a band crossed tangentially
        # by an arm curved on the scale of L spans √(2δL) along it, and an elastic
        # foundation k bends it on (EI/k)^¼; neither resolves below one of the MAX_STEPS
        # RK4 steps a solve takes at most, L / MAX_STEPS.
        length = float(arm.length)
        least = length / MAX_STEPS**2
        if self.distance is not None and self.distance < least:
            raise ValueError(
                f"Contact.distance must be at least L / {MAX_STEPS}² = {least:.3g} m on this "
                f"arm (L = {length:.4g} m), got {self.distance:.3g} m: a narrower band spans "
                f"less along the arm (√(2δL) where the arm meets an obstacle tangentially) "
                f"than the shortest step a solve takes, L / {MAX_STEPS}; give a wider "
                f"distance, or none (default {DISTANCE:g} L)")
        if self.stiffness is not None:
            EI = min(float(min(np.diagonal(seg.stiffness)[4:])) for seg in arm.segments)
            most = EI * (MAX_STEPS / length) ** 4
            k = float(np.max(self.stiffness))
            if k > most:
                raise ValueError(
                    f"Contact.stiffness must be at most EI ({MAX_STEPS}/L)⁴ = {most:.3g} N/m² "
                    f"on this arm (EI = {EI:.3g} N m², L = {length:.4g} m), got {k:.3g} "
                    f"N/m²: a stiffer penalty bends the arm on (EI/k)^¼, shorter than the "
                    f"shortest step a solve takes (L / {MAX_STEPS}); give a smaller stiffness, "
                    "or none (the solver chooses one from the loads)")

    def surface_radii(self, arm) -> np.ndarray:
        """The surface radius of each of the arm's segments (m): ``radius``, else the
        sections'. ValueError where neither is known."""
        if self.radius is not None:
            return np.full(len(arm.segments), self.radius)
        radii = [segment.radius for segment in arm.segments]
        if any(r is None for r in radii):
            raise ValueError("Contact.radius is required for an arm given by its stiffnesses "
                             "(Arm.from_stiffness, from_stiffness_matrix): the arm's surface "
                             "radius in m, e.g. Contact(obstacles, radius=0.01)")
        return np.array(radii, dtype=np.float64)

    def station_radii(self, arm, s) -> np.ndarray:
        """The arm's surface radius at each station s (m)."""
        bounds = np.asarray(arm.boundaries)
        segment = np.clip(np.searchsorted(bounds, s, side="right") - 1, 0, len(bounds) - 2)
        return self.surface_radii(arm)[segment]

    def band(self, length: float) -> float:
        """The contact distance δ in m for an arm of length ``length``."""
        return self.distance if self.distance is not None else DISTANCE * length

    def kernel_rows(self) -> np.ndarray:
        """The obstacles' rows for the solver (K, 8)."""
        return np.array([o.kernel_row() for o in self.obstacles])

    def gaps(self, positions, radii) -> tuple[np.ndarray, np.ndarray]:
        """(gaps (...), forces (..., 3)): at centreline positions (..., 3) with surface
        radii (...) (m), the distance from the arm's surface to the nearest obstacle (m) and
        the contact force per unit length (N/m, spatial) with this law (``stiffness`` set)."""
        p = np.asarray(positions, dtype=np.float64)
        gap = np.full(p.shape[:-1], np.inf)
        force = np.zeros(p.shape)
        k = None if self.stiffness is None else np.asarray(self.stiffness)[..., None]
        for obstacle in self.obstacles:
            d, n = _distance(obstacle.kernel_row(), p)
            g = d - radii
            gap = np.minimum(gap, g)
            if k is not None:
                force += pressure(g, self.distance, k)[..., None] * n
        return gap, force


def along_the_arm(contact, radii, positions, inner: int = 0):
    """(gaps (..., S), forces (..., S, 3)) of the arm at ``positions`` (B..., [T...,] S, 3)
    with surface ``radii`` (S,): the distance to the nearest obstacle (m; inf without a
    Contact) and the contact force per length (N/m, spatial; zero without one). The law's
    stiffness is one per case (the batch axes B...) or one number; ``inner`` axes
    (time) lie between the batch axes and the stations."""
    p = np.asarray(positions)
    if contact is None:
        return np.full(p.shape[:-1], np.inf), np.zeros(p.shape)
    if np.ndim(contact.stiffness) and inner:  # k (B...) against (B..., T..., S)
        k = np.asarray(contact.stiffness).reshape(
            np.shape(contact.stiffness) + (1,) * inner)
        contact = contact._with_checked_stiffness(k)
    return contact.gaps(p, radii)


def resultant(s, positions, forces) -> np.ndarray:
    """(..., 6): the force (N) and its moment about the origin (N m) of forces per length
    (..., S, 3) at ``positions`` (..., S, 3) on stations s (S,), by the trapezoidal rule
    (stations fine enough to resolve the contact zones: about √(EI/GA) wide)."""
    wrench = np.concatenate([forces, np.cross(positions, forces)], axis=-1)
    ds = np.diff(np.asarray(s))[:, None]
    return (0.5 * (wrench[..., 1:, :] + wrench[..., :-1, :]) * ds).sum(-2)


def balance(arm, loads, s, poses, base_wrench) -> np.ndarray:
    """(B..., 6): the obstacles' total force on the arm (N) and its moment about the spatial
    origin (N m) from the global balance of an equilibrium with ``poses`` (B..., S, 4, 4) at
    stations ``s`` (S,) and base wrench ``base_wrench`` (B..., 6; every force applied to the
    arm and its moment about the base, as the solver returns it): that wrench moved to the
    origin, less the other loads' resultant (:func:`softarm.loads.applied_wrench`, which
    needs every cut among ``s``). Exact to the solve's tolerance however narrow the contact
    zones, where a sum of the pressure on stations is not (docs/contact.md)."""
    force = base_wrench[..., :3]
    moment = base_wrench[..., 3:] + np.cross(poses[..., 0, :3, 3], force)
    others = tuple(load for load in loads if load.kind != "contact")
    return np.concatenate([force, moment], axis=-1) - applied_wrench(arm, others, s, poses)
