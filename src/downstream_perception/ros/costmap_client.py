"""Follow a published costmap the way move_base does: the full grid on <topic>, then the changed
windows on <topic>_updates (map_msgs/OccupancyGridUpdate). Needs rospy (import it only in a ROS
process); the rest of the package does not.

    client = CostmapClient("/costmap/costmap")
    grid = client.grid()  # int8 numpy array [rows, cols], -1 unknown, 0..100 cost
"""

from __future__ import annotations

import threading
import time

import numpy as np
import rospy
from map_msgs.msg import OccupancyGridUpdate
from nav_msgs.msg import OccupancyGrid


class CostmapClient:
    """The current costmap rebuilt from full grids plus updates, safe to read from any thread."""

    def __init__(self, topic: str) -> None:
        self._lock = threading.Lock()
        self._info = None
        self._header = None
        self._grid: np.ndarray | None = None
        self._last_full: np.ndarray | None = None
        self.full_grids = 0
        self.updates = 0
        self.updates_dropped = 0  # updates that did not fit the current grid
        self.last_change_wall = 0.0  # time.time() of the last full grid or update
        rospy.Subscriber(topic, OccupancyGrid, self._on_full, queue_size=10)
        rospy.Subscriber(f"{topic}_updates", OccupancyGridUpdate, self._on_update, queue_size=100)

    def _on_full(self, msg: OccupancyGrid) -> None:
        grid = np.asarray(msg.data, dtype=np.int8).reshape(msg.info.height, msg.info.width)
        with self._lock:
            self._info, self._header = msg.info, msg.header
            self._grid = grid.copy()
            self._last_full = grid
            self.full_grids += 1
            self.last_change_wall = time.time()

    def _on_update(self, msg: OccupancyGridUpdate) -> None:
        with self._lock:
            if self._grid is None:
                return  # an update before any full grid cannot be placed
            rows, cols = self._grid.shape
            if (
                msg.x + msg.width > cols
                or msg.y + msg.height > rows
                or len(msg.data) != msg.width * msg.height
            ):
                # An update for another size: one sent before a resize that arrived after the
                # new full grid (two topics, no order between them). Dropped, as rviz does.
                self.updates_dropped += 1
                return
            patch = np.asarray(msg.data, dtype=np.int8).reshape(msg.height, msg.width)
            self._grid[msg.y : msg.y + msg.height, msg.x : msg.x + msg.width] = patch
            self.updates += 1
            self.last_change_wall = time.time()

    @property
    def received(self) -> bool:
        with self._lock:
            return self._grid is not None

    def grid(self) -> np.ndarray:
        """A copy of the current grid (rows = y). Raises if nothing was received yet."""
        with self._lock:
            if self._grid is None:
                raise RuntimeError("no costmap received yet")
            return self._grid.copy()

    def last_full_grid(self) -> np.ndarray:
        """The last grid received whole on <topic> (without the updates since)."""
        with self._lock:
            if self._last_full is None:
                raise RuntimeError("no costmap received yet")
            return self._last_full.copy()

    def message(self) -> OccupancyGrid:
        """The current costmap as one nav_msgs/OccupancyGrid (as if sent in full)."""
        with self._lock:
            if self._grid is None or self._info is None:
                raise RuntimeError("no costmap received yet")
            msg = OccupancyGrid(header=self._header, info=self._info)
            msg.data = self._grid.ravel().tolist()
            return msg

    def origin(self) -> tuple[float, float]:
        with self._lock:
            if self._info is None:
                raise RuntimeError("no costmap received yet")
            return self._info.origin.position.x, self._info.origin.position.y

    def cell(self, x: float, y: float) -> int:
        """Value of the cell containing world point (x, y) in the grid's frame."""
        with self._lock:
            if self._grid is None or self._info is None:
                raise RuntimeError("no costmap received yet")
            res = self._info.resolution
            col = int(np.floor((x - self._info.origin.position.x) / res))
            row = int(np.floor((y - self._info.origin.position.y) / res))
            return int(self._grid[row, col])
