"""Swarm simulator: the paper's bio-inspired agents in an arena, logged as a base station sees them.

``simulate(arena, ...) -> Simulation`` runs the RW / WF / S motion model
(:mod:`.motion`), encounter tracking (:mod:`.sensing`) and base-station commands
(:mod:`.commands`) and returns an :class:`~swarmtopo.log.EncounterLog` with optional
ground truth.  Parameters and project choices: :mod:`.params`.
"""

from .params import BEHAVIOURS, Command, MotionParams, SensingParams
from .sensing import EncounterTracker
from .simulate import (MAX_AGENTS, Simulation, check_run_size, check_static_time, check_time_step, interpreted_kernels,
                       simulate)

__all__ = ["BEHAVIOURS", "MAX_AGENTS", "Command", "EncounterTracker", "MotionParams",
           "SensingParams", "Simulation", "check_run_size", "check_static_time", "check_time_step",
           "interpreted_kernels", "simulate"]
