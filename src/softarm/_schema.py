"""The case-file schema: TOML table machinery and one table of keys per kind, read and written.

Every table of a case file is described once, by rows of :class:`softarm.loads.Key` (the same
rows the load classes declare in ``Load.schema``), and each description serves both directions:
:mod:`softarm.case` reads a file with it, and :func:`arm_to_dict`, :func:`loads_to_dict`,
:func:`solve_to_dict` and :func:`sweep_to_dict` write a model back with it.

- :data:`ARM`, :data:`STIFFNESS`, :data:`MATERIAL`: a uniform arm (one ``[arm]`` or
  ``[[segment]]`` table) and its ``stiffness`` and ``material`` sub-tables;
- :data:`SECTIONS`: one schema per section ``kind`` (``circle``, ``tube``, ``rectangle``,
  ``general``);
- each load class's ``schema`` (:data:`softarm.loads.LOAD_KINDS`);
- :data:`OBSTACLES` and :data:`CONTACT`: the ``[[obstacle]]`` tables by ``kind`` and the
  ``[contact]`` table, which together make one :class:`softarm.Contact` load;
- :data:`SOLVE` and :data:`SWEEP`: the ``[solve]`` and ``[sweep]`` tables.

The reader checks only what a TOML value is (its type and shape: a string is not a number);
whether a value is allowed is the model's rule, checked once in the model's constructor
(:mod:`softarm.model`, :mod:`softarm.loads`). :meth:`Table.build` calls that constructor and
maps its ValueError/TypeError onto the key path (``case.toml: segment[2].section.radius:
must be ...``).
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

from ._sweep_table import COMPONENTS, Sweep
from ._validate import as_array, format_value
from .contact import OBSTACLE_KINDS, Contact
from .errors import CaseError, CaseTypeError
from .loads import Key, as_loads
from .model import (
    Arm,
    Circle,
    Material,
    Rectangle,
    Rigidities,
    Section,
    SegmentedArm,
    StiffnessMatrix,
    Tube,
)
from .routing import ROUTINGS

__all__ = [
    "ARM",
    "CONTACT",
    "DESIGN",
    "MATERIAL",
    "OBSTACLES",
    "ROUTING",
    "SECTIONS",
    "SIMULATE",
    "SOLVE",
    "STIFFNESS",
    "SWEEP",
    "Field",
    "Schema",
    "Table",
    "arm_to_dict",
    "contact_to_dict",
    "loads_to_dict",
    "solve_to_dict",
    "sweep_to_dict",
]


@dataclass(frozen=True)
class Field(Key):
    """A :class:`~softarm.loads.Key` of a table that is not a load's.

    Adds ``attribute``, the model's name for the value when the file's differs (the material's
    ``E`` is ``Material.youngs_modulus``), and the kinds "text" (a string, one of ``choices``
    if given), "integer" (>= ``minimum`` if given) and "numbers" (a non-empty list of finite
    numbers). ``finite``: a "number" that no model checks, so the reader rejects inf and nan.
    """

    attribute: str = ""
    choices: tuple[str, ...] = ()
    minimum: int | None = None
    finite: bool = False

    def to_case(self, value):
        if value is None:
            return None
        if self.kind == "text":
            return str(value)
        if self.kind == "integer":
            return int(value)
        if self.kind == "numbers":
            return [float(v) for v in value]
        return super().to_case(value)


def _attribute(key: Key) -> str:
    return getattr(key, "attribute", "") or key.name


@dataclass(frozen=True)
class Schema:
    """The keys of one kind of table and the model class they build.

    ``kind`` is the table's ``kind = ...`` value where it has one (sections), else "".
    """

    kind: str
    cls: type
    keys: tuple[Key, ...]

    def read(self, table: Table) -> dict:
        """The values of the keys present, by model attribute (absent ones take the model's
        default); a missing required key is recorded in ``table`` (see :meth:`Table.build`)."""
        return {_attribute(key): table.read(key) for key in self.keys if table.wants(key)}

    def write(self, obj) -> dict:
        """``obj``'s table: its ``kind`` if any, then every key whose value is not None."""
        out = {"kind": self.kind} if self.kind else {}
        for key in self.keys:
            value = key.to_case(getattr(obj, _attribute(key)))
            if value is not None:
                out[key.name] = value
        return out


# --------------------------------------------------------------------------------------------
# One schema per kind
# --------------------------------------------------------------------------------------------

_LENGTH = "m"

