"""Pure-numpy simulation: analytic worlds, a 2-D lidar, robot trajectories, moving objects with a
detector, 3-D scenes with a depth camera (sim.depth_camera), and people seen through a pinhole
camera as a 2-D box detector reports them (sim.image_scene)."""

from downstream_perception.sim.image_scene import (
    IMAGE_SCENES,
    ImageFrame,
    ImageScene,
    ImageSceneConfig,
)
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
    "IMAGE_SCENES",
    "WORLDS",
    "ImageFrame",
    "ImageScene",
    "ImageSceneConfig",
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
