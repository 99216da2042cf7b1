"""Key paths: one number of a case file named by where it lives (docs/case-files.md).

A *key path* names one number of a case file, counted as the file counts its tables
(from 1): ``load[2].force.magnitude``, ``load[1].moment.y``, ``load[3].tension``,
``arm.length``, ``arm.section.radius``, ``segment[2].material.E``, ``arm.curvature.z``.
Load paths are resolved against the load class's own ``schema`` (:data:`softarm.loads.
LOAD_KINDS`), arm paths against the case-file schema of the arm's tables
(:mod:`softarm._schema`): a new load kind or section kind is addressable without code here.
:func:`resolve` finds where a path's number lives (the case reader checks the paths of a
``[sweep]`` design with it), :func:`set_value` writes a number there (a sweep's cases).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _schema
from ._sweep_table import KEY_PATH, set_vector
from .loads import LOAD_KINDS

__all__ = ["VECTOR_COMPONENTS", "Target", "resolve", "set_value"]

#: Components of a vector named in a key path.
VECTOR_COMPONENTS = ("x", "y", "z", "magnitude")  # (COMPONENTS, in the order of a message)


@dataclass(frozen=True)
class Target:
    """A resolved key path: where its number lives in the case file's tables.

    ``table``: the keys from the file's top level to the table holding the number (e.g.
    ``("segment", 1, "section")``, list indices from 0); ``key`` the number's key;
    ``component`` one of x, y, z, magnitude for a vector, else None; ``unit``; ``load`` the
    load index (from 0) for a load field, else None; ``batched``: the load class takes this
    field with a leading batch axis (set by :class:`softarm.sweep._design.Plan`).
    """

    path: str
    table: tuple
    key: str
    component: str | None
    unit: str
    load: int | None = None
    batched: bool = False


def _choose(path: str, what: str, name: str, choices) -> None:
    if name not in choices:
        raise ValueError(f"{path}: unknown {what} {name!r}{_schema.suggest(name, choices)}; "
                         f"expected one of {', '.join(choices) if choices else '(none)'}")


def _number_or_vector(path: str, keys, rest: list[str], table: tuple, load=None) -> Target:
    """The target of ``rest`` = [key] or [key, component] among ``keys`` (schema rows)."""
    sweepable = {k.name: k for k in keys if k.kind in ("number", "magnitude", "vector")}
    _choose(path, "key", rest[0], tuple(sweepable))
    key = sweepable[rest[0]]
    if key.kind == "vector":
        if len(rest) != 2:
            raise ValueError(f"{path}: {key.name} is a vector; name a component: "
                             f"{', '.join(f'{key.name}.{c}' for c in VECTOR_COMPONENTS)}")
        _choose(path, "component", rest[1], VECTOR_COMPONENTS)
        return Target(path, table, key.name, rest[1], key.unit, load)
    if len(rest) != 1:
        raise ValueError(f"{path}: {key.name} is a number; nothing follows it")
    return Target(path, table, key.name, None, key.unit, load)


def resolve(data: dict, path: str) -> Target:
    """The :class:`Target` of key path ``path`` in the validated case-file dict ``data``.

    Raises
    ------
    ValueError
        Naming the path and what is wrong (unknown table, index out of range, unknown key,
        a vector without a component, a key that is not a number).
    """
    match = KEY_PATH.fullmatch(path)
    if match is None:
        raise ValueError(f"{path}: not a key path (expected e.g. 'load[1].force.magnitude', "
                         "'arm.length' or 'segment[2].section.radius')")
    head, number, arm_head, rest = match.groups()
    rest = rest.split(".")
    if head == "load":
        loads = data.get("load", [])
        loads = [loads] if isinstance(loads, dict) else loads
        index = int(number)
        if not 1 <= index <= len(loads):
            raise ValueError(f"{path}: there are {len(loads)} [[load]] tables, got load[{index}]"
                             " (counted from 1)")
        cls = LOAD_KINDS[loads[index - 1]["kind"]]
        return _number_or_vector(path, cls.schema, rest, ("load", index - 1), index - 1)
    if arm_head:
        if "arm" not in data:
            raise ValueError(f"{path}: this case has [[segment]] tables, not [arm]; use "
                             "segment[1]., segment[2]., ...")
        table, where = data["arm"], ("arm",)
    else:
        segments = data.get("segment")
        if segments is None:
            raise ValueError(f"{path}: this case has an [arm] table, not [[segment]]; use "
                             "arm.")
        segments = [segments] if isinstance(segments, dict) else segments
        index = int(number)
        if not 1 <= index <= len(segments):
            raise ValueError(f"{path}: there are {len(segments)} [[segment]] tables, got "
                             f"segment[{index}] (counted from 1)")
        table, where = segments[index - 1], ("segment", index - 1)
    # an arm given by a full stiffness_matrix has no table of numbers to sweep by name
    subtables = ("section", "material") if "section" in table else (
        ("stiffness",) if "stiffness" in table else ())
    if rest[0] in ("section", "material", "stiffness"):
        if rest[0] not in subtables:
            given = " and ".join(subtables) or "stiffness_matrix"
            raise ValueError(f"{path}: this arm is given by its {given}, not {rest[0]}")
        if len(rest) < 2:
            raise ValueError(f"{path}: name a key of the {rest[0]} table")
        if rest[0] == "section":
            schema = _schema.SECTIONS[table["section"]["kind"]]
        else:
            schema = _schema.MATERIAL if rest[0] == "material" else _schema.STIFFNESS
        return _number_or_vector(path, schema.keys, rest[1:], (*where, rest[0]))
    choices = (*(k.name for k in _schema.ARM.keys), *subtables)
    if rest[0] not in [k.name for k in _schema.ARM.keys]:
        _choose(path, "key", rest[0], choices)
    return _number_or_vector(path, _schema.ARM.keys, rest, where)


def _table_of(data: dict, table: tuple) -> dict:
    node = data
    for key in table:
        if not (isinstance(key, int) and isinstance(node, dict)):  # a lone [segment] table
            try:
                node = node[key]
            except (KeyError, IndexError, TypeError):
                raise ValueError(f"the case has no table {'.'.join(map(str, table))}"
                                 ) from None
    return node


def set_value(data: dict, target: Target, value: float) -> None:
    """Write ``value`` at ``target`` into the case-file dict ``data`` (in place)."""
    table = _table_of(data, target.table)
    if target.component is None:
        table[target.key] = float(value)
    else:
        current = np.asarray(table.get(target.key, (0.0, 0.0, 0.0)), dtype=np.float64)
        table[target.key] = set_vector(current, target.component, np.float64(value),
                                        target.path).tolist()