#: Section kinds by their ``kind`` value (``[arm.section]``).
SECTIONS: dict[str, Schema] = {
    "circle": Schema("circle", Circle, (Key("radius", "number", _LENGTH, required=True),)),
    "tube": Schema("tube", Tube, (Key("outer_radius", "number", _LENGTH, required=True),
                                  Key("inner_radius", "number", _LENGTH, required=True))),
    "rectangle": Schema("rectangle", Rectangle, (Key("width", "number", _LENGTH, required=True),
                                                 Key("height", "number", _LENGTH,
                                                     required=True))),
    "general": Schema("general", Section, (
        Key("area", "number", "m²", required=True), Key("Iy", "number", "m⁴", required=True),
        Key("Iz", "number", "m⁴", required=True), Key("J", "number", "m⁴", required=True),
        Key("shear_factor_y", "number", "(dimensionless)"),
        Key("shear_factor_z", "number", "(dimensionless)"))),
}
_SECTION_OF = {schema.cls: schema for schema in SECTIONS.values()}

#: ``[arm.material]``: E and exactly one of nu and G (the model says so), density optional.
MATERIAL = Schema("", Material, (
    Field("E", "number", "Pa", required=True, attribute="youngs_modulus"),
    Field("nu", "number", "(dimensionless)", attribute="poisson_ratio"),
    Field("G", "number", "Pa", attribute="shear_modulus"),
    Key("density", "number", "kg/m³")))

#: ``[arm.stiffness]``: the six rigidities, instead of a section and a material.
STIFFNESS = Schema("", Rigidities, (
    Key("EA", "number", "N", required=True), Key("GAy", "number", "N", required=True),
    Key("GAz", "number", "N", required=True), Key("GJ", "number", "N m²", required=True),
    Key("EIy", "number", "N m²", required=True), Key("EIz", "number", "N m²", required=True)))

#: ``[arm]`` or one ``[[segment]]``: its own keys. Its sub-tables, ``stiffness`` or
#: ``section`` and ``material`` (one or the other), are the schemas above; a full 6 × 6
#: stiffness is the key ``stiffness_matrix`` instead.
ARM = Schema("", Arm, (
    Key("length", "number", "m", required=True),
    Key("curvature", "vector", "1/m"),
    Key("mass_per_length", "number", "kg/m"),
    Key("magnetization", "vector", "A m²/m"),
    Key("tip_magnet", "vector", "A m²")))

#: A tendon's or chamber's ``routing`` table, by its ``kind``.
ROUTING: dict[str, Schema] = {
    "straight": Schema("straight", ROUTINGS["straight"], (
        Key("y", "number", _LENGTH), Key("z", "number", _LENGTH))),
    "helix": Schema("helix", ROUTINGS["helix"], (
        Key("radius", "number", _LENGTH, required=True),
        Key("turns_per_metre", "number", "1/m", required=True), Key("phase", "number", "rad"))),
    "polynomial": Schema("polynomial", ROUTINGS["polynomial"], (
        Field("y", "numbers", "m/m^k"), Field("z", "numbers", "m/m^k"))),
}

#: One ``[[obstacle]]`` table by its ``kind`` (:data:`softarm.contact.OBSTACLE_KINDS`; each
#: obstacle's ``to_case`` writes the same keys).
OBSTACLES: dict[str, Schema] = {
    "plane": Schema("plane", OBSTACLE_KINDS["plane"], (
        Key("point", "vector", _LENGTH, required=True),
        Key("normal", "vector", "(dimensionless, any length)", required=True))),
    "sphere": Schema("sphere", OBSTACLE_KINDS["sphere"], (
        Key("center", "vector", _LENGTH, required=True),
        Key("radius", "number", _LENGTH, required=True))),
    "capsule": Schema("capsule", OBSTACLE_KINDS["capsule"], (
        Key("a", "vector", _LENGTH, required=True), Key("b", "vector", _LENGTH, required=True),
        Key("radius", "number", _LENGTH, required=True))),
}

#: ``[contact]``: the contact law of the case's obstacles (:class:`softarm.Contact`'s own keys).
CONTACT = Schema("", Contact, Contact.schema)

#: ``[solve]``: the keys of :class:`softarm.case.SolveOptions` (which checks the values).
SOLVE = (Field("method", "text", choices=("auto", "numeric")),
         Field("stations", "integer"),
         Field("tol", "number", "units of the arm length"),
         Field("branch", "text", choices=("connected", "stable")))

