"""The TSDF nodelet's mesh as a subscriber sees it (for tests, the demo and tools)."""

from __future__ import annotations

import numpy as np
import rospy
from visualization_msgs.msg import Marker, MarkerArray


class MeshCollector:
    """Keeps the latest mesh published on `topic` (per-block TRIANGLE_LIST markers): DELETE
    drops a block, DELETEALL (after ~clear) all of them."""

    def __init__(self, topic: str) -> None:
        self.blocks: dict[int, np.ndarray] = {}  # marker id -> (3 n, 3) triangle corners
        self.messages = 0
        self.deleted_all = False
        self.subscriber = rospy.Subscriber(topic, MarkerArray, self._on_mesh, queue_size=20)

    def _on_mesh(self, msg: MarkerArray) -> None:
        for m in msg.markers:
            if m.action == Marker.DELETEALL:
                self.blocks.clear()
                self.deleted_all = True
            elif m.action == Marker.DELETE:
                self.blocks.pop(m.id, None)
            else:
                self.blocks[m.id] = np.array([[p.x, p.y, p.z] for p in m.points]).reshape(-1, 3)
        self.messages += 1

    def corners(self) -> np.ndarray:
        """All triangle corners (3 per triangle), (N, 3) m."""
        return np.vstack(list(self.blocks.values())) if self.blocks else np.empty((0, 3))
