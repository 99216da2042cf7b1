"""A clone with nothing beside it (issue 11): the reference tables ship inside the package, and
nothing refers to a folder outside the repository.

.ci/run proves the whole of it (the README's test command from a clean copy alone in a temporary
folder, and `softarm reproduce --strict` from the installed wheel); these tests pin the parts.
"""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

import pytest

from softarm import cli
from softarm.validation import TABLES, find_data_dir, reference_table, run

ROOT = Path(__file__).resolve().parents[1]

# Built from pieces so that neither this file nor a grep for the folder's name matches it.
SIBLING = "sha" + "red"
OUTSIDE = (re.compile(r"\.\./" + SIBLING), re.compile("NOTES" + r"\.md"),
           re.compile(r"parents\[\d\]\s*/\s*\"" + SIBLING))


def _files():
    for folder in ("src", "tests", "examples", "benchmarks"):
        for path in sorted((ROOT / folder).rglob("*")):
            if path.is_file() and path.suffix in (".py", ".toml", ".md", ".json"):
                yield path
    yield ROOT / "README.md"
    yield ROOT / "pyproject.toml"


def test_nothing_refers_to_a_folder_beside_the_repository():
    found = []
    for path in _files():
        text = path.read_text(encoding="utf-8")
        for pattern in OUTSIDE:
            for match in pattern.finditer(text):
                line = text.count("\n", 0, match.start()) + 1
                found.append(f"{path.relative_to(ROOT)}:{line}: {match.group(0)}")
    assert found == []


def test_readme_test_section_reads_nothing_from_outside():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Test", 1)[1].split("\n## ", 1)[0]
    assert 'pip install ".[test]" && pytest' in section
    assert SIBLING not in section
    assert "src/softarm/validation/data" in section


@pytest.mark.parametrize("name", TABLES)
def test_packaged_tables_carry_their_provenance(name):
    folder = resources.files("softarm.validation") / "data"
    assert (folder / name).is_file()
    table = reference_table(name)
    assert table.get("title") or table.get("_about")
    # every table names where its numbers come from: citations at the top or per entry, or
    # (peer codes' outputs) the repository and commit that were run
    text = str(table)
    # (buckling.json: a "provenance" list per fact, its entries marked FOUND / COMPUTED HERE;
    # actuation_benchmarks.json: the peer codes' repository and commit)
    assert "citation" in text or "provenance" in text or ("repository" in text
                                                          and "commit" in text)
    assert any(key in text for key in ("found", "computed_here", "FOUND", "COMPUTED HERE"))
    readme = (folder / "README.md").read_text(encoding="utf-8")
    assert f"`{name}`" in readme


def test_mattiasson_table_holds_the_published_numbers():
    # Mattiasson (1981) Table 1 at k = PL²/EI = 1: w/L = 0.30172, u/L = 0.05643 (as quoted in
    # the table's "found_values"); the same digits are in the test suite's other references.
    found = reference_table("mattiasson_cantilever.json")["found_values"][0]["values"]
    assert found["1.0"] == {"w_over_L": 0.30172, "u_over_L": 0.05643}
    with pytest.raises(ValueError, match="name must be one of"):
        reference_table("no_such_table.json")


def test_reproduce_uses_the_packaged_tables_by_default():
    report = run(["shear_deformable_tip_force"], progress=None)
    assert str(report.data_dir) == str(find_data_dir())
    assert report.count("skipped") == 0 and report.count("pass") > 0
    assert report.exit_code == 0 and report.strict_exit_code() == 0
    bare = run(["shear_deformable_tip_force"], data_dir=None, progress=None)
    assert bare.count("skipped") > 0 and bare.count("pass") == 0
    assert bare.exit_code == 0 and bare.strict_exit_code() == 1


def test_reproduce_strict_exits_1_on_skipped_checks(tmp_path, capsys):
    empty = tmp_path / "no_tables"
    empty.mkdir()
    argv = ["reproduce", "--case", "shear_deformable_tip_force", "--no-figures", "--data",
            str(empty), "--out", str(tmp_path / "out")]
    assert cli.main(argv) == 0  # skipped checks are not failures by default
    capsys.readouterr()
    assert cli.main([*argv, "--strict"]) == 1
    err = capsys.readouterr().err
    assert re.search(r"reproduce: \d+ checks skipped \(--strict\)", err)
    capsys.readouterr()
    assert cli.main(["reproduce", "--case", "shear_deformable_tip_force", "--no-figures",
                     "--strict", "--out", str(tmp_path / "out2")]) == 0