#: ``[inverse]`` (:class:`softarm.case.InverseTask`): the target of ``softarm inverse``.
INVERSE = (Key("target", "vector", "m", required=True),
           Field("tol", "number", "units of the arm length"),
           Field("lower", "numbers"), Field("upper", "numbers"),
           Field("max_iterations", "integer", minimum=1), Field("starts", "integer", minimum=1))

#: ``[simulate]`` (:class:`softarm.case.Simulation`), by name; its sub-tables ``damping``,
#: ``[[simulate.input]]`` and ``base`` are :data:`DAMPING`, :data:`SCHEDULE` and :data:`BASE`.
SIMULATE = {key.name: key for key in (
    Field("duration", "number", "s", required=True), Field("dt", "number", "s", required=True),
    Field("stations", "integer", minimum=3), Field("tol", "number", "units of the arm length"),
    Field("alpha", "number", finite=True),
    Field("initial", "text", choices=("rest", "equilibrium")))}

#: ``[simulate.damping]`` (:class:`softarm.Damping`): ``retardation`` or a 6 × 6 ``matrix``.
DAMPING = (Key("retardation", "number", "s"), Field("matrix", "rows", "N s, N m² s"))

#: One ``[[simulate.input]]`` (:class:`softarm.case.Schedule`): ``load`` counts from 1.
SCHEDULE = (Field("load", "integer", minimum=1, required=True),
            Field("times", "numbers", "s", required=True),
            Field("values", "rows", "the input's unit", required=True))

#: ``[simulate.base]`` (:class:`softarm.case.BaseMotion`).
BASE = (Field("times", "numbers", "s", required=True),
        Field("positions", "rows", "m", required=True), Field("rotations", "rows", "rad"))

#: ``[sweep]`` (:class:`softarm.sweep.Sweep`), by name: ``load`` counts from 1 in the file,
#: from 0 in the model; ``field`` is one of the swept load's vectors; either ``values`` or
#: ``start``, ``stop`` and ``steps``.
SWEEP = {key.name: key for key in (
    Field("load", "integer", minimum=1), Field("field", "text"),
    Field("component", "text", choices=COMPONENTS), Field("name", "text"),
    Field("values", "numbers"), Field("start", "number", finite=True),
    Field("stop", "number", finite=True), Field("steps", "integer", minimum=2))}

#: ``[sweep]`` with a ``design`` (:class:`softarm.sweep.Design`) and its
#: ``[[sweep.parameter]]`` tables (:class:`softarm.sweep.Parameter`), by name.
DESIGN = {key.name: key for key in (
    Field("samples", "integer", minimum=1), Field("seed", "integer", minimum=0),
    Field("path", "text"), Field("values", "numbers"), Field("start", "number", finite=True),
    Field("stop", "number", finite=True), Field("steps", "integer", minimum=2))}


# --------------------------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------------------------


def _arm_table(arm: Arm) -> dict:
    rest = ARM.write(arm)
    out = {"length": rest.pop("length")}  # the file's order: length, the sub-tables, the rest
    if isinstance(arm.section, Rigidities):
        out["stiffness"] = STIFFNESS.write(arm.section)
    elif isinstance(arm.section, StiffnessMatrix):
        out["stiffness_matrix"] = [list(row) for row in arm.section.matrix]
    else:
        out["section"] = _SECTION_OF[type(arm.section)].write(arm.section)
        out["material"] = MATERIAL.write(arm.material)
    return {**out, **rest}


def arm_to_dict(arm: Arm | SegmentedArm) -> dict:
    """The case-file tables describing ``arm``: ``{"arm": {...}}`` or ``{"segment": [...]}``."""
    if isinstance(arm, SegmentedArm):
        return {"segment": [_arm_table(a) for a in arm.segments]}
    return {"arm": _arm_table(arm)}


def loads_to_dict(loads) -> list[dict]:
    """The ``[[load]]`` tables describing ``loads`` (batched vectors become nested lists); a
    :class:`softarm.Contact` is not a ``[[load]]`` table but :func:`contact_to_dict`'s."""
    return [load.to_case() for load in as_loads(loads) if not isinstance(load, Contact)]


