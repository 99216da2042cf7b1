"""The ``softarm`` command: solve a case file, export the result, plot it, and the rest.

The commands, their options, exit codes and output rules are documented in docs/cli.md (a
test compares it with this parser): 0 success; 1 a failure (the solver did not converge, a
state outside the model, a failed check of ``softarm reproduce``, a full disk, out of memory,
a sweep worker killed); 2 bad input (one line naming the file, the key and what is wrong);
130 interrupted (Ctrl-C). Every error is one line on stderr, never a traceback. Outputs are
written to a temporary file beside the target and renamed, so a failure never leaves a
half-written result and an existing output stays intact.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import contextlib
import errno
import importlib.util
import os
import signal
import sys
import threading
import time
import warnings
from collections.abc import Sequence
from importlib import resources
from pathlib import Path

import numpy as np

from . import __version__
from .case import Case, CaseError, load_case
from .errors import ConvergenceError, InadmissibleStateError, StabilityWarning
from .io import FORMATS, load_saved, read_trajectory, save_result
from .statics.tip_contact import METHOD as TIP_CONTACT
from .sweep import solve_case

__all__ = ["main"]

_PICTURE_SUFFIXES = (".png", ".pdf", ".svg")


class _Progress:
    """A plain-text progress bar on stderr, shown only once a run has taken over ``delay``
    seconds and redrawn at most every 0.1 s: ``solving [###...] 12/40 steps, 3.1 s``, or with
    ``rate=True`` (a sweep) ``sweep [###...] 1200/10000 cases, 512 cases/s, ETA 0:17`` and the
    number of failed cases. The rate counts from the first report (after resuming)."""

    def __init__(self, stream=None, delay: float = 1.0, width: int = 30, *,
                 label: str = "solving", unit: str = "steps", rate: bool = False):
        self.stream = sys.stderr if stream is None else stream
        self.delay = delay
        self.width = width
        self.label, self.unit, self.rate = label, unit, rate
        self.start = time.perf_counter()
        self.first: tuple[float, int] | None = None
        self.shown = False
        self.last = 0.0

    def __call__(self, done: int, total: int, failed: int = 0) -> None:
        if self.first is None:
            self.first = (time.perf_counter(), done)
        if done == total and not self.shown:
            _Interrupt.check()
            return  # finished before the bar was due: nothing to show
        self.line(lambda now: self._bar(now, done, total, failed), final=done >= total)

    def line(self, text, final: bool = False) -> None:
        """Redraw the line ``text(now)`` (a callable: built only when it is drawn) once the
        delay has passed, at most every 0.1 s unless ``final``."""
        _Interrupt.check()  # a Ctrl-C that something below swallowed
        now = time.perf_counter()
        if (now - self.start < self.delay or now - self.last < 0.1) and not final:
            return
        self.last = now
        self.stream.write("\r" + text(now))
        self.stream.flush()
        self.shown = True

    def _bar(self, now: float, done: int, total: int, failed: int) -> str:
        filled = round(self.width * done / max(total, 1))
        bar = "#" * filled + "." * (self.width - filled)
        text = f"{self.label} [{bar}] {done}/{total} {self.unit}"
        if self.rate:
            elapsed = now - self.first[0]
            rate = (done - self.first[1]) / elapsed if elapsed > 0 else 0.0
            if rate > 0:
                text += f", {rate:.4g} {self.unit}/s, ETA {_duration((total - done) / rate)}"
        else:
            text += f", {now - self.start:.1f} s"
        if failed:
            text += f", {failed} failed"
        return text

    def close(self) -> None:
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()
            self.shown = False


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line on stderr (exit code 2), like every other bad input."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _integer(text: str, least: int) -> int:
    try:
        value = int(text)
    except ValueError:
        try:  # an integer written as a float, e.g. 1e3
            number = float(text)
        except ValueError:
            number = None
        if number is None or not number.is_integer():
            raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None
        value = int(number)
    if value < least:
        raise argparse.ArgumentTypeError(f"must be >= {least}, got {value}")
    return value


def _stations(text: str) -> int:
    return _integer(text, 2)


def _every(text: str) -> int:
    return _integer(text, 1)


def _tolerance(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text!r}")
    return value


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value


def _fields(text: str) -> tuple[str, ...]:
    from .sweep import FIELDS

    names = tuple(name.strip() for name in text.split(",") if name.strip())
    unknown = [n for n in names if n not in FIELDS]
    if unknown or not names:
        raise argparse.ArgumentTypeError(f"must be among {', '.join(FIELDS)}, got {text!r}")
    return names


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="softarm",
        description="Static equilibria of soft robotic arms (Cosserat rods on SE(3)).",
        epilog="Case files are documented in docs/case-files.md. Start with: softarm demo",
    )
    parser.add_argument("--version", action="version", version=f"softarm {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    solve = commands.add_parser("solve", help="solve a case file, print a summary, export",
                                description="Solve a TOML case file (every step of its "
                                "[sweep], if any), print a summary and write what is asked.")
    solve.add_argument("case", metavar="CASE.toml", help="case file")
    solve.add_argument("-o", "--output", action="append", default=[], metavar="OUT",
                       help="write the result to OUT (.csv, .json or .npz; may be repeated)")
    solve.add_argument("--plot", metavar="PICTURE", help="draw the result (.png, .pdf, .svg)")
    solve.add_argument("--method", choices=("auto", "numeric"),
                       help="override [solve] method (default from the file, else auto)")
    solve.add_argument("--stations", type=_stations, metavar="N",
                       help="number of output stations (default from the file, else 101)")
    solve.add_argument("--tol", type=_tolerance,
                       help="tip position tolerance relative to the arm length (default 1e-8)")
    solve.set_defaults(run=_run_solve)

    simulate = commands.add_parser(
        "simulate", help="simulate a case's [simulate] table over time, export the trajectory",
        description="Run the case file's [simulate] table (the arm's motion under its loads, "
        "actuator schedules and base motion; every step of a one-parameter [sweep] at once) "
        "with a progress bar, print a summary and write the trajectory. Ctrl-C or a step "
        "that cannot be solved keeps the steps done so far: they are written, marked "
        "incomplete.")
    simulate.add_argument("case", metavar="CASE.toml", help="case file with a [simulate] table")
    simulate.add_argument("-o", "--output", action="append", default=[], metavar="OUT",
                          help="write the trajectory to OUT (.npz, .zarr or .csv; may be "
                          "repeated)")
    simulate.add_argument("--plot", metavar="PICTURE",
                          help="draw snapshots, the tip's path and the energies (.png, .pdf, "
                          ".svg)")
    simulate.add_argument("--every", type=_every, default=1, metavar="K",
                          help="keep every K-th time step in the outputs (the first time "
                          "included; default 1: every step)")
    simulate.set_defaults(run=_run_simulate)

    critical = commands.add_parser(
        "critical", help="the critical load factor of a case and its buckling mode",
        description="Scale the case's loads (or those given with --vary) by a load factor λ "
        "from 0 and print the smallest λ at which the arm loses stability (softarm."
        "critical_load), its kind (fold or bifurcation), nullity and mode.")
    critical.add_argument("case", metavar="CASE.toml", help="case file (no [sweep])")
    critical.add_argument("--vary", type=int, action="append", metavar="K",
                          help="scale only load K (counted from 1 as in the file; may be "
                          "repeated); the others are held at their value")
    critical.add_argument("--max-factor", type=_tolerance, default=10.0, metavar="F",
                          help="largest load factor searched (default 10)")
    critical.set_defaults(run=_run_critical)

    plot = commands.add_parser("plot", help="re-plot a saved result",
                               description="Re-plot a result written by 'softarm solve -o'.")
    plot.add_argument("result", metavar="RESULT", help="result file (.csv, .json or .npz)")
    plot.add_argument("-o", "--output", metavar="PICTURE",
                      help="picture to write (default: RESULT with suffix .png)")
    plot.set_defaults(run=_run_plot)

    view = commands.add_parser(
        "view", help="write an interactive 3D view of a saved result (HTML)",
        description="Write a self-contained HTML file (opens offline in any browser) with an "
        "interactive 3D view of a result written by 'softarm solve -o': the arm as a tube, "
        "hover read-outs, the loads; a sweep gets a slider. A trajectory (written by softarm "
        "simulate): the moving arm with a time slider, play at "
        "real time or a chosen rate, the tip's path and the energy plot. Needs pip install "
        "'softarm[view]'.")
    view.add_argument("result", metavar="RESULT",
                      help="result file (.csv, .json or .npz) or trajectory file (softarm "
                      "simulate's .npz, .zarr or .csv)")
    view.add_argument("--case", type=_positive, metavar="K",
                      help="of a trajectory file of a sweep of simulations, the case to view "
                      "(counted from 1; default 1)")
    view.add_argument("-o", "--output", metavar="HTML",
                      help="HTML file to write (default: RESULT with suffix .html)")
    view.set_defaults(run=_run_view)

    app = commands.add_parser(
        "app", help="explore a case live in the browser, with a slider per load",
        description="Serve a live view of a case on http://127.0.0.1:PORT: a slider for each "
        "load component re-solves the arm (following it from its last equilibrium) and "
        "redraws it. Ctrl-C stops it. Needs pip install 'softarm[view]'.")
    app.add_argument("case", metavar="CASE.toml", help="case file")
    app.add_argument("--port", type=_port, default=8050,
                     help="TCP port on 127.0.0.1 (default 8050; 0: any free port)")
    app.add_argument("--no-browser", action="store_true",
                     help="do not open a browser tab, only print the address")
    app.add_argument("--dynamic", action="store_true",
                     help="the arm in motion: the sliders drive a simulation stepped in real "
                     "time (softarm.Simulator) and the page shows the arm swinging; the "
                     "default for a case with a [simulate] table (its dt, stations, damping)")
    app.add_argument("--static", action="store_true",
                     help="the static app even for a case with a [simulate] table")
    app.add_argument("--dt", type=_seconds, metavar="DT",
                     help="the dynamic mode's time step in s (default: the [simulate] "
                     "table's, else 0.002; implies --dynamic)")
    app.add_argument("--damping", type=_seconds, metavar="TAU",
                     help="the dynamic mode's Kelvin-Voigt retardation time in s (default: "
                     "the [simulate] table's, else undamped; implies --dynamic)")
    app.set_defaults(run=_run_app)

    inverse = commands.add_parser(
        "inverse", help="find the actuation inputs that bring the tip to a target",
        description="Find the tensions, pressures or field components (the case's actuator "
        "loads) that bring the tip to a target position, under the case's other loads, and "
        "print them with the equilibrium they produce. The target comes from --target or "
        "the file's [inverse] table (docs/control.md).")
    inverse.add_argument("case", metavar="CASE.toml", help="case file")
    inverse.add_argument("--target", type=float, nargs=3, metavar=("X", "Y", "Z"),
                         help="tip target in m, spatial frame (default: [inverse] target)")
    inverse.add_argument("-o", "--output", action="append", default=[], metavar="OUT",
                         help="write the equilibrium reached (.csv, .json or .npz)")
    inverse.add_argument("--plot", metavar="PICTURE", help="draw it (.png, .pdf, .svg)")
    inverse.set_defaults(run=_run_inverse)

    sweep = commands.add_parser(
        "sweep", help="solve a [sweep] design into a resumable Zarr store",
        description="Solve every case of the case file's [sweep] (a design over any "
        "parameters, or a one-parameter sweep) in chunks, in-process, on N local processes or "
        "a Dask cluster, into a Zarr store that softarm.open_sweep reads with xarray. Needs "
        "pip install 'softarm[sweep]' ('softarm[dask]' for --scheduler).")
    sweep.add_argument("case", metavar="CASE.toml", help="case file with a [sweep] table")
    sweep.add_argument("-o", "--output", required=True, metavar="OUT.zarr",
                       help="Zarr store to write (a folder)")
    sweep.add_argument("--workers", type=_positive, default=1, metavar="N",
                       help="local worker processes (default 1: in this process); with "
                       "--scheduler local, the LocalCluster's workers")
    sweep.add_argument("--scheduler", metavar="ADDRESS",
                       help="'local' (a Dask LocalCluster of --workers processes) or a Dask "
                       "scheduler address such as tcp://host:8786")
    sweep.add_argument("--resume", action="store_true",
                       help="finish the chunks an interrupted run of the same sweep left, "
                       "with the options the store was started with")
    sweep.add_argument("--fields", type=_fields, metavar="F,...",
                       help="outputs to keep, comma-separated, among tip, positions, "
                       "orientations, poses, strains, stresses (default tip,positions)")
    sweep.add_argument("--stations", type=_stations, metavar="N",
                       help="number of output stations (default from the file, else 101)")
    sweep.add_argument("--dtype", choices=("float64", "float32"),
                       help="of the stored outputs (default float64)")
    sweep.add_argument("--chunk", type=_positive, metavar="N",
                       help="cases per chunk (task and store chunk; default up to 1000)")
    sweep.add_argument("--path", action="store_true", default=None,
                       help="follow a one-parameter load sweep quasi-statically, serially, "
                       "instead of solving each case from the unloaded arm")
    sweep.add_argument("--method", choices=("auto", "numeric"),
                       help="override [solve] method (default from the file, else auto)")
    sweep.add_argument("--tol", type=_tolerance,
                       help="tip position tolerance relative to the arm length (default 1e-8)")
    sweep.set_defaults(run=_run_sweep)

    demo = commands.add_parser("demo", help="solve and plot a built-in example",
                               description="Solve the built-in two-segment silicone arm under "
                               "gravity and a tip load; write demo.png and demo.csv.")
    demo.add_argument("--out", metavar="DIR", default=".",
                      help="folder for demo.png and demo.csv (default: the working directory)")
    demo.set_defaults(run=_run_demo)

    from .warmup import STEPS  # (softarm's own modules: no numba until a step runs)

    compile_ = commands.add_parser(
        "compile", help="compile softarm's kernels ahead of time",
        description="Compile the kernels a first solve needs ("
        + "; ".join(step.text for step in STEPS if step.first) + "), or with --all those of "
        "every capability (" + "; ".join(step.text for step in STEPS if not step.first)
        + "), and cache them: for a container build or a cluster image. Each capability "
        "otherwise compiles on its first use; a cached one loads in a fraction of a second.")
    compile_.add_argument("--all", action="store_true",
                          help="every capability, not only what a first solve needs")
    compile_.add_argument("--jobs", type=_positive, default=None, metavar="N",
                          help="with --all, compile on N cores at once (default: every core "
                          "of this machine, at most 4)")
    compile_.set_defaults(run=_run_compile)

    from .validation import add_parser as add_reproduce  # softarm reproduce [--out DIR] (#6)

    add_reproduce(commands)
    return parser


class _Interrupt:
    """SIGINT while the command runs: raise KeyboardInterrupt, as Python does, and remember it.

    A KeyboardInterrupt raised while numba is inside a ctypes callback (llvmlite's object
    cache, called from LLVM's C code right after the long machine-code step of a compile or a
    cache load: where a Ctrl-C during a compile most often lands) is swallowed there, and
    Python prints "Exception ignored on calling ctypes callback function" with a traceback;
    the command would go on, even write its outputs. So :meth:`unraisable` (the command's
    ``sys.unraisablehook``) drops that message and delivers the interrupt again from another
    thread a moment later (``_thread.interrupt_main``), when the main thread is back in
    Python code; and :meth:`check`, at every progress report and before the outputs are
    written, raises any interrupt still pending. Once the command starts writing its outputs
    (``done``: :func:`_write`, or the command's end), a Ctrl-C is only remembered: the exit
    status is the command's, and 130 means that nothing was written.
    """

    seen = False
    done = False

    @classmethod
    def handler(cls, signum, frame):
        cls.seen = True
        if not cls.done:
            raise KeyboardInterrupt

    @classmethod
    def check(cls) -> None:
        if cls.seen and not cls.done:
            raise KeyboardInterrupt

    @classmethod
    def unraisable(cls, previous):
        def hook(unraisable):
            if not (isinstance(unraisable.exc_value, KeyboardInterrupt)
                    or unraisable.exc_type is KeyboardInterrupt):
                return previous(unraisable)
            cls.seen = True
            if not cls.done:
                again = threading.Timer(0.01, cls._again)
                again.daemon = True
                again.start()
            return None
        return hook

    @classmethod
    def _again(cls) -> None:
        """Run the handler again in the main thread, if the command still runs."""
        if not cls.done and signal.getsignal(signal.SIGINT) == cls.handler:
            import _thread

            _thread.interrupt_main()


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``softarm`` command with ``argv`` (default ``sys.argv[1:]``); return the exit
    code (see the module docstring and docs/cli.md)."""
    _Interrupt.seen = _Interrupt.done = False
    previous = mask = None
    with contextlib.suppress(ValueError, OSError):  # ValueError: not the main thread
        previous = signal.signal(signal.SIGINT, _Interrupt.handler)
    hook, sys.unraisablehook = sys.unraisablehook, _Interrupt.unraisable(sys.unraisablehook)
    try:
        if previous is not None and hasattr(signal, "pthread_sigmask"):
            # the launcher (src/_softarm_cli.py) holds a Ctrl-C until this handler is in place
            mask = signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
        code = _main(argv)
        _Interrupt.done = True
        return code
    except KeyboardInterrupt:
        return interrupted()
    except BaseException:
        # A C extension may turn the KeyboardInterrupt raised in its initialisation into
        # another error (scipy's HiGHS wrapper, imported by `softarm reproduce`'s parser:
        # "ImportError: initialization failed"): what decides is the memory of the Ctrl-C.
        if _Interrupt.seen and not _Interrupt.done:
            return interrupted()
        raise
    finally:
        _Interrupt.done = True
        sys.unraisablehook = hook
        if mask is not None:  # held again if it was held (the launcher's exit)
            with contextlib.suppress(ValueError, OSError):
                signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        if previous is not None and signal.getsignal(signal.SIGINT) == _Interrupt.handler:
            with contextlib.suppress(ValueError, OSError):
                signal.signal(signal.SIGINT, previous)


def _main(argv: Sequence[str] | None) -> int:
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:  # argparse reports usage errors itself, with code 2
        return int(exit_.code or 0) if not isinstance(exit_.code, str) else 2
    try:
        return args.run(args)
    except CaseError as error:
        return _fail(2, f"softarm: error: {error}")
    except InadmissibleStateError as error:  # the model has no equilibrium there
        return _fail(1, f"softarm: no equilibrium: {error}")
    except ConvergenceError as error:  # (its message says what and why, with the residual)
        return _fail(1, f"softarm: the solver did not converge: {error}")
    except BrokenPipeError:  # e.g. `softarm solve case.toml | head`
        with contextlib.suppress(OSError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as error:  # writing an output: full disk, size limit, permissions, ...
        where = f"{error.filename}: " if error.filename else ""
        what = error.strerror or str(error)
        code = 1 if error.errno in _FAILURES else 2
        return _fail(code, f"softarm: error: {where}cannot write: {what}")
    except MemoryError:
        return _fail(1, "softarm: out of memory (solve fewer cases or stations at a time)")
    except (ValueError, TypeError) as error:  # bad input found by the library
        return _fail(2, f"softarm: error: {error}")


#: errno values of an OSError that are a failure of the machine (exit 1), not bad input.
_FAILURES = {errno.ENOSPC, errno.EFBIG, errno.EIO, getattr(errno, "EDQUOT", errno.ENOSPC)}


def _line(message: str, limit: int = 600) -> str:
    """``message`` on one line, cut to ``limit`` characters (no multi-line array dumps)."""
    text = " ".join(str(message).split())
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _fail(code: int, message: str) -> int:
    if code != 130:  # an error that a Ctrl-C became (in a C extension) is the Ctrl-C
        _Interrupt.check()
    print(_line(message), file=sys.stderr)
    return code


def interrupted(what: str = "interrupted") -> int:
    """Ctrl-C: say so in one line and return 130; a second Ctrl-C is ignored from here on."""
    with contextlib.suppress(ValueError, OSError):  # ValueError: not the main thread
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(OSError, ValueError):
        print(f"softarm: {what}", file=sys.stderr, flush=True)
    return 130


# --------------------------------------------------------------------------------------------


def _check_picture(path: str, inputs=(), taken=()) -> Path:
    """:func:`_check_output` of a picture, where matplotlib is installed (checked before any
    solve: no output is written)."""
    if importlib.util.find_spec("matplotlib") is None:
        raise CaseError(f"{path}: drawing a picture needs matplotlib, which is not installed: "
                        'pip install "softarm[plot]"')
    return _check_output(path, _PICTURE_SUFFIXES, "picture", inputs, taken)


def _check_output(path: str, suffixes: tuple[str, ...], what: str, inputs=(),
                  taken=()) -> Path:
    """An output path that can be written: a known suffix, an existing folder, not a folder
    itself, not one of ``inputs`` nor ``taken`` (the other outputs), even through a link."""
    out = Path(path)
    if out.suffix.lower() not in suffixes:
        raise CaseError(f"{out}: unknown {what} format {out.suffix or '(no suffix)'!r}; use "
                        f"one of {', '.join(suffixes)}")
    target = Path(os.path.realpath(out))  # a symbolic link is written through to its target
    if not target.parent.is_dir():
        raise CaseError(f"{out}: folder {target.parent} does not exist")
    if target.is_dir():
        raise CaseError(f"{out}: is a folder; give a file name ending in {suffixes[0]}")
    for other in inputs:
        if _same_file(out, Path(other)):
            raise CaseError(f"{out}: is the input file {other}; choose another output")
    for other in taken:
        if _same_file(out, Path(other)):
            raise CaseError(f"{out}: given twice as an output")
    return out


def _same_file(a: Path, b: Path) -> bool:
    """True if ``a`` and ``b`` name the same file (links and relative paths resolved)."""
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
    except OSError:
        return False
    return os.path.realpath(a) == os.path.realpath(b)


def _solve(case: Case, args) -> tuple:
    progress = _Progress()
    start = time.perf_counter()
    # A single solve has no steps to count; say that something is happening if it is slow
    # (a first compile announces itself, with its time: softarm._jit)
    notice = threading.Timer(2.0, lambda: print("solving...", file=sys.stderr, flush=True))
    notice.daemon = True
    if case.sweep is None:
        notice.start()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", StabilityWarning)
            result = solve_case(case, method=args.method, stations=args.stations,
                                tol=args.tol, progress=progress)
    except (ValueError, TypeError) as error:  # the solver rejected the case's data
        raise CaseError(_named(error, case.source or case.name)) from None
    finally:
        notice.cancel()
        progress.close()
    _report(caught)
    return result, time.perf_counter() - start


def _named(error: Exception, *where) -> str:
    """The error's message, starting with the first of ``where`` (a file) unless it starts
    with one of them already (the library names the file itself where it knows it)."""
    text = str(error)
    if any(text.startswith(f"{w}: ") for w in where):
        return text
    return f"{where[0]}: {text}"


def _report(caught) -> None:
    """Warnings caught around a solve: a StabilityWarning as one line on stderr, anything
    else as Python shows it."""
    for warning in caught:
        if issubclass(warning.category, StabilityWarning):
            print(_line(f"softarm: warning: {str(warning.message).removeprefix('softarm: ')}"),
                  file=sys.stderr)
        else:
            warnings.showwarning(warning.message, warning.category, warning.filename,
                                 warning.lineno)


def _run_critical(args) -> int:
    case = load_case(args.case)
    if case.sweep is not None:
        raise CaseError(f"{case.source or case.name}: softarm critical takes a case without "
                        "[sweep] (the load factor is the sweep)")
    vary = None
    if args.vary:
        for k in args.vary:
            if not 1 <= k <= len(case.loads):
                raise CaseError(f"--vary {k}: the case has {len(case.loads)} loads "
                                "(counted from 1)")
        vary = [case.loads[k - 1] for k in args.vary]
    from .stability import critical_load

    start = time.perf_counter()
    point = critical_load(case.arm, case.loads, vary, max_factor=args.max_factor)
    seconds = time.perf_counter() - start
    from .plot import describe_loads

    lines = [f"case      {case.name}" + (f"  ({case.source})" if case.source else ""),
             f"loads     {describe_loads(case.loads, None)}",
             "varied    " + ("all loads" if vary is None else
                            ", ".join(f"load {k}" for k in args.vary))]
    if point is None:
        lines.append(f"critical  none: stable up to load factor {args.max_factor:g}")
    else:
        mode = point.mode
        lines += [
            f"critical  load factor λc = {point.factor:.12g} ({point.kind}, nullity "
            f"{point.nullity}; Morse index {point.index_before} -> {point.index_after})",
        ]
        for i in range(point.nullity):
            tip = mode.displacement[i, -1]
            k = int(np.argmax(np.linalg.norm(mode.displacement[i], axis=-1)))
            lines += [
                f"mode {i + 1}    base reaction change (null vector of ∂r/∂x) "
                f"{_vector(mode.base_reaction[i])} (N, N m)",
                f"          tip displacement direction {_vector(tip)}, largest at s = "
                f"{mode.s[k]:.4g} m",
            ]
    lines.append(f"time      {seconds:.3g} s")
    print("\n".join(lines))
    return 0


def _outputs(args) -> tuple[list[Path], Path | None]:
    """The result files (-o) and picture (--plot) asked for, checked before any solve."""
    outputs: list[Path] = []
    for name in args.output:
        outputs.append(_check_output(name, FORMATS, "output", [args.case], outputs))
    picture = _check_picture(args.plot, [args.case], outputs) if args.plot else None
    return outputs, picture


def _run_solve(args) -> int:
    outputs, picture = _outputs(args)
    case = load_case(args.case)
    result, seconds = _solve(case, args)
    print(_summary(case, result, seconds))
    _write(case, result, outputs, picture)
    return 0


def _trajectory_outputs(args) -> tuple[list[Path], Path | None]:
    """The trajectory files (-o) and picture (--plot) of ``softarm simulate``, checked
    before any step: a known suffix, an existing folder, not the input, not given twice; a
    ``.zarr`` (a folder) may exist (it is replaced) and needs xarray and zarr."""
    from .io import TRAJECTORY_FORMATS

    outputs: list[Path] = []
    for name in args.output:
        out = Path(name)
        if out.suffix.lower() == ".zarr":
            if importlib.util.find_spec("xarray") is None or \
                    importlib.util.find_spec("zarr") is None:
                raise CaseError(f"{out}: a .zarr output needs xarray and zarr: pip install "
                                "'softarm[sweep]'")
            if not Path(os.path.realpath(out)).parent.is_dir():
                raise CaseError(f"{out}: folder {Path(os.path.realpath(out)).parent} does not "
                                "exist")
            if out.exists() and not out.is_dir():
                raise CaseError(f"{out}: exists and is not a folder (a Zarr store is a folder)")
            if any(_same_file(out, other) for other in outputs):
                raise CaseError(f"{out}: given twice as an output")
            outputs.append(out)
        else:
            outputs.append(_check_output(name, TRAJECTORY_FORMATS, "trajectory", [args.case],
                                         outputs))
    picture = _check_picture(args.plot, [args.case], outputs) if args.plot else None
    return outputs, picture


def _run_simulate(args) -> int:
    from .case import join_trajectories, simulation_parts
    from .io import TrajectoryStore, save_trajectory

    outputs, picture = _trajectory_outputs(args)
    case = load_case(args.case)
    where = case.source or case.name
    if case.simulation is None:
        raise CaseError(f"{where}: simulate: missing (softarm simulate needs a [simulate] "
                        "table; docs/case-files.md)")
    if case.design is not None:
        raise CaseError(f"{where}: sweep: a design ([[sweep.parameter]]) of simulations is not "
                        "supported yet; a one-parameter load [sweep] is")
    total = case.simulation.steps
    # Zarr outputs alone (no picture, no other format): each part is written as it is done
    # and dropped, so that a run of any length fits in memory (TrajectoryStore); otherwise
    # the parts are kept and joined, and written at the end
    streamed = bool(outputs) and picture is None and \
        all(out.suffix.lower() == ".zarr" for out in outputs)
    stores = [TrajectoryStore(out, case, every=args.every) for out in outputs] \
        if streamed else []
    progress = _Progress(label="simulating", unit="steps")
    parts, figures, stopped = [], _RunFigures(), None
    start = time.perf_counter()
    try:
        try:
            for part in simulation_parts(case, joined=not streamed):
                figures.add(part)
                if streamed:
                    for store in stores:
                        store.append(part)
                else:
                    parts.append(part)
                progress(figures.steps, total)
        except (ValueError, TypeError) as error:  # the simulation rejected the case's data
            raise CaseError(_named(error, where)) from None
    except KeyboardInterrupt:
        with contextlib.suppress(ValueError, OSError):  # (no second Ctrl-C while writing)
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        stopped = ("interrupted", 130)
    except ConvergenceError as error:
        stopped = (f"the solver did not converge: {error}", 1)
    except BaseException:
        for store in stores:  # (what was streamed stays, marked incomplete)
            store.close(complete=False, reason="stopped by an error")
        raise
    finally:
        progress.close()
    seconds = time.perf_counter() - start
    if stopped is not None and figures.steps < 0:
        return _fail(stopped[1], f"softarm: {stopped[0]} (no step done; nothing written)")
    reason = "" if stopped is None else _line(stopped[0], 300)
    for store in stores:
        store.close(complete=stopped is None, reason=reason)
    if not streamed:
        trajectory = join_trajectories(parts)  # (the picture: every step)
        kept = trajectory if args.every == 1 else join_trajectories([trajectory],
                                                                   every=args.every)
        for out in outputs:
            save_trajectory(kept, out, case, complete=stopped is None, reason=reason,
                            every=args.every)
        if picture is not None:
            from . import plot

            plot.plot_trajectory(trajectory, name=case.name, sweep=case.sweep, path=picture)
    failed = np.flatnonzero(np.ravel(figures.failed)) if figures.failed is not None else ()
    if stopped is None and len(failed):
        values = case.sweep.values if case.sweep is not None else range(len(failed))
        print(f"softarm: {len(failed)} of {figures.failed.size} cases failed (their values "
              f"are NaN in the outputs from their failed step on): sweep values "
              f"{', '.join(f'{values[b]:g}' for b in failed[:10])}"
              + (" ..." if len(failed) > 10 else ""), file=sys.stderr)
    if stopped is not None:
        kept = f"; wrote the {figures.steps} of {total} steps done (to t = {figures.end:.6g} " \
            f"s) to {', '.join(map(str, outputs + ([picture] if picture else [])))}" \
            if outputs or picture else \
            f"; {figures.steps} of {total} steps were done (no output asked)"
        return _fail(stopped[1], f"softarm: {stopped[0]}{kept}")
    print(_simulation_summary(case, figures, seconds))
    for out in [*outputs, *([picture] if picture else [])]:
        print(f"wrote {out}")
    return 0


class _RunFigures:
    """What ``softarm simulate`` says of a run, gathered part by part (a streamed run keeps
    no trajectory): steps, the last time, Newton's iterations and corrections, the tip's
    path (an unbatched run) and the energy at the start and now."""

    def __init__(self):
        self.steps = -1  # the times seen, less one
        self.stations, self.batch_shape, self.end = 0, (), 0.0
        self.iterations, self.counted, self.most_iterations = 0.0, 0, 0
        self.largest_correction = 0.0
        self.tip_start = self.tip_end = None
        self.farthest = 0.0
        self.energy_start = self.energy_end = None
        self.failed = None

    def add(self, part) -> None:
        first = self.steps < 0  # (a later part starts after the last time seen)
        self.steps += part.times.size
        self.stations, self.batch_shape = part.s.size, part.batch_shape
        self.end = float(part.times[-1])
        steps = part.iterations[..., 1:] if first else part.iterations  # (no step at t0)
        self.iterations += float(np.sum(steps))
        self.counted += steps.size
        self.most_iterations = max(self.most_iterations, int(np.max(part.iterations)))
        self.largest_correction = max(self.largest_correction, float(np.max(part.errors)))
        total = part.energy.total
        if first:
            self.energy_start = total[..., 0]
            self.tip_start = part.tip_position[..., 0, :]
        self.energy_end = total[..., -1]
        self.tip_end = part.tip_position[..., -1, :]
        if not part.batch_shape:
            self.farthest = max(self.farthest, float(np.max(np.linalg.norm(
                part.tip_position - self.tip_start, axis=-1))))
        if part.failed is not None:
            self.failed = part.failed if self.failed is None else self.failed | part.failed


def _simulation_summary(case: Case, figures: _RunFigures, seconds: float) -> str:
    from .plot import describe_loads

    options = case.simulation
    drift = np.max(np.abs(figures.energy_end - figures.energy_start))
    lines = [f"case      {case.name}" + (f"  ({case.source})" if case.source else ""),
             f"loads     {describe_loads(case.loads, case.sweep)}",
             f"simulated {figures.steps} steps of {options.dt:g} s to t = {figures.end:.6g} s,"
             f" {figures.stations} stations"
             + (f", {int(np.prod(figures.batch_shape))} cases" if figures.batch_shape
                else ""),
             f"Newton    {figures.iterations / max(figures.counted, 1):.3g} iterations a step "
             f"on average, at most {figures.most_iterations}; largest step correction "
             f"{figures.largest_correction:.2e} L"]
    if not figures.batch_shape:
        lines.append(f"tip       at t = {figures.end:.6g} s: {_vector(figures.tip_end)} m; "
                     f"farthest from its start {figures.farthest:.4g} m")
    lines += [f"energy    kinetic + elastic + gravity + dissipated changed by up to {drift:.3g} J"
              " (the work of the base and actuators, and the time steps' error)",
              f"time      {seconds:.3g} s"]
    return "\n".join(lines)


def _run_inverse(args) -> int:
    import dataclasses

    from ._schema import loads_to_dict
    from .control import InverseSolver

    outputs, picture = _outputs(args)
    case = load_case(args.case)
    task = case.inverse
    if args.target is None and task is None:
        raise CaseError(f"{args.case}: no target: give --target X Y Z or an [inverse] table "
                        "with target = [x, y, z]")
    target = np.array(args.target if args.target is not None else task.target)
    if not np.all(np.isfinite(target)):
        raise CaseError(f"--target must be 3 finite numbers in m, got {args.target}")
    actuators = [load for load in case.loads if load.inputs]
    if not actuators:
        raise CaseError(f"{args.case}: no actuator to control: add a tendon, chamber or "
                        "magnetic load ([[load]] kind = \"tendon\", ...)")
    others = [load for load in case.loads if not load.inputs]
    bounds = None
    if task is not None and (task.lower is not None or task.upper is not None):
        bounds = (-np.inf if task.lower is None else np.array(task.lower),
                  np.inf if task.upper is None else np.array(task.upper))
    # the [inverse] table's settings (InverseTask's defaults are InverseSolver's)
    settings = {} if task is None else dict(tol=task.tol, max_iterations=task.max_iterations,
                                            starts=task.starts)
    try:
        solver = InverseSolver(case.arm, actuators, others, bounds=bounds, **settings,
                               s=int(case.solve.stations), solver_tol=float(case.solve.tol))
    except (ValueError, TypeError) as error:
        raise CaseError(f"{args.case}: inverse: {error}") from None
    # a target can take minutes (an arm in contact: a second or more per forward solve):
    # after a second, the start, iterations and tip error so far on one line of stderr
    progress = _Progress()
    solver.progress = lambda begun, iterations, error: progress.line(
        lambda now: f"inverse: start {begun} (of at most {solver.starts}), iteration "
                    f"{iterations}, tip error {error * solver.length:.3g} m, "
                    f"{now - progress.start:.1f} s")
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", StabilityWarning)
            answer = solver.solve(target)
    finally:
        progress.close()
    seconds = time.perf_counter() - start
    _report(caught)
    solved = [*others, *solver.actuators_at(answer.inputs)]
    names = [f"{load.kind} {k + 1} {name}" for k, load in enumerate(actuators)
             for name in load.inputs for _ in range(_input_size(load, name))]
    units = [dict((n, u) for n, u, _ in load.arrays)[name] for load in actuators
             for name in load.inputs for _ in range(_input_size(load, name))]
    lines = [f"case      {case.name}" + (f"  ({case.source})" if case.source else ""),
             f"target    {_vector(target)} m",
             f"reached   {'yes' if answer.reached else 'NO (the closest point found)'}: tip "
             f"{_vector(answer.equilibrium.tip_position)} m, error "
             f"{answer.error * solver.length:.3g} m ({answer.error:.2g} L)",
             "inputs    " + "\n          ".join(
                 f"{name}: {value:.6g} {unit}" + (" (at its bound)" if bound else "")
                 for name, value, unit, bound in zip(names, answer.inputs, units,
                                                     answer.at_bound, strict=True)),
             f"iterations {answer.iterations} (starts tried {answer.starts}), condition "
             f"{answer.condition:.3g}, time {seconds:.3g} s"]
    print("\n".join(lines))
    solved_case = dataclasses.replace(case, loads=tuple(solved),
                                      data={**case.data, "load": loads_to_dict(solved)})
    _write(solved_case, answer.equilibrium, outputs, picture)
    return 0


def _input_size(load, name: str) -> int:
    return int(np.size(getattr(load, name)))


def _write(case: Case, result, outputs, picture) -> None:
    _Interrupt.check()  # a Ctrl-C not yet raised (see _Interrupt): nothing is written
    # From here the outputs are written, all of them: a Ctrl-C is only remembered (exit 130
    # means that nothing was written; the writing takes a fraction of a second)
    _Interrupt.done = True
    for out in outputs:
        save_result(result, out, case)
        print(f"wrote {out}")
    if picture is not None:
        _plot(case, result, picture)
        print(f"wrote {picture}")


def _plot(case: Case, result, picture: Path) -> None:
    try:
        from . import plot
    except ImportError as error:  # pragma: no cover - matplotlib missing
        raise CaseError(f"{picture}: {error}") from None
    try:
        if case.sweep is not None:
            plot.plot_sweep(result, sweep=case.sweep, name=case.name, path=picture)
        else:
            plot.plot_equilibrium(result, name=case.name, path=picture)
    except ImportError as error:  # pragma: no cover - matplotlib missing
        raise CaseError(f"{picture}: {error}") from None


def _run_plot(args) -> int:
    source = Path(args.result)
    picture = _check_picture(args.output or str(source.with_suffix(".png")), [source])
    saved = load_saved(source)
    from . import plot

    plot.plot_result_file(saved, path=picture)
    print(f"wrote {picture}")
    return 0


def _run_view(args) -> int:
    source = Path(args.result)
    page = _check_output(args.output or str(source.with_suffix(".html")), (".html", ".htm"),
                         "page", [source])
    trajectory = _is_trajectory(source)  # written by softarm simulate
    saved = read_trajectory(source) if trajectory else load_saved(source)
    try:
        from . import view

        if trajectory:
            view.view_trajectory_file(saved, page, case=args.case)
        else:
            if args.case is not None:
                raise CaseError(f"{source}: --case is for a trajectory file of a sweep of "
                                "simulations; this is a result file")
            view.view_result_file(saved, page)
    except ImportError as error:  # plotly missing
        raise CaseError(f"{page}: {error}") from None
    print(f"wrote {page}")
    return 0


def _is_trajectory(path: Path) -> bool:
    """True if ``path`` is a trajectory file (softarm.io.save_trajectory's: a ``.zarr``
    folder, or ``.npz`` or ``.csv`` whose metadata say ``"kind": "trajectory"``)."""
    import json
    import zipfile

    suffix = path.suffix.lower()
    try:
        if suffix == ".zarr":
            return path.is_dir()
        if suffix == ".npz" and zipfile.is_zipfile(path):
            with np.load(path, allow_pickle=False) as data:
                return "meta" in data.files and \
                    json.loads(str(data["meta"])).get("kind") == "trajectory"
        if suffix == ".csv" and path.is_file():
            with path.open(encoding="utf-8") as stream:
                for line, _ in zip(stream, range(50), strict=False):
                    if line.startswith("# meta: "):
                        return json.loads(line[len("# meta: "):]).get("kind") == "trajectory"
    except (OSError, ValueError, UnicodeDecodeError):
        return False  # (then read as a result file, which says what is wrong)
    return False


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"must be in 0 ... 65535, got {value}")
    return value


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a time in s, got {text!r}") from None
    if not (np.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"must be a time >= 0 s, got {text!r}")
    return value


def _run_app(args) -> int:
    case = load_case(args.case)
    from . import app

    dynamics = None
    asked = args.dynamic or args.dt is not None or args.damping is not None
    if args.static and asked:
        raise CaseError("--static cannot go with --dynamic, --dt or --damping")
    if asked or (case.simulation is not None and not args.static):
        if args.dt == 0:
            raise CaseError("--dt must be a positive time step in s, got 0")
        dynamics = app.Dynamics.of(case, dt=args.dt, damping=args.damping)
    try:
        return app.serve(case, port=args.port, browser=not args.no_browser,
                         dynamics=dynamics)
    except ImportError as error:  # plotly missing
        raise CaseError(str(error)) from None


def _duration(seconds: float) -> str:
    if not np.isfinite(seconds):
        return "?"
    seconds = round(seconds)
    hours, rest = divmod(seconds, 3600)
    return f"{hours}:{rest // 60:02d}:{rest % 60:02d}" if hours else \
        f"{rest // 60}:{rest % 60:02d}"


def _run_sweep(args) -> int:
    from . import sweep

    try:
        import xarray  # noqa: F401
        import zarr  # noqa: F401
    except ImportError as error:
        raise CaseError(f"softarm sweep needs xarray and zarr ({error.name} is missing): pip "
                        "install 'softarm[sweep]'") from None
    out = Path(args.output)
    if out.suffix.lower() != ".zarr":  # a folder of Zarr arrays, not a file of that format
        raise CaseError(f"{out}: a sweep store is a Zarr folder; give a name ending in .zarr, "
                        f"got suffix {out.suffix or '(none)'!r}")
    if _same_file(out, Path(args.case)):
        raise CaseError(f"{out}: is the input file {args.case}; choose another output")
    case = load_case(args.case)
    if case.sweep is None and case.design is None:
        raise CaseError(f"{args.case}: sweep: missing (softarm sweep needs a [sweep] table)")
    executor = cluster = client = None
    mapper = None
    killed = concurrent.futures.BrokenExecutor  # what a worker that died raises
    if args.scheduler is not None:
        try:
            from distributed import Client, KilledWorker, LocalCluster
        except ImportError:
            raise CaseError("--scheduler needs Dask's distributed: pip install "
                            "'softarm[dask]'") from None
        killed = (concurrent.futures.BrokenExecutor, KilledWorker)
    path = args.path
    if args.resume and path is None:  # a store started with --path resumes serially too
        from .sweep._store import recorded_options

        try:
            recorded = recorded_options(out)
        except ValueError as error:
            raise CaseError(str(error)) from None
        path = bool(recorded and recorded["path"])
    if path and (args.scheduler is not None or args.workers > 1):
        raise CaseError(("this store was started with --path: it " if args.path is None else
                         "--path ") + "follows the cases one after the other, in this "
                        "process; give no --workers or --scheduler")
    progress = _Progress(label="sweep", unit="cases", rate=True)
    start = time.perf_counter()
    try:
        if args.scheduler is not None:
            if args.scheduler == "local":
                cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1,
                                       processes=True, dashboard_address=None)
                client = Client(cluster)
            else:
                client = _connect(Client, args.scheduler)
            executor = client.get_executor(pure=False)
            mapper = executor.map
        elif args.workers > 1 and not path:
            executor = sweep.process_pool(args.workers, case)  # forked where safe
            mapper = executor.map
        try:
            result = sweep.run(case, out=out, map=mapper, chunk=args.chunk,
                               fields=args.fields, stations=args.stations, dtype=args.dtype,
                               method=args.method, tol=args.tol, resume=args.resume,
                               path=args.path, progress=progress)
        except (ValueError, TypeError) as error:
            raise CaseError(_named(error, case.source or case.name, out)) from None
        except killed:  # a worker killed (the OOM killer: SIGKILL), a process or a Dask one
            progress.close()
            print("softarm: a worker process of the sweep died (killed by the system, e.g. "
                  "out of memory); the finished chunks are kept: finish with softarm sweep "
                  f"{args.case} -o {out} --resume", file=sys.stderr)  # whole, however long
            return 1
    except KeyboardInterrupt:
        progress.close()
        return interrupted(f"interrupted; finish it with softarm sweep {args.case} -o {out} "
                           "--resume")
    finally:
        progress.close()
        if executor is not None and client is None:
            executor.shutdown(cancel_futures=True)
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    status = np.asarray(result["status"].values)
    solved = int(np.sum(status == 0))
    failed = int(np.sum(status > 0))
    print(f"case      {case.name}" + (f"  ({case.source})" if case.source else ""))
    print(f"sweep     {status.size} cases over {', '.join(sweep.design_of(case).paths)}")
    print(f"solved    {solved} ok, {failed} failed"
          + (" (see the status and message variables)" if failed else ""))
    print(f"time      {time.perf_counter() - start:.3g} s")
    print(f"wrote     {out}  (softarm.open_sweep({str(out)!r}) reads it with xarray)")
    return 0


def _run_compile(args) -> int:
    from .warmup import compile_kernels

    bar = _CompileBar(sys.stderr)
    start = time.perf_counter()
    jobs = args.jobs or min(os.cpu_count() or 1, 4)
    done = compile_kernels(all=args.all, progress=bar, jobs=jobs if args.all else 1)
    compiled = sum(len(keys) for _, _, keys in done)
    print(f"{compiled} kernel{'s' if compiled != 1 else ''} compiled in "
          f"{time.perf_counter() - start:.0f} s; later runs load them from numba's cache"
          if compiled else "every kernel was already compiled (numba's cache)")
    return 0


class _CompileBar:
    """``softarm compile``'s progress: on a terminal a bar per step, redrawn as it runs
    (``compiling [#####.....] 2/11 Jacobians  8 s of about 14 s``); a line per step at its end
    (on stdout, also when not a terminal: a build log)."""

    width = 24

    def __init__(self, stream):
        self.stream = stream
        self.tty = stream.isatty()

    def __call__(self, step, index, count, elapsed, estimate):
        if threading.current_thread() is threading.main_thread():
            _Interrupt.check()  # (the redraws come from a thread while the step runs)
        if estimate < 0:  # the step is done
            if self.tty:
                self.stream.write("\r" + " " * 100 + "\r")
                self.stream.flush()
            print(f"{index + 1:>2}/{count} {step.text}: {elapsed:.1f} s", flush=True)
            return
        if not self.tty:
            return
        elapsed = elapsed or 0.0
        filled = min(self.width - 1, round(self.width * elapsed / max(estimate, 1e-9)))
        bar = "#" * filled + "." * (self.width - filled)
        text = f"compiling [{bar}] {index + 1}/{count} {step.text}"
        self.stream.write(f"\r{text[:72]}  {elapsed:.0f} s of about {estimate:.0f} s")
        self.stream.flush()


def _connect(client, address: str):
    """A Dask ``client(address)``, or one line if no scheduler answers there within Dask's
    connect timeout (``distributed.comm.timeouts.connect``, 30 s unless configured)."""
    import dask
    from dask.utils import parse_timedelta

    timeout = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), "s")
    try:
        return client(address, timeout=timeout)
    except OSError:  # distributed's "Timed out trying to connect"
        raise CaseError(f"cannot reach the Dask scheduler at {address} within {timeout:g} s"
                        ) from None


