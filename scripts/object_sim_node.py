#!/usr/bin/env python3
"""Object simulator node: moving objects seen by a detector on a moving robot, with truth.

Runs sim.ObjectScene (see its docstring) at ~rate_hz. The robot drives along odom x at
~robot_speed_mps; each frame it publishes tf odom->base_link, the detections in base_link on
`detections` (downstream_perception/DetectedObjectArray, per-detection covariance, truth ids;
clutter has truth_id -1), the ground truth of every object in odom on `~truth` (same stamp;
score 1 if visible, 0 while occluded), and latched std_msgs/Bool(True) on `~done` after ~frames.
"""

from __future__ import annotations

import numpy as np
import rospy
import tf2_ros
from std_msgs.msg import Bool

from downstream_perception.msg import DetectedObjectArray
from downstream_perception.ros.util import detection_array, transform_stamped
from downstream_perception.sim import ObjectScene, SceneConfig


def main() -> None:
    rospy.init_node("object_sim")
    p = rospy.get_param
    config = SceneConfig(
        num_objects=int(p("~num_objects", 30)),
        rate_hz=float(p("~rate_hz", 10.0)),
        seed=int(p("~seed", 0)),
    )
    robot_speed = float(p("~robot_speed_mps", 0.5))
    frames = int(p("~frames", 300))
    start_delay = float(p("~start_delay_s", 2.0))
    scene = ObjectScene(config)
    tf = tf2_ros.TransformBroadcaster()
    detections = rospy.Publisher("detections", DetectedObjectArray, queue_size=20)
    truth = rospy.Publisher("~truth", DetectedObjectArray, queue_size=20)
    done = rospy.Publisher("~done", Bool, queue_size=1, latch=True)
    rospy.sleep(start_delay)  # let subscribers connect
    rate = rospy.Rate(config.rate_hz)
    t0 = rospy.Time.now()
    variance = config.noise_std_m**2
    for _ in range(frames):
        if rospy.is_shutdown():
            return
        f = scene.step()
        stamp = t0 + rospy.Duration.from_sec(f.stamp)
        robot_x = robot_speed * f.stamp
        tf.sendTransform(transform_stamped("odom", "base_link", stamp, x=robot_x))
        in_base = f.positions - np.array([robot_x, 0.0])
        detections.publish(
            detection_array(stamp, "base_link", in_base, f.scores, f.detection_truth, variance)
        )
        truth.publish(
            detection_array(
                stamp, "odom", f.truth_positions, f.visible.astype(float), f.truth_ids, 0.0
            )
        )
        rate.sleep()
    done.publish(Bool(data=True))
    rospy.spin()


if __name__ == "__main__":
    main()
