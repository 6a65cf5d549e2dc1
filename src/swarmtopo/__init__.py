"""swarmtopo: topological maps of unknown arenas from who-met-whom-when.

Pipeline (one module per stage)::

    Arena --sim.simulate--> EncounterLog --graph--> EncounterGraph --landmarks-->
    L x L distances --persistence--> Diagram --classify--> TopologicalMap
                                         \\--embed (MDS)--> pictures
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("swarmtopo")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

from .arena import Arena
from .errors import ArenaError, InputError, SwarmtopoError
from .log import EncounterLog

__all__ = ["Arena", "ArenaError", "EncounterLog", "InputError", "SwarmtopoError", "__version__"]
