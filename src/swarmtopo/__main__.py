"""The ``swarmtopo`` command (``python -m swarmtopo``): the command line, with Ctrl-C
during its start-up (while the modules load) said in one line like Ctrl-C later on."""

import os
import signal
import sys

INTERRUPTED = 130
"""Exit status after Ctrl-C (128 + SIGINT)."""


def main() -> None:
    """Load the command line and run it; Ctrl-C before it runs writes nothing, exit 130."""
    try:
        from swarmtopo.cli import main as run
    except KeyboardInterrupt:
        print("interrupted: nothing written", file=sys.stderr)
        _exit_interrupted()
    try:
        run()
    except SystemExit as exc:
        if exc.code == INTERRUPTED:  # Ctrl-C, already said in one line
            _exit_interrupted()
        _finished()
        raise
    _finished()


def _finished() -> None:
    """The command is done and said so: a Ctrl-C now, while the interpreter shuts
    down, has nothing left to interrupt (it would end the process by SIGINT)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _exit_interrupted() -> None:
    """Exit 130 now.  CPython kills itself with SIGINT at exit (status -2, not 130) when
    the Ctrl-C first struck inside C code that runs Python source, as some compiled
    modules do while they load, even though the interrupt was handled; everything the
    command wrote is closed by then, so nothing is left to finalize."""
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(INTERRUPTED)


if __name__ == "__main__":
    main()
