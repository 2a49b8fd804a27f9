"""Replay a recorded bag into the costmap, tracker and TSDF nodelets, with a progress bar, the
outputs (map_server map, tracks CSV, mesh, OctoMap) and a report. See ``cli.DESCRIPTION``."""

from downstream_perception.replay.cli import main
from downstream_perception.replay.outputs import (
    FREE_MAX,
    OCCUPIED_MIN,
    PGM_FREE,
    PGM_OCCUPIED,
    PGM_UNKNOWN,
    occupancy_to_pgm,
    read_pgm,
)
from downstream_perception.replay.pipeline import ReplayError
from downstream_perception.replay.progress import Progress

__all__ = [
    "FREE_MAX",
    "OCCUPIED_MIN",
    "PGM_FREE",
    "PGM_OCCUPIED",
    "PGM_UNKNOWN",
    "Progress",
    "ReplayError",
    "main",
    "occupancy_to_pgm",
    "read_pgm",
]
