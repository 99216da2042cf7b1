"""Entry point of the ``softarm`` command, outside the package so that it runs first.

The command's work is :func:`softarm.cli.main`; this module only imports it, which loads numpy,
scipy and numba and takes a moment. A Ctrl-C during that start-up still ends with one line and
exit status 130, as at any other moment, instead of a traceback from the middle of an import.
"""

import signal
import sys


def _ignore_ctrl_c() -> None:
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except (ValueError, OSError):  # pragma: no cover - not the main thread
        pass


def main() -> int:
    try:
        from softarm.cli import main as run
    except KeyboardInterrupt:
        _ignore_ctrl_c()
        try:
            sys.stderr.write("softarm: interrupted\n")
            sys.stderr.flush()
        except (ValueError, OSError):  # pragma: no cover - stderr closed
            pass
        return 130
    code = run()  # handles a Ctrl-C during the work itself (exit status 130, one line)
    # The work is done and its outputs written: a Ctrl-C from here on, while the interpreter
    # shuts down, is ignored instead of killing the process without a word.
    _ignore_ctrl_c()
    return code


if __name__ == "__main__":
    sys.exit(main())
