"""Simulated twins of the rig's devices, deterministic for a seed and run on a virtual clock."""

from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.sim.tracker import (
    TrackerConfig,
    TrackerCsvWriter,
    read_tracker_csv,
    simulate_tracker,
    write_tracker_csv,
)

__all__ = [
    "Pendulum",
    "PendulumConfig",
    "TrackerConfig",
    "TrackerCsvWriter",
    "read_tracker_csv",
    "simulate_tracker",
    "write_tracker_csv",
]
