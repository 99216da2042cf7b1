"""The validation machinery of ``softarm reproduce`` (issue 6): gating, outputs, skips, failures.

The full set of cases runs in ``test_full_reproduction`` (marked slow, still run by .ci/run);
the other tests run a fast subset and check that the check *can* fail.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

from softarm.validation import CASES, Check, main, reproduce, run
from softarm.validation._checks import STATUSES, finding, gate, skipped

# rod_benchmarks.json, shear_deformable_tip_force: parameters and the computed GA = 500 N row
# (Simo-Reissner cantilever, L = 1, EI = 10, EA = 1e8, tip force 10 N; closed form of Batista
# 2016 as computed there). Written out here so that the failure test can alter it.
_SHEAR_CASE = {
    "shear_deformable_tip_force": {
        "found": {"params": {"L": 1, "E": 10, "I": 1, "A": 1e7, "J": 1e7, "F": 10}},
        "computed_here": [{
            "GA": 500.0,
            "tip_x": 0.9386843659276073,
            "tip_transverse": 0.31781389331496873,
            "tip_rotation_rad": 0.458409551307623,
        }],
    }
}


def _write_tables(folder: Path, shear_case: dict) -> Path:
    folder.mkdir()
    (folder / "rod_benchmarks.json").write_text(json.dumps(shear_case), encoding="utf-8")
    return folder


# ------------------------------------------------------------------------------------------
# gating logic
# ------------------------------------------------------------------------------------------
def test_gate_passes_within_tolerance_and_fails_beyond():
    args = ("case", "item", "method", "q")
    assert gate(*args, 1.0, 1.0 + 0.9e-6, 1e-6, "src").status == "pass"
    assert gate(*args, 1.0, 1.0 + 1.1e-6, 1e-6, "src").status == "fail"
    assert gate(*args, 2.0, 2.0 * (1 + 0.9e-3), 1e-3, "src", error_kind="rel").status == "pass"
    assert gate(*args, 2.0, 2.0 * (1 + 1.1e-3), 1e-3, "src", error_kind="rel").status == "fail"


def test_gate_fails_without_a_value():
    """A route that raised gives NaN: a failure, never a silent pass."""
    check = gate("case", "item", "method", "q", 1.0, math.nan, 1e-6, "src", note="boom")
    assert check.status == "fail" and math.isnan(check.error) and check.note == "boom"


def test_angles_compare_modulo_two_pi():
    check = gate("c", "i", "m", "angle", 4.0, 4.0 - 2 * math.pi + 1e-9, 1e-8, "src",
                 error_kind="angle")
    assert check.status == "pass"
    assert check.value == pytest.approx(4.0 + 1e-9, abs=1e-12)  # shown on the reference branch
    assert gate("c", "i", "m", "angle", 4.0, 4.1, 1e-8, "src", error_kind="angle").status == "fail"


def test_findings_and_skips_are_never_gated():
    bad = finding("c", "i", "m", "q", 1.0, 2.0, "src")
    assert bad.status == "finding" and bad.error == pytest.approx(1.0) and not bad.gated
    gone = skipped("c", "i", "m", "q", "src", "table missing")
    assert gone.status == "skipped" and gone.tolerance is None
    with pytest.raises(ValueError, match="status"):
        Check("c", "i", "m", "q", 1.0, 1.0, "abs", None, "src", "maybe")


# ------------------------------------------------------------------------------------------
# cases
# ------------------------------------------------------------------------------------------
def test_closed_form_cases_pass_without_the_data_folder():
    report = run(["fig2_pure_bending", "pure_torsion", "axial_force"], data_dir=None,
                 progress=None)
    assert report.count("pass") == len(report.checks) > 0
    assert report.exit_code == 0
    # Every check names its source, with the paper's equation where there is one.
    assert all(check.source for check in report.checks)
    assert any("eq. 37" in check.source for check in report.checks)


def test_table_cases_are_skipped_not_failed_when_the_data_folder_is_missing(tmp_path):
    report = run(["mattiasson_cantilever", "follower_tip_force", "fig3_shear_load"],
                 data_dir=tmp_path / "missing", progress=None)
    assert report.count("fail") == 0 and report.exit_code == 0
    skips = [c for c in report.checks if c.status == "skipped"]
    assert {c.case for c in skips} == {"mattiasson_cantilever", "follower_tip_force",
                                       "fig3_shear_load"}
    assert all("not found" in c.note for c in skips)
    # Fig. 3 with the paper's printed parameters needs no table and still runs.
    assert any(c.case == "fig3_shear_load" and c.status == "pass" for c in report.checks)


def test_a_wrong_reference_fails(tmp_path):
    """The same case passes with the right reference and fails when one number is off."""
    good = run(["shear_deformable_tip_force"], data_dir=_write_tables(tmp_path / "good",
               _SHEAR_CASE), progress=None)
    assert good.count("fail") == 0 and good.count("pass") == 6

    wrong = json.loads(json.dumps(_SHEAR_CASE))
    wrong["shear_deformable_tip_force"]["computed_here"][0]["tip_x"] += 1e-3
    bad = run(["shear_deformable_tip_force"], data_dir=_write_tables(tmp_path / "bad", wrong),
              progress=None)
    failed = [c for c in bad.checks if c.status == "fail"]
    assert {c.quantity for c in failed} == {"tip x [m]"}
    assert len(failed) == 2  # the numerical solver and analytic.elastica
    assert all(c.error == pytest.approx(1e-3, rel=1e-3) for c in failed)
    assert bad.exit_code == 1


def test_shear_finding_shows_the_flapwise_failure_of_the_small_displacement_solution():
    """C9 (docs/closed-forms.md): at the flapwise stiffness (k up to 1.9) eq. 58 is off by tens of
    percent."""
    report = run(["fig3_shear_load"], progress=None)  # the packaged tables
    tips = {c.item.split(":")[0]: c for c in report.checks
            if c.status == "finding" and c.quantity.startswith("z at r/L = 1 ")
            and "17.792" in c.item}
    assert tips["printed"].error < 0.01  # chordwise pair: within 1 % of the exact solution
    assert tips["flapwise"].error > 0.2   # flapwise pair: the approximation fails
    assert report.count("fail") == 0


# ------------------------------------------------------------------------------------------
# outputs
# ------------------------------------------------------------------------------------------
def test_outputs_parse(tmp_path):
    progress = io.StringIO()
    report = reproduce(tmp_path / "out", cases=["fig2_pure_bending", "pure_torsion"],
                       data_dir=tmp_path / "missing", progress=progress)
    out = tmp_path / "out"
    with (out / "tables" / "checks.csv").open(encoding="utf-8", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == len(report.checks)
    for row in rows:
        assert row["status"] in STATUSES
        float(row["reference"]), float(row["value"]), float(row["error"])
        assert row["source"]
    text = (out / "validation.md").read_text(encoding="utf-8")
    assert "softarm reproduce --out docs" in text.splitlines()[2]
    assert f"**Summary: {report.summary()}.**" in text and "tables/checks.csv" in text
    assert "![fig2_pure_bending](figures/fig2_pure_bending.png)" in text
    table_lines = [line for line in text.splitlines() if line.startswith("| ")]
    # every table row has the same number of cells as its header (no stray '|')
    for line in table_lines:
        cells = line.replace("\\|", "").count("|")
        assert cells in (8, 7), line
    png = out / "figures" / "fig2_pure_bending.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size < 150_000
    assert "reproduce [" in progress.getvalue() and "2/2" in progress.getvalue()


def test_command_exit_status(tmp_path):
    args = ["--out", str(tmp_path), "--case", "pure_torsion", "--no-figures"]
    assert main(args) == 0
    assert (tmp_path / "validation.md").is_file()
    assert not (tmp_path / "figures").exists()
    data = _write_tables(tmp_path / "bad", {"shear_deformable_tip_force": {
        **_SHEAR_CASE["shear_deformable_tip_force"],
        "computed_here": [{**_SHEAR_CASE["shear_deformable_tip_force"]["computed_here"][0],
                           "tip_rotation_rad": 0.5}]}})
    args = ["--out", str(tmp_path / "o2"), "--case", "shear_deformable_tip_force",
            "--data", str(data), "--no-figures"]
    assert main(args) == 1


def test_softarm_reproduce_subcommand(tmp_path, capsys):
    """The summary and the files written go to stdout, the progress to stderr (docs/cli.md:
    results and summaries on stdout)."""
    from softarm.cli import main as softarm_main

    code = softarm_main(["reproduce", "--out", str(tmp_path), "--case", "axial_force",
                         "--no-figures"])
    assert code == 0
    out, err = capsys.readouterr()
    assert out.splitlines() == [
        out.splitlines()[0], f"  wrote {tmp_path / 'validation.md'}",
        f"  wrote {tmp_path / 'tables' / 'checks.csv'}"]
    assert re.fullmatch(r"reproduce: 8 checks: 8 pass, 0 fail, 0 finding, 0 skipped in "
                        r"\d+\.\d s", out.splitlines()[0])
    assert "reproduce [" in err and "checks:" not in err and "wrote" not in err
    assert softarm_main(["reproduce", "--case", "no_such_case"]) == 2


# matplotlib blocked as if it were not installed (a plain `pip install .`)
_WITHOUT_MATPLOTLIB = """\
import sys
sys.modules["matplotlib"] = None
from softarm.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.parametrize("failing", [False, True])
@pytest.mark.slow
def test_reproduce_without_matplotlib_writes_the_report_without_figures(tmp_path, failing):
    """No traceback: the report and tables, one line saying how to get the figures, and the
    exit status of the checks alone (0, or 1 with a failed check)."""
    argv = ["reproduce", "--out", str(tmp_path / "out"), "--case", "fig2_pure_bending"]
    if failing:  # a failing check as well: the exit status is still the checks'
        data = _write_tables(tmp_path / "bad", {"shear_deformable_tip_force": {
            **_SHEAR_CASE["shear_deformable_tip_force"],
            "computed_here": [{**_SHEAR_CASE["shear_deformable_tip_force"]["computed_here"][0],
                               "tip_rotation_rad": 0.5}]}})
        argv += ["--case", "shear_deformable_tip_force", "--data", str(data)]
    child = subprocess.run([sys.executable, "-c", _WITHOUT_MATPLOTLIB, *argv],
                           capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert child.returncode == (1 if failing else 0), child.stderr
    assert "Traceback" not in child.stderr and "Error" not in child.stderr, child.stderr
    notes = [line for line in child.stderr.splitlines() if "matplotlib" in line]
    assert notes == ["reproduce: the report has no figures: matplotlib is not installed "
                     "(pip install \"softarm[plot]\" draws them)"], child.stderr
    report = (tmp_path / "out" / "validation.md").read_text(encoding="utf-8")
    assert "## Paper Fig. 2" in report and "![" not in report
    assert (tmp_path / "out" / "tables" / "checks.csv").is_file()
    assert not (tmp_path / "out" / "figures").exists()
    assert "wrote" in child.stdout and "png" not in child.stdout


@pytest.mark.slow
def test_plot_without_matplotlib_is_one_line(tmp_path):
    case = tmp_path / "moment.toml"
    case.write_text('[arm]\nlength = 1.0\nstiffness = { EA = 1e6, GAy = 1e6, GAz = 1e6, '
                    'GJ = 1.0, EIy = 1.0, EIz = 1.0 }\n[[load]]\nkind = "tip"\n'
                    'moment = [0.0, 3.0, 0.0]\n', encoding="utf-8")
    result = tmp_path / "moment.csv"
    child = subprocess.run([sys.executable, "-c", _WITHOUT_MATPLOTLIB, "solve", str(case), "-o",
                            str(result)], capture_output=True, text=True, timeout=600)
    assert child.returncode == 0, child.stderr
    child = subprocess.run([sys.executable, "-c", _WITHOUT_MATPLOTLIB, "plot", str(result)],
                           capture_output=True, text=True, timeout=600)
    assert child.returncode == 2
    assert child.stderr == (f"softarm: error: {tmp_path / 'moment.png'}: drawing a picture "
                            'needs matplotlib, which is not installed: pip install '
                            '"softarm[plot]"\n')
    assert not (tmp_path / "moment.png").exists()
    # a command that solves and draws refuses before it solves: nothing written (the demo
    # wrote its table, then failed on the picture)
    for command in (["demo", "--out", str(tmp_path)],
                    ["solve", str(case), "-o", str(tmp_path / "again.csv"), "--plot",
                     str(tmp_path / "again.png")]):
        child = subprocess.run([sys.executable, "-c", _WITHOUT_MATPLOTLIB, *command],
                               capture_output=True, text=True, timeout=600)
        assert child.returncode == 2 and child.stderr.count("\n") == 1, child.stderr
        assert "needs matplotlib" in child.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["moment.csv", "moment.toml"]


def test_unknown_case_is_rejected():
    with pytest.raises(ValueError, match="unknown"):
        run(["no_such_case"], progress=None)


@pytest.mark.slow
def test_full_reproduction(tmp_path):
    """Every case of ``softarm reproduce`` against the packaged tables: all gated checks pass."""
    report = reproduce(tmp_path, progress=None)
    failed = [c for c in report.checks if c.status == "fail"]
    assert not failed, failed[:5]
    assert report.count("skipped") == 0
    assert {case.name for case, _, _ in report.cases} == {case.name for case in CASES}
    for png in (tmp_path / "figures").glob("*.png"):
        assert png.stat().st_size < 150_000, png
