"""External loads on an arm, each stating its frame, behind one interface: :class:`Load`.

*Dead* loads keep their components in the fixed (spatial, base) frame whatever the arm does;
*follower* loads keep their components in the material frame of the cross-section they act on.
Force and moment arrays may carry leading batch axes, (..., 3): a batch of load cases solved
together, the batch axes reappearing on every output array.

Every load kind declares, once, in its own class: its batch shape, its components in another
base frame, the stations where it cuts the arm, what it adds to the solver's load channels
(:meth:`Load.apply` on a :class:`LoadTarget`), a one-line description and its case-file row.
The solvers and tools never branch on load kinds: a new kind is a new class here.
"""

from __future__ import annotations

import abc
import copy
import dataclasses
import functools
from dataclasses import dataclass, field
from typing import ClassVar, Protocol

import numpy as np

from ._validate import as_array, as_matrices, as_vectors, format_value, real
from .routing import Routing

__all__ = [
    "LOAD_KINDS",
    "LOAD_LIMIT",
    "Chamber",
    "DistributedForce",
    "DistributedMoment",
    "Gravity",
    "InputRules",
    "Key",
    "Load",
    "LoadTarget",
    "MagneticField",
    "PointLoad",
    "Tendon",
    "TipLoad",
    "applied_wrench",
    "as_loads",
    "batch_shape",
    "check_magnitudes",
    "largest_force",
    "path_tangent",
]


def _vector(obj, name: str) -> np.ndarray:
    # A private copy: freezing the caller's own array (np.asarray does not copy) would make it
    # read-only behind their back, and later writes to it would change the load.
    array = as_vectors(getattr(obj, name), f"{type(obj).__name__}.{name}", 3).copy()
    array.setflags(write=False)
    object.__setattr__(obj, name, array)
    return array


def _common_shape(shapes) -> tuple[int, ...]:
    """np.broadcast_shapes, with the common case first: all shapes equal (one load case, or
    one batch shape throughout) needs no broadcasting (np.broadcast_shapes: ~5 µs a call)."""
    first = shapes[0] if shapes else ()
    if all(shape == first for shape in shapes):
        return first
    return np.broadcast_shapes(*shapes)


def _broadcast(obj, *names: str) -> tuple[int, ...]:
    """The batch shape of the named (..., 3) fields, ValueError if they do not broadcast."""
    shapes = [getattr(obj, name).shape[:-1] for name in names]
    try:
        return _common_shape(shapes)
    except ValueError:
        kind = type(obj).__name__
        fields_ = " and ".join(f"{kind}.{name}" for name in names)
        got = " and ".join(str(getattr(obj, name).shape) for name in names)
        raise ValueError(f"{fields_} must have batch shapes that broadcast, got shapes {got}"
                         ) from None


def _check_follower(obj) -> None:
    if not isinstance(obj.follower, (bool, np.bool_)):
        raise TypeError(
            f"{type(obj).__name__}.follower must be True or False, got "
            f"{format_value(obj.follower)}")
    object.__setattr__(obj, "follower", bool(obj.follower))


