"""swarmtopo: topological maps of unknown arenas from who-met-whom-when.

A swarm of agents that cannot localize themselves reports encounter events
``[t, a, b]`` and status changes; swarmtopo recovers the arena's Betti numbers
(beta_0 regions, beta_1 holes) with a confidence, and pictures to check them.

>>> import swarmtopo as st
>>> arena = st.random_arena(2, rng=1)                       # doctest: +SKIP
>>> sim = st.simulate(arena, n_agents=200, duration=30.0, rng=1)
>>> tmap = st.map_encounters(sim.log)
>>> tmap.betti, tmap.confidence

The public names (loaded on first use, so ``import swarmtopo`` stays light):

``simulate``         run the bio-inspired swarm in an arena -> ``Simulation`` (``.log``)
``MotionParams``     the cockroach's motion; ``Billiard``, ``RunAndTumble``, ``Brownian``, ``LevyWalk``, ``Flocking`` others
``perturb``          a log through a faulty radio (``Faults``: lost, false, late, duplicated reports, dying agents)
``read_log``         a log folder (events.csv|parquet, status, meta.json) -> ``EncounterLog``
``read_trace``       a proximity trace (CSV/Parquet, SocioPatterns, ONE) -> ``(EncounterLog, report)``
``map_encounters``   ``EncounterLog`` -> ``TopologicalMap`` (Betti numbers, confidence, diagrams)
``MapConfig``        the pipeline's options; ``config_from_options`` parses them as users write them
``TopologicalMap``   the result; ``map_json`` gives its map.json document
``write_map``        map.json, report.html and figures into a folder
``Arena``            free space as polygons; ``random_arena``, ``default_arena``, ``read_arena``
``ChangingArena``    an arena whose obstacles come and go (``TimedObstacle``); ``changing_arena``
``BeaconTrack``      a localized leader's track (``track_along``, ``long_axis_track``); ``hall_arena``
``EncounterLog``     the events a base station receives
``load_classifier``  a Betti reader by preset name (default, trace, paper) or file
``SwarmtopoError``, ``InputError``, ``ArenaError``   what bad input raises
"""

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("swarmtopo")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

_PUBLIC = {
    "simulate": "swarmtopo.sim",
    "Simulation": "swarmtopo.sim",
    "MotionParams": "swarmtopo.sim",
    "Billiard": "swarmtopo.sim",
    "RunAndTumble": "swarmtopo.sim",
    "Brownian": "swarmtopo.sim",
    "LevyWalk": "swarmtopo.sim",
    "Flocking": "swarmtopo.sim",
    "Faults": "swarmtopo.sim",
    "perturb": "swarmtopo.sim",
    "read_log": "swarmtopo.io",
    "read_trace": "swarmtopo.io",
    "read_arena": "swarmtopo.io",
    "map_encounters": "swarmtopo.pipeline",
    "MapConfig": "swarmtopo.pipeline",
    "config_from_options": "swarmtopo.pipeline",
    "TopologicalMap": "swarmtopo.pipeline",
    "map_json": "swarmtopo.viz.summary",
    "write_map": "swarmtopo.viz.report",
    "Arena": "swarmtopo.arena",
    "random_arena": "swarmtopo.arena",
    "default_arena": "swarmtopo.arena",
    "ChangingArena": "swarmtopo.changing",
    "TimedObstacle": "swarmtopo.changing",
    "changing_arena": "swarmtopo.changing",
    "BeaconTrack": "swarmtopo.beacon",
    "track_along": "swarmtopo.beacon",
    "long_axis_track": "swarmtopo.beacon",
    "hall_arena": "swarmtopo.arena",
    "EncounterLog": "swarmtopo.log",
    "load_classifier": "swarmtopo.readers.registry",
    "SwarmtopoError": "swarmtopo.errors",
    "InputError": "swarmtopo.errors",
    "ArenaError": "swarmtopo.errors",
}
__all__ = sorted(_PUBLIC) + ["__version__"]


def __getattr__(name: str):
    """Load a public name on first use (PEP 562)."""
    if name not in _PUBLIC:
        raise AttributeError(f"module 'swarmtopo' has no attribute {name!r}")
    value = getattr(import_module(_PUBLIC[name]), name)
    globals()[name] = value
    return value


def __dir__():
    return __all__
