"""Swarm simulator: the paper's bio-inspired agents in an arena, logged as a base station sees them.

``simulate(arena, ...) -> Simulation`` runs the RW / WF / S motion model
(:mod:`.motion`) or another motion model (:mod:`.walkers`: billiard, run-and-tumble,
Brownian, Lévy walk, flocking), encounter tracking (:mod:`.sensing`) and base-station commands
(:mod:`.commands`) and returns an :class:`~swarmtopo.log.EncounterLog` with optional
ground truth.  Parameters and project choices: :mod:`.params`.  ``perturb(log,
Faults(...), seed)`` passes any log through a faulty radio (:mod:`.faults`).
"""

from .faults import Faults, perturb
from .params import (BEHAVIOURS, MOTION_MODELS, Billiard, Brownian, Command, Flocking, LevyWalk, MotionParams,
                     RunAndTumble, SensingParams, make_motion)
from .sensing import EncounterTracker
from .simulate import (MAX_AGENTS, Simulation, check_run_size, check_static_time, check_time_step, interpreted_kernels,
                       simulate)

__all__ = ["BEHAVIOURS", "MAX_AGENTS", "MOTION_MODELS", "Billiard", "Brownian", "Command", "EncounterTracker",
           "Faults", "Flocking", "LevyWalk", "MotionParams", "RunAndTumble", "SensingParams", "Simulation", "check_run_size",
           "check_static_time", "check_time_step", "interpreted_kernels", "make_motion", "perturb", "simulate"]
