"""Small rospy helpers shared by the simulator nodes and the rostests (needs rospy)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import rospy
from geometry_msgs.msg import TransformStamped


def transform_stamped(
    parent: str,
    child: str,
    stamp: rospy.Time,
    x: float = 0.0,
    y: float = 0.0,
    z: float = 0.0,
    yaw: float = 0.0,
) -> TransformStamped:
    """parent <- child as a planar pose (x, y, yaw) raised by z (REP-103: metres, radians)."""
    t = TransformStamped()
    t.header.frame_id = parent
    t.header.stamp = stamp
    t.child_frame_id = child
    t.transform.translation.x = float(x)
    t.transform.translation.y = float(y)
    t.transform.translation.z = float(z)
    t.transform.rotation.z = math.sin(yaw / 2.0)
    t.transform.rotation.w = math.cos(yaw / 2.0)
    return t


def wait_until(predicate: Callable[[], bool], timeout_s: float = 15.0) -> bool:
    """Polls predicate every 0.1 s (wall time) until it holds or timeout_s passes; returns its
    last value."""
    deadline = time.time() + timeout_s
    while time.time() < deadline and not rospy.is_shutdown():
        if predicate():
            return True
        time.sleep(0.1)
    return bool(predicate())
