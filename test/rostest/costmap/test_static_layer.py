#!/usr/bin/env python3
"""rostest: downstream_perception/StaticLayer in the costmap nodelet, fed like map_server feeds
costmap_2d (a latched /map, then map_msgs/OccupancyGridUpdate on /map_updates).

The map is 60 x 40 cells at 0.05 m with origin (-1.0, -0.5): a lethal border (100), an unknown
block (-1), a cell of 50 (below lethal_cost_threshold 100: free with trinary_costmap), free
elsewhere. Both costmaps start 40 x 40 at 0.1 m and must take the map's geometry."""

from __future__ import annotations

import threading
import time
import unittest

import dynamic_reconfigure.client
import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from map_msgs.msg import OccupancyGridUpdate
from nav_msgs.msg import OccupancyGrid
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import transform_stamped, wait_until

LETHAL, FREE, UNKNOWN = 100, 0, -1
W, H, RES, OX, OY = 60, 40, 0.05, -1.0, -0.5


def map_data() -> np.ndarray:
    grid = np.zeros((H, W), dtype=np.int8)
    grid[0, :] = grid[-1, :] = grid[:, 0] = grid[:, -1] = 100
    grid[20:30, 40:50] = -1  # rows = y, columns = x
    grid[5, 5] = 50
    return grid


def occupancy_grid(data: np.ndarray, frame: str = "map", width: int = W) -> OccupancyGrid:
    msg = OccupancyGrid()
    msg.header.frame_id = frame
    msg.header.stamp = rospy.Time.now()
    msg.info.width, msg.info.height, msg.info.resolution = width, H, RES
    msg.info.origin.position.x, msg.info.origin.position.y = OX, OY
    msg.info.origin.orientation.w = 1.0
    msg.data = data.ravel().tolist()
    return msg


