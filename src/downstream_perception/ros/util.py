"""Small rospy helpers shared by the simulator nodes and the rostests (needs rospy)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import rospy
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import LaserScan


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


def laser_scan(
    stamp: rospy.Time,
    frame: str,
    ranges: np.ndarray | list[float],
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
) -> LaserScan:
    """A LaserScan (ranges in m, angles in rad); angle_max follows from the beam count."""
    msg = LaserScan()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    msg.angle_min = angle_min
    msg.angle_increment = angle_increment
    msg.angle_max = angle_min + (len(ranges) - 1) * angle_increment
    msg.range_min = range_min
    msg.range_max = range_max
    msg.ranges = np.asarray(ranges, dtype=np.float32).tolist()
    return msg


def transform_from_matrix(
    parent: str, child: str, stamp: rospy.Time, T: np.ndarray
) -> TransformStamped:
    """parent <- child from a 4 x 4 homogeneous matrix (rotation to quaternion, Shepperd)."""
    R = np.asarray(T, dtype=float)[:3, :3]
    trace = np.trace(R)
    if trace > 0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = (0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s)
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
        v = [0.0, 0.0, 0.0]
        v[i] = 0.25 * s
        v[j] = (R[j, i] + R[i, j]) / s
        v[k] = (R[k, i] + R[i, k]) / s
        q = ((R[k, j] - R[j, k]) / s, v[0], v[1], v[2])
    t = TransformStamped()
    t.header.frame_id = parent
    t.header.stamp = stamp
    t.child_frame_id = child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = (
        float(T[0, 3]),
        float(T[1, 3]),
        float(T[2, 3]),
    )
    r = t.transform.rotation
    r.w, r.x, r.y, r.z = (float(c) for c in q)
    return t


def detection_array(
    stamp: rospy.Time,
    frame: str,
    positions: np.ndarray,
    scores: np.ndarray,
    truth: np.ndarray,
    variance: float,
    sizes: np.ndarray | None = None,
    labels: list[str] | None = None,
    class_ids: list[int] | None = None,
) -> Any:
    """A DetectedObjectArray of POSITION detections: positions (N, 2) m in `frame`, scores,
    truth ids (-1 = clutter), isotropic position variance (m^2), sizes (N, 2) m (default 0.5 m
    squares), labels (default "object") and class ids (default 0; the tracker keeps one label
    per class id)."""
    from downstream_perception.msg import DetectedObject, DetectedObjectArray

    msg = DetectedObjectArray()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    n = len(positions)
    sizes = np.full((n, 2), 0.5) if sizes is None else np.asarray(sizes, dtype=float)
    labels = ["object"] * n if labels is None else labels
    class_ids = [0] * n if class_ids is None else class_ids
    for (x, y), score, truth_id, (sx, sy), label, class_id in zip(
        positions, scores, truth, sizes, labels, class_ids, strict=True
    ):
        d = DetectedObject()
        d.header = msg.header
        d.kind = DetectedObject.POSITION
        d.class_id = int(class_id)
        d.label = label
        d.score = float(score)
        d.position.x, d.position.y = float(x), float(y)
        d.position_covariance = [variance, 0.0, 0.0, variance]
        d.size_x, d.size_y = float(sx), float(sy)
        d.truth_id = int(truth_id)
        msg.detections.append(d)
    return msg


def wait_until(predicate: Callable[[], bool], timeout_s: float = 15.0) -> bool:
    """Polls predicate every 0.1 s (wall time) until it holds or timeout_s passes; returns its
    last value."""
    deadline = time.time() + timeout_s
    while time.time() < deadline and not rospy.is_shutdown():
        if predicate():
            return True
        time.sleep(0.1)
    return bool(predicate())


def refuse_existing_output(path: Path, overwrite: bool, tool: str) -> None:
    """Exits (status 1, the reason on stderr) when `path` exists and `overwrite` is not given, or
    when it is not a regular file (a directory, a device, a dangling or live symlink): a
    converter never replaces a file it was not asked to replace."""
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise SystemExit(f"{tool}: {path} is not a regular file; refusing to write it")
    if path.exists() and not overwrite:
        raise SystemExit(f"{tool}: {path} exists; pass --overwrite to replace it")
