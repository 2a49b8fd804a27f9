"""What a replay runs, from the user's YAML files: per capability (costmap, tracker, TSDF) the
topics it reads, their message types and the frame it works in."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

# costmap_2d's data_type -> the message type on the topic.
SOURCE_TYPES = {
    "LaserScan": "sensor_msgs/LaserScan",
    "PointCloud2": "sensor_msgs/PointCloud2",
    "PointCloud": "sensor_msgs/PointCloud",
}


class ReplayError(Exception):
    """The bag cannot be replayed with this configuration; the message says why."""


@dataclass
class Input:
    """One topic a nodelet reads."""

    capability: str  # costmap | tracker | tsdf
    name: str  # the observation source, "detections", "depth image", ...
    topic: str
    msg_type: str
    frame_of_data: bool = True  # its header frame must be joined by tf to the capability's frame


@dataclass
class Capability:
    name: str
    config: Path
    frame: str  # the frame it works in: the costmap's global_frame, tracking_frame, world_frame
    inputs: list[Input]
    launch_args: dict[str, str] = field(default_factory=dict)


@dataclass
class Pipeline:
    capabilities: list[Capability]
    robot_frame: str = "base_link"  # the path drawn in the report: first frame <- robot_frame

    @property
    def inputs(self) -> list[Input]:
        return [i for c in self.capabilities for i in c.inputs]

    def capability(self, name: str) -> Capability | None:
        return next((c for c in self.capabilities if c.name == name), None)


def absolute(topic: str) -> str:
    """Relative names resolve at the root, where the launch files run the nodelets."""
    return topic if topic.startswith("/") else "/" + topic


def load_yaml(path: Path) -> dict[str, Any]:
    try:
        config = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as e:
        raise ReplayError(f"{path}: cannot read the configuration: {e}") from e
    if not isinstance(config, dict):
        raise ReplayError(f"{path}: the configuration is not a YAML mapping")
    return config


def costmap_capability(path: Path) -> tuple[Capability, str]:
    """The observation sources of a costmap YAML (ours or costmap_2d's: under each obstacle
    layer's namespace, or at the top level before Hydro), and its robot_base_frame."""
    config = load_yaml(path)
    inputs = []
    for layer, ns in [("", config)] + [(k, v) for k, v in config.items() if isinstance(v, dict)]:
        names = ns.get("observation_sources")
        if not isinstance(names, str):
            continue
        for name in names.split():
            source = ns.get(name, {})
            if not isinstance(source, dict):
                continue
            data_type = str(source.get("data_type", "PointCloud"))  # costmap_2d's default
            kind = SOURCE_TYPES.get(data_type, data_type)
            topic = absolute(str(source.get("topic", name)))
            inputs.append(Input("costmap", f"{layer}/{name}".lstrip("/"), topic, kind))
    if not inputs:
        raise ReplayError(f"{path} names no observation_sources: nothing to replay into it")
    frame = str(config.get("global_frame", "map"))
    return Capability("costmap", path, frame, inputs), str(
        config.get("robot_base_frame", "base_link")
    )


def tracker_capability(path: Path, detections: str) -> Capability:
    config = load_yaml(path)
    topic = absolute(detections)
    inputs = [Input("tracker", "detections", topic, "downstream_perception/DetectedObjectArray")]
    frame = str(config.get("tracking_frame", "odom"))
    return Capability("tracker", path, frame, inputs, {"detections": topic})


def tsdf_capability(path: Path, depth: str, points: str) -> Capability:
    config = load_yaml(path)
    depth, points = absolute(depth), absolute(points)
    inputs = [
        Input("tsdf", "depth image", f"{depth}/image", "sensor_msgs/Image"),
        Input("tsdf", "camera info", f"{depth}/camera_info", "sensor_msgs/CameraInfo", False),
        Input("tsdf", "points", points, "sensor_msgs/PointCloud2"),
    ]
    frame = str(config.get("world_frame", "odom"))
    return Capability("tsdf", path, frame, inputs, {"depth": depth, "points": points})
