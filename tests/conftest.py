"""Shared fixtures: the only source of randomness in the tests is the seeded ``rng``."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.validation import reference_table as _packaged_table


@pytest.fixture
def rng():
    return np.random.default_rng(20181001)


def reference_table(name: str) -> dict:
    """A reference table shipped in the package (softarm/validation/data, with provenance)."""
    return _packaged_table(name)
