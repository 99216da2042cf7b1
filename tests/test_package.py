"""The package as a whole: import hygiene, version, public names, and pinned conventions."""

from __future__ import annotations

import importlib.metadata
import itertools
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm import Arm, Circle, Equilibrium, Material, TipLoad
from softarm.lie import se3, so3

ROOT = Path(__file__).resolve().parents[1]

if sys.version_info >= (3, 11):
    import tomllib
else:  # the runtime dependency tomli covers Python 3.10
    import tomli as tomllib


def test_import_does_not_import_matplotlib():
    code = "import softarm, sys; assert 'matplotlib' not in sys.modules, 'matplotlib imported'"
    completed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                               timeout=120, check=False)
    assert completed.returncode == 0, completed.stderr


def test_version_matches_the_dynamic_version_source():
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert "version" in pyproject["project"]["dynamic"]
    source = ROOT / pyproject["tool"]["hatch"]["version"]["path"]
    # hatchling's default version pattern: a line `__version__ = "..."`.
    found = re.findall(r'^__version__\s*=\s*["\']([^"\']+)["\']', source.read_text("utf-8"),
                       flags=re.MULTILINE)
    assert found == [softarm.__version__]
    assert re.fullmatch(r"\d+\.\d+\.\d+([.-]?(a|b|rc|dev|post)\d*)*", softarm.__version__)
    assert importlib.metadata.version("softarm") == softarm.__version__


@pytest.mark.slow
def test_plain_pytest_says_why_a_test_was_skipped(tmp_path):
    """The project's pytest configuration reports the reason of every skip (``-rs``): a plain
    ``pytest`` must not print "4 skipped" and leave the reader to guess; failures stay listed
    in the short summary too (pytest's default ``-rfE``)."""
    (tmp_path / "test_skip.py").write_text(
        "import pytest\n\n\ndef test_needs_a_browser():\n"
        "    pytest.skip('chromium-driver is not installed')\n\n\n"
        "def test_fails():\n    assert 1 == 2\n", encoding="utf-8")
    child = subprocess.run(
        [sys.executable, "-m", "pytest", "-c", str(ROOT / "pyproject.toml"), "--rootdir",
         str(tmp_path), "-p", "no:cacheprovider", str(tmp_path / "test_skip.py")],
        capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert child.returncode == 1, child.stdout + child.stderr
    summary = child.stdout.split("short test summary info")[1]
    assert re.search(r"SKIPPED \[1\] .*test_skip\.py:\d+: chromium-driver is not installed",
                     summary), child.stdout
    assert re.search(r"FAILED .*test_skip\.py::test_fails", summary), child.stdout


def _readme_outputs() -> list[str]:
    """The files and folders that the README's ``softarm`` commands (in its code blocks
    without a language: the shell ones) write, relative to the working directory:
    -o/--output, --plot, --out, and demo's two; a folder as FOLDER/x."""
    import shlex

    commands, fence = [], None
    for line in (ROOT / "README.md").read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            fence = line[3:].strip() if fence is None else None
        elif fence == "":
            commands += line.split("#")[0].split("&&")
    outputs = []
    for command in commands:
        words = shlex.split(command)
        if words[:1] != ["softarm"] or len(words) < 2:
            continue
        folder = words[1] in ("sweep", "reproduce")  # their outputs are folders
        for flag, value in itertools.pairwise(words):
            if flag in ("-o", "--output", "--plot", "--out"):
                outputs.append(value.rstrip("/") + ("/x" if folder else ""))
        if words[1] == "demo" and "--out" not in words:
            outputs += ["demo.png", "demo.csv"]
    return [path for path in outputs if not Path(path).is_absolute()]


def test_the_readme_commands_leave_no_untracked_files():
    """Run in the clone, the README's commands write only what .gitignore ignores (or tracked
    files such as docs/): no demo.png, result.csv, ... among the untracked files."""
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: .gitignore is not used")
    outputs = _readme_outputs()
    assert {"demo.png", "demo.csv", "result.csv", "validation/x"} <= set(outputs)
    tracked = set(subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True,
                                 text=True, check=True).stdout.split())
    outputs = [path for path in outputs
               if not any(name == path or name.startswith(path.removesuffix("x"))
                          for name in tracked)]
    check = subprocess.run(["git", "check-ignore", "--no-index", *outputs], cwd=ROOT,
                           capture_output=True, text=True)
    assert sorted(check.stdout.split()) == sorted(outputs), check.stderr


def test_every_public_name_exists():
    assert len(set(softarm.__all__)) == len(softarm.__all__)
    missing = [name for name in softarm.__all__ if not hasattr(softarm, name)]
    assert missing == []
    assert "__version__" in softarm.__all__
    # Star-import gives exactly the public names.
    namespace: dict = {}
    exec("from softarm import *", namespace)
    assert set(namespace) - {"__builtins__"} == set(softarm.__all__)


# ---------------------------------------------------------------------------------------------
# Conventions (STYLE.md "Conventions"; Grazioso et al. 2018, eqs. 62-67: linear part first).


def test_twists_are_linear_part_first():
    u, w = np.array([1.0, 2.0, 3.0]), np.array([0.4, -0.5, 0.6])
    X = se3.hat(np.concatenate([u, w]))
    assert np.array_equal(X[:3, 3], u)  # u in the last column
    assert np.array_equal(X[:3, :3], so3.hat(w))  # ω~ in the rotation block
    assert np.array_equal(X[3], np.zeros(4))
    # A pure translation twist moves the origin by u.
    assert np.array_equal(se3.exp(np.concatenate([u, np.zeros(3)]))[:3, 3], u)
    # ad(h) = [[ω~, u~], [0, ω~]] (eq. 67, the paper's hat).
    A = se3.ad(np.concatenate([u, w]))
    assert np.array_equal(A[:3, 3:], so3.hat(u))
    assert np.array_equal(A[:3, :3], so3.hat(w)) and np.array_equal(A[3:, 3:], so3.hat(w))
    assert np.array_equal(A[3:, :3], np.zeros((3, 3)))


def test_so3_hat_is_the_cross_product():
    a, b = np.array([1.0, 2.0, 3.0]), np.array([-0.5, 0.25, 2.0])
    assert np.allclose(so3.hat(a) @ b, np.cross(a, b), rtol=1e-15, atol=0)


def test_arm_axis_is_material_e1():
    arm = Arm(0.5, Circle(0.01), Material(1e6, poisson_ratio=0.5))
    assert np.array_equal(arm.reference_strain[:3], [1.0, 0.0, 0.0])
    # The unloaded straight arm, H(s) = exp(s f⁰), runs along the spatial x axis.
    assert np.allclose(se3.exp(0.5 * arm.reference_strain)[:3, 3], [0.5, 0.0, 0.0], atol=0)


def test_equilibrium_views_and_read_only_arrays(rng):
    n = 5
    poses = se3.exp(rng.normal(size=(2, n, 6)))
    result = Equilibrium(s=np.linspace(0.0, 1.0, n), poses=poses,
                         strains=np.zeros((2, n, 6)), stresses=rng.normal(size=(2, n, 6)),
                         arm=None, loads=(TipLoad(),), method="test", exact=False)
    assert np.array_equal(result.positions, poses[..., :3, 3])
    assert np.array_equal(result.rotations, poses[..., :3, :3])
    assert np.array_equal(result.tip, poses[:, -1])
    assert np.array_equal(result.tip_position, poses[:, -1, :3, 3])
    for array in (result.s, result.poses, result.strains, result.stresses, result.positions):
        assert not array.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            array.flat[0] = 1.0