def _rotated(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rᵀ v: spatial components re-expressed in a base frame with rotation R."""
    return np.einsum("ji,...j->...i", R, v)


def _fmt(vector: np.ndarray, unit: str) -> str:
    if vector.ndim > 1:
        return f"batch {vector.shape[:-1]} in {unit}"
    return "(" + ", ".join(f"{x:.4g}" for x in vector) + f") {unit}"


class LoadTarget(Protocol):
    """What a load writes into: the load channels of a solver (see :meth:`Load.apply`).

    Every vector broadcasts against the batch shape of the loads being solved. Components
    are spatial for dead loads and material for follower loads.
    """

    arm: object  #: the Arm or SegmentedArm being solved
    length: float  #: its length in m

    def distributed(self, *, force=None, moment=None, follower: bool = False,
                    span: tuple[float, float] | None = None, per_mass: bool = False) -> None:
        """A uniform force (N/m) and moment (N m/m) per unit length on ``span`` (m; None: the
        whole arm); ``per_mass``: the force is an acceleration times the linear density."""

    def point(self, s: float, *, force=None, moment=None) -> None:
        """A dead point wrench (N, N m) at arc length s (s = L: the tip)."""

    def tip(self, *, force=None, moment=None, follower: bool = False) -> None:
        """A wrench at the tip, dead or follower."""

    def actuator(self, kind: str, magnitude, routing: Routing,
                 span: tuple[float, float]) -> None:
        """An actuator acting through the constitutive law on ``span`` (m): ``kind``
        "tendon" (``magnitude`` its tension τ, N) or "chamber" (p A, N), along ``routing``."""

    def displaced_tendon(self, displacement, routing: Routing,
                         span: tuple[float, float]) -> None:
        """A displacement-controlled tendon (its tension an unknown). A target that does not
        define it does not handle them: the statics solver replaces such tendons by
        tension-controlled ones before applying loads (``Tendon.with_tension``)."""

    def field(self, field, gradient=None) -> None:
        """A magnetic field B(x) = B0 + G x, spatial (T, T/m), acting on the arm's
        magnetisation and dipoles."""

    def contact(self, load) -> None:
        """Contact with rigid obstacles (a :class:`softarm.Contact`, which carries its
        obstacles and law): a force that depends on the arm's shape."""


@dataclass(frozen=True)
class Key:
    """One key of a load's case-file table (``[[load]]``), read and written alike.

    ``kind``: "vector" (3 numbers in ``unit``, batchable: shape (..., 3)), "magnitude" (a
    number in ``unit``, batchable: shape (...)), "matrix" (3 × 3 in ``unit``, batchable:
    (..., 3, 3)), "number" (in ``unit``, not batchable), "flag" (a bool), "span" ((s0, s1)
    in m), "index" (an integer >= 0) or "routing" (a :mod:`softarm.routing` path, a table
    in the file). An absent optional key takes the load class's default.
    """

    name: str
    kind: str
    unit: str = ""
    required: bool = False

    def to_case(self, value):
        """``value`` as a TOML-ready value (lists and plain numbers), or None to omit it."""
        if value is None:
            return None
        if self.kind in ("vector", "magnitude", "matrix"):
            return np.asarray(value).tolist()
        if self.kind == "span":
            return [float(v) for v in value]
        if self.kind == "routing":
            return value.to_case()
        return {"number": float, "flag": bool, "index": int}[self.kind](value)


#: The trailing (object) shape of each batchable key kind.
_OBJECT_SHAPES = {"vector": (3,), "magnitude": (), "matrix": (3, 3)}


#: Every load kind by its case-file name, filled as the classes are defined.
LOAD_KINDS: dict[str, type] = {}


class Load(abc.ABC):
    """Base of every load kind.

    A load states its frame (dead: spatial components; follower: material components) and
    carries batch axes on its arrays. Subclasses define:

    - ``kind``: the case-file name of the kind (``[[load]] kind = ...``);
    - ``batch_shape``: the broadcast batch shape of its arrays;
    - :meth:`apply`: what it adds to a solver's load channels (:class:`LoadTarget`);
    - :meth:`in_base_frame`: the same load with its dead components in another base frame;
    - :meth:`describe`: a one-line description.

    :meth:`cuts` (stations where the arm must be cut: point loads, span ends) and
    :meth:`check` (a check against the arm) have defaults.
    """

    kind: ClassVar[str]
    #: The load's case-file keys, in file order.
    schema: ClassVar[tuple[Key, ...]]
    #: The vector fields of the load, (name, unit): derived from ``schema``.
    vectors: ClassVar[tuple[tuple[str, str], ...]] = ()
    #: Every batchable field, (name, unit, object shape): vectors (3,), magnitudes (),
    #: matrices (3, 3); derived from ``schema``.
    arrays: ClassVar[tuple[tuple[str, str, tuple[int, ...]], ...]] = ()
    #: The fields that are actuation inputs (a tendon's tension, a chamber's pressure, a
    #: field's B0): every component is one column of an actuation Jacobian, in load order.
    inputs: ClassVar[tuple[str, ...]] = ()
    #: True for a load whose magnitude is an unknown of the solve (a tendon under
    #: displacement control, :class:`Tendon`).
    displacement_controlled: ClassVar[bool] = False
    #: True for an actuator that runs through the sections and ends at the base plate (a
    #: tendon, a chamber): the base wrench is then shared by the clamp and the actuator.
    acts_through_base: ClassVar[bool] = False

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "schema" in cls.__dict__:
            cls.vectors = tuple((k.name, k.unit) for k in cls.schema if k.kind == "vector")
            cls.arrays = tuple((k.name, k.unit, _OBJECT_SHAPES[k.kind]) for k in cls.schema
                               if k.kind in _OBJECT_SHAPES)
        if "kind" in cls.__dict__:
            LOAD_KINDS[cls.kind] = cls

    def to_case(self) -> dict:
        """The load's ``[[load]]`` table (batched vectors become nested lists)."""
        out = {"kind": self.kind}
        for key in self.schema:
            value = key.to_case(getattr(self, key.name))
            if value is not None:
                out[key.name] = value
        return out

    @property
    @abc.abstractmethod
    def batch_shape(self) -> tuple[int, ...]:
        """The broadcast batch shape of the load's arrays."""

    @abc.abstractmethod
    def apply(self, target: LoadTarget) -> None:
        """Add this load to ``target``'s load channels."""

    @abc.abstractmethod
    def in_base_frame(self, R: np.ndarray, origin=None) -> Load:
        """The same load for an arm clamped with base rotation R at ``origin`` (m, default
        the spatial origin): dead (spatial) components re-expressed in the base frame
        (Rᵀ v), follower components unchanged (a field that varies in space is also moved
        by ``origin``)."""

    @abc.abstractmethod
    def describe(self, swept: tuple[str, str] | None = None) -> str:
        """One line saying what the load is, with its frame and units. ``swept`` = (field
        name, text): that field is described by the text (a sweep's range) instead."""

    def _fields_text(self, swept) -> str:
        """"force (0, 0, -1) N, moment ..." for the non-zero (or batched, or swept) vectors."""
        items = []
        for name, unit in self.vectors:
            value = np.asarray(getattr(self, name))
            if swept is not None and swept[0] == name:
                items.append(f"{name} {swept[1]}")
            elif value.ndim > 1:
                items.append(f"{name} (batch of {value.shape[:-1]})")
            elif np.any(value != 0):
                items.append(f"{name} {_fmt(value, unit)}")
        return ", ".join(items) if items else "zero"

    def cuts(self, arm) -> tuple[float, ...]:
        """Arc lengths (m) where the arm must be cut for this load (default: none)."""
        return ()

    def check(self, arm) -> None:  # noqa: B027 (a default that does nothing on purpose)
        """ValueError if the load does not fit ``arm`` (default: every load fits)."""

    def scaled(self, factor) -> Load:
        """The same load with every batchable field (force, tension, field, ...) multiplied
        by ``factor`` (broadcast over the batch axes)."""
        factor = np.asarray(factor, dtype=np.float64)
        changes = {}
        for name, _, shape in self.arrays:
            value = getattr(self, name)
            if value is not None:
                changes[name] = value * factor.reshape(factor.shape + (1,) * len(shape))
        return self.replace(**changes)

    def replace(self, **changes) -> Load:
        """A copy with some fields changed (validated like a new load)."""
        return dataclasses.replace(self, **changes)

    def _with_checked(self, **arrays) -> Load:
        """A copy with these magnitude fields (arrays of the field's shape) changed *without
        validation*: for a caller that keeps the values in their domain itself (inverse
        statics: finite inputs clipped to bounds that keep tensions >= 0), in a loop where
        validating a new load each time was 5 % of a tracked target."""
        if hasattr(self, "__dict__"):  # (a plain shallow copy: copy.copy's protocol costs 3×)
            new = object.__new__(type(self))
            new.__dict__.update(self.__dict__)
        else:  # a subclass with __slots__
            new = copy.copy(self)
        for name, value in arrays.items():
            array = np.array(value, dtype=np.float64)
            array.setflags(write=False)
            object.__setattr__(new, name, array)
        return new

    def part(self, shape, index) -> Load:
        """The load of the cases ``index`` (a case's tuple of indices, or a tuple of index
        arrays) of the whole batch ``shape``, into which this load's batch broadcasts: its
        batched fields gathered (a broadcast field is not expanded to the whole batch
        first)."""
        if not self.batch_shape:
            return self
        changes = {}
        for name, _, object_shape in self.arrays:
            value = getattr(self, name)
            if value is not None and np.ndim(value) > len(object_shape):
                changes[name] = np.broadcast_to(value, (*shape, *object_shape))[index]
        return self.replace(**changes)

    def take(self, index) -> Load:
        """The load of one case (or a sub-batch) of a batch: ``index`` into the batch axes."""
        shape = self.batch_shape
        return self.replace(**{
            name: np.broadcast_to(getattr(self, name), (*shape, *object_shape))[index]
            for name, _, object_shape in self.arrays if getattr(self, name) is not None})


@dataclass(frozen=True, eq=False)
class TipLoad(Load):
    """Force and moment applied at the free end (s = L).

    Parameters
    ----------
    force : array_like, shape (..., 3)
        N. Spatial components for a dead load, tip material components for a follower load.
    moment : array_like, shape (..., 3)
        N m, in the same frame as ``force``.
    follower : bool, keyword-only
        False (dead: fixed in space) or True (follower: fixed in the tip's material frame).

    Examples
    --------
    >>> TipLoad(force=[0.0, 0.0, -1.0]).force
    array([ 0.,  0., -1.])
    """

    kind: ClassVar[str] = "tip"
    schema: ClassVar = (Key("force", "vector", "N"), Key("moment", "vector", "N m"),
                        Key("follower", "flag"))

    force: np.ndarray = (0.0, 0.0, 0.0)
    moment: np.ndarray = (0.0, 0.0, 0.0)
    follower: bool = field(default=False, kw_only=True)

    def __post_init__(self):
        _vector(self, "force")
        _vector(self, "moment")
        _broadcast(self, "force", "moment")
        _check_follower(self)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return _broadcast(self, "force", "moment")

    def apply(self, target: LoadTarget) -> None:
        target.tip(force=self.force, moment=self.moment, follower=self.follower)

    def in_base_frame(self, R, origin=None) -> TipLoad:
        if self.follower:
            return self
        return TipLoad(_rotated(R, self.force), _rotated(R, self.moment))

    def describe(self, swept=None) -> str:
        return ("follower tip " if self.follower else "tip ") + self._fields_text(swept)


@dataclass(frozen=True, eq=False)
class Gravity(Load):
    """Weight of the arm: a dead distributed force μ g per unit length, μ the mass per length.

    Parameters
    ----------
    acceleration : array_like, shape (..., 3)
        g in m/s², spatial frame. Default (0, 0, -9.81).
    """

    kind: ClassVar[str] = "gravity"
    schema: ClassVar = (Key("acceleration", "vector", "m/s²"),)

    acceleration: np.ndarray = (0.0, 0.0, -9.81)

    def __post_init__(self):
        _vector(self, "acceleration")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.acceleration.shape[:-1]

    def check(self, arm) -> None:
        if any(seg.linear_density is None for seg in arm.segments):
            raise ValueError(
                "Gravity needs the arm's mass: give the material a density or the arm "
                "a mass_per_length (Arm.linear_density is None)"
            )

    def apply(self, target: LoadTarget) -> None:
        target.distributed(force=self.acceleration, per_mass=True)

    def in_base_frame(self, R, origin=None) -> Gravity:
        return Gravity(_rotated(R, self.acceleration))

    def describe(self, swept=None) -> str:
        default = self.acceleration.ndim == 1 and np.array_equal(self.acceleration,
                                                                 (0.0, 0.0, -9.81))
        return "gravity" if default and swept is None else (
            "gravity " + self._fields_text(swept).removeprefix("acceleration "))


def _check_span(obj) -> None:
    """``span`` = (s0, s1) with 0 <= s0 < s1, or None; ``segment`` a segment index or None."""
    name = type(obj).__name__
    if obj.span is not None and obj.segment is not None:
        raise ValueError(f"{name}: give span or segment, not both "
                         f"(got span={format_value(obj.span)}, "
                         f"segment={format_value(obj.segment)})")
    if obj.segment is not None:
        if isinstance(obj.segment, bool) or not isinstance(obj.segment, (int, np.integer)) \
                or obj.segment < 0:
            raise ValueError(f"{name}.segment must be a segment index >= 0, got "
                             f"{format_value(obj.segment)}")
        object.__setattr__(obj, "segment", int(obj.segment))
    if obj.span is not None:
        span = as_array(obj.span, f"{name}.span")
        if span.shape != (2,) or not 0.0 <= span[0] < span[1]:
            raise ValueError(f"{name}.span must be (s0, s1) in m with 0 <= s0 < s1, got "
                             f"{format_value(obj.span)}")
        object.__setattr__(obj, "span", (float(span[0]), float(span[1])))


def _resolved_span(obj, arm) -> tuple[float, float] | None:
    """The span of a distributed load on ``arm`` in m (None: the whole arm)."""
    name = type(obj).__name__
    if obj.segment is not None:
        bounds = arm.boundaries
        if obj.segment >= len(bounds) - 1:
            raise ValueError(f"{name}.segment must be a segment index in [0, "
                             f"{len(bounds) - 2}] for this arm, got {obj.segment}")
        return (float(bounds[obj.segment]), float(bounds[obj.segment + 1]))
    if obj.span is not None and obj.span[1] > arm.length * (1 + 8 * np.finfo(float).eps):
        raise ValueError(f"{name}.span must lie on the arm, in [0, L] = [0, {arm.length!r}] "
                         f"m, got {obj.span!r}")
    return None if obj.span is None else (obj.span[0], min(obj.span[1], arm.length))


def _span_text(obj) -> str:
    if obj.segment is not None:
        return f" on segment {obj.segment}"
    if obj.span is not None:
        return f" on [{obj.span[0]:.4g}, {obj.span[1]:.4g}] m"
    return ""


@dataclass(frozen=True, eq=False)
class _Distributed(Load):
    """Shared by the uniform distributed loads: frame, span and segment."""

    follower: bool = field(default=False, kw_only=True)
    span: tuple[float, float] | None = field(default=None, kw_only=True)
    segment: int | None = field(default=None, kw_only=True)

    def __post_init__(self):
        name, _ = self.vectors[0]
        _vector(self, name)
        _check_follower(self)
        _check_span(self)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return getattr(self, self.vectors[0][0]).shape[:-1]

    def cuts(self, arm) -> tuple[float, ...]:
        span = _resolved_span(self, arm)
        return () if span is None else span

    def check(self, arm) -> None:
        _resolved_span(self, arm)

    def apply(self, target: LoadTarget) -> None:
        name, _ = self.vectors[0]
        target.distributed(**{name: getattr(self, name)}, follower=self.follower,
                           span=_resolved_span(self, target.arm))

    def in_base_frame(self, R, origin=None):
        if self.follower:
            return self
        name, _ = self.vectors[0]
        return self.replace(**{name: _rotated(R, getattr(self, name))})

    def describe(self, swept=None) -> str:
        return (("follower distributed " if self.follower else "distributed ")
                + self._fields_text(swept) + _span_text(self))


@dataclass(frozen=True, eq=False)
class DistributedForce(_Distributed):
    """A uniform force per unit length, on the whole arm, a span or a segment.

    Parameters
    ----------
    force : array_like, shape (..., 3)
        N/m. Spatial components (dead, default) or material components of the section it
        acts on (``follower=True``: it turns with the section).
    follower : bool, keyword-only
    span : (s0, s1), keyword-only, optional
        Arc lengths in m: the load acts on [s0, s1] only.
    segment : int, keyword-only, optional
        Index of the segment of a :class:`~softarm.SegmentedArm` the load acts on.
    """

    kind: ClassVar[str] = "distributed"
    schema: ClassVar = (Key("force", "vector", "N/m", required=True), Key("follower", "flag"),
                        Key("span", "span", "m"), Key("segment", "index"))

    force: np.ndarray = (0.0, 0.0, 0.0)


@dataclass(frozen=True, eq=False)
class DistributedMoment(_Distributed):
    """A uniform moment per unit length (a couple density), on the whole arm, a span or a
    segment.

    Parameters
    ----------
    moment : array_like, shape (..., 3)
        N m/m. Spatial components (dead, default) or material components (``follower=True``).
    follower, span, segment
        As for :class:`DistributedForce`.
    """

    kind: ClassVar[str] = "distributed_moment"
    schema: ClassVar = (Key("moment", "vector", "N m/m", required=True),
                        Key("follower", "flag"), Key("span", "span", "m"),
                        Key("segment", "index"))

    moment: np.ndarray = (0.0, 0.0, 0.0)


@dataclass(frozen=True, eq=False)
class PointLoad(Load):
    """A dead force and moment applied at an interior station s.

    Parameters
    ----------
    s : float
        Arc length in m, in [0, L] (checked against the arm when solving).
    force : array_like, shape (..., 3)
        N, spatial frame.
    moment : array_like, shape (..., 3)
        N m, spatial frame.
    """

    kind: ClassVar[str] = "point"
    schema: ClassVar = (Key("s", "number", "m", required=True), Key("force", "vector", "N"),
                        Key("moment", "vector", "N m"))

    s: float
    force: np.ndarray = (0.0, 0.0, 0.0)
    moment: np.ndarray = (0.0, 0.0, 0.0)

    def __post_init__(self):
        s = as_array(self.s, "PointLoad.s")
        if s.ndim != 0:
            raise ValueError(f"PointLoad.s must be a single arc length in m, got "
                             f"{format_value(self.s)}")
        object.__setattr__(self, "s", float(s))
        _vector(self, "force")
        _vector(self, "moment")
        _broadcast(self, "force", "moment")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return _broadcast(self, "force", "moment")

    def check(self, arm) -> None:
        if not 0.0 <= self.s <= arm.length:
            raise ValueError(
                f"PointLoad.s must lie on the arm, in [0, L] = [0, {arm.length!r}] m, "
                f"got {self.s!r}"
            )

    def cuts(self, arm) -> tuple[float, ...]:
        return (self.s,)

    def apply(self, target: LoadTarget) -> None:
        target.point(self.s, force=self.force, moment=self.moment)

    def in_base_frame(self, R, origin=None) -> PointLoad:
        return PointLoad(self.s, _rotated(R, self.force), _rotated(R, self.moment))

    def describe(self, swept=None) -> str:
        return f"point load at s = {self.s:.4g} m: " + self._fields_text(swept)


def _magnitude(obj, name: str, *, nonnegative: bool, unit: str) -> np.ndarray:
    """A batchable number (shape (...)), a private frozen copy; >= 0 if ``nonnegative``."""
    array = as_array(getattr(obj, name), f"{type(obj).__name__}.{name}").copy()
    if nonnegative and np.any(array < 0.0):
        raise ValueError(f"{type(obj).__name__}.{name} must be >= 0 {unit} (a tendon cannot "
                         f"push), got {format_value(np.min(array))}")
    array.setflags(write=False)
    object.__setattr__(obj, name, array)
    return array


def _routing(obj) -> None:
    if not isinstance(obj.routing, Routing):
        raise TypeError(f"{type(obj).__name__}.routing must be a softarm.routing path "
                        f"(Straight, Helix or Polynomial), got {format_value(obj.routing)}")


def _magnitude_text(value: np.ndarray, unit: str, swept, name: str) -> str:
    if swept is not None and swept[0] == name:
        return swept[1]
    if value.ndim:
        return f"(batch of {value.shape})"
    return f"{float(value):.4g} {unit}"


def _check_on_arm(obj, arm, *names) -> None:
    for name in names:
        value = getattr(obj, name)
        if value is not None and not 0.0 <= value <= arm.length * (1 + 8 * np.finfo(float).eps):
            raise ValueError(f"{type(obj).__name__}.{name} must lie on the arm, in [0, L] = "
                             f"[0, {arm.length!r}] m, got {value!r}")


#: Paths already checked on an arm: (routing, id(arm), span) -> arm, held so that its id
#: stays its own. Routings are frozen dataclasses, equal by value: a control loop that builds
#: new tendons on the same paths with new tensions thousands of times checks each path once.
_CHECKED_PATHS: dict = {}


def _check_tangent(obj, arm) -> None:
    """ValueError if the path's tangent w = e1 + κ⁰ × r + r' vanishes on the unloaded arm
    (a tendon folded back along itself has no direction to pull in)."""
    start, end = obj.path_span(arm.length)
    key = (obj.routing, id(arm), start, end)
    try:
        if key in _CHECKED_PATHS:
            return
    except TypeError:  # a user's routing class that cannot be hashed: checked every time
        key = None
    _check_path(obj, arm, start, end)
    if key is None:
        return
    if len(_CHECKED_PATHS) >= 256:
        _CHECKED_PATHS.pop(next(iter(_CHECKED_PATHS)))
    _CHECKED_PATHS[key] = arm


def path_tangent(position, derivative, strain) -> np.ndarray:
    """w = v + u × r + r', the tangent of a path r(s) (a tendon's, a chamber's centroid's)
    through the sections: d(p + R r)/ds in material components, m/m, shape (..., 3), from
    the path's ``position`` r and ``derivative`` r' (m, m/m, material: a routing's
    ``position(s)`` and ``derivative(s)``) and the total strain ``strain`` ε = (v; u)
    (..., 6; f⁰ in the unloaded arm) at the same arc lengths, all broadcasting."""
    strain = np.asarray(strain, dtype=np.float64)
    return strain[..., :3] + np.cross(strain[..., 3:], position) + derivative


def _check_path(obj, arm, start, end) -> None:
    bounds = arm.boundaries
    for k, segment in enumerate(arm.segments):
        lo, hi = max(start, bounds[k]), min(end, bounds[k + 1])
        if lo >= hi:
            continue
        s = np.linspace(lo, hi, 257)
        w = path_tangent(obj.routing.position(s), obj.routing.derivative(s),
                         segment.reference_strain)
        norm = np.linalg.norm(w, axis=-1)
        if np.min(norm) < 1e-6:
            raise ValueError(
                f"{type(obj).__name__}.routing: the path's tangent w = e1 + κ⁰ × r + r' "
                f"vanishes near s = {s[np.argmin(norm)]:.4g} m (|w| = {np.min(norm):.2g}): the "
                "path doubles back along the arm there and a tendon cannot pull along it")


@dataclass(frozen=True, eq=False)
class Tendon(Load):
    """A frictionless tendon pulled with tension τ, or pulled in by a prescribed length
    (``displacement``), anchored at arc length ``end``, running along ``routing`` through
    the sections from the base (Rucker & Webster 2011).

    The arm and its tendons are solved together: the tendon acts through the constitutive
    law (``docs/actuation.md``), its pull on the sections it bends around and its anchor
    load included exactly.

    Give exactly one of ``tension`` (tension control) and ``displacement`` (displacement
    control: what a motor with an encoder sets). Under displacement control the tension is
    an unknown, solved so that the tendon's length less its length on the unloaded arm equals
    ``displacement``; a tendon that would need τ < 0 (given more length than its path
    needs) is *slack*: τ = 0, reported in ``Equilibrium.tendon_slack`` (``docs/control.md``).

    Parameters
    ----------
    tension : float or array_like, shape (...)
        τ >= 0 in N (a tendon cannot push), batchable.
    routing : softarm.routing.Straight, Helix or Polynomial
        The path r(s) in the section, material frame, as a function of the arm's arc length.
    end : float, optional
        Arc length in m where the tendon is anchored (default: the tip).
    displacement : float or array_like, shape (...), keyword-only
        The prescribed change of the tendon's length from the unloaded arm, m (negative:
        pulled in), batchable; instead of ``tension``.

    Examples
    --------
    >>> from softarm.routing import Straight
    >>> Tendon(2.0, Straight(0.0, 0.01)).describe()
    'tendon 2 N, straight at (y, z) = (0, 0.01) m, anchored at the tip'
    >>> Tendon(routing=Straight(0.0, 0.01), displacement=-0.002).describe()
    'tendon pulled in by 0.002 m, straight at (y, z) = (0, 0.01) m, anchored at the tip'
    """

    kind: ClassVar[str] = "tendon"
    acts_through_base: ClassVar[bool] = True
    schema: ClassVar = (Key("tension", "magnitude", "N"), Key("displacement", "magnitude", "m"),
                        Key("routing", "routing", required=True), Key("end", "number", "m"))

    tension: np.ndarray | None = None
    routing: Routing | None = None
    end: float | None = None
    displacement: np.ndarray | None = field(default=None, kw_only=True)

    def __post_init__(self):
        if (self.tension is None) == (self.displacement is None):
            given = "both" if self.tension is not None else "neither"
            raise TypeError(f"Tendon needs exactly one of tension (N, tension control) and "
                            f"displacement (m, displacement control), got {given}")
        if self.tension is not None:
            _magnitude(self, "tension", nonnegative=True, unit="N")
        else:
            _magnitude(self, "displacement", nonnegative=False, unit="m")
        _routing(self)
        if self.end is not None:
            end = real(self.end, "Tendon.end", "m")
            if not end > 0.0:
                raise ValueError(f"Tendon.end must be an arc length > 0 m, got "
                                 f"{format_value(self.end)}")
            object.__setattr__(self, "end", end)

    @property
    def inputs(self) -> tuple[str, ...]:
        """The actuation input: ("tension",) or, under displacement control,
        ("displacement",)."""
        return ("tension",) if self.displacement is None else ("displacement",)

    @property
    def displacement_controlled(self) -> bool:
        """True if the tendon's length change is prescribed (its tension an unknown)."""
        return self.displacement is not None

    def with_tension(self, tension) -> Tendon:
        """The same tendon under tension control, pulled with ``tension`` (N)."""
        return Tendon(tension, self.routing, self.end)

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return (self.tension if self.displacement is None else self.displacement).shape

    def check(self, arm) -> None:
        _check_on_arm(self, arm, "end")
        _check_tangent(self, arm)

    def cuts(self, arm) -> tuple[float, ...]:
        return () if self.end is None or self.end >= arm.length else (self.end,)

    def path_span(self, length: float) -> tuple[float, float]:
        """Where the tendon runs, (0, end) in m, on an arm of this length."""
        return 0.0, length if self.end is None else min(self.end, length)

    def apply(self, target: LoadTarget) -> None:
        if self.displacement is not None:
            # the tension is an unknown: a solver that handles displacement control replaces
            # the tendon by :meth:`with_tension` first; any other target (a closed form)
            # learns that it meets a load it does not know
            target.displaced_tendon(self.displacement, self.routing,
                                    self.path_span(target.length))
            return
        target.actuator("tendon", self.tension, self.routing, self.path_span(target.length))

    def in_base_frame(self, R, origin=None) -> Tendon:
        return self  # material frame throughout

    def describe(self, swept=None) -> str:
        where = "the tip" if self.end is None else f"s = {self.end:.4g} m"
        if self.displacement is not None:
            d = self.displacement
            if (swept is not None and swept[0] == "displacement") or d.ndim or d >= 0:
                what = f"length change {_magnitude_text(d, 'm', swept, 'displacement')}"
            else:
                what = f"pulled in by {-float(d):.4g} m"
        else:
            what = _magnitude_text(self.tension, "N", swept, "tension")
        return f"tendon {what}, {self.routing.describe()}, anchored at {where}"


@dataclass(frozen=True, eq=False)
class Chamber(Load):
    """A pneumatic chamber at uniform pressure p between arc lengths ``start`` and ``end``,
    its centroid along ``routing``.

    The exact rigid-section model: the fluid cut by each section pushes p A d1 through the
    chamber's centroid r(s), a wrench p A (e1; r × e1) on the section (material), closed by
    end caps at ``end`` and ``start``. Not modelled: ballooning of the walls, a stiffness that
    changes with pressure, volume (rather than pressure) control (``docs/actuation.md``).

    Parameters
    ----------
    pressure : float or array_like, shape (...)
        p in Pa (gauge; negative for vacuum), batchable.
    area : float
        A in m², the chamber's area in the cross-section plane (> 0).
    routing : softarm.routing path
        The chamber centroid's path in the section (material frame).
    start, end : float
        Arc lengths in m (defaults: 0 and the tip).
    """

    kind: ClassVar[str] = "chamber"
    acts_through_base: ClassVar[bool] = True
    inputs: ClassVar = ("pressure",)
    schema: ClassVar = (Key("pressure", "magnitude", "Pa", required=True),
                        Key("area", "number", "m²", required=True),
                        Key("routing", "routing", required=True), Key("start", "number", "m"),
                        Key("end", "number", "m"))

    pressure: np.ndarray
    area: float
    routing: Routing
    start: float = 0.0
    end: float | None = None

    def __post_init__(self):
        _magnitude(self, "pressure", nonnegative=False, unit="Pa")
        area = real(self.area, "Chamber.area", "m²")
        if not area > 0.0:
            raise ValueError(f"Chamber.area must be > 0 m², got {format_value(self.area)}")
        object.__setattr__(self, "area", area)
        _routing(self)
        object.__setattr__(self, "start", real(self.start, "Chamber.start", "m"))
        if self.end is not None:
            object.__setattr__(self, "end", real(self.end, "Chamber.end", "m"))
        if self.start < 0.0 or (self.end is not None and not self.end > self.start):
            raise ValueError(f"Chamber.start and Chamber.end must satisfy 0 <= start < end, "
                             f"got start={self.start!r}, end={self.end!r}")

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return self.pressure.shape

    def check(self, arm) -> None:
        _check_on_arm(self, arm, "start", "end")
        if self.start >= arm.length:
            raise ValueError(f"Chamber.start must be < L = {arm.length!r} m, got {self.start!r}")

    def cuts(self, arm) -> tuple[float, ...]:
        return tuple(c for c in (self.start, self.end) if c is not None and 0.0 < c < arm.length)

    def path_span(self, length: float) -> tuple[float, float]:
        """Where the chamber is, (start, end) in m, on an arm of this length."""
        return self.start, length if self.end is None else min(self.end, length)

    def apply(self, target: LoadTarget) -> None:
        target.actuator("chamber", self.pressure * self.area, self.routing,
                        self.path_span(target.length))

    def in_base_frame(self, R, origin=None) -> Chamber:
        return self

    def describe(self, swept=None) -> str:
        span = "" if self.start == 0.0 and self.end is None else \
            f" on [{self.start:.4g}, {self.end if self.end is not None else 'L'}] m"
        return (f"chamber {_magnitude_text(self.pressure, 'Pa', swept, 'pressure')} over "
                f"{self.area:.4g} m², {self.routing.describe()}{span}")


@dataclass(frozen=True, eq=False)
class MagneticField(Load):
    """An external magnetic field B(x) = B0 + G x acting on the arm's hard magnets (its
    ``magnetization`` per length and ``tip_magnet`` dipoles, fixed in the material).

    A magnetisation m (material, A m²/m) feels the torque (R m) × B(p) and the force
    Gᵀ (R m) per unit length; a dipole the same, concentrated. A field in current-free space
    has a symmetric, traceless gradient; another gets a warning.

    Parameters
    ----------
    field : array_like, shape (..., 3)
        B0 in T, spatial components, batchable.
    gradient : array_like, shape (..., 3, 3), optional
        G in T/m, spatial (B varies as G x, x the spatial position in m); default uniform.
    """

    kind: ClassVar[str] = "magnetic"
    inputs: ClassVar = ("field",)
    schema: ClassVar = (Key("field", "vector", "T", required=True),
                        Key("gradient", "matrix", "T/m"))

    field: np.ndarray
    gradient: np.ndarray | None = None

    def __post_init__(self):
        _vector(self, "field")
        if self.gradient is not None:
            G = as_matrices(self.gradient, "MagneticField.gradient", 3).copy()
            G.setflags(write=False)
            object.__setattr__(self, "gradient", G)
            asymmetry = np.max(np.abs(G - np.swapaxes(G, -1, -2)), initial=0.0)
            trace = np.max(np.abs(np.trace(G, axis1=-2, axis2=-1)), initial=0.0)
            size = max(np.max(np.abs(G), initial=0.0), 1e-300)
            if max(asymmetry, trace) > 1e-9 * size:
                import warnings
                warnings.warn(
                    f"MagneticField.gradient is not symmetric and traceless (largest asymmetry "
                    f"{asymmetry:.3g} T/m, trace {trace:.3g} T/m): no field in current-free "
                    "space has such a gradient (curl B = 0, div B = 0)", UserWarning,
                    stacklevel=3)
            try:
                np.broadcast_shapes(self.field.shape[:-1], G.shape[:-2])
            except ValueError:
                raise ValueError(f"MagneticField.field and MagneticField.gradient must have "
                                 f"batch shapes that broadcast, got {self.field.shape} and "
                                 f"{G.shape}") from None

    @property
    def batch_shape(self) -> tuple[int, ...]:
        if self.gradient is None:
            return self.field.shape[:-1]
        return np.broadcast_shapes(self.field.shape[:-1], self.gradient.shape[:-2])

    def apply(self, target: LoadTarget) -> None:
        target.field(self.field, self.gradient)

    def in_base_frame(self, R, origin=None) -> MagneticField:
        # B at x = o + R x' in base components: Rᵀ (B0 + G o) + Rᵀ G R x'
        if self.gradient is None:
            return MagneticField(_rotated(R, self.field))
        o = np.zeros(3) if origin is None else np.asarray(origin, dtype=np.float64)
        B = self.field + np.einsum("...ij,j->...i", self.gradient, o)
        return MagneticField(_rotated(R, B), np.einsum("ji,...jk,kl->...il", R, self.gradient,
                                                         R))

    def describe(self, swept=None) -> str:
        text = "magnetic " + self._fields_text(swept)
        if self.gradient is not None:
            text += (", gradient (batch)" if self.gradient.ndim > 2 else
                     f", gradient up to {np.max(np.abs(self.gradient)):.4g} T/m")
        return text


#: Load subclasses met by :func:`as_loads` (isinstance on an abstract base class costs
#: about 0.3 µs a call, and one solve checks its loads several times)
_LOAD_TYPES: set[type] = set()


def as_actuators(actuators) -> tuple[Load, ...]:
    """The actuators as loads, each checked: loads with actuation inputs (Tendon, Chamber,
    MagneticField), single (unbatched)."""
    actuators = as_loads(actuators)
    for load in actuators:
        if not load.inputs:
            raise TypeError(f"actuators must be loads with actuation inputs (Tendon, "
                            f"Chamber, MagneticField), got {load!r}")
        if load.batch_shape != ():
            raise ValueError(f"actuators must be single (unbatched) loads, got "
                             f"{type(load).__name__} of batch shape {load.batch_shape}")
    return actuators


def as_loads(loads) -> tuple[Load, ...]:
    """A single load or a sequence of loads as a tuple, TypeError for anything else."""
    if type(loads) in (tuple, list) and all(type(item) in _LOAD_TYPES for item in loads):
        return tuple(loads)
    if isinstance(loads, Load):
        _LOAD_TYPES.add(type(loads))
        return (loads,)
    try:
        items = None if isinstance(loads, (str, bytes, dict)) else tuple(loads)
    except TypeError:
        items = None
    if items is None:
        raise TypeError(f"loads must be a softarm.Load or a list of them, got "
                        f"{format_value(loads)}")
    for item in items:
        if not isinstance(item, Load):
            raise TypeError(
                f"loads must be softarm.Load instances (TipLoad, Gravity, DistributedForce, "
                f"DistributedMoment, PointLoad, ...), got {format_value(item)} of type "
                f"{type(item).__name__}")
        _LOAD_TYPES.add(type(item))
    return items


def batch_shape(loads) -> tuple[int, ...]:
    """The broadcast batch shape of all loads, ValueError if they do not broadcast."""
    shapes = [load.batch_shape for load in as_loads(loads)]
    try:
        return _common_shape(shapes)
    except ValueError as error:
        raise ValueError(f"loads have batch shapes {shapes} that do not broadcast") from error



#: The largest load accepted, in units of the arm's bending scale (EI/L² for a force, EI/L
#: for a moment, EI the largest bending or torsional stiffness of its segments): beyond it the
#: rod is a string whose shape double precision cannot follow, and closed forms overflow.
LOAD_LIMIT = 1e12


def _largest(value) -> float:
    """max |value| over every component and case (0 for None or an empty array)."""
    if value is None:
        return 0.0
    value = np.asarray(value)
    if value.size <= 16:  # (one case: in Python, a third of numpy's call overhead)
        return max(map(abs, value.ravel().tolist()), default=0.0)
    return float(np.abs(value).max())


@functools.lru_cache(maxsize=256)
def _reach(routing, length: float) -> float:
    """``routing.bound(length)``, remembered (routings are frozen and hashable)."""
    return routing.bound(length)


@functools.lru_cache(maxsize=64)
def _cached_scales(arm) -> tuple[float, ...]:
    return _scales(arm)


def _scales(arm) -> tuple[float, ...]:
    """(EI/L² in N, EI/L in N m, the largest mass per length in kg/m, magnetisation per
    length in A m²/m and tip dipole in A m²) of an arm, for :func:`check_magnitudes`."""
    segments = arm.segments
    length = float(arm.length)
    bending = max(float(np.max(np.diagonal(seg.stiffness)[3:])) for seg in segments)
    mass = max(seg.linear_density or 0.0 for seg in segments)
    magnets = [max(_largest(getattr(seg, name, None)) for seg in segments)
               for name in ("magnetization", "tip_magnet")]
    return bending / length**2, bending / length, mass, *magnets


class _Sizes:
    """A :class:`LoadTarget` that measures a load against the arm's bending scale: the
    largest force over EI/L² and moment over EI/L it brings (a distributed one over the
    arm's length, an actuator's pull and its moment arm, a field's torque and force on the
    arm's magnets), over its whole batch."""

    def __init__(self, arm, scales):
        self.arm, self.length = arm, float(arm.length)
        self.force_scale, self.moment_scale, self.mass, self.magnetization, self.dipole = \
            scales
        self.size = 0.0

    def _force(self, value: float) -> None:
        self.size = max(self.size, value / self.force_scale)

    def _moment(self, value: float) -> None:
        self.size = max(self.size, value / self.moment_scale)

    def distributed(self, *, force=None, moment=None, follower=False, span=None,
                    per_mass=False):
        self._force(_largest(force) * (self.mass if per_mass else 1.0) * self.length)
        self._moment(_largest(moment) * self.length)

    def point(self, s, *, force=None, moment=None):
        self._force(_largest(force))
        self._moment(_largest(moment))

    def tip(self, *, force=None, moment=None, follower=False):
        self.point(self.length, force=force, moment=moment)

    def actuator(self, kind, magnitude, routing, span):
        pull = _largest(magnitude)
        self._force(pull)
        try:
            reach = _reach(routing, self.length)
        except TypeError:  # a user's routing class that cannot be hashed
            reach = routing.bound(self.length)
        self._moment(pull * reach)

    def displaced_tendon(self, displacement, routing, span):
        # a length change, measured against the arm's length (the tension is solved)
        self.size = max(self.size, _largest(displacement) / self.length)

    def contact(self, load):
        pass  # (a reaction: as large as the loads that press the arm on the obstacles)

    def field(self, field, gradient=None):
        # B over the arm: |B0| + |G| L; the torque m × B and the force Gᵀ m on the magnets
        spread = _largest(gradient) * 3.0
        B = _largest(field) * 3.0 ** 0.5 + spread * self.length
        self._moment(B * (self.magnetization * self.length + self.dipole))
        self._force(spread * (self.magnetization * self.length + self.dipole))


def largest_force(arm, loads):
    """The largest force (N) the loads can apply to ``arm`` from outside, per case: a float
    for single loads, else an array of their batch shape. A bound of the tension they can
    cause anywhere in the arm: each force's components' magnitudes summed, a distributed
    force's over the length it acts on, summed over the loads. The solver's route counts it
    (kL = L √(F/EI), statics/_stiff.py).

    Each load is measured through its own :meth:`Load.apply` (the interface every kind
    implements, as :func:`check_magnitudes` measures it), so a kind made of the
    :class:`LoadTarget`'s calls is counted without code of its own: forces at points and
    along the arm, a field gradient's force on the arm's magnets. An actuator (a tendon's
    tension, a chamber's p A) counts nothing: it is internal, balanced by the sections it
    pushes on, and compresses the backbone as much as it pulls (docs/solver.md, "The
    route"); nor does contact (a reaction to the other loads; the route sends it to multiple
    shooting whatever its size)."""
    target = _Forces(arm)
    for load in loads if type(loads) is tuple else as_loads(loads):
        load.apply(target)
    return target.force


def _magnitudes(value):
    """Σ |component| over the last axis: (..., 3) -> (...) (a float for one vector)."""
    value = np.asarray(value)
    if value.ndim == 1:  # (one case: in Python, a third of numpy's call overhead)
        return sum(map(abs, value.tolist()))
    return np.abs(value).sum(-1)


class _Forces:
    """A :class:`LoadTarget` that measures the largest force (N) loads apply to the arm
    from outside (:func:`largest_force`): ``force``, a float or an array of the loads'
    batch shape."""

    def __init__(self, arm):
        self.arm, self.length = arm, float(arm.length)
        self.force = 0.0

    def distributed(self, *, force=None, moment=None, follower=False, span=None,
                    per_mass=False):
        if force is None:
            return
        lo, hi = (0.0, self.length) if span is None else span
        bounds = self.arm.boundaries
        along = 0.0
        for k, segment in enumerate(self.arm.segments):  # (∫ ds, or ∫ μ ds, on the span)
            overlap = max(0.0, min(hi, bounds[k + 1]) - max(lo, bounds[k]))
            along += overlap * ((segment.linear_density or 0.0) if per_mass else 1.0)
        self.force = self.force + _magnitudes(force) * along

    def point(self, s, *, force=None, moment=None):
        if force is not None:
            self.force = self.force + _magnitudes(force)

    def tip(self, *, force=None, moment=None, follower=False):
        self.point(self.length, force=force)

    def actuator(self, kind, magnitude, routing, span):
        pass  # internal (largest_force)

    def displaced_tendon(self, displacement, routing, span):
        pass  # internal, like a tendon under tension control

    def contact(self, load):
        pass  # (largest_force)

    def field(self, field, gradient=None):
        # the force Gᵀ (R m) per length on a magnetisation m and on each dipole: its
        # components' magnitudes are at most Σ|G_ij| |m| whatever the rotation R
        if gradient is None:
            return
        magnets = sum(_norm(getattr(seg, "magnetization", None)) * seg.length
                      + _norm(getattr(seg, "tip_magnet", None)) for seg in self.arm.segments)
        self.force = self.force + np.abs(np.asarray(gradient)).sum((-1, -2)) * magnets


def applied_wrench(arm, loads, s, poses) -> np.ndarray:
    """(B..., 6): the resultant of every force the loads apply to the arm from outside,
    contact excepted, on an equilibrium with ``poses`` (B..., S, 4, 4) at stations ``s``
    (S,): the force (N) and its moment about the spatial origin (N m), spatial components.

    Actuators count nothing (a tendon's pull and a chamber's pressure are internal to the
    arm and its actuators, their reaction on the base included in the solver's base wrench),
    nor does a Contact (what this balances: the solver's contact wrench is the base wrench
    less this, docs/contact.md). Each load is read through its own :meth:`Load.apply`.

    ``s`` must hold every cut (the segments' joints, the spans' ends and the point loads'
    stations): a distributed load is integrated on each smooth piece between two cuts by
    Simpson's rule on the stations (fourth order in their spacing)."""
    target = _Applied(arm, np.asarray(s, dtype=np.float64), np.asarray(poses))
    for load in loads if type(loads) is tuple else as_loads(loads):
        load.apply(target)
    return target.wrench


class _Applied:
    """A :class:`LoadTarget` that sums the wrench loads apply at an equilibrium's poses
    (:func:`applied_wrench`): ``wrench`` (B..., 6), about the spatial origin."""

    def __init__(self, arm, s, poses):
        self.arm, self.length, self.s = arm, float(arm.length), s
        self.R, self.p = poses[..., :3, :3], poses[..., :3, 3]
        self.wrench = np.zeros((*poses.shape[:-3], 6))

    def _at(self, s: float) -> int:
        i = int(np.argmin(np.abs(self.s - s)))
        if abs(self.s[i] - s) > 1e-12 * self.length:
            raise ValueError(f"applied_wrench: the stations lack the cut s = {s!r} m")
        return i

    def _add(self, force, moment, at) -> None:
        """A force (B..., 3) at the point ``at`` (B..., 3) and a couple (B..., 3)."""
        self.wrench[..., :3] += force
        self.wrench[..., 3:] += np.cross(at, force) + moment

    def _integrated(self, density, lo: float, hi: float, per_segment=None) -> np.ndarray:
        """∫ density over [lo, hi] (density (B..., S, k) on the stations), piece by piece
        between the segments' joints inside, each piece's density times its segment's
        ``per_segment`` factor if given (a joint's station belongs to both pieces: one
        array for every station cannot hold its two linear densities)."""
        from scipy.integrate import simpson  # (scipy: a dependency; loaded on first use)

        bounds = self.arm.boundaries
        cuts = [b for b in bounds if lo < b < hi]
        total = 0.0
        for a, b in zip([lo, *cuts], [*cuts, hi], strict=True):
            i, k = self._at(a), self._at(b)
            if k <= i:
                continue
            piece = density[..., i:k + 1, :]
            if per_segment is not None:  # (the segment holding the piece's middle)
                segment = int(np.searchsorted(bounds, 0.5 * (a + b), side="right")) - 1
                piece = piece * per_segment[min(segment, len(per_segment) - 1)]
            total = total + simpson(piece, x=self.s[i:k + 1], axis=-2)
        return total

    def distributed(self, *, force=None, moment=None, follower=False, span=None,
                    per_mass=False):
        lo, hi = (0.0, self.length) if span is None else span
        rotate = (lambda v: np.einsum("...ij,...j->...i", self.R,
                                      np.asarray(v)[..., None, :])) if follower else \
            (lambda v: np.broadcast_to(np.asarray(v)[..., None, :], self.p.shape))
        if force is not None:
            f = rotate(force)
            mass = np.array([seg.linear_density or 0.0 for seg in self.arm.segments]) \
                if per_mass else None
            density = np.concatenate([f, np.cross(self.p, f)], axis=-1)
            self.wrench += self._integrated(density, lo, hi, mass)
        if moment is not None:
            density = np.concatenate([np.zeros(self.p.shape), rotate(moment)], -1)
            self.wrench += self._integrated(density, lo, hi)

    def point(self, s, *, force=None, moment=None):
        i = self._at(s)
        self._add(np.zeros(3) if force is None else np.asarray(force, dtype=np.float64),
                  np.zeros(3) if moment is None else np.asarray(moment, dtype=np.float64),
                  self.p[..., i, :])

    def tip(self, *, force=None, moment=None, follower=False):
        R = self.R[..., -1, :, :]
        turn = (lambda v: np.einsum("...ij,...j->...i", R, np.asarray(v))) if follower \
            else np.asarray
        self._add(np.zeros(3) if force is None else turn(force),
                  np.zeros(3) if moment is None else turn(moment), self.p[..., -1, :])

    def actuator(self, kind, magnitude, routing, span):
        pass  # internal (applied_wrench)

    def displaced_tendon(self, displacement, routing, span):
        pass  # internal

    def contact(self, load):
        pass  # what applied_wrench balances

    def field(self, field, gradient=None):
        # a magnetisation m (material) per length feels the couple (R m) × B(p) and the
        # force Gᵀ (R m); a dipole at its segment's distal end the same, concentrated
        B0 = np.asarray(field, dtype=np.float64)
        G = None if gradient is None else np.asarray(gradient, dtype=np.float64)

        def wrench(m, R, p, along):  # (force, couple) on magnets m (material) at R, p
            mu = np.einsum("...ij,j->...i", R, m)  # (``along``: p has a station axis)
            B = B0[..., None, :] if along else B0
            force = np.zeros(mu.shape)
            if G is not None:
                Gs = G[..., None, :, :] if along else G
                B = B + np.einsum("...ij,...j->...i", Gs, p)
                force = np.einsum("...ji,...j->...i", Gs, mu)
            return force, np.cross(mu, B)

        bounds = self.arm.boundaries
        for k, segment in enumerate(self.arm.segments):
            m = getattr(segment, "magnetization", None)
            if m is not None:
                i, e = self._at(bounds[k]), self._at(bounds[k + 1])
                f, c = wrench(np.asarray(m, dtype=np.float64), self.R[..., i:e + 1, :, :],
                              self.p[..., i:e + 1, :], True)
                density = np.zeros((*self.p.shape[:-1], 6))
                density[..., i:e + 1, :] = np.concatenate(
                    [f, np.cross(self.p[..., i:e + 1, :], f) + c], axis=-1)
                self.wrench += self._integrated(density, bounds[k], bounds[k + 1])
            dipole = getattr(segment, "tip_magnet", None)
            if dipole is not None:
                e = self._at(bounds[k + 1])
                f, c = wrench(np.asarray(dipole, dtype=np.float64), self.R[..., e, :, :],
                              self.p[..., e, :], False)
                self._add(f, c, self.p[..., e, :])


def _norm(vector) -> float:
    return 0.0 if vector is None else float(np.linalg.norm(vector))


def _size(load, arm, scales, target=None) -> float:
    """A load's size in units of the bending scale (``target``: a :class:`_Sizes` to reuse)."""
    target = _Sizes(arm, scales) if target is None else target
    target.size = 0.0
    load.apply(target)
    return target.size


def check_magnitudes(arm, loads, function: str = "") -> None:
    """ValueError naming the load (and its field) whose size exceeds :data:`LOAD_LIMIT`
    times the arm's bending scale: every kind of load, every route (the closed forms and the
    numerical solver call it before computing anything). ``function``: a prefix for the
    message (the closed form called)."""
    try:
        scales = _cached_scales(arm)
    except TypeError:  # an unhashable field (never with the model's own types)
        scales = _scales(arm)
    if not all(np.isfinite(scales[:2])) or min(scales[:2]) <= 0.0:
        return  # an arm without a bending scale: its own checks say so
    target = _Sizes(arm, scales)
    for load in as_loads(loads):
        size = _size(load, arm, scales, target)
        if size <= LOAD_LIMIT:  # (NaN cannot occur: loads and arms are finite)
            continue
        size, name, unit = max(_field_sizes(load, arm, scales), default=(size, "", ""))
        value = _largest(getattr(load, name)) if name else size
        raise ValueError(
            f"{function + ': ' if function else ''}{type(load).__name__}"
            f"{'.' + name if name else ''}: a load of {value:.3g}{' ' + unit if unit else ''} "
            f"is not representable on this arm: it exceeds {LOAD_LIMIT:.0e} times the bending "
            f"scale (EI/L² = {scales[0]:.3g} N, EI/L = {scales[1]:.3g} N m), where double "
            "precision cannot follow the shape")


def _field_sizes(load, arm, scales):
    """(size, field name, unit) of each batchable field of ``load`` alone (the others at
    zero): which of them makes a load too large (a rare path: the error message's)."""
    present = [(name, unit) for name, unit, _ in load.arrays
               if getattr(load, name) is not None]
    for name, unit in present:
        others = {other: np.zeros_like(getattr(load, other)) for other, _ in present
                  if other != name}
        yield _size(load.replace(**others) if others else load, arm, scales), name, unit


#: The inputs at which :class:`InputRules` measures a load's growth (any value far beyond
#: every limit, whose products with the arm's scales stay finite)
_FAR = 1e100


class InputRules:
    """The rules that actuation inputs given apart from their loads obey on an arm, the same
    as the loads' own (a tendon cannot push: its tension >= 0; pressures and fields of any
    sign; every input finite) and :func:`check_magnitudes`' size limit: for the routes that
    take inputs as numbers (``ForwardSolver.solve``, ``Simulator.step`` and ``run``,
    ``simulate``'s schedules), so that every input is held to one rule on every route.

    :meth:`admits` is the common case's test, one comparison per input against bounds set
    once (an input at most the bound keeps its load within half the size limit, whatever
    the others); beyond it :meth:`check` builds the loads at those inputs (their own rules
    and messages) and measures them.

    Parameters
    ----------
    arm : Arm or SegmentedArm
    actuators : sequence of loads with inputs (:func:`as_actuators`), their inputs in order
        (a tendon's tension, a chamber's pressure, a field's three components).
    """

    def __init__(self, arm, actuators):
        self.arm = arm
        self.actuators = as_actuators(actuators)
        try:
            scales = _cached_scales(arm)
        except TypeError:  # an unhashable field (never with the model's own types)
            scales = _scales(arm)
        # (an arm without a bending scale: check_magnitudes measures nothing on it)
        measured = all(np.isfinite(scales[:2])) and min(scales[:2]) > 0.0
        #: per load: (its first input, its inputs' count, (field name, shape) of each)
        self.columns = []
        low, high = [], []
        first = 0
        for load in self.actuators:
            fields = [(name, np.shape(getattr(load, name))) for name in load.inputs]
            count = sum(int(np.prod(shape)) for _, shape in fields)
            self.columns.append((first, count, fields))
            bound = self._bound(load, fields, scales) if measured else np.inf
            try:  # a load whose inputs cannot be negative (a tendon) says so itself
                load.replace(**{name: np.full(shape, -1.0) for name, shape in fields})
                least = -bound
            except (TypeError, ValueError):
                least = 0.0
            low += [least] * count
            high += [bound] * count
            first += count
        self.low, self.high = np.array(low), np.array(high)

    def _bound(self, load, fields, scales) -> float:
        """The input t (every input of ``load`` at ±t) below which its size stays within
        half of :data:`LOAD_LIMIT`: its size grows at most linearly in t, from size(0) at
        the slope (size(T) - size(0)) / T at a far T (a load's size is the largest of
        terms affine in its inputs' largest |value|, of slopes >= 0)."""
        def size(t):
            return _size(load._with_checked(**{name: np.full(shape, t)
                                               for name, shape in fields}), self.arm, scales)

        at_zero = size(0.0)
        slope = (size(_FAR) - at_zero) / _FAR
        room = 0.5 * LOAD_LIMIT - at_zero
        if room <= 0.0:
            return 0.0
        return room / slope if slope > 0.0 else np.inf

    def admits(self, inputs) -> bool:
        """Whether every row of ``inputs`` (..., n) passes the common case's test (finite,
        within the bounds set at construction: NaN fails it)."""
        q = np.asarray(inputs)
        return bool(((q >= self.low) & (q <= self.high)).all())

    def check(self, inputs, name: str = "inputs") -> None:
        """ValueError naming the first inadmissible input of ``inputs`` (..., n), finite
        floats, as ``name[index]`` (its index in ``inputs``), with its load's own message
        (``Tendon.tension must be >= 0 N (a tendon cannot push), got -2``) or
        :func:`check_magnitudes`'; nothing if every row is admissible."""
        fault = self.first_fault(inputs)
        if fault is not None:
            raise ValueError(f"{name}[{fault[0]}]: {fault[1]}")

    def first_fault(self, inputs) -> tuple[str, str] | None:
        """(the index of the first inadmissible input of ``inputs`` (..., n) in C order, as
        text: ``"2, 0"``; its load's message), or None if all are admissible."""
        q = np.asarray(inputs, dtype=np.float64)
        if self.admits(q):
            return None
        batch = q.shape[:-1]
        for load, (first, count, fields) in zip(self.actuators, self.columns, strict=True):
            columns = q[..., first:first + count]
            if ((columns >= self.low[first:first + count])
                    & (columns <= self.high[first:first + count])).all():
                continue
            if self._fault(load, fields, columns) is None:  # (beyond the screen only)
                continue
            for index in np.ndindex(*batch):  # the first row at fault, to name it
                fault = self._fault(load, fields, columns[index])
                if fault is not None:
                    where = str(first) if count == 1 else f"{first}:{first + count}"
                    return ", ".join([*(str(i) for i in index), where]), fault
        return None

    def _fault(self, load, fields, columns) -> str | None:
        """The message of ``load`` at the inputs ``columns`` (..., count), None if fine."""
        batch, start, values = columns.shape[:-1], 0, {}
        for field_name, shape in fields:
            size = int(np.prod(shape))
            values[field_name] = columns[..., start:start + size].reshape(batch + shape)
            start += size
        try:
            check_magnitudes(self.arm, [load.replace(**values)])
        except (TypeError, ValueError) as error:
            return str(error)
        return None

