"""The ``swarmtopo`` command (``python -m swarmtopo``): the command line, with Ctrl-C
during its start-up (while the modules load) said in one line like Ctrl-C later on."""

import sys


def main() -> None:
    """Load the command line and run it; Ctrl-C before it runs writes nothing, exit 130."""
    try:
        from swarmtopo.cli import main as run
    except KeyboardInterrupt:
        print("interrupted: nothing written", file=sys.stderr)
        sys.exit(130)
    run()


if __name__ == "__main__":
    main()
