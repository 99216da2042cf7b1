"""Shared fixtures: the only source of randomness in the tests is the seeded ``rng``.

Hypothesis (the property tests of tests/lie and tests/analytic) draws its examples from a
fixed seed too (``derandomize``), with no example database: every run, CI's included,
tests the same examples, and a failure reproduces. (A random draw once found a hang in
CI that no local run had met: the example is now pinned in its test.)
"""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest
from hypothesis import settings

from softarm.validation import reference_table as _packaged_table

settings.register_profile("softarm", derandomize=True, database=None)
settings.load_profile("softarm")

# The one-line notice a kernel's first compile prints (softarm._jit) depends on what the
# numba cache holds when a test runs: off for the suite and the commands it starts, on in
# tests/test_compile.py, which tests it.
os.environ["SOFTARM_COMPILE_NOTICE"] = "0"


@pytest.fixture(autouse=True)
def _sigint_restored():
    """Each test leaves Ctrl-C as it found it. softarm.cli.main ignores a second Ctrl-C after an
    interrupt, for the rest of the process (cli.interrupted): called in the test process
    (tests/test_simulate_cli.py), that left SIGINT ignored for the tests after it, whose
    commands then inherited it and could not be interrupted (with pytest-xdist, the order of
    tests/test_hard_edges.py's Ctrl-C test and that one depends on the worker)."""
    handler = signal.getsignal(signal.SIGINT)
    yield
    if handler is not None and signal.getsignal(signal.SIGINT) is not handler:
        signal.signal(signal.SIGINT, handler)


@pytest.fixture
def rng():
    return np.random.default_rng(20181001)


def reference_table(name: str) -> dict:
    """A reference table shipped in the package (softarm/validation/data, with provenance)."""
    return _packaged_table(name)


@pytest.fixture(scope="module")
def browser():
    """A module's headless chromium (tests/_browser.py: skipped, or failed in CI, without
    it), whose scripts may take a minute."""
    import _browser

    driver = _browser.chromium()
    driver.set_script_timeout(60)
    yield driver
    driver.quit()
