#!/usr/bin/env python3
"""rostest: inflation in the published costmap equals the formula on exact distances."""

from __future__ import annotations

import time
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PolygonStamped
from nav_msgs.msg import OccupancyGrid
from std_msgs.msg import Bool

RADIUS_M = 0.55  # cfg/test_inflation.yaml
SCALING = 3.0
INSCRIBED_M = 0.3  # square footprint +-0.3 m, no padding


def formula(d: np.ndarray) -> np.ndarray:
    """costmap_2d's cost for distances d (m), written independently of the C++ code."""
    with np.errstate(over="ignore"):
        decay = np.floor(252.0 * np.exp(-SCALING * (d - INSCRIBED_M)))
    cost = np.where(d <= INSCRIBED_M + 1e-9, 253.0, decay)
    cost = np.where(d > RADIUS_M + 1e-9, 0.0, cost)
    return np.where(d == 0.0, 254.0, cost).astype(np.int64)


def to_occupancy(cost: np.ndarray) -> np.ndarray:
    """costmap_2d's cost -> OccupancyGrid translation."""
    out = 1 + (97 * (cost - 1)) // 251
    out = np.where(cost == 0, 0, out)
    out = np.where(cost == 253, 99, out)
    out = np.where(cost == 254, 100, out)
    return np.where(cost == 255, -1, out)


class CostmapInflationTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_costmap_inflation")
        cls.latest: OccupancyGrid | None = None
        cls.footprint: PolygonStamped | None = None
        cls.done = False
        cls.inflation_status: dict[str, str] = {}

        def on_grid(msg: OccupancyGrid) -> None:
            cls.latest = msg

        def on_done(msg: Bool) -> None:
            cls.done = cls.done or msg.data

        def on_footprint(msg: PolygonStamped) -> None:
            cls.footprint = msg

        def on_diag(msg: DiagnosticArray) -> None:
            for status in msg.status:
                if "layer inflation" in status.name:
                    cls.inflation_status = {kv.key: kv.value for kv in status.values}

        rospy.Subscriber("/costmap/costmap", OccupancyGrid, on_grid, queue_size=1)
        rospy.Subscriber("/costmap/footprint", PolygonStamped, on_footprint, queue_size=1)
        rospy.Subscriber("/sim_done", Bool, on_done, queue_size=1)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=10)
        deadline = time.time() + 90.0
        while not cls.done and time.time() < deadline and not rospy.is_shutdown():
            time.sleep(0.1)
        assert cls.done, "the simulator never reported sim_done"
        time.sleep(1.5)  # a map published after the last scans
        assert cls.latest is not None, "no costmap was published"
        info = cls.latest.info
        cls.resolution = round(float(info.resolution), 6)  # float32 in the message: 0.05000000075
        cls.grid = np.asarray(cls.latest.data, dtype=np.int64).reshape(info.height, info.width)

    def test_every_cell_follows_the_formula_on_exact_distances(self) -> None:
        lethal = np.argwhere(self.grid == 100)
        self.assertGreater(len(lethal), 500, "the shelves should be lethal after the drive")
        ys, xs = np.indices(self.grid.shape)
        d2 = np.full(self.grid.shape, np.inf)
        for ly, lx in lethal:
            d2 = np.minimum(d2, (ys - ly) ** 2 + (xs - lx) ** 2)
        expected = formula(np.sqrt(d2) * self.resolution)
        known = self.grid >= 0
        mismatch = known & (self.grid != to_occupancy(expected))
        where = np.argwhere(mismatch)[:8]
        detail = [
            (
                int(y),
                int(x),
                int(self.grid[y, x]),
                int(to_occupancy(expected)[y, x]),
                round(float(np.sqrt(d2[y, x])), 2),
            )
            for y, x in where
        ]
        self.assertEqual(
            int(mismatch.sum()),
            0,
            f"{int(mismatch.sum())} known cells differ; (y, x, got, expected, d cells): {detail}",
        )
        # Unknown cells stay unknown only where the inflation cost is below inscribed
        # (inflate_unknown false); >= 253 overwrites them.
        self.assertTrue(np.all(expected[~known] < 253))
        # The inflation is really there: inscribed and decaying cells beside the walls.
        self.assertGreater(int((self.grid == 99).sum()), 1000)
        self.assertGreater(int(((self.grid > 0) & (self.grid < 99)).sum()), 500)

    def test_footprint_is_published_and_sets_the_inscribed_radius(self) -> None:
        self.assertIsNotNone(self.footprint)
        points = [(p.x, p.y) for p in self.footprint.polygon.points]
        self.assertEqual(len(points), 4)
        self.assertAlmostEqual(max(abs(x) for x, _ in points), 0.3, places=5)
        self.assertEqual(self.footprint.header.frame_id, "base_link")
        self.assertAlmostEqual(float(self.inflation_status["inscribed radius (m)"]), 0.3, places=5)
        self.assertEqual(self.inflation_status["config errors"], "0")
        self.assertGreater(int(self.inflation_status["updates"]), 5)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_costmap_inflation", CostmapInflationTest)
