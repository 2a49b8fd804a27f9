#!/usr/bin/env python3
"""rostest: tracked objects swept into the costmap at the right time and place.

The test plays the detector: the lesson's forklift rolls along y = 4.0921 m in map at -0.6 m/s,
seen in base_link at 15 Hz (noise-free, a point). The costmap must show the swept corridor on
row 81 from the forklift's cell back along its path by 0.6 m/s x (age + 1.5 s), inflated by
exactly 8 cells (0.40 m) at each end, and nothing once detections stop and the track times out.
"""

from __future__ import annotations

import math
import threading
import unittest

import dynamic_reconfigure.client
import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.msg import DetectedObjectArray, TrackedObjectArray
from downstream_perception.planar import se2_matrix
from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import detection_array, transform_stamped, wait_until

SPEED = -0.6  # m/s along map x
Y = 4.0921  # m: row floor(4.0921 / 0.05) = 81
RES = 0.05
HORIZON = 1.5
MAP_ODOM = (2.0, 1.0, math.radians(10))
ODOM_BASE = (3.0, 0.0, math.radians(30))


BASE_FROM_MAP = np.linalg.inv(se2_matrix(*MAP_ODOM) @ se2_matrix(*ODOM_BASE))


class TrackedObstaclesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tracked_obstacles")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "odom", now, *MAP_ODOM[:2], yaw=MAP_ODOM[2]),
                transform_stamped("odom", "base_link", now, *ODOM_BASE[:2], yaw=ODOM_BASE[2]),
            ]
        )
        cls.detections = rospy.Publisher("/forklift/detections", DetectedObjectArray, queue_size=5)
        cls.tracks: list[TrackedObjectArray] = []
        rospy.Subscriber("/tracker/tracks", TrackedObjectArray, cls.tracks.append, queue_size=50)
        cls.costmap = CostmapClient("/costmap/costmap")
        cls.running = True
        cls.x0 = 10.0
        cls.t0 = rospy.Time.now() + rospy.Duration(1.0)
        cls.thread = threading.Thread(target=cls.detect, daemon=True)
        cls.thread.start()

    @classmethod
    def detect(cls) -> None:
        rate = rospy.Rate(15.0)
        while cls.running and not rospy.is_shutdown():
            stamp = rospy.Time.now()
            t = (stamp - cls.t0).to_sec()
            if t >= 0.0:
                p_map = np.array([cls.x0 + SPEED * t, Y, 1.0])
                x, y, _ = BASE_FROM_MAP @ p_map
                # The lesson's point object: size 0.
                cls.detections.publish(
                    detection_array(
                        stamp, "base_link", np.array([[x, y]]), np.array([0.9]), np.array([1]),
                        1e-4, sizes=np.zeros((1, 2)),
                    )
                )  # fmt: skip
            rate.sleep()

    def test_corridor_then_expiry(self) -> None:
        self.assertTrue(wait_until(lambda: self.costmap.received, 20.0), "no costmap")
        self.assertTrue(
            wait_until(lambda: bool(self.tracks) and len(self.tracks[-1].tracks) == 1, 20.0),
            "no track",
        )
        rospy.sleep(3.0)  # the velocity estimate settles; the corridor follows the forklift
        track = self.tracks[-1].tracks[0]
        # Tracks live in odom: rotated by map <- odom's 10 degrees they move at -0.6 m/s along x.
        c, s = math.cos(MAP_ODOM[2]), math.sin(MAP_ODOM[2])
        vx_map = c * track.velocity.x - s * track.velocity.y
        vy_map = s * track.velocity.x + c * track.velocity.y
        self.assertAlmostEqual(vx_map, SPEED, delta=0.05)
        self.assertAlmostEqual(vy_map, 0.0, delta=0.05)

        spans = []
        for _ in range(5):
            row = self.costmap.grid()[81]
            t = (rospy.Time.now() - self.t0).to_sec()
            lethal = np.flatnonzero(row == 100)
            inflated = np.flatnonzero(row > 0)
            self.assertGreater(lethal.size, 0, "no lethal cells on row 81")
            # The corridor's far end is the forklift's cell at the track's stamp (it moves
            # towards -x). The grid read here is up to one publish period (0.25 s) plus one
            # update (0.08 s) old: the end lies between the cells of now and of 0.5 s ago.
            newest = math.floor((self.x0 + SPEED * t) / RES)
            oldest = math.floor((self.x0 + SPEED * (t - 0.5)) / RES)
            self.assertGreaterEqual(lethal[-1], newest - 1)
            self.assertLessEqual(lethal[-1], oldest + 1)
            # Back along its path by 0.6 m/s x (age + 1.5 s): about 18 cells plus the age.
            self.assertGreaterEqual(lethal.size, round(abs(SPEED) * HORIZON / RES) - 1)
            self.assertLessEqual(lethal.size, round(abs(SPEED) * (HORIZON + 0.5) / RES) + 2)
            # Inflated exactly 8 cells (0.40 m) beyond each end of the lethal core.
            self.assertEqual(inflated[0], lethal[0] - 8)
            self.assertEqual(inflated[-1], lethal[-1] + 8)
            # Nothing off the corridor: rows beyond 8 cells from row 81 are free.
            grid = self.costmap.grid()
            self.assertEqual(int((grid[:73] > 0).sum() + (grid[90:] > 0).sum()), 0)
            spans.append((int(inflated[-1] - inflated[0]), int(lethal[-1] - lethal[0])))
            rospy.sleep(0.3)
        rospy.loginfo("corridor spans (inflated, lethal) in cells: %s", spans)
        print(f"\ncorridor spans (inflated cells, lethal cells): {spans}")

        # Detections stop: the tracker stops publishing, the layer drops the track after
        # track_timeout_s (0.5 s) and the corridor vanishes.
        type(self).running = False
        self.assertTrue(
            wait_until(lambda: int((self.costmap.grid() > 0).sum()) == 0, 5.0),
            "the corridor stayed after the track timed out",
        )

    def test_rejected_reconfigure_value_is_reverted_and_its_error_clears(self) -> None:
        status: dict[str, DiagnosticStatus] = {}

        def on_diag(msg: DiagnosticArray) -> None:
            for st in msg.status:
                status[st.name] = st

        def layer() -> DiagnosticStatus | None:
            return next((v for k, v in status.items() if k.endswith("layer tracked")), None)

        sub = rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=20)
        client = dynamic_reconfigure.client.Client("/costmap/tracked", timeout=20.0)
        used = client.update_configuration({"prediction_horizon_s": -1.0})
        self.assertEqual(
            used["prediction_horizon_s"], HORIZON, "the server shows the refused value"
        )
        self.assertTrue(
            wait_until(
                lambda: layer() is not None and layer().level == DiagnosticStatus.ERROR, 15.0
            )
        )
        client.update_configuration({"prediction_horizon_s": HORIZON})
        self.assertTrue(
            wait_until(
                lambda: layer() is not None and layer().level != DiagnosticStatus.ERROR, 15.0
            ),
            str(layer()),
        )
        sub.unregister()


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "tracked_obstacles", TrackedObstaclesTest)