def _run_demo(args) -> int:
    folder = Path(args.out)
    if not folder.is_dir():
        raise CaseError(f"{folder}: folder does not exist")
    with resources.as_file(resources.files("softarm") / "data" / "demo.toml") as path:
        case = load_case(path)
    table = _check_output(str(folder / "demo.csv"), FORMATS, "output")
    picture = _check_picture(str(folder / "demo.png"))
    args.method = args.stations = args.tol = None
    result, seconds = _solve(case, args)
    print(_summary(case, result, seconds))
    _write(case, result, [table], picture)
    print(f"the demo case file is {resources.files('softarm') / 'data' / 'demo.toml'}; "
          f"copy it to start your own: softarm solve my_arm.toml --plot my_arm.png")
    return 0


# --------------------------------------------------------------------------------------------


def _vector(v, digits: int = 5) -> str:
    """(a, b, c) with ``digits`` significant digits; a zero is 0, never -0."""
    return "(" + ", ".join(f"{c + 0.0:.{digits}g}" for c in np.asarray(v, dtype=float)) + ")"


def _peak(values: np.ndarray, s: np.ndarray) -> tuple[float, float]:
    """max |values| over the last axis and the station where it occurs (unbatched)."""
    k = int(np.argmax(values))
    return float(values[k]), float(s[k])


