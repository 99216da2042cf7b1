"""Running the cases, and writing the CSV tables, the figures and the Markdown report."""

from __future__ import annotations

import csv
import math
import sys
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TextIO

from ._checks import CaseResult, Check, DataTables, find_data_dir
from .cases import CASES, ValidationCase

__all__ = ["COMMAND", "Report", "run", "write_outputs"]

#: The command that regenerates the committed report (named at the top of docs/validation.md).
COMMAND = "softarm reproduce --out docs"

_CHECK_FIELDS = ("case", "item", "method", "quantity", "reference", "value", "error",
                 "error_kind", "tolerance", "status", "source", "note")

_AUTO = object()


@dataclass
class Report:
    """The outcome of a validation run.

    Attributes
    ----------
    cases : list of (ValidationCase, CaseResult, seconds)
    data_dir : Path, importlib.resources folder or None
        The reference-table folder used (None: run without tables).
    seconds : float
        Wall time of the whole run (the case computations, not the output writing).
    """

    cases: list[tuple[ValidationCase, CaseResult, float]] = field(default_factory=list)
    data_dir: object = None
    seconds: float = 0.0

    @property
    def checks(self) -> list[Check]:
        return [check for _, result, _ in self.cases for check in result.checks]

    def count(self, status: str) -> int:
        return sum(check.status == status for check in self.checks)

    @property
    def failed(self) -> bool:
        return self.count("fail") > 0

    @property
    def exit_code(self) -> int:
        """1 if any gated check failed, else 0 (findings and skipped checks never fail)."""
        return 1 if self.failed else 0

    def strict_exit_code(self) -> int:
        """1 if any gated check failed or any check was skipped, else 0 (``--strict``)."""
        return 1 if self.failed or self.count("skipped") else 0

    def summary(self) -> str:
        counts = ", ".join(f"{self.count(s)} {s}" for s in ("pass", "fail", "finding", "skipped"))
        return f"{len(self.checks)} checks: {counts}"


def _where(directory) -> str:
    """A short name for a reference-table folder: the packaged one, or its last two parts."""
    if str(directory) == str(find_data_dir()):
        return "softarm/validation/data"
    return "/".join(Path(str(directory)).parts[-2:])


def _progress(stream: TextIO | None, done: int, total: int, text: str) -> None:
    if stream is None:
        return
    width = 24
    filled = round(width * done / total) if total else width
    stream.write(f"reproduce [{'#' * filled}{'.' * (width - filled)}] {done}/{total} {text}\n")
    stream.flush()


def run(cases: Sequence[str] | None = None, *, data_dir=_AUTO,
        progress: TextIO | str | None = "stderr") -> Report:
    """Run validation cases and collect their checks.

    Parameters
    ----------
    cases : sequence of str, optional
        Case names (see :data:`softarm.validation.CASES`); all of them by default.
    data_dir : path or None, optional
        Folder with the reference tables; by default the tables shipped in the package
        (:func:`find_data_dir`). None runs without tables: their checks are skipped (and
        reported as such).
    progress : text stream, "stderr" or None
        Where the plain-text progress bar goes (``sys.stderr`` at call time by default; None
        for silence).
    """
    progress = sys.stderr if isinstance(progress, str) else progress
    by_name = {case.name: case for case in CASES}
    if cases is None:
        selected = list(CASES)
    else:
        unknown = [name for name in cases if name not in by_name]
        if unknown:
            raise ValueError(f"cases must be among {sorted(by_name)}, got unknown {unknown}")
        selected = [by_name[name] for name in cases]
    directory = find_data_dir() if data_dir is _AUTO else data_dir
    tables = DataTables(directory)
    report = Report(data_dir=tables.directory)
    if progress is not None:
        where = _where(tables.directory) if tables.directory is not None else "none (skipping)"
        # (a kernel's first compile on this machine says so itself, with its time: _jit)
        progress.write(f"reproduce: {len(selected)} cases; reference tables: {where}\n")
    start = time.perf_counter()
    for i, case in enumerate(selected):
        _progress(progress, i, len(selected), f"{case.name} ...")
        t0 = time.perf_counter()
        result = case.run(tables)
        seconds = time.perf_counter() - t0
        report.cases.append((case, result, seconds))
        fails = sum(c.status == "fail" for c in result.checks)
        _progress(progress, i + 1, len(selected),
                  f"{case.name}: {len(result.checks)} checks, {fails} failed ({seconds:.1f} s)")
    report.seconds = time.perf_counter() - start
    return report


