"""Pure-numpy simulation: analytic worlds, a 2-D lidar, robot trajectories, moving objects with a
detector, and 3-D scenes with a depth camera (sim.depth_camera)."""

from downstream_perception.sim.lidar import Lidar, LidarConfig
from downstream_perception.sim.objects import Frame, ObjectScene, SceneConfig
from downstream_perception.sim.trajectory import Trajectory, aisle_drive, stand
from downstream_perception.sim.world import (
    WORLDS,
    MovingBox,
    MovingCircle,
    SeenObject,
    World,
    aisle_traffic,
    box_segments,
    open_field,
    warehouse_aisle,
)

__all__ = [
    "WORLDS",
    "Frame",
    "ObjectScene",
    "SceneConfig",
    "Lidar",
    "LidarConfig",
    "MovingBox",
    "MovingCircle",
    "SeenObject",
    "Trajectory",
    "World",
    "aisle_drive",
    "aisle_traffic",
    "box_segments",
    "open_field",
    "stand",
    "warehouse_aisle",
]
