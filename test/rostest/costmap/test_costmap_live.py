#!/usr/bin/env python3
"""rostest: live features of the costmap nodelet on scripted scans and clouds.

The node plays the robot: it broadcasts map -> base_link (the robot can be moved), static
base_link -> laser / camera, and publishes at 10 Hz a LaserScan computed from a world with a wall
at x = 2 m (|y| < 0.3 m) plus one self-hit 0.2 m behind the sensor, and a PointCloud2 with a box
at (0.1, 2.0) inside the height band and a floor patch at (-1, 1) below it. Test methods run in
name order and build on each other.
"""

from __future__ import annotations

import functools
import math
import threading
import time
import unittest

import dynamic_reconfigure.client
import numpy as np
import rospy
import rostest
from sensor_msgs import point_cloud2
from sensor_msgs.msg import LaserScan, PointCloud2
from std_srvs.srv import Empty
from tf2_ros import StaticTransformBroadcaster, TransformBroadcaster

from downstream_perception.ros import util as ros_util
from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import laser_scan, transform_stamped

WALL_X = 2.025  # a cell centre: no float rounding decides the cell
N_BEAMS = 720
CAMERA_Z = 0.5


def scan_ranges(robot_x: float) -> np.ndarray:
    """Ranges from (robot_x, 0) with yaw 0 in the scripted world (numpy, one value per beam)."""
    angles = -math.pi + np.arange(N_BEAMS) * (2 * math.pi / N_BEAMS)
    ranges = np.full(N_BEAMS, np.inf, dtype=np.float32)
    c = np.cos(angles)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = (WALL_X - robot_x) / c
    hit_y = r * np.sin(angles)
    wall = (c > 1e-6) & (np.abs(hit_y) < 0.3)
    ranges[wall] = r[wall]
    ranges[0] = 0.2  # angle -pi: a self-hit on the robot's own body, inside the footprint
    return ranges


class Robot:
    """Publishes tf, scans and clouds from a background thread; tests pause it and move it."""

    def __init__(self) -> None:
        self.x = 0.0
        self.publishing = True
        self.lock = threading.Lock()
        self.tf = TransformBroadcaster()
        self.static = StaticTransformBroadcaster()
        now = rospy.Time.now()
        self.static.sendTransform(
            [
                transform_stamped("base_link", "laser", now),
                transform_stamped("base_link", "camera", now, z=CAMERA_Z),
            ]
        )
        self.scan_pub = rospy.Publisher("/scan", LaserScan, queue_size=5)
        self.cloud_pub = rospy.Publisher("/cloud", PointCloud2, queue_size=5)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        rate = rospy.Rate(20)
        k = 0
        while not rospy.is_shutdown():
            now = rospy.Time.now()
            with self.lock:
                x, publishing = self.x, self.publishing
            self.tf.sendTransform(transform_stamped("map", "base_link", now, x=x))
            if publishing and k % 2 == 1:
                self._publish_scan(x, now)
                self._publish_cloud(now)
            k += 1
            rate.sleep()

    def _publish_scan(self, robot_x: float, stamp: rospy.Time) -> None:
        msg = laser_scan(
            stamp, "laser", scan_ranges(robot_x), -math.pi, 2 * math.pi / N_BEAMS, 0.05, 30.0
        )
        self.scan_pub.publish(msg)

    def _publish_cloud(self, stamp: rospy.Time) -> None:
        # Camera frame = base_link raised by CAMERA_Z; points relative to it.
        xs, ys = np.meshgrid(np.linspace(0.05, 0.15, 3), np.linspace(1.95, 2.05, 3))
        box = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, 0.3 - CAMERA_Z)], axis=1)
        floor = np.array([[-1.0, 1.0, 0.0 - CAMERA_Z], [-1.02, 1.02, 0.02 - CAMERA_Z]])
        header = rospy.Header(stamp=stamp, frame_id="camera")
        self.cloud_pub.publish(point_cloud2.create_cloud_xyz32(header, np.vstack([box, floor])))

    def pause(self) -> None:
        with self.lock:
            self.publishing = False

    def resume(self) -> None:
        with self.lock:
            self.publishing = True

    def move_to(self, x: float) -> None:
        with self.lock:
            self.x = x


# Every wait in this test allows 20 s.
wait_until = functools.partial(ros_util.wait_until, timeout_s=20.0)


def cell_value(grid: np.ndarray, origin: tuple[float, float], x: float, y: float) -> int:
    return int(grid[int((y - origin[1]) / 0.05), int((x - origin[0]) / 0.05)])


class CostmapLiveTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_costmap_live")
        cls.live = CostmapClient("/costmap_live/costmap")
        cls.rolling = CostmapClient("/costmap_rolling/costmap")
        cls.robot = Robot()
        cls.origin = (-5.0, -5.0)

    def lethal_at(self, x: float, y: float) -> bool:
        return cell_value(self.live.grid(), self.origin, x, y) == 100

    def test_1_scan_wall_cloud_band_and_footprint_clearing(self) -> None:
        self.assertTrue(
            wait_until(lambda: self.live.received and self.lethal_at(WALL_X, 0.0)),
            f"the wall seen by the scan never became lethal; lethal cells at "
            f"{np.argwhere(self.live.grid() == 100)[:10].tolist() if self.live.received else None}",
        )
        self.assertTrue(
            wait_until(lambda: self.lethal_at(0.1, 2.0)), "the cloud's box is not lethal"
        )
        grid = self.live.grid()
        # The self-hit 0.2 m behind the sensor lies inside the +-0.3 m footprint: cleared to free.
        self.assertEqual(cell_value(grid, self.origin, -0.2, 0.0), 0)
        # Floor points below min_obstacle_height never mark.
        self.assertNotEqual(cell_value(grid, self.origin, -1.0, 1.0), 100)
        # Inflation around the wall: the cell 0.1 m in front of it is inscribed or inflated.
        self.assertGreater(cell_value(grid, self.origin, WALL_X - 0.1, 0.0), 0)

    def test_2_updates_rebuild_the_full_grid(self) -> None:
        self.robot.pause()
        time.sleep(1.5)  # the last scans integrated and published as updates
        self.assertGreater(self.live.updates, 0, "no ~costmap_updates were published")
        rebuilt = self.live.grid()
        fulls_before = self.live.full_grids
        client = dynamic_reconfigure.client.Client("/costmap_live", timeout=10)
        client.update_configuration({"always_send_full_costmap": True})
        self.assertTrue(
            wait_until(lambda: self.live.full_grids > fulls_before), "no full grid followed"
        )
        full = self.live.last_full_grid()
        np.testing.assert_array_equal(rebuilt, full)
        self.assertGreater(int(np.count_nonzero(full == 100)), 10)
        client.update_configuration({"always_send_full_costmap": False})

    def test_3_reconfigure_disables_and_enables_a_layer(self) -> None:
        client = dynamic_reconfigure.client.Client("/costmap_live/obstacles", timeout=10)
        client.update_configuration({"enabled": False})
        self.assertTrue(
            wait_until(lambda: int(np.count_nonzero(self.live.grid() == 100)) == 0),
            "lethal cells stayed after the obstacle layer was disabled",
        )
        client.update_configuration({"enabled": True})
        self.assertTrue(
            wait_until(lambda: self.lethal_at(WALL_X, 0.0)),
            "the wall did not come back when the layer was enabled again",
        )

    def test_4_decay_fades_unseen_obstacles_to_unknown(self) -> None:
        # No scans arrive (paused): only decay can remove the wall.
        client = dynamic_reconfigure.client.Client("/costmap_live/obstacles", timeout=10)
        client.update_configuration({"decay_time_s": 0.5})
        self.assertTrue(
            wait_until(lambda: int(np.count_nonzero(self.live.grid() == 100)) == 0),
            "lethal cells did not decay",
        )
        self.assertEqual(cell_value(self.live.grid(), self.origin, WALL_X, 0.0), -1)
        client.update_configuration({"decay_time_s": 0.0})

    def test_5_clear_service_forgets_everything(self) -> None:
        self.robot.resume()
        self.assertTrue(wait_until(lambda: self.lethal_at(WALL_X, 0.0)), "wall not re-seen")
        self.robot.pause()
        time.sleep(0.5)
        rospy.wait_for_service("/costmap_live/clear", timeout=10)
        rospy.ServiceProxy("/costmap_live/clear", Empty)()

        def cleared() -> bool:
            grid = self.live.grid()
            # Only the footprint (12 x 12 cells) is known again: it is cleared every update.
            return (
                int(np.count_nonzero(grid == 100)) == 0 and int(np.count_nonzero(grid >= 0)) <= 144
            )

        self.assertTrue(wait_until(cleared), "the map was not cleared")

    def test_6_rolling_window_follows_the_robot(self) -> None:
        self.robot.resume()
        self.assertTrue(
            # costmap_2d's rule: origin 0 + whole cells toward robot - (80 - 0.5) * 0.05 / 2 =
            # -1.9875, truncated toward zero: -39 cells, -1.95 m.
            wait_until(
                lambda: self.rolling.received and abs(self.rolling.origin()[0] + 1.95) < 1e-6
            ),
            f"rolling origin {self.rolling.origin() if self.rolling.received else None}",
        )
        for x in np.arange(0.05, 1.0001, 0.05):
            self.robot.move_to(float(x))
            time.sleep(0.15)
        self.assertTrue(
            wait_until(lambda: abs(self.rolling.origin()[0] - (-1.0)) < 1e-6),
            f"rolling origin {self.rolling.origin()} did not follow the robot to x = 1",
        )

        def wall_in_place() -> bool:
            grid, origin = self.rolling.grid(), self.rolling.origin()
            return cell_value(grid, origin, WALL_X, 0.0) == 100

        self.assertTrue(wait_until(wall_in_place), "the wall is not at x = 2 m in the rolled map")
        grid, origin = self.rolling.grid(), self.rolling.origin()
        # Behind the wall (x > 2.05 m) nothing was ever seen: unknown.
        self.assertEqual(cell_value(grid, origin, 2.8, 0.0), -1)
        # Every lethal cell lies on the wall, at its world position.
        ys, xs = np.nonzero(grid == 100)
        world_x = origin[0] + (xs + 0.5) * 0.05
        self.assertTrue(np.all(np.abs(world_x - WALL_X) < 0.051), world_x)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_costmap_live", CostmapLiveTest)
