"""Files in and out: log folders, proximity traces and arenas.

:mod:`.tables` is the one CSV / Parquet / agent-ID parser; :mod:`.logs` (log folders and
their ground truth) and :mod:`.traces` (CSV / Parquet, SocioPatterns and ONE traces) are
thin users of it, :mod:`.arenas` reads and writes GeoJSON, and :mod:`.output` replaces an
output folder whole or not at all.  JSON helpers live in :mod:`swarmtopo._json`, so that
the numerical core never imports this package.
"""

from .arenas import read_arena, write_arena
from .logs import (GROUND_TRUTH_META_KEYS, read_log, read_trajectories, read_truth, strip_ground_truth,
                   write_log)
from .traces import read_trace

__all__ = ["GROUND_TRUTH_META_KEYS", "read_arena", "read_log", "read_trace", "read_trajectories", "read_truth",
           "strip_ground_truth", "write_arena", "write_log"]
