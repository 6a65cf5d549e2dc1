"""Files in and out: log folders, proximity traces and arenas.

:mod:`.tables` is the one CSV / Parquet / agent-ID parser; :mod:`.logs` (log folders and
their ground truth) and :mod:`.traces` (CSV / Parquet, SocioPatterns and ONE traces) are
thin users of it, :mod:`.arenas` reads and writes GeoJSON.  JSON helpers live in
:mod:`swarmtopo._json`, so that the numerical core never imports this package.
"""

from .arenas import read_arena, write_arena
from .logs import (GROUND_TRUTH_META_KEYS, log_files, make_folder, read_log, read_trajectories, read_truth,
                   refuse_protected, strip_ground_truth, write_log)
from .traces import FORMATS as TRACE_FORMATS
from .traces import SOCIOPATTERNS_WINDOW, IngestReport, read_trace

__all__ = ["GROUND_TRUTH_META_KEYS", "SOCIOPATTERNS_WINDOW", "TRACE_FORMATS", "IngestReport", "log_files",
           "make_folder", "read_arena", "read_log", "read_trace", "read_trajectories", "read_truth",
           "refuse_protected", "strip_ground_truth", "write_arena", "write_log"]
