"""Entry point of the ``softarm`` command, outside the package so that it runs first.

The command's work is :func:`softarm.cli.main`; this module only imports it, which loads numpy,
scipy and numba and takes a moment. A Ctrl-C during that start-up still ends with one line and
exit status 130, as at any other moment, instead of a traceback from the middle of an import.

Design note: the Ctrl-C handler is installed by the first statements of this module, before
anything heavy is imported; only the Python interpreter's own start-up (10-70 ms, before any
line of softarm runs) is out of reach. Until :func:`main` is called, a Ctrl-C is only
remembered (the entry script runs lines of its own in between), and main() looks first. During
the import in main(), a Ctrl-C raises KeyboardInterrupt and is also remembered: a C extension
may turn the KeyboardInterrupt into an ImportError (numpy: "PyCapsule_Import could not import
module ...") or an ``except`` in a library may swallow it, so what decides is the memory, not
the exception's type. Once imported, SIGINT is *blocked* (held by the kernel, not lost) until
:func:`softarm.cli.main` has installed its own handler and unblocks it: a Ctrl-C in between
reaches that handler. ``softarm.cli.main`` restores the mask when it returns, so a Ctrl-C after
the command's work (its outputs written) stays held and is dropped at exit: the exit status is
the command's.
"""

# _signal and sys are built into the interpreter: importing them looks for no file, so the
# handler is in place a few microseconds after this module starts. (``import signal`` first,
# a Python module found on sys.path, left a window: CI's SIGINT at 0.05 s landed in its
# file lookup, before the handler, and the command died with a traceback from this module.)
import _signal
import sys

_INTERRUPTED = False
#: Whether a Ctrl-C raises: only inside main(). Before it, in the entry script's own lines
#: between its import of this module and its call of main() (pip's script runs a re.sub
#: there; CI's SIGINT at 0.05 s landed in it), a Ctrl-C is only remembered, and main()
#: starts by looking.
_ARMED = False


def _on_ctrl_c(signum, frame):
    global _INTERRUPTED
    _INTERRUPTED = True
    if _ARMED:
        raise KeyboardInterrupt


try:
    _signal.signal(_signal.SIGINT, _on_ctrl_c)
except (ValueError, OSError):  # pragma: no cover - not the main thread
    pass

import signal  # noqa: E402  (the handler above is in place)


def _block_ctrl_c() -> None:
    """Hold SIGINT (pending) until softarm.cli.main unblocks it; where signals cannot be
    blocked (Windows), ignore it from now on instead."""
    try:
        if hasattr(signal, "pthread_sigmask"):
            signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except (ValueError, OSError):  # pragma: no cover - not the main thread
        pass


def _interrupted() -> int:
    _block_ctrl_c()
    try:
        sys.stderr.write("softarm: interrupted\n")
        sys.stderr.flush()
    except (ValueError, OSError):  # pragma: no cover - stderr closed
        pass
    return 130


def main() -> int:
    global _ARMED
    try:
        _ARMED = True  # (inside the try: a Ctrl-C raising from here on is caught below)
        if _INTERRUPTED:  # remembered before main() was called
            return _interrupted()
        from softarm.cli import main as run

        if hasattr(signal, "pthread_sigmask"):
            # held from here until softarm.cli.main's handler is in place (it unblocks)
            signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    except BaseException:
        if not _INTERRUPTED:
            raise
        return _interrupted()
    if _INTERRUPTED:  # a KeyboardInterrupt that something in the import swallowed
        return _interrupted()
    try:
        code = run()  # handles a Ctrl-C during the work itself (exit status 130, one line)
    except KeyboardInterrupt:  # (only where signals cannot be blocked, at run's very start)
        return _interrupted()
    # The work is done and its outputs written: a Ctrl-C from here on, while the interpreter
    # shuts down, is held or ignored instead of killing the process without a word.
    _block_ctrl_c()
    return code


if __name__ == "__main__":
    sys.exit(main())
