#!/usr/bin/env python3
"""rostest: a tracked object is drawn once, by its prediction (clear_tracked_objects).

The test plays the robot's lidar and its detector: a round cart (0.6 m) crosses 3 m in front of
a standing robot at 0.3 m/s, a wall stands at 6 m. The real tracker confirms the cart. Costmap
`plain` (obstacle layer alone) draws the cart where its returns landed, and never ahead of it;
costmap `handoff` (obstacle layer with clear_tracked_objects, plus the TrackedObstacleLayer)
draws nothing behind the cart and the 1 s predicted sweep ahead of it. Both keep the wall.
"""

from __future__ import annotations

import threading
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import LaserScan
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.msg import DetectedObjectArray
from downstream_perception.planar import se2_matrix
from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import (
    detection_array,
    laser_scan,
    transform_stamped,
    wait_until,
)
from downstream_perception.sim import Lidar, LidarConfig
from downstream_perception.sim.world import MovingCircle, World

MAP_ODOM = (0.4, -0.3, 0.1)
ODOM_BASE = (0.2, 0.1, -0.1)  # the base stands at yaw 0 in map
CART_X, CART_Y0, CART_SPEED, CART_RADIUS = 3.0, -2.5, 0.3, 0.3
WALL_X = 6.0
ORIGIN, RES = (-2.0, -5.0), 0.05
WALL_REGION_X = 5.7  # cells beyond this belong to the wall


MAP_BASE = se2_matrix(*MAP_ODOM) @ se2_matrix(*ODOM_BASE)
BASE_MAP = np.linalg.inv(MAP_BASE)


class TrackedClearingTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tracked_clearing")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "odom", now, *MAP_ODOM[:2], yaw=MAP_ODOM[2]),
                transform_stamped("odom", "base_link", now, *ODOM_BASE[:2], yaw=ODOM_BASE[2]),
            ]
        )
        cls.maps = {k: CostmapClient(f"/{k}/costmap") for k in ("plain", "handoff")}
        cls.layer_status: dict[str, str] = {}
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=20)
        cls.scans = rospy.Publisher("/clearing_test/scan", LaserScan, queue_size=5)
        cls.detections = rospy.Publisher(
            "/clearing_test/detections", DetectedObjectArray, queue_size=5
        )
        duration = 2 * abs(CART_Y0) / CART_SPEED
        cls.world = World(
            segments=np.array([[WALL_X, -4.5, WALL_X, 4.5]]),
            movers=[
                MovingCircle(
                    CART_RADIUS,
                    np.array([[0.0, CART_X, CART_Y0], [duration, CART_X, -CART_Y0]]),
                )
            ],
        )
        cls.lidar = Lidar(LidarConfig(num_beams=720, noise_std_m=0.005))
        cls.t0 = rospy.Time.now() + rospy.Duration(1.0)
        cls.running = True
        for target, rate in ((cls.publish_scan, 10.0), (cls.publish_detection, 15.0)):
            threading.Thread(target=cls.loop, args=(target, rate), daemon=True).start()

    @classmethod
    def on_diagnostics(cls, msg: DiagnosticArray) -> None:
        for s in msg.status:
            if s.name.endswith("handoff: layer obstacles"):
                cls.layer_status = {kv.key: kv.value for kv in s.values}

    @classmethod
    def loop(cls, publish, rate_hz: float) -> None:  # type: ignore[no-untyped-def]
        rate = rospy.Rate(rate_hz)
        while cls.running and not rospy.is_shutdown():
            stamp = rospy.Time.now()
            t = (stamp - cls.t0).to_sec()
            if t >= 0.0:
                publish(stamp, t)
            rate.sleep()

    @classmethod
    def cart_y(cls, t: float) -> float:
        return CART_Y0 + CART_SPEED * t

    @classmethod
    def publish_scan(cls, stamp: rospy.Time, t: float) -> None:
        pose = (float(MAP_BASE[0, 2]), float(MAP_BASE[1, 2]), 0.0)
        c = cls.lidar.config
        ranges = cls.lidar.scan(cls.world, pose, t)
        cls.scans.publish(
            laser_scan(
                stamp, "base_link", ranges, c.angle_min, c.angle_increment, c.range_min, 10.0
            )
        )

    @classmethod
    def publish_detection(cls, stamp: rospy.Time, t: float) -> None:
        x, y, _ = BASE_MAP @ np.array([CART_X, cls.cart_y(t), 1.0])
        cls.detections.publish(
            detection_array(
                stamp, "base_link", np.array([[x, y]]), np.array([0.9]), np.array([1]), 1e-4,
                sizes=np.full((1, 2), 2 * CART_RADIUS),
            )
        )  # fmt: skip

    def lethal_cells(self, key: str) -> tuple[np.ndarray, np.ndarray]:
        """Map coordinates (x, y) of every lethal cell's centre."""
        rows, cols = np.nonzero(self.maps[key].grid() == 100)
        return ORIGIN[0] + (cols + 0.5) * RES, ORIGIN[1] + (rows + 0.5) * RES

    def test_cart_is_drawn_once_by_its_prediction(self) -> None:
        self.assertTrue(
            wait_until(lambda: all(m.received for m in self.maps.values()), 20.0), "no costmaps"
        )
        rospy.sleep(max(0.0, 4.0 - (rospy.Time.now() - self.t0).to_sec()))
        trail = []
        for _ in range(6):
            cy = self.cart_y((rospy.Time.now() - self.t0).to_sec())
            for key in ("plain", "handoff"):
                x, y = self.lethal_cells(key)
                wall = x >= WALL_REGION_X
                self.assertGreater(int(wall.sum()), 100, f"{key}: the wall is missing")
                floor_x, floor_y = x[~wall], y[~wall]
                ahead = int((floor_y > cy + 0.45).sum())
                behind = int((floor_y < cy - 0.6).sum())
                if key == "plain":
                    # Returns land on the cart's rim: cells at the cart, none ahead of it.
                    near = (np.abs(floor_x - CART_X) <= 0.5) & (np.abs(floor_y - cy) <= 0.6)
                    cells = np.round(np.c_[floor_x, floor_y], 2)[:20].tolist()
                    self.assertGreater(
                        int(near.sum()), 3, f"plain: no cart at y {cy:.2f}; lethal floor: {cells}"
                    )
                    self.assertEqual(ahead, 0, "plain: cells ahead of the cart")
                    trail.append(behind)
                else:
                    # Only the prediction: within the cart's width of its line, from where it
                    # was measured to 1 s (+ the grid's age) ahead, and nothing behind it.
                    self.assertGreater(ahead, 0, "handoff: no predicted cells ahead of the cart")
                    self.assertEqual(behind, 0, f"handoff: {behind} cells behind the cart")
                    self.assertLessEqual(float(np.abs(floor_x - CART_X).max()), 0.35)
                    self.assertLessEqual(float(floor_y.max()), cy + 0.3 + CART_SPEED * 1.5 + 0.1)
            rospy.sleep(0.4)
        self.assertTrue(
            wait_until(lambda: "cells cleared under tracks (total)" in self.layer_status, 10.0),
            f"no clearing diagnostics: {sorted(self.layer_status)}",
        )
        cleared = int(self.layer_status["cells cleared under tracks (total)"])
        self.assertGreater(cleared, 0)
        self.assertEqual(int(self.layer_status["tracks: track arrays received"]) > 0, True)
        print(f"\nplain: lethal cells behind the cart per sample {trail}; handoff: none")
        print(f"handoff: {cleared} cells of the cart's returns cleared under its track")
        type(self).running = False


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "tracked_clearing", TrackedClearingTest)