def contact_to_dict(loads) -> dict:
    """The ``[[obstacle]]`` tables and the ``[contact]`` table of the :class:`softarm.Contact`
    among ``loads`` (``{}`` without one): ``{"obstacle": [...], "contact": {...}}``, the
    contact table only when it holds a value."""
    contacts = [load for load in as_loads(loads) if isinstance(load, Contact)]
    if not contacts:
        return {}
    if len(contacts) > 1:
        raise ValueError(f"loads must hold at most one softarm.Contact (it takes every "
                         f"obstacle), got {len(contacts)}")
    contact = contacts[0]
    if np.ndim(contact.stiffness):  # the solver's per case: solved again, it chooses them
        contact = contact.replace(stiffness=None)
    out = {"obstacle": [obstacle.to_case() for obstacle in contact.obstacles]}
    law = CONTACT.write(contact)
    for key, default in (("friction", 0.0), ("slip_velocity", Contact.slip_velocity)):
        if law.get(key) == default:
            del law[key]  # the default
    if law:
        out["contact"] = law
    return out


def solve_to_dict(options) -> dict:
    """The ``[solve]`` table of a :class:`softarm.case.SolveOptions`."""
    return Schema("", type(options), SOLVE).write(options)


def sweep_to_dict(sweep: Sweep) -> dict:
    """The ``[sweep]`` table of a :class:`softarm.sweep.Sweep` (``load`` counted from 1, the
    values listed)."""
    keys = ("load", "field", "component", "values") + (("name",) if sweep.name else ())
    out = Schema("", Sweep, tuple(SWEEP[k] for k in keys)).write(sweep)
    out["load"] += 1
    return out


# --------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------


