"""The softarm command at its hard edges (issue 11): one line on stderr, exit 2 for bad input and
1 for a failure, no partial file, an existing output left intact, exit 130 on Ctrl-C.

The references are the exit-code contract of docs/cli.md and the files on disk before and after
each run (compared byte for byte).
"""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm import _validate, cli, io

# A case with an exact closed form (no numerical solve, no compiled kernels): a tip moment
# about a principal axis rolls the arm into a circle (Grazioso et al. 2018, eqs. 37-38).
MOMENT_CASE = """\
name = "moment"
[arm]
length = 1.0
stiffness = { EA = 1e6, GAy = 1e6, GAz = 1e6, GJ = 1.0, EIy = 1.0, EIz = 1.0 }
[[load]]
kind = "tip"
moment = [0.0, 3.0, 0.0]
"""


def run(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str) -> str:
    """The stderr of a failed run: exactly one short line, no traceback (a progress bar,
    redrawn in place with carriage returns, and the "solving..." of a solve still running
    after 2 s, cli.py, aside)."""
    lines = [line.rsplit("\r", 1)[-1] for line in err.split("\n")]
    lines = [line for line in lines
             if line.strip() and not line.startswith("solving [") and line != "solving..."]
    assert len(lines) == 1, err
    assert "Traceback" not in err and len(lines[0]) < 500, err
    return lines[0]


@pytest.fixture
def case(tmp_path) -> Path:
    path = tmp_path / "moment.toml"
    path.write_text(MOMENT_CASE, encoding="utf-8")
    return path


@pytest.fixture
def result_csv(tmp_path, case, capsys) -> Path:
    out = tmp_path / "result.csv"
    code, _, err = run(capsys, "solve", case, "-o", out)
    assert code == 0, err
    return out


def listing(folder: Path) -> dict[str, bytes]:
    return {p.name: (p.read_bytes() if p.is_file() else b"<dir>") for p in folder.iterdir()}


# --- output paths -----------------------------------------------------------------------------

def test_output_path_that_is_a_folder(tmp_path, case, capsys):
    (tmp_path / "out.csv").mkdir()
    before = listing(tmp_path)
    code, _, err = run(capsys, "solve", case, "-o", tmp_path / "out.csv")
    assert code == 2
    assert "is a folder" in one_line(err)
    assert listing(tmp_path) == before
    (tmp_path / "pic.png").mkdir()
    code, _, err = run(capsys, "solve", case, "--plot", tmp_path / "pic.png")
    assert code == 2 and "is a folder" in one_line(err)


def test_output_path_equal_to_the_input_whatever_its_suffix(tmp_path, capsys):
    # a case file named .csv: writing the result there would destroy the input
    case = tmp_path / "case.csv"
    case.write_text(MOMENT_CASE, encoding="utf-8")
    code, _, err = run(capsys, "solve", case, "-o", case)
    assert code == 2 and "is the input file" in one_line(err)
    assert case.read_text(encoding="utf-8") == MOMENT_CASE
    # through a symbolic link, and for `softarm plot` too
    link = tmp_path / "link.json"
    link.symlink_to(case)
    code, _, err = run(capsys, "solve", case, "-o", link)
    assert code == 2 and "is the input file" in one_line(err)
    assert case.read_text(encoding="utf-8") == MOMENT_CASE


def test_plot_output_equal_to_its_input_through_a_link(tmp_path, result_csv, capsys):
    before = result_csv.read_bytes()
    link = tmp_path / "picture.png"
    link.symlink_to(result_csv)
    code, _, err = run(capsys, "plot", result_csv, "-o", link)
    assert code == 2 and "is the input file" in one_line(err)
    assert result_csv.read_bytes() == before


def test_same_output_twice(tmp_path, case, capsys):
    out = tmp_path / "a.csv"
    code, _, err = run(capsys, "solve", case, "-o", out, "-o", tmp_path / "." / "a.csv")
    assert code == 2 and "given twice" in one_line(err)
    assert not out.exists()


def test_symlink_output_is_written_through_to_its_target(tmp_path, case, result_csv, capsys):
    target = tmp_path / "target.json"
    target.write_text("old", encoding="utf-8")
    link = tmp_path / "link.json"
    link.symlink_to(target)
    code, _, err = run(capsys, "solve", case, "-o", link)
    assert code == 0, err
    assert link.is_symlink() and os.readlink(link) == str(target)  # the link is kept
    written = io.load_result(target)  # and its target holds the result
    expected = io.load_result(result_csv)
    np.testing.assert_allclose(written.poses, expected.poses, rtol=0, atol=1e-15)


