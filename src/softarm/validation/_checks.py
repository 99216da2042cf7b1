"""Checks, case results and the reference tables shipped with the package."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

__all__ = [
    "GATED",
    "STATUSES",
    "TABLES",
    "CaseResult",
    "Check",
    "DataTables",
    "find_data_dir",
    "finding",
    "gate",
    "reference_table",
    "skipped",
]

#: The four outcomes of a check. Only "fail" makes ``softarm reproduce`` exit with 1.
STATUSES = ("pass", "fail", "finding", "skipped")
GATED = ("pass", "fail")

#: The reference tables shipped in ``softarm/validation/data`` (each with its provenance).
TABLES = ("mattiasson_cantilever.json", "princeton_beam.json", "rod_benchmarks.json",
          "actuation_benchmarks.json", "buckling.json")


@dataclass(frozen=True)
class Check:
    """One scalar comparison of softarm against a reference.

    Attributes
    ----------
    case : str
        Case identifier, e.g. ``"mattiasson_cantilever"``.
    item : str
        The load or station within the case, e.g. ``"k = 1"``.
    method : str
        The softarm route that produced ``value``, e.g. ``"solve(method='numeric')"``.
    quantity : str
        What is compared, with its unit or normalisation, e.g. ``"w/L"``.
    reference : float
        The reference value (NaN when skipped).
    value : float
        softarm's value (NaN when skipped or when softarm raised).
    error_kind : str
        ``"abs"``: |value - reference|, in the unit of ``quantity``; ``"rel"``:
        |value - reference| / |reference|; ``"angle"``: the wrapped angle difference in rad.
    tolerance : float or None
        Largest accepted error for a gated check, None for findings and skipped checks.
    source : str
        Where the reference comes from (paper and equation, or file and key).
    status : str
        ``"pass"``, ``"fail"`` (gated), ``"finding"`` (an approximation against the exact
        answer, reported and never gated) or ``"skipped"``.
    note : str
        Why a check was skipped or failed, or anything a reader must know.
    """

    case: str
    item: str
    method: str
    quantity: str
    reference: float
    value: float
    error_kind: str
    tolerance: float | None
    source: str
    status: str
    note: str = ""

    def __post_init__(self):
        if self.status not in STATUSES:
            raise ValueError(f"Check.status must be one of {STATUSES}, got {self.status!r}")
        if self.error_kind not in ("abs", "rel", "angle"):
            raise ValueError(f"Check.error_kind must be 'abs', 'rel' or 'angle', got "
                             f"{self.error_kind!r}")

    @property
    def error(self) -> float:
        """The error of ``value`` against ``reference`` as defined by ``error_kind``."""
        return _error(self.reference, self.value, self.error_kind)

    @property
    def gated(self) -> bool:
        return self.status in GATED


def _error(reference: float, value: float, kind: str) -> float:
    difference = value - reference
    if kind == "angle":
        return abs(math.remainder(difference, 2 * math.pi))
    if kind == "rel":
        return abs(difference) / abs(reference) if reference != 0 else math.inf
    return abs(difference)


def _on_branch(reference: float, value: float, kind: str) -> float:
    """An angle moved by a multiple of 2π to the reference's branch (other kinds unchanged)."""
    if kind != "angle" or not (math.isfinite(reference) and math.isfinite(value)):
        return value
    return reference + math.remainder(value - reference, 2 * math.pi)


def gate(case, item, method, quantity, reference, value, tolerance, source, *,
         error_kind="abs", note="") -> Check:
    """A gated check: "pass" if the error is finite and <= ``tolerance``, else "fail"."""
    reference = float(reference)
    value = _on_branch(reference, float(value), error_kind)
    error = _error(reference, value, error_kind)
    status = "pass" if math.isfinite(error) and error <= tolerance else "fail"
    return Check(case, item, method, quantity, reference, value, error_kind, float(tolerance),
                 source, status, note)


def finding(case, item, method, quantity, reference, value, source, *, error_kind="rel",
            note="") -> Check:
    """An approximation compared with the exact answer: reported, never gated."""
    reference = float(reference)
    value = _on_branch(reference, float(value), error_kind)
    return Check(case, item, method, quantity, reference, value, error_kind, None, source,
                 "finding", note)


def skipped(case, item, method, quantity, source, note, *, error_kind="abs") -> Check:
    """A check that could not run (e.g. its reference table is missing)."""
    return Check(case, item, method, quantity, math.nan, math.nan, error_kind, None, source,
                 "skipped", note)


@dataclass
class CaseResult:
    """What one validation case produced.

    Attributes
    ----------
    checks : list of Check
    figures : dict
        File stem -> callable drawing a :class:`matplotlib.figure.Figure` (called only when
        outputs are written, so the checks never need matplotlib).
    tables : dict
        File stem -> (header, rows) written as CSV beside the check table.
    markdown : list of str
        Extra Markdown paragraphs for the report's section on this case.
    """

    checks: list[Check] = field(default_factory=list)
    figures: dict[str, Callable[[], object]] = field(default_factory=dict)
    tables: dict[str, tuple[Sequence[str], list[Sequence]]] = field(default_factory=dict)
    markdown: list[str] = field(default_factory=list)


def find_data_dir() -> Any:
    """The folder of reference tables shipped inside the package (``softarm/validation/data``).

    Read with :mod:`importlib.resources`, so it works from a wheel, a zip or a checkout alike;
    its ``README.md`` says where each table comes from.
    """
    return resources.files("softarm.validation") / "data"


def reference_table(name: str) -> dict:
    """One of the packaged reference tables (:data:`TABLES`), parsed.

    Examples
    --------
    >>> reference_table("mattiasson_cantilever.json")["title"][:27]
    'Large-deflection cantilever'
    """
    if name not in TABLES:
        raise ValueError(f"name must be one of {TABLES}, got {name!r}")
    return json.loads((find_data_dir() / name).read_text(encoding="utf-8"))


class DataTables:
    """Reference tables (JSON) from a folder, loaded lazily; None where missing.

    ``directory`` is a path, a :mod:`importlib.resources` folder (the packaged tables, the
    default of :func:`softarm.validation.run`) or None (no tables: every table-based check is
    skipped).
    """

    def __init__(self, directory):
        if isinstance(directory, (str, os.PathLike)):
            directory = Path(directory)
        self.directory = directory
        self._cache: dict[str, dict | None] = {}

    def get(self, name: str) -> dict | None:
        """The parsed JSON file ``name``, or None if the folder or the file is missing."""
        if name not in self._cache:
            path = None if self.directory is None else self.directory / name
            self._cache[name] = (json.loads(path.read_text(encoding="utf-8"))
                                 if path is not None and path.is_file() else None)
        return self._cache[name]

    def missing_reason(self, name: str) -> str:
        if self.directory is None:
            return "run without reference tables (data_dir=None)"
        return f"reference table {name} not found in {self.directory}"
