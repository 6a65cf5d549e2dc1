"""The mapping pipeline: options (:mod:`.config`), settings decided from the data
(:mod:`.settings`), regions (:mod:`.regions`), time windows (:mod:`.windows`), the
straight sequence of stages (:mod:`.map`) and its result (:mod:`.result`)."""

from .config import MapConfig, config_from_options
from .map import STAGES, map_encounters
from .result import RegionMap, TopologicalMap, WindowMap

__all__ = ["MapConfig", "RegionMap", "STAGES", "TopologicalMap", "WindowMap", "config_from_options", "map_encounters"]