def test_disk_full_exit_1_one_line_and_the_old_output_intact(tmp_path, case, result_csv,
                                                             capsys, monkeypatch):
    before = result_csv.read_bytes()
    real_fdopen = os.fdopen

    class FullDisk:
        """A stream whose writes fail as on a full disk (ENOSPC)."""

        def __init__(self, stream):
            self.stream = stream

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.stream.close()

        def write(self, data):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(io.os, "fdopen", lambda *a, **k: FullDisk(real_fdopen(*a, **k)))
    code, _, err = run(capsys, "solve", case, "-o", result_csv)
    assert code == 1
    line = one_line(err)
    assert str(result_csv) in line and os.strerror(errno.ENOSPC) in line
    assert result_csv.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["moment.toml", "result.csv"]


def _limit_file_size():  # runs in the child before exec: 4 kB files at most
    import resource

    resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))


@pytest.mark.skipif(sys.platform == "win32", reason="RLIMIT_FSIZE is POSIX")
@pytest.mark.slow
def test_file_size_limit_exit_1_in_a_real_process(tmp_path, case, result_csv):
    before = result_csv.read_bytes()
    assert len(before) > 4096  # the result does not fit under the limit
    done = subprocess.run([sys.executable, "-m", "softarm", "solve", str(case), "-o",
                           str(result_csv)], capture_output=True, text=True, timeout=300,
                          preexec_fn=_limit_file_size, check=False)
    assert done.returncode == 1, done.stderr
    line = one_line(done.stderr)
    assert str(result_csv) in line and os.strerror(errno.EFBIG) in line
    assert result_csv.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["moment.toml", "result.csv"]


