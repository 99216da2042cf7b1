"""Shared fixtures: the only source of randomness in the tests is the seeded ``rng``.

Hypothesis (the property tests of tests/lie and tests/analytic) draws its examples from a
fixed seed too (``derandomize``), with no example database: every run, CI's included,
tests the same examples, and a failure reproduces. (A random draw once found a hang in
CI that no local run had met: the example is now pinned in its test.)

A plain ``pytest`` leaves out the tests marked ``slow`` (README, "Test"): ``pytest -m slow``
runs only them, ``pytest --run-slow`` everything, and a slow test named by its node id
(``pytest tests/test_compile.py::test_...``) runs as named; any ``-m`` expression decides
alone. .ci/run runs ``pytest`` and then ``pytest -m slow``.
"""

from __future__ import annotations

import os
import signal
from collections import Counter
from pathlib import Path

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


def pytest_addoption(parser):
    parser.addoption("--run-slow", action="store_true", default=False,
                     help="run the tests marked slow too (a plain pytest leaves them out; "
                          "-m slow runs only them)")


def _named(config) -> list[str]:
    """The node ids (relative to the rootdir) that the command line names: its arguments
    with a ``::``."""
    named = []
    for arg in config.args:
        path, sep, rest = arg.partition("::")
        if not sep:
            continue
        try:
            path = Path(path).resolve().relative_to(config.rootpath).as_posix()
        except ValueError:
            continue
        named.append(f"{path}::{rest}")
    return named


def _slow_left_out(config) -> bool:
    return not (config.option.markexpr or config.getoption("--run-slow"))


#: test files that start first under pytest-xdist, in this order (two workers take them in turn).
#: First the longest single piece of work (``softarm compile --all`` and every capability after it:
#: ``pytest -m slow``), so that it runs beside everything else instead of after it, and the slow
#: tests after it load what it compiled. Then, for a first run (numba's cache empty, most of its
#: time compiling), files whose first tests compile different capabilities, so that the two workers
#: do not compile the same one at once (measured: 97 s of such duplicates in a 431-s run, the
#: passive solver and the contact solver above all): the passive solver and multiple shooting;
#: contact; dynamics; actuated arms (their limits: after the first file's multiple shooting
#: with its verdict, which they use too, is in the cache: 32 s compiled twice at once before).
STARTS_FIRST = ("tests/test_compile_all.py", "tests/statics/test_invariants.py",
                "tests/test_contact.py", "tests/test_dynamics.py", "tests/test_model_limits.py")


def pytest_collection_modifyitems(config, items):
    _leave_out_slow(config, items)
    _order_files(config, items)


def _order_files(config, items) -> None:
    """The files in the order pytest-xdist hands them out (``--dist loadfile``,
    ``--no-loadscope-reorder``): :data:`STARTS_FIRST` in its order, then the files with more
    tests first (what xdist itself would do: its longest files tend to be its largest), each
    file's tests in their own order. Without xdist the order is only rearranged by file."""
    def file_of(item) -> str:
        path = Path(item.path).resolve()
        return path.relative_to(config.rootpath).as_posix() \
            if path.is_relative_to(config.rootpath) else path.as_posix()

    files = {id(item): file_of(item) for item in items}
    counts = Counter(files.values())  # (in the order the files were collected)
    first = {name: position for position, name in enumerate(STARTS_FIRST)}
    rank = {name: (first.get(name, len(first)), -count, position)
            for position, (name, count) in enumerate(counts.items())}
    items.sort(key=lambda item: rank[files[id(item)]])


def _leave_out_slow(config, items) -> None:
    if not _slow_left_out(config):
        return
    named = _named(config)

    def runs(item) -> bool:
        return item.get_closest_marker("slow") is None or any(
            item.nodeid == n or item.nodeid.startswith((n + "::", n + "[")) for n in named)

    left_out = [item for item in items if not runs(item)]
    if left_out:
        config.hook.pytest_deselected(items=left_out)
        items[:] = [item for item in items if runs(item)]
    _SLOW_LEFT_OUT[0] = len(left_out)
    if hasattr(config, "workerinput"):  # a pytest-xdist worker: told to the controller
        config.workeroutput["slow_left_out"] = len(left_out)


#: how many tests marked slow this run leaves out (with pytest-xdist: as a worker counted)
_SLOW_LEFT_OUT = [0]


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    _SLOW_LEFT_OUT[0] = max(_SLOW_LEFT_OUT[0],
                            getattr(node, "workeroutput", {}).get("slow_left_out", 0))


def pytest_terminal_summary(terminalreporter, config):
    if _SLOW_LEFT_OUT[0] and not hasattr(config, "workerinput"):
        terminalreporter.write_line(
            f"{_SLOW_LEFT_OUT[0]} tests marked slow were left out: pytest -m slow runs them, "
            "pytest --run-slow runs everything")


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