class Table:
    """A TOML table being read: typed getters that record the key path, then :meth:`done`
    rejects the keys nobody asked for.

    ``batched`` (result files only): vectors may carry batch axes.
    """

    def __init__(self, data, path: str, where: str, *, batched: bool = False):
        if not isinstance(data, dict):
            raise CaseError(f"{where}: {path or 'file'}: must be a table, got {format_value(data)}")
        self.data = data
        self.path = path
        self.where = where
        self.batched = batched
        self.used: set[str] = set()
        self.absent: list[tuple[str, str]] = []  # (key, what): missing, reported by build()

    def key(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def error(self, key: str | None, what: str, kind: type = CaseError) -> CaseError:
        return kind(f"{self.where}: {self.key(key) if key else self.path}: {what}")

    def type_error(self, key: str | None, what: str) -> CaseError:
        return self.error(key, what, CaseTypeError)

    def missing(self, key: str, what: str) -> CaseError:
        """'missing', or 'unknown key' when a present key looks like a misspelling of it."""
        return self._misspelled(key) or self.error(key, f"missing ({what})")

    def _misspelled(self, key: str) -> CaseError | None:
        close = difflib.get_close_matches(key, [k for k in self.data if k not in self.used],
                                          n=1, cutoff=0.6)
        return self.error(close[0], f"unknown key; did you mean {key!r}?") if close else None

    def has(self, key: str) -> bool:
        return key in self.data

    def raw(self, key: str, default=None):
        self.used.add(key)
        return self.data.get(key, default)

    # --- one key of a schema ----------------------------------------------------------------

    def wants(self, key: Key) -> bool:
        """Whether ``key`` is in the table; a required key that is not is recorded."""
        if key.name in self.data:
            return True
        if key.required:
            self.lacks(key.name, f"a {key.kind}{_in(key.unit)}")
        return False

    def lacks(self, key: str, what: str) -> None:
        """Record that the required ``key`` (``what``: what it should hold) is missing:
        :meth:`build` reports it unless the model finds a fault in a key before it."""
        self.absent.append((key, what))

    def read(self, key: Key):
        """The value of ``key`` (present in the table), checked for its TOML type only."""
        kind = key.kind
        if kind == "vector":
            return self.vector(key.name, key.unit)
        if kind == "number":
            return self.number(key.name, key.unit, finite=getattr(key, "finite", False))
        if kind == "flag":
            return self.boolean(key.name, default=False)
        if kind in ("index", "integer"):
            return self.integer(key.name, minimum=0 if kind == "index" else key.minimum)
        if kind == "text":
            return self.string(key.name, key.choices or None)
        if kind == "numbers":
            return self.numbers(key.name)
        if kind == "magnitude":  # a number, or (result files) a nested list of them
            if not self.batched:
                return self.number(key.name, key.unit)
            return self.array(key.name, key.unit, ())
        if kind == "matrix":
            return self.array(key.name, key.unit, (3, 3))
        if kind == "routing":
            table = self.table(key.name)
            schema = ROUTING[table.string("kind", tuple(ROUTING))]
            values = schema.read(table)
            return table.build(schema.keys, lambda: schema.cls(**values))
        if kind == "rows":  # a list of numbers or of lists of numbers: the model checks shapes
            raw = self.raw(key.name)
            if not (isinstance(raw, list) and raw and not _has_bool(raw) and all(
                    isinstance(v, Real) or (isinstance(v, list) and v and all(
                        isinstance(x, Real) for x in v)) for v in raw)):
                raise self.type_error(key.name, f"must be a list of numbers or of lists of "
                                      f"numbers{_in(key.unit)}, got {format_value(raw)}")
            return raw
        if kind == "span":  # two numbers in m
            raw = self.raw(key.name)
            if not (isinstance(raw, list) and len(raw) == 2 and not _has_bool(raw)
                    and all(isinstance(v, Real) for v in raw)):
                raise self.error(key.name, "must be [s0, s1], two numbers in m, got "
                                 f"{format_value(raw)}")
            return tuple(float(v) for v in raw)
        raise AssertionError(f"no reader for keys of kind {kind!r}")  # pragma: no cover

    def build(self, keys: tuple[Key, ...], make: Callable):
        """``make()``, the model's constructor, once every key is read: its ValueError or
        TypeError becomes a :class:`CaseError` naming the key path of the value at fault.

        A required key absent from the file is reported as missing, unless the model finds
        a fault in a key that is present first (the model checks in the file's order).
        """
        for key, _ in self.absent:  # a misspelled key first, then any other unknown key
            error = self._misspelled(key)
            if error is not None:
                raise error
        self.done()
        try:
            made = make()
        except (TypeError, ValueError) as error:
            key, what = _model_message(str(error), keys)
            if self.absent and (key is None or key not in self.data):
                raise self._absent() from None
            kind = CaseTypeError if isinstance(error, TypeError) else CaseError
            if key is not None and key not in self.data:
                key, what = None, f"{key} {what}"
            raise self.error(key, what, kind) from None
        if self.absent:  # the model took its default, but the file must give the key
            raise self._absent()
        return made

    def _absent(self) -> CaseError:
        key, what = self.absent[0]
        self.absent = []
        return self.missing(key, what)

    # --- typed getters ------------------------------------------------------------------------

    def number(self, key: str, unit: str, *, required: bool = True, default=None,
               finite: bool = False):
        """A number (int or float, not a bool) in ``unit``. Its range is the model's rule;
        ``finite``: reject inf and nan here, for values no model checks."""
        if key not in self.data:
            if required:
                raise self.missing(key, f"a number{_in(unit)}")
            self.used.add(key)
            return default
        value = self.raw(key)
        if isinstance(value, bool) or not isinstance(value, Real):
            raise self.type_error(key, f"must be a number{_in(unit)}, got "
                                  f"{format_value(value)}")
        if finite and not math.isfinite(value):
            raise self.error(key, f"must be finite, got {format_value(value)}")
        return float(value)

    def integer(self, key: str, *, default=None, minimum: int | None = 0) -> int:
        if key not in self.data:
            if default is None:
                raise self.missing(key, "an integer")
            self.used.add(key)
            return default
        value = self.raw(key)
        if isinstance(value, bool) or not isinstance(value, Integral):
            raise self.type_error(key, f"must be an integer, got {format_value(value)}")
        if minimum is not None and value < minimum:
            raise self.error(key, f"must be >= {minimum}, got {format_value(value)}")
        return int(value)

    def string(self, key: str, choices=None, *, default=None) -> str:
        if key not in self.data:
            if default is None:
                raise self.missing(key, f"one of {_quoted(choices)}" if choices else "a string")
            self.used.add(key)
            return default
        value = self.raw(key)
        if not isinstance(value, str):
            raise self.type_error(key, f"must be a string, got {format_value(value)}")
        if choices is not None and value not in choices:
            raise self.error(key, f"unknown value {format_value(value)}; expected one of "
                             f"{_quoted(choices)}{suggest(value, choices)}")
        return value

    def boolean(self, key: str, *, default: bool) -> bool:
        value = self.raw(key, default)
        if not isinstance(value, bool):
            raise self.type_error(key, f"must be true or false, got {format_value(value)}")
        return value

    def vector(self, key: str, unit: str, *, default=(0.0, 0.0, 0.0)) -> np.ndarray:
        value = self.raw(key, default)
        what = f"must be a list of 3 finite numbers{_in(unit)}, got {format_value(value)}"
        try:
            array = as_array(value, key)  # strict: no strings, bools or complex numbers
        except TypeError as error:
            raise self.type_error(key, f"{what} ({str(error).split(', got ')[-1]})") from None
        except ValueError:
            raise self.error(key, what) from None
        if not (array.ndim >= 1 and array.shape[-1] == 3 and (self.batched or array.ndim == 1)):
            raise self.error(key, what)
        return array

    def array(self, key: str, unit: str, shape: tuple[int, ...]) -> np.ndarray:
        """Finite numbers of trailing shape ``shape`` (batch axes only in result files)."""
        value = self.raw(key)
        what = (f"must be {'a number' if not shape else f'a {shape[0]} × {shape[1]} list'} "
                f"of finite numbers{_in(unit)}, got {format_value(value)}")
        try:
            array = as_array(value, key)
        except TypeError:
            raise self.type_error(key, what) from None
        except ValueError:
            raise self.error(key, what) from None
        n = len(shape)
        if array.shape[array.ndim - n:] != shape or (not self.batched and array.ndim != n):
            raise self.error(key, what)
        return array

    def numbers(self, key: str) -> tuple[float, ...]:
        """A non-empty list of finite numbers."""
        raw = self.raw(key)
        if (not isinstance(raw, list) or not raw or _has_bool(raw)
                or not all(isinstance(v, Real) and math.isfinite(v) for v in raw)):
            wrong_type = isinstance(raw, list) and raw and not all(
                isinstance(v, Real) and not isinstance(v, bool) for v in raw)
            raise self.error(key, "must be a non-empty list of finite numbers, got "
                             f"{format_value(raw)}",
                             CaseTypeError if wrong_type else CaseError)
        return tuple(float(v) for v in raw)

    def table(self, key: str) -> Table:
        return Table(self.raw(key), self.key(key), self.where, batched=self.batched)

    def tables(self, key: str) -> list[Table]:
        value = self.raw(key, [])
        if isinstance(value, dict):
            value = [value]
        if not isinstance(value, list):
            raise self.error(key, f"must be an array of tables ([[{key}]]), got "
                             f"{format_value(value)}")
        return [Table(item, f"{self.key(key)}[{i + 1}]", self.where, batched=self.batched)
                for i, item in enumerate(value)]

    def done(self) -> None:
        unknown = [k for k in self.data if k not in self.used]
        if unknown:
            key = unknown[0]
            known = sorted(self.used)
            raise self.error(key, "unknown key" + suggest(key, known)
                             + (f" (known keys here: {', '.join(known)})" if known else ""))


_MODEL_MESSAGE = re.compile(r"([A-Z]\w*)(?:\.(\w+))?:?\s+(.*)", re.S)


def _model_message(text: str, keys: tuple[Key, ...]) -> tuple[str | None, str]:
    """A model's message "Tube.inner_radius must be ..." as (file key, "must be ...").

    The model's names become the file's: ``Cls.attribute`` anywhere in the message becomes the
    key's name, and so does a bare attribute renamed in the file (``poisson_ratio`` -> ``nu``).
    The key is None when the message names no attribute ("Gravity needs the arm's mass").
    """
    match = _MODEL_MESSAGE.fullmatch(text)
    if match is None:
        return None, text
    cls, attribute, what = match.groups()
    names = {_attribute(k): k.name for k in keys}
    what = re.sub(rf"\b{cls}\.(\w+)", lambda m: names.get(m[1], m[1]), what)
    renamed = [a for a, name in names.items() if a != name]
    if renamed:
        what = re.sub(r"\b(" + "|".join(renamed) + r")\b", lambda m: names[m[1]], what)
    if attribute is None:
        return None, what
    return names.get(attribute, attribute), what


def _has_bool(value) -> bool:
    if isinstance(value, bool):
        return True
    if isinstance(value, (list, tuple)):
        return any(_has_bool(v) for v in value)
    return False


def _in(unit: str) -> str:
    """" in N" for a unit, "" for a dimensionless key (never "a number in , got")."""
    return f" in {unit}" if unit else ""


def _quoted(choices) -> str:
    return ", ".join(repr(c) for c in choices)


def suggest(value: str, choices) -> str:
    """"; did you mean 'x'?" for the closest of ``choices``, or ""."""
    close = difflib.get_close_matches(str(value), list(choices), n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""
