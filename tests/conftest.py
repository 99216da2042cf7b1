"""Shared fixtures: the only source of randomness in the tests is the seeded ``rng``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

#: ../shared/data beside the project root (reference tables with their provenance).
SHARED_DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


@pytest.fixture
def rng():
    return np.random.default_rng(20181001)


def shared_table(name: str) -> dict:
    """A reference table from ../shared/data; fails the test if the folder is missing."""
    path = SHARED_DATA / name
    if not path.exists():
        pytest.fail(f"reference table {path} not found: shared/ must sit beside the repository")
    return json.loads(path.read_text())
