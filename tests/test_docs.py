"""The user documentation against the program (issue 30): docs/cli.md names every command and
every option that ``softarm --help`` lists, and the README links every page of docs/.

The reference is the command's own argument parser (what ``--help`` prints).
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from softarm import cli

ROOT = Path(__file__).resolve().parents[1]
CLI_MD = (ROOT / "docs" / "cli.md").read_text(encoding="utf-8")


def _commands() -> dict[str, argparse.ArgumentParser]:
    parser = cli._parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def test_the_synopsis_names_every_command():
    synopsis = CLI_MD.split("```")[1]
    for name in _commands():
        assert re.search(rf"^softarm {name}\b", synopsis, flags=re.M), name


@pytest.mark.parametrize("name", sorted(_commands()))
def test_every_option_is_documented(name):
    """Each option of the command (one of its spellings) appears in docs/cli.md, and the
    command has a paragraph or section of its own beyond the synopsis."""
    command = _commands()[name]
    for action in command._actions:
        if not action.option_strings or action.option_strings == ["-h", "--help"]:
            continue
        assert any(re.search(rf"`[^`]*{re.escape(option)}\b", CLI_MD)
                   for option in action.option_strings), (name, action.option_strings)
    body = CLI_MD.split("```", 2)[2]
    assert f"softarm {name}`" in body, f"no paragraph on softarm {name}"


def test_the_readme_links_every_page_of_the_docs():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    documentation = readme.split("## Documentation", 1)[1]
    for page in sorted((ROOT / "docs").glob("*.md")):
        assert f"](docs/{page.name})" in documentation, page.name


def _python_blocks(text: str) -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.M | re.S)


#: A class named in the docs with an attribute, as `Class.attribute`: where it lives
_CLASSES = {
    "Trajectory": "softarm.Trajectory", "Equilibrium": "softarm.Equilibrium",
    "Simulator": "softarm.Simulator", "State": "softarm.State", "Energy": "softarm.Energy",
    "Solver": "softarm.statics.Solver", "ForwardSolver": "softarm.ForwardSolver",
    "ForwardResult": "softarm.ForwardResult", "InverseSolver": "softarm.InverseSolver",
    "InverseResult": "softarm.InverseResult", "Contact": "softarm.Contact",
    "Branch": "softarm.Branch", "CriticalPoint": "softarm.CriticalPoint",
    "Stability": "softarm.Stability", "Arm": "softarm.Arm", "Tendon": "softarm.Tendon",
    "Chamber": "softarm.Chamber",
}


def test_every_class_attribute_the_docs_name_exists():
    """`Trajectory.contact`, `Equilibrium.tip_compliance`, ...: each `Class.name` in the README
    and docs/ is an attribute, property, method or dataclass field of that class, or one its
    methods set on the instance (a docs page
    once named the trajectory's contact law by a name it does not have)."""
    import importlib
    import inspect

    texts = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    missing = []
    for path in texts:
        text = path.read_text(encoding="utf-8")
        for name, attribute in re.findall(rf"`({'|'.join(_CLASSES)})\.([A-Za-z_]\w*)", text):
            module, _, cls = _CLASSES[name].rpartition(".")
            owner = getattr(importlib.import_module(module), cls)
            fields = getattr(owner, "__dataclass_fields__", {})
            if not (hasattr(owner, attribute) or attribute in fields
                    or re.search(rf"self\.{attribute}\s*[:=]", inspect.getsource(owner))):
                missing.append(f"{path.name}: {name}.{attribute}")
    assert missing == []


@pytest.mark.slow  # (a first simulation in a fresh cache compiles the dynamics)
def test_the_readme_line_that_writes_a_trajectory_page_works_as_printed(tmp_path):
    """The README prints ``softarm.view.write_trajectory_html(trajectory, "swing.html",
    arm=arm)``: after a plain ``import softarm`` (which imports neither plotly nor numba),
    ``softarm.view`` is there, and the line writes the page. Run in a fresh interpreter: in
    this one another test may have imported softarm.view already."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    line = re.search(r"`(softarm\.view\.write_trajectory_html\([^`]*\))`", readme).group(1)
    code = f"""
import sys
import numpy as np
import softarm
assert not {{"plotly", "numba", "matplotlib"}} & set(sys.modules), "import softarm got heavy"
arm = softarm.Arm(0.2, softarm.Circle(0.01), softarm.Material(1e6, poisson_ratio=0.5,
                                                              density=1100.0))
trajectory = softarm.simulate(arm, [softarm.Gravity()], duration=2e-3, dt=1e-3, stations=5)
{line}
"""
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    page = (tmp_path / "swing.html").read_text(encoding="utf-8")
    assert page.startswith("<!DOCTYPE html>") or "<html" in page[:200]


@pytest.mark.slow
def test_the_readmes_python_runs_and_prints_what_its_comment_says(tmp_path, monkeypatch,
                                                                capsys):
    """The README's Python blocks, one after the other as a reader types them (each block
    uses the names of the ones before), run without an error; the first print shows what
    its comment says (the method and the tip to the four digits printed)."""
    import warnings

    monkeypatch.chdir(tmp_path)
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = _python_blocks(readme)
    assert len(blocks) >= 4
    namespace: dict = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (a StabilityWarning is the reader's to see)
        for block in blocks:
            exec(compile(block, "README.md", "exec"), namespace)
    printed = capsys.readouterr().out.splitlines()[0].replace("[", " ").replace("]", " ")
    said = re.search(r"print\(eq\.method, eq\.tip_position\)\s*#\s*(.*)", readme).group(1)
    said = said.replace("[", " ").replace("]", " ").split()
    assert printed.split()[0] == said[0]
    np.testing.assert_allclose([float(v) for v in printed.split()[1:]],
                               [float(v) for v in said[1:]], atol=6e-5)


def test_softarm_compile_and_the_docs_list_every_capability():
    """Each capability ``softarm compile --all`` compiles (softarm.warmup.STEPS) is listed by
    ``softarm compile --help``, in docs/cli.md and in docs/performance.md's cold compile."""
    from softarm.warmup import STEPS

    help_text = " ".join(_commands()["compile"].format_help().split())
    cli_md = " ".join(CLI_MD.split())
    performance = " ".join((ROOT / "docs" / "performance.md").read_text(
        encoding="utf-8").split("### Cold compile", 1)[1].split())
    for step in STEPS:
        text = " ".join(step.text.split())
        assert text in help_text, step.name
        assert text in cli_md, step.name
        assert text in performance, step.name