class DiagnosticsWatch:
    """The latest diagnostics status (message and values) of each layer, by layer name."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._status: dict[str, tuple[str, dict[str, str]]] = {}
        rospy.Subscriber("/diagnostics", DiagnosticArray, self._on_diag, queue_size=20)

    def _on_diag(self, msg: DiagnosticArray) -> None:
        with self._lock:
            for s in msg.status:
                for layer in ("static_map", "static_free"):
                    if f"layer {layer}" in s.name:
                        self._status[layer] = (s.message, {kv.key: kv.value for kv in s.values})

    def get(self, layer: str) -> tuple[str, dict[str, str]]:
        with self._lock:
            return self._status.get(layer, ("", {}))


class StaticLayerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_static_layer")
        cls.static_tf = StaticTransformBroadcaster()
        cls.static_tf.sendTransform([transform_stamped("map", "base_link", rospy.Time.now())])
        cls.diag = DiagnosticsWatch()
        cls.costmap = CostmapClient("/costmap/costmap")
        cls.costmap_free = CostmapClient("/costmap_free/costmap")
        cls.map_pub = rospy.Publisher("/map", OccupancyGrid, queue_size=1, latch=True)
        cls.update_pub = rospy.Publisher("/map_updates", OccupancyGridUpdate, queue_size=10)

    def wait_geometry(self, client: CostmapClient, width: int) -> bool:
        return wait_until(lambda: client.received and client.message().info.width == width, 30.0)

    def wait_diag(self, layer: str, key: str, value: str) -> dict[str, str]:
        wait_until(lambda: self.diag.get(layer)[1].get(key) == value, 20.0)
        return self.diag.get(layer)[1]

    def test_static_layer(self) -> None:
        # 1. No map yet: the nodelet runs (publishes its 4 x 4 m default) and names the topic.
        self.assertTrue(self.wait_geometry(self.costmap, 40), "no costmap without a map")
        self.assertTrue(wait_until(lambda: self.diag.get("static_map")[0] != "", 20.0))
        message, values = self.diag.get("static_map")
        self.assertEqual(message, "waiting for map on /map")
        self.assertEqual(values["map received"], "no")

        # 2. The map: both costmaps take its size, resolution and origin.
        data = map_data()
        self.map_pub.publish(occupancy_grid(data))
        for client in (self.costmap, self.costmap_free):
            self.assertTrue(self.wait_geometry(client, W), "costmap not resized to the map")
            info = client.message().info
            self.assertEqual((info.width, info.height), (W, H))
            self.assertAlmostEqual(info.resolution, RES, places=6)
            self.assertAlmostEqual(info.origin.position.x, OX, places=6)
            self.assertAlmostEqual(info.origin.position.y, OY, places=6)
        walls = data == 100

        def drawn(client: CostmapClient) -> bool:
            g = client.grid()
            return g.shape == (H, W) and bool(np.all(g[walls] == LETHAL))

        self.assertTrue(wait_until(lambda: drawn(self.costmap), 20.0), "walls not lethal")
        self.assertTrue(wait_until(lambda: drawn(self.costmap_free), 20.0), "walls not lethal")
        g, gf = self.costmap.grid(), self.costmap_free.grid()
        self.assertTrue(np.all(g[20:30, 40:50] == UNKNOWN), "unknown not kept (tracked)")
        self.assertTrue(np.all(gf[20:30, 40:50] == FREE), "unknown not free (untracked)")
        self.assertEqual(g[5, 5], FREE, "50 < lethal_cost_threshold is free (trinary)")
        self.assertEqual(int(np.count_nonzero(g == LETHAL)), int(np.count_nonzero(walls)))
        values = self.wait_diag("static_map", "map received", "yes")
        self.assertEqual(values["lethal cells"], str(int(np.count_nonzero(walls))))
        self.assertEqual(values["unknown cells"], "100")
        self.assertEqual(self.diag.get("static_free")[1]["unknown cells"], "0")

        # 3. An update: a 5 x 4 lethal block at cells x 10..14, y 10..13.
        up = OccupancyGridUpdate()
        up.header.frame_id = "map"
        up.x, up.y, up.width, up.height = 10, 10, 5, 4
        up.data = [100] * 20
        # One connection: both costmaps live in the same manager process.
        self.assertTrue(wait_until(lambda: self.update_pub.get_num_connections() >= 1, 20.0))
        self.update_pub.publish(up)
        self.assertTrue(
            wait_until(lambda: bool(np.all(self.costmap.grid()[10:14, 10:15] == LETHAL)), 20.0),
            "update not applied",
        )
        self.assertEqual(self.costmap.grid()[14, 10], FREE, "update spilled outside its window")
        self.assertTrue(
            wait_until(lambda: bool(np.all(self.costmap_free.grid()[10:14, 10:15] == LETHAL)), 20.0)
        )

        # 4. The map's size is locked (costmap_2d's size_locked): a reconfigure of width is not
        # applied.
        dynamic_reconfigure.client.Client("/costmap", timeout=20.0).update_configuration(
            {"width": 2.0}
        )
        time.sleep(1.0)
        self.assertEqual(self.costmap.message().info.width, W, "reconfigure resized a map")

        # 5. Refusals: an update sticking out of the map, a map whose data does not fill
        # width x height, a map in another frame. Each is counted; the map stays.
        bad_up = OccupancyGridUpdate()
        bad_up.x, bad_up.y, bad_up.width, bad_up.height = 58, 0, 5, 1
        bad_up.data = [0] * 5  # would clear the wall cells 58, 59 of row 0 if written
        self.update_pub.publish(bad_up)
        values = self.wait_diag("static_map", "updates refused", "1")
        self.assertEqual(values["updates refused"], "1")
        self.assertIn("outside", values["last refusal"])

        short = occupancy_grid(data)
        short.data = short.data[:10]
        self.map_pub.publish(short)
        values = self.wait_diag("static_map", "maps refused", "1")
        self.assertEqual(values["maps refused"], "1")
        self.assertIn("10 values", values["last refusal"])

        self.map_pub.publish(occupancy_grid(np.zeros((H, W), dtype=np.int8), frame="odom"))
        values = self.wait_diag("static_map", "maps refused", "2")
        self.assertEqual(values["maps refused"], "2")
        self.assertIn("global_frame", values["last refusal"])
        message, _ = self.diag.get("static_map")
        self.assertIn("previous map", message)

        time.sleep(1.0)  # a few more updates and publishes of the costmap
        g = self.costmap.grid()
        self.assertEqual(g.shape, (H, W), "a refused map changed the costmap")
        self.assertTrue(np.all(g[walls] == LETHAL), "a refused map or update cleared the walls")
        self.assertTrue(np.all(g[10:14, 10:15] == LETHAL))
        self.assertEqual(g[0, 58:60].tolist(), [LETHAL, LETHAL], "the refused update was written")


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "static_layer", StaticLayerTest)