# ------------------------------------------------------------------------------------------
# Outputs
# ------------------------------------------------------------------------------------------
def _number(x) -> str:
    if x is None:
        return ""
    return "nan" if isinstance(x, float) and math.isnan(x) else repr(float(x))


def write_csv(report: Report, directory: Path) -> list[Path]:
    """checks.csv (every check) and the tables the cases produced, in ``directory``."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = [directory / "checks.csv"]
    with paths[0].open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(_CHECK_FIELDS)
        for c in report.checks:
            writer.writerow([c.case, c.item, c.method, c.quantity, _number(c.reference),
                             _number(c.value), _number(c.error), c.error_kind,
                             _number(c.tolerance), c.status, c.source, c.note])
    for _, result, _ in report.cases:
        for stem, (header, rows) in result.tables.items():
            path = directory / f"{stem}.csv"
            with path.open("w", newline="", encoding="utf-8") as handle:
                writer = csv.writer(handle)
                writer.writerow(header)
                writer.writerows([[_number(v) if isinstance(v, float) else v for v in row]
                                  for row in rows])
            paths.append(path)
    return paths


def write_figures(report: Report, directory: Path, dpi: int = 100) -> list[Path]:
    """Every figure the cases produced, as PNG in ``directory`` (needs matplotlib)."""
    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for _, result, _ in report.cases:
        for stem, draw in result.figures.items():
            path = directory / f"{stem}.png"
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # e.g. layout engine notices
                draw().savefig(path, dpi=dpi, bbox_inches="tight", metadata={"Software": None})
            paths.append(path)
    return paths


def _cell(x: float, kind: str = "") -> str:
    if x is None:
        return "—"
    if math.isnan(x):
        return "—"
    if kind == "error":
        return "0" if x == 0 else f"{x:.1e}"
    return f"{x:.8g}"


def _escape(text: str) -> str:
    """Text safe inside a Markdown table cell."""
    return text.replace("|", "\\|").replace("\n", " ")


_MARK = {"pass": "pass", "fail": "**FAIL**", "finding": "finding", "skipped": "skipped"}


def _group(checks: list[Check]):
    """Checks grouped by (item, method, gated), in order: one Markdown row per group."""
    groups: dict[tuple[str, str, bool], list[Check]] = {}
    for check in checks:
        groups.setdefault((check.item, check.method, check.gated), []).append(check)
    return groups


def _status_of(checks: list[Check]) -> str:
    statuses = {c.status for c in checks}
    for status in ("fail", "skipped", "finding", "pass"):
        if status in statuses:
            return status
    return "pass"


def _worst(checks: list[Check]) -> str:
    gated = [c for c in checks if c.gated]
    if not gated:
        return "—"
    worst = max(gated, key=lambda c: c.error / c.tolerance if c.tolerance else math.inf)
    return f"{_cell(worst.error, 'error')} / {worst.tolerance:.2g}"


def _findings_summary(report: Report) -> list[str]:
    """One line per (case, approximation, item family): its largest error against exact."""
    worst: dict[tuple[str, str, str], Check] = {}
    for check in report.checks:
        if check.status != "finding" or math.isnan(check.error):
            continue
        family = check.item.split(":")[0] if ":" in check.item else ""
        key = (check.case, check.method, family)
        if key not in worst or check.error > worst[key].error:
            worst[key] = check
    if not worst:
        return []
    lines = ["", "Findings (approximations against the exact solution, largest error):", ""]
    for (case, method, family), c in worst.items():
        size = f"{100 * c.error:.3g} %" if c.error_kind == "rel" else f"{c.error:.3g}"
        where = f"{family} pair, " if family else ""
        lines.append(f"- `{method}` ({where}[{case}](#{case.replace('_', '-')})): {size} "
                     f"({c.error_kind}) in {_escape(c.quantity)}, {_escape(c.item)}")
    return lines


def markdown(report: Report, figures: dict[str, str] | None = None) -> str:
    """The report as Markdown; ``figures`` maps a figure stem to its relative link."""
    figures = figures or {}
    lines = [
        "# Validation",
        "",
        f"*Generated by `{COMMAND}`; do not edit by hand. The same command with another "
        "`--out DIR` writes this report, its figures and its CSV tables to DIR.*",
        "",
        "softarm against the closed forms of Grazioso, Di Gironimo & Siciliano (RoboSoft 2018, "
        "\"the paper\"), against the classic large-deflection rod benchmarks and against the "
        "reference tables shipped with softarm in `softarm/validation/data` (each row names "
        "its source, and says when a reference was *computed* rather than published; the "
        "folder's README.md gives each table's provenance).",
        "",
        "- **pass / fail**: an exact route of softarm (a closed form where it is exact, or the "
        "numerical solver, `solve(method='numeric')`) against a reference, gated by a "
        "tolerance. Any failure makes the command exit with status 1.",
        "- **finding**: an *approximation* (the paper's small-displacement shear solution, or "
        "its constant-strain formula off a principal axis) against the exact answer. Reported, "
        "never gated: a large error there is a property of the approximation.",
        "- **skipped**: the reference table was not found (the command still runs every case "
        "whose reference is a closed form; `softarm reproduce --strict` exits with status 1 "
        "on a skipped check too).",
        "",
        "Errors: `abs` = |softarm − reference| in the unit of the quantity (lengths divided by L "
        "where the quantity says /L); `angle` = the same for angles, compared modulo 2π (softarm's "
        "angle is shown on the reference's branch); `rel` = |softarm − reference| / |reference|. "
        "Numerical solves use `tol = 1e-10` (tip position error estimate / L).",
        "",
        f"**Summary: {report.summary()}.** Every check, with full precision, is in "
        "[tables/checks.csv](tables/checks.csv).",
        "",
        "| case | checks | pass | fail | finding | skipped | worst gated error / tolerance |",
        "|---|---|---|---|---|---|---|",
    ]
    for case, result, _ in report.cases:
        c = result.checks
        n = {s: sum(x.status == s for x in c) for s in ("pass", "fail", "finding", "skipped")}
        lines.append(f"| [{case.title}](#{case.name.replace('_', '-')}) | {len(c)} | "
                     f"{n['pass']} | {n['fail']} | {n['finding']} | {n['skipped']} | "
                     f"{_worst(c)} |")
    lines += _findings_summary(report)
    if report.data_dir is None or not report.data_dir.is_dir():
        missing = "(none)" if report.data_dir is None else _where(report.data_dir)
        lines += ["", f"Reference folder `{missing}` not found: table-based checks skipped "
                  "(see each case)."]
    else:
        lines += ["", f"Reference tables read from `{_where(report.data_dir)}` (the package's "
                  "own by default; `--data DIR` for another folder)."]
    for case, result, _ in report.cases:
        lines += ["", f"<a id=\"{case.name.replace('_', '-')}\"></a>", "",
                  f"## {case.title}", "", case.description, ""]
        for stem in result.figures:
            if stem in figures:
                lines += [f"![{stem}]({figures[stem]})", ""]
        for paragraph in result.markdown:
            lines += [paragraph, ""]
        sources = list(dict.fromkeys(c.source for c in result.checks))
        lines += ["Sources: " + "; ".join(f"[{i + 1}] {_escape(s)}"
                                          for i, s in enumerate(sources)), ""]
        lines += ["| load / item | softarm route | quantity: reference → softarm | error | "
                  "tolerance | result | source |", "|---|---|---|---|---|---|---|"]
        for (item, method, _), group in _group(result.checks).items():
            parts = []
            for c in group:
                if c.status == "skipped":
                    parts.append(_escape(c.quantity))
                else:
                    parts.append(f"{_escape(c.quantity)}: {_cell(c.reference)} → "
                                 f"{_cell(c.value)}")
            worst = max(group, key=lambda c: (c.error / c.tolerance if c.tolerance else
                                              (c.error if not math.isnan(c.error) else -1)))
            tol = "—" if worst.tolerance is None else f"{worst.tolerance:.2g}"
            err = (f"{_cell(worst.error, 'error')} ({worst.error_kind})"
                   if not math.isnan(worst.error) else "—")
            notes = _escape("; ".join(dict.fromkeys(c.note for c in group if c.note)))
            result_cell = _MARK[_status_of(group)] + (f" ({notes})" if notes else "")
            refs = sorted({sources.index(c.source) + 1 for c in group})
            cited = ", ".join(f"[{r}]" for r in refs)
            lines.append(f"| {_escape(item)} | `{method}` | {'<br>'.join(parts)} | {err} | "
                         f"{tol} | {result_cell} | {cited} |")
    lines.append("")
    return "\n".join(lines)


def write_outputs(report: Report, out: Path | str, *, figures: bool = True) -> dict[str, list]:
    """Write ``out/validation.md``, ``out/figures/*.png`` and ``out/tables/*.csv``.

    Returns the written paths by kind.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = {"csv": write_csv(report, out / "tables"), "png": [], "md": []}
    if figures:
        written["png"] = write_figures(report, out / "figures")
    links = {p.stem: f"figures/{p.name}" for p in written["png"]}
    path = out / "validation.md"
    path.write_text(markdown(report, links), encoding="utf-8")
    written["md"].append(path)
    return written
