"""Smoke test of benchmarks/run.py (issue 7): it runs, its table parses, its answers are right.

Times are never asserted (speed is measured in benchmarks/, not in tests); tip errors are,
because a benchmark that times a wrong answer is worthless.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

# benchmarks/run.py --quick takes 20 s warm and up to 2 min while it compiles (117 s in a
# cold .ci/run on a slow hour): the module's tests run with pytest -m slow
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]
RUN = ROOT / "benchmarks" / "run.py"


def _run_module():
    spec = importlib.util.spec_from_file_location("benchmarks_run", RUN)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "performance.md"
    done = subprocess.run(
        [sys.executable, str(RUN), "--quick", "--no-pyelastica", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    return out.read_text(), done.stdout


def test_quick_run_writes_report(quick_report):
    text, stdout = quick_report
    for heading in ("## Machine", "## Compilation", "## Against peers", "## Throughput",
                    "## Stiff problems", "## Verdicts"):
        assert heading in text
    assert stdout.count("VERDICT") == 10


def test_table_parses_and_covers_every_case_and_tool(quick_report):
    rows = _run_module().parse_table(quick_report[0])
    cases = {row["case"] for row in rows}
    assert cases == {"mattiasson_k1", "mattiasson_k2", "mattiasson_k5", "mattiasson_k10",
                     "pure_bending_tau3", "princeton_shear_P13.345",
                     "soft_arm_3d_gravity_oblique"}
    for case in cases:
        tools = {row["tool"] for row in rows if row["case"] == case}
        assert {"softarm numeric", "scipy solve_bvp", "scipy shooting"} <= tools
    for row in rows:
        float(row["wall ms (median)"])  # parses; the value itself is not checked


def test_tip_errors_are_small(quick_report):
    rows = _run_module().parse_table(quick_report[0])
    for row in rows:
        # references: Mattiasson (1981) Table 1, Grazioso et al. (2018) eq. 37, closed-form
        # elastica, tight solves cross-checked by scipy shooting (see the report)
        error = float(row["tip error / L"])
        if row["tool"].startswith("softarm"):
            assert error <= 1e-6, row
        else:
            assert error <= 1e-5, row
