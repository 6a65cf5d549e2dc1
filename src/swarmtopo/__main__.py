"""``python -m swarmtopo`` runs the command line."""

from .cli import main

main()