def _summary(case: Case, result, seconds: float) -> str:
    from .lie import so3
    from .plot import describe_loads

    lines = [f"case      {case.name}" + (f"  ({case.source})" if case.source else ""),
             f"loads     {describe_loads(case.loads, case.sweep)}"]
    residual = np.max(np.asarray(result.residual, dtype=float))
    exactness = "exact" if result.exact else "approximate"
    estimate = np.max(np.asarray(result.error_estimate, dtype=float))
    if not result.exact and np.isfinite(estimate):
        exactness += f", tip error estimate {estimate:.2e} m"
    lines.append(f"method    {result.method} ({exactness}; residual {residual:.2e} N, N m)")
    if result.batch_shape:
        lines.append(_sweep_table(case, result))
    else:
        rotvec, quat = so3.log(result.tip[:3, :3]), so3.to_quaternion(result.tip[:3, :3])
        angle = np.degrees(np.linalg.norm(rotvec))
        lines += [
            f"tip       position {_vector(result.tip_position)} m",
            f"          rotation vector {_vector(rotvec)} rad ({angle:.4g}°), "
            f"quaternion (w, x, y, z) {_vector(quat)}",
        ]
        s, eps, sig = result.s, result.strains, result.stresses
        rows = [
            ("axial strain |γ1|", np.abs(eps[:, 0]), ""),
            ("shear strain |γ2, γ3|", np.hypot(eps[:, 1], eps[:, 2]), ""),
            ("twist |κ1|", np.abs(eps[:, 3]), "1/m"),
            ("curvature |κ2, κ3|", np.hypot(eps[:, 4], eps[:, 5]), "1/m"),
            ("force |n|", np.linalg.norm(sig[:, :3], axis=-1), "N"),
            ("moment |m|", np.linalg.norm(sig[:, 3:], axis=-1), "N m"),
        ]
        lines.append("maximum   " + "\n          ".join(
            f"{name:<22} {value:.4g} {unit:<3} at s = {where:.4g} m"
            for name, values, unit in rows for value, where in [_peak(values, s)]))
        if result.tendon_tensions is not None:
            lines.append("tendons   " + "\n          ".join(_tendon_lines(result)))
        if result.base_wrench is not None:
            # with tendons or chambers the clamp and the actuators share the base wrench
            actuated = any(load.acts_through_base for load in result.loads)
            what = "total wrench (clamp and actuators)" if actuated else "clamp reaction"
            lines.append(f"base      {what} force "
                         f"{_vector(result.base_wrench[:3])} N, moment "
                         f"{_vector(result.base_wrench[3:])} N m")
        if any(load.kind == "contact" for load in result.loads):
            lines.append(f"contact   {_contact_line(result)}")
        if result.stability is not None:
            lines.append(f"stability {result.stability.describe()}")
    lines.append(f"time      {seconds:.3g} s")
    return "\n".join(lines)


