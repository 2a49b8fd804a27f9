"""Shared by the costmap rostests: follows the published costmap, the simulator's end-of-drive
flag and one layer's diagnostics, and waits for the drive to end."""

from __future__ import annotations

import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from nav_msgs.msg import OccupancyGrid
from std_msgs.msg import Bool

from downstream_perception.ros.costmap_client import CostmapClient


class CostmapWatch:
    def __init__(self, layer: str, costmap_topic: str = "/costmap/costmap") -> None:
        self.client = CostmapClient(costmap_topic)
        self.done_wall: float | None = None
        self.layer_status: dict[str, str] = {}
        self._layer = f"layer {layer}"
        rospy.Subscriber("/sim_done", Bool, self._on_done, queue_size=1)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self._on_diag, queue_size=10)

    @property
    def latest(self) -> OccupancyGrid | None:
        """The current costmap (full grid plus updates), or None before the first one."""
        return self.client.message() if self.client.received else None

    @property
    def latest_wall(self) -> float:
        return self.client.last_change_wall

    def _on_done(self, msg: Bool) -> None:
        if msg.data and self.done_wall is None:
            self.done_wall = time.time()

    def _on_diag(self, msg: DiagnosticArray) -> None:
        for status in msg.status:
            if self._layer in status.name:
                self.layer_status = {kv.key: kv.value for kv in status.values}

    def wait_for_drive_end(self, timeout_s: float = 90.0) -> None:
        deadline = time.time() + timeout_s
        while self.done_wall is None and time.time() < deadline and not rospy.is_shutdown():
            time.sleep(0.1)
        assert self.done_wall is not None, "the simulator never reported sim_done"
