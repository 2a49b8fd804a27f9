#!/usr/bin/env python3
"""rostest: costmap_2d's host-level keys keep their meaning in our costmap host.

prehydro: no ~plugins, so the list costmap_2d generates (obstacle_layer, inflation_layer) with the
pre-Hydro keys moved into it; a misspelt and a wrongly typed key are named. empty: no layers is an
ERROR, and publish_frequency's default 0 publishes nothing but a new subscriber's grid.
/robot/aliases: costmap_2d's type name and the move_base spelling load our layers, the footprint
is found one namespace up, a host-level key costmap_2d would not copy is named, and a rejected
reconfigure value is reverted."""

from __future__ import annotations

import math
import subprocess
import sys
import time
import unittest

import dynamic_reconfigure.client
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PolygonStamped
from nav_msgs.msg import OccupancyGrid
from sensor_msgs.msg import LaserScan
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until

LETHAL = 100


class Costmap2dHostTest(unittest.TestCase):
    status: dict[str, DiagnosticStatus] = {}

    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_costmap_2d_host")

        def on_diag(msg: DiagnosticArray) -> None:
            for s in msg.status:
                cls.status[s.name] = s

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=50)
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "base_link", now),
                transform_stamped("base_link", "laser", now, x=0.01, y=0.01),
            ]
        )
        cls.prehydro = CostmapClient("/prehydro/costmap")
        cls.pub = rospy.Publisher("/host_scan", LaserScan, queue_size=10)
        assert wait_until(lambda: cls.pub.get_num_connections() >= 1, 30.0), "nobody on /host_scan"

    # ------------------------------------------------------------------ helpers
    def diag(self, node: str, task: str = "costmap") -> DiagnosticStatus:
        def find() -> DiagnosticStatus | None:
            for name, s in self.status.items():
                if name.startswith(node.lstrip("/") + ":") and name.endswith(": " + task):
                    return s
            return None

        self.assertTrue(
            wait_until(lambda: find() is not None, 20.0),
            f"no status {node}: {task} in {sorted(self.status)}",
        )
        found = find()
        assert found is not None
        return found

    def warnings(self, node: str) -> list[str]:
        return [
            kv.value for kv in self.diag(node).values if kv.key.startswith("parameter warning ")
        ]

    # ------------------------------------------------------------------ tests
    def test_prehydro_list_is_generated_and_keys_moved(self) -> None:
        self.assertTrue(wait_until(lambda: rospy.has_param("/prehydro/plugins"), 20.0))
        self.assertEqual(
            rospy.get_param("/prehydro/plugins"),
            [
                {"name": "obstacle_layer", "type": "costmap_2d::ObstacleLayer"},
                {"name": "inflation_layer", "type": "costmap_2d::InflationLayer"},
            ],
        )
        self.assertEqual(rospy.get_param("/prehydro/obstacle_layer/observation_sources"), "laser")
        self.assertEqual(rospy.get_param("/prehydro/obstacle_layer/laser/topic"), "host_scan")
        self.assertEqual(rospy.get_param("/prehydro/inflation_layer/inflation_radius"), 0.4)
        for moved in ("observation_sources", "laser", "inflation_radius", "obstacle_range"):
            self.assertFalse(rospy.has_param("/prehydro/" + moved), moved + " was not moved")

    def test_prehydro_marks_within_obstacle_range_and_inflates_by_the_moved_radius(self) -> None:
        # Four beams from the laser at (0.01, 0.01), off the cell edges: +x 1.5 m (beyond
        # obstacle_range 1 m), +y 0.8 m (marks).
        ranges = [1.5, 0.8, math.inf, math.inf]

        def drawn() -> bool:
            return self.prehydro.received and self.prehydro.cell(0.025, 0.825) == LETHAL

        deadline = time.time() + 20.0
        while not drawn() and time.time() < deadline:
            self.pub.publish(
                laser_scan(rospy.Time.now(), "laser", ranges, 0.0, math.pi / 2, 0.05, 10.0)
            )
            time.sleep(0.2)
        self.assertTrue(drawn(), "the obstacle at 0.8 m never marked")
        cell = self.prehydro.cell
        self.assertNotEqual(cell(1.525, 0.025), LETHAL, "marked beyond obstacle_range")
        # inflation_radius 0.4 m (moved from the host): a cost 0.3 m beside the hit, none at 0.5 m.
        self.assertGreater(cell(0.325, 0.825), 0, "no inflation 0.3 m from the obstacle")
        self.assertEqual(cell(0.525, 0.825), 0, "inflated beyond inflation_radius 0.4 m")

    def test_prehydro_a_late_subscriber_first_gets_the_current_grid(self) -> None:
        """costmap_2d sends each new subscriber the current grid, whatever publish_frequency
        (5 Hz here). A latched ~costmap handed it the last full grid published instead, drawn
        before the obstacle. A process of its own: rospy shares one connection per topic."""
        self.test_prehydro_marks_within_obstacle_range_and_inflates_by_the_moved_radius()
        code = (
            "import rospy; from nav_msgs.msg import OccupancyGrid;"
            "rospy.init_node('late_subscriber', anonymous=True);"
            "m = rospy.wait_for_message('/prehydro/costmap', OccupancyGrid, timeout=20.0);"
            "i = int((0.825 - m.info.origin.position.y) / m.info.resolution);"
            "j = int((0.025 - m.info.origin.position.x) / m.info.resolution);"
            "print(m.data[i * m.info.width + j])"
        )
        out = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, timeout=60.0
        )
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(int(out.stdout.strip()), LETHAL, "the first grid was not the current one")

    def test_prehydro_names_the_misspelt_and_the_string_key(self) -> None:
        self.assertTrue(wait_until(lambda: len(self.warnings("/prehydro")) >= 2, 20.0))
        text = "\n".join(self.warnings("/prehydro"))
        self.assertIn("raytrace_rnage", text)
        self.assertIn("'1.0e1' (string)", text)
        status = self.diag("/prehydro")
        self.assertEqual(status.level, DiagnosticStatus.WARN, status.message)
        values = {kv.key: kv.value for kv in status.values}
        self.assertEqual(float(values["update rate requested (Hz)"]), 5.0)

    def test_no_layers_is_an_error_and_publish_frequency_zero_answers_new_subscribers_only(
        self,
    ) -> None:
        """publish_frequency's default 0: no periodic grid, but the new subscriber gets the
        current grid once (costmap_2d's Costmap2DPublisher::onNewSubscription)."""
        received: list[OccupancyGrid] = []
        sub = rospy.Subscriber("/empty/costmap", OccupancyGrid, received.append)
        status = self.diag("/empty")
        self.assertEqual(status.level, DiagnosticStatus.ERROR)
        self.assertIn("no layers", status.message)
        time.sleep(2.0)
        sub.unregister()
        self.assertEqual(
            len(received), 1, "publish_frequency 0: expected one grid for the new subscriber"
        )

    def test_costmap_2d_type_names_load_our_layers(self) -> None:
        self.diag("/robot/aliases", "layer obstacles")
        self.diag("/robot/aliases", "layer inflation")
        text = "\n".join(self.warnings("/robot/aliases"))
        self.assertIn("/robot/aliases/inflation_radius", text)

    def test_footprint_is_found_one_namespace_up_and_padded_as_costmap_2d(self) -> None:
        msg = rospy.wait_for_message("/robot/aliases/footprint", PolygonStamped, timeout=20.0)
        points = [(round(p.x, 4), round(p.y, 4)) for p in msg.polygon.points]
        # footprint_padding 0.01: a coordinate that is exactly 0 stays 0 (costmap_2d's sign0).
        self.assertEqual(points, [(0.31, 0.0), (0.0, 0.21), (-0.31, 0.0), (0.0, -0.21)])

    def test_a_rejected_reconfigure_value_is_reverted_and_its_error_clears(self) -> None:
        client = dynamic_reconfigure.client.Client("/robot/aliases", timeout=20.0)
        used = client.update_configuration({"update_frequency": -1.0, "robot_radius": -1.0})
        self.assertEqual(used["update_frequency"], 5.0, "the server shows the refused value")
        self.assertEqual(used["robot_radius"], 0.46, "the server shows the refused radius")
        self.assertTrue(
            wait_until(lambda: "update_frequency" in self.diag("/robot/aliases").message, 20.0)
        )
        client.update_configuration({"update_frequency": 4.0})
        self.assertTrue(
            wait_until(lambda: self.diag("/robot/aliases").level != DiagnosticStatus.ERROR, 20.0),
            self.diag("/robot/aliases").message,
        )


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "costmap_2d_host", Costmap2dHostTest)