def _contact_line(result) -> str:
    """What the obstacles do to a single equilibrium: the tip's reaction where it is held
    exactly (statics/tip_contact.py), else the total contact force and its moment about the
    origin (Equilibrium.contact_wrench), or the nearest gap where nothing touches."""
    wrench = np.asarray(result.contact_wrench)
    if not wrench.any():
        return f"no obstacle touched (nearest gap {float(np.min(result.gaps)):.4g} m)"
    if result.method == TIP_CONTACT:
        line = f"the tip held exactly: reaction {_vector(wrench[:3])} N at the tip"
        contact = next(load for load in result.loads if load.kind == "contact")
        if contact.friction:  # (stuck or sliding: its lean against Coulomb's μ)
            tip = np.asarray(result.poses)[-1, :3, 3]
            normal = min((o.distance(tip) for o in contact.obstacles), key=lambda f: f[0])[1]
            pressing = float(wrench[:3] @ normal)
            along = float(np.linalg.norm(wrench[:3] - pressing * normal))
            lean = along / (contact.friction * pressing)
            line += (f" ({'sliding' if lean > 1.0 - 1e-6 else 'stuck'}: tangential "
                     f"{along:.4g} N, {lean:.4g} × μ × the normal {pressing:.4g} N)")
        return line
    return (f"total force {_vector(wrench[:3])} N, moment {_vector(wrench[3:])} N m about the "
            "origin")


