"""Planar rigid transforms as 3 x 3 homogeneous numpy matrices (x, y in m, yaw in rad, REP-103),
shared by the simulator nodes, the rostests and the tools."""

from __future__ import annotations

import math

import numpy as np


def se2_matrix(x: float, y: float, yaw: float) -> np.ndarray:
    """parent <- child for a child frame at (x, y) turned by yaw in the parent."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, x], [s, c, y], [0.0, 0.0, 1.0]])
