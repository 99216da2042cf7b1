"""The user documentation against the program (issue 30): docs/cli.md names every command and
every option that ``softarm --help`` lists, and the README links every page of docs/.

The reference is the command's own argument parser (what ``--help`` prints).
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

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