def _tendon_lines(result) -> list[str]:
    """One line per tendon of a single equilibrium: its tension, length and length change,
    how it is controlled and, under displacement control, whether it is slack."""
    tendons = [load for load in result.loads if load.kind == "tendon"]
    lines = []
    for k, (load, t, length, change) in enumerate(zip(
            tendons, result.tendon_tensions, result.tendon_lengths,
            result.tendon_length_changes, strict=True)):
        line = (f"{k + 1}: tension {t:.4g} N, length {length:.6g} m, change "
                f"{1e3 * change:+.4g} mm")
        if load.displacement_controlled:
            line += f" (displacement-controlled: set {1e3 * float(load.displacement):+.4g} mm"
            line += "; SLACK: given more length than its path needs, no tension)" \
                if result.tendon_slack[k] else ")"
        lines.append(line)
    return lines


def _sweep_table(case: Case, result) -> str:
    sweep = case.sweep
    values = np.asarray(sweep.values) if sweep is not None else \
        np.arange(result.batch_shape[0])
    label = sweep.label if sweep is not None else "step"
    tips = result.tip_position.reshape(-1, 3)
    residual = np.broadcast_to(np.asarray(result.residual, dtype=float),
                               result.batch_shape).reshape(-1)
    curvature = np.max(np.hypot(result.strains[..., 4], result.strains[..., 5]), axis=-1)
    head = (f"{label:>26}  {'tip x (m)':>11} {'tip y (m)':>11} {'tip z (m)':>11} "
            f"{'max |κ2,κ3| 1/m':>16} {'residual':>9}")
    rows = [f"{v:>26.6g}  {t[0]:>11.5g} {t[1]:>11.5g} {t[2]:>11.5g} {k:>16.4g} {r:>9.1e}"
            for v, t, k, r in zip(values, tips, curvature.reshape(-1), residual, strict=True)]
    if result.stability is not None:  # the Morse index, * where the verdict is undecided
        head += f" {'index':>6}"
        index = np.broadcast_to(result.stability.index, result.batch_shape).reshape(-1)
        sure = np.broadcast_to(result.stability.conservative, result.batch_shape).reshape(-1)
        rows = [f"{row} {i:>5d}{' ' if c else '*'}"
                for row, i, c in zip(rows, index, sure, strict=True)]
    return "sweep\n" + "\n".join(["  " + head, *("  " + r for r in rows)])