def test_reproduce_into_a_file_is_one_line(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x", encoding="utf-8")
    code, _, err = run(capsys, "reproduce", "--out", blocker, "--case", "pure_torsion",
                       "--no-figures")
    assert code == 2
    assert str(blocker) in one_line(err)
    assert blocker.read_text(encoding="utf-8") == "x"


# --- sizes that cannot be allocated -----------------------------------------------------------

def test_stations_1e9_rejected_with_the_memory_it_needs(case, capsys, monkeypatch):
    # 1e9 stations × 28 float64 (pose 16, strains 6, stresses 6) = 224 GB; the limit is pinned
    # to 8 GB here so that the test does not depend on this machine's memory.
    monkeypatch.setattr(_validate, "memory_limit", lambda: 8 * 10**9)
    code, _, err = run(capsys, "solve", case, "--stations", "1e9")
    assert code == 2
    line = one_line(err)
    assert "1000000000 stations" in line and "224 GB" in line and "8 GB" in line


def test_sweep_sizes_rejected_before_parsing_on(tmp_path, capsys):
    # 1e11 steps × (101 stations × 224 B + 640 B) = 2.33 PB, and 1e7 × (101 × 224 B + 640 B)
    # = 233 GB, and the work of the parts (_validate.check_allocation): 234 GB; more than any
    # machine this runs on has (half of its memory is the limit).
    for steps, need in (("1e11", "2.33 PB"), ("100000000000", "2.33 PB"),
                        ("10000000", "234 GB")):
        path = tmp_path / "sweep.toml"
        path.write_text(MOMENT_CASE + f"[sweep]\nstart = 0.0\nstop = 1.0\nsteps = {steps}\n",
                        encoding="utf-8")
        code, _, err = run(capsys, "solve", path)
        assert code == 2
        line = one_line(err)
        assert "sweep.steps" in line and need in line, line


def test_library_rejects_a_batch_before_allocating(monkeypatch):
    # 1000 cases × (101 stations × 224 B + 640 B) = 23.3 MB for the result and the work of
    # one part, 3 × 1000 × 12288 B = 36.9 MB: 60.1 MB against a limit pinned to 1 MB
    monkeypatch.setattr(_validate, "memory_limit", lambda: 10**6)
    arm = softarm.Arm.from_stiffness(1.0, 1e6, 1e6, 1e6, 1.0, 1.0, 1.0)
    moments = np.zeros((1000, 3))
    moments[:, 1] = 1.0
    for method in ("auto", "numeric"):
        with pytest.raises(ValueError, match=r"1000 load cases × 101 stations would need "
                                             r"60\.1 MB"):
            softarm.solve(arm, softarm.TipLoad(moment=moments), method=method)
    # 10⁵ stations × 224 B + 640 B, and 3 × 12288 B of work: 22.4 MB
    with pytest.raises(ValueError, match=r"s: 1 load case × 100000 stations would need 22\.4 MB"):
        softarm.analytic.tip_moment(arm, [0.0, 1.0, 0.0], s=100_000)
    small = softarm.solve(arm, softarm.TipLoad(moment=moments[:10]), s=11)  # 400 kB: fine
    assert small.poses.shape == (10, 11, 4, 4)


# --- lengths beyond float64 -------------------------------------------------------------------

@pytest.mark.parametrize(("build", "name"), [
    (lambda: softarm.Arm(1e-300, softarm.Circle(0.01), softarm.Material(1e6, 0.5)),
     "Arm.length"),
    (lambda: softarm.Arm(1e300, softarm.Circle(0.01), softarm.Material(1e6, 0.5)),
     "Arm.length"),
    (lambda: softarm.Arm.from_stiffness(1e-300, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0), "Arm.length"),
    (lambda: softarm.Circle(1e100), "Circle.radius"),
    (lambda: softarm.Circle(1e-300), "Circle.radius"),
    (lambda: softarm.Tube(1e200, 1.0), "Tube.outer_radius"),
    (lambda: softarm.Rectangle(1e-200, 0.01), "Rectangle.width"),
])
def test_extreme_lengths_rejected_at_construction(build, name):
    # r = 1e-300 would give the area π r² = 0 and r = 1e100 would overflow r⁴; L = 1e-300 or
    # 1e300 would overflow EI/L². The message names the given length, not a derived quantity.
    with pytest.raises(ValueError, match=rf"^{name.replace('.', '[.]')} must be a length in m "
                                         r"between 1e-12 and 1e\+12"):
        build()


def test_extreme_length_in_a_case_file(tmp_path, capsys):
    path = tmp_path / "tiny.toml"
    path.write_text(MOMENT_CASE.replace("length = 1.0", "length = 1e-300"), encoding="utf-8")
    code, _, err = run(capsys, "solve", path)
    assert code == 2 and "tiny.toml: arm.length: must be a length in m" in one_line(err)
    path.write_text(MOMENT_CASE.replace(
        "stiffness = { EA = 1e6, GAy = 1e6, GAz = 1e6, GJ = 1.0, EIy = 1.0, EIz = 1.0 }",
        "section = { kind = 'circle', radius = 1e100 }\nmaterial = { E = 1e6, nu = 0.5 }"),
        encoding="utf-8")
    code, _, err = run(capsys, "solve", path)
    assert code == 2 and "tiny.toml: arm.section.radius: must be a length in m" in one_line(err)


# --- softarm plot on broken result files ------------------------------------------------------

def _json_variant(tmp_path, result_csv, name, change) -> Path:
    source = result_csv.with_suffix(".json")
    if not source.exists():
        io.save_result(io.load_result(result_csv), source, io.load_saved(result_csv).case)
    document = json.loads(source.read_text(encoding="utf-8"))
    change(document)
    path = tmp_path / name
    path.write_text(json.dumps(document), encoding="utf-8")
    return path


def test_plot_on_broken_files_is_one_short_line(tmp_path, result_csv, capsys):
    saved = io.load_saved(result_csv)
    npz = io.save_result(saved.result, tmp_path / "good.npz", saved.case)
    data = npz.read_bytes()
    broken = {
        "truncated.npz": data[: len(data) // 2],
        "garbage.npz": b"\x00garbage" * 100,
        "empty.json": b"",
    }
    for name, content in broken.items():
        (tmp_path / name).write_bytes(content)

    def nan_pose(d):
        d["poses"][7][0][3] = float("nan")

    def short_poses(d):
        d["poses"] = d["poses"][:5]

    def exact_no(d):
        d["exact"] = "no"

    def string_column(d):
        d["columns"]["x_m"][3] = "0.5"

    def wrong_position(d):
        d["columns"]["z_m"][50] += 1e-3

    for change in (nan_pose, short_poses, exact_no, string_column, wrong_position):
        _json_variant(tmp_path, result_csv, f"{change.__name__}.json", change)
    # an NPZ whose poses have the wrong size
    with np.load(npz) as z:
        arrays = dict(z)
    arrays["poses"] = arrays["poses"][:50]
    np.savez(tmp_path / "short.npz", **arrays)
    # a CSV with a NaN row
    lines = result_csv.read_text(encoding="utf-8").splitlines()
    row = next(i for i, line in enumerate(lines) if line and not line.startswith("#")) + 20
    lines[row] = ",".join(["nan"] * len(lines[row].split(",")))
    (tmp_path / "nan_row.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")

    expected = {
        "truncated.npz": "not an NPZ archive", "garbage.npz": "not an NPZ archive",
        "empty.json": "not a softarm result file", "nan_pose.json": "'poses' is not finite",
        "short_poses.json": "'poses' has shape (5, 4, 4), expected (101, 4, 4)",
        "exact_no.json": "'exact' must be true or false, got 'no'",
        "string_column.json": "numbers only",
        "wrong_position.json": "disagree with the positions",
        "short.npz": "'poses' has shape (50, 4, 4)",
        "nan_row.csv": f"line {row + 1}: column 's_m' is not finite",
    }
    for name, message in expected.items():
        path = tmp_path / name
        code, _, err = run(capsys, "plot", path)
        assert code == 2, (name, err)
        line = one_line(err)
        assert line.startswith(f"softarm: error: {path}") and message in line, line
        assert len(line) < 250, line
        assert not path.with_suffix(".png").exists()
    # the library says the same (a CaseError is a ValueError)
    with pytest.raises(ValueError, match="'exact' must be true or false"):
        io.load_result(tmp_path / "exact_no.json")


# --- Ctrl-C -----------------------------------------------------------------------------------

# A numerical sweep long enough to be interrupted at every moment below (gravity and a tip
# force have no closed form): the solver works in chunks, returning to Python often.
LONG_SWEEP = """\
name = "long"
[arm]
length = 0.3
section = { kind = "circle", radius = 0.01 }
material = { E = 1.5e6, nu = 0.49, density = 1070.0 }
[[load]]
kind = "gravity"
[[load]]
kind = "tip"
force = [0.0, 0.1, -0.2]
[solve]
tol = 1e-12
stations = 11
[sweep]
load = 2
start = 0.0
stop = 0.4
steps = 20000
"""


@pytest.mark.parametrize("delay", [0.3, 1.0, 3.0])
@pytest.mark.slow
def test_ctrl_c_at_any_moment_exit_130_one_line(tmp_path, delay):
    """SIGINT while the command imports numpy/numba (0.3 s), later while it reads, compiles or
    solves: exit 130, one line, no output file. Run as the ``softarm`` entry point does."""
    case = tmp_path / "long.toml"
    case.write_text(LONG_SWEEP, encoding="utf-8")
    out = tmp_path / "out.csv"
    launcher = "import sys, _softarm_cli; sys.exit(_softarm_cli.main())"
    process = subprocess.Popen(
        [sys.executable, "-c", launcher, "solve", str(case), "-o", str(out)],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(delay)
    assert process.poll() is None, "finished before the interrupt"
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert one_line(err) == "softarm: interrupted"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.toml"]


@pytest.mark.parametrize("became", [ImportError("initialization failed"), ValueError("bad")])
def test_a_ctrl_c_that_a_c_extension_turns_into_another_error_is_still_a_ctrl_c(
        monkeypatch, capsys, became):
    """Found by CI: a SIGINT landing in scipy's HiGHS wrapper while the parser imports
    ``softarm reproduce`` (pybind11 turns the KeyboardInterrupt of its initialisation into
    "ImportError: initialization failed") gave a traceback and exit 1. The same as a test:
    the handler runs (as the signal would) and something turns its KeyboardInterrupt into
    another error, either escaping the command or caught by its own error handling (a
    ValueError is "bad input", exit 2): exit 130, one line."""
    def parser_interrupted_in_an_import():
        try:
            cli._Interrupt.handler(signal.SIGINT, None)
        except KeyboardInterrupt as interrupt:
            raise became from interrupt
        raise AssertionError("the handler did not raise")

    if isinstance(became, ImportError):
        monkeypatch.setattr(cli, "_parser", parser_interrupted_in_an_import)
        argv = ["--version"]
    else:
        original = cli._parser

        def parser():
            built = original()
            solve = built._subparsers._group_actions[0].choices["solve"]
            solve.set_defaults(run=lambda args: parser_interrupted_in_an_import())
            return built

        monkeypatch.setattr(cli, "_parser", parser)
        argv = ["solve", "nothing.toml"]
    assert cli.main(argv) == 130
    assert one_line(capsys.readouterr().err) == "softarm: interrupted"


def test_a_ctrl_c_between_the_entry_scripts_import_and_its_call_is_a_ctrl_c():
    """Found by CI: pip's entry script runs lines of its own (a re.sub of argv[0]) between
    ``from _softarm_cli import main`` and ``main()``; a SIGINT there (at 0.05 s) raised from
    the handler outside any try: a traceback and death by SIGINT. The signal sent in exactly
    that gap: exit 130, one line, and main() returns before importing softarm at all."""
    launcher = ("import os, signal, sys, _softarm_cli\n"
                "os.kill(os.getpid(), signal.SIGINT)\n"
                "sys.exit(_softarm_cli.main() + 100 * ('softarm.cli' in sys.modules))")
    run = subprocess.run([sys.executable, "-c", launcher, "--version"], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 130, run.stderr
    assert one_line(run.stderr) == "softarm: interrupted"
