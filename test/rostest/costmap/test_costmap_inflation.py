#!/usr/bin/env python3
"""rostest: inflation in the published costmap equals the formula on exact distances."""

from __future__ import annotations

import time
import unittest

import numpy as np
import rospy
import rostest
from costmap_watch import CostmapWatch
from geometry_msgs.msg import PolygonStamped

import downstream_perception as dp

RADIUS_M = 0.55  # test/rostest/costmap/inflation_config.yaml
SCALING = 3.0
INSCRIBED_M = 0.3  # square footprint +-0.3 m, no padding


def formula(d: np.ndarray) -> np.ndarray:
    """costmap_2d's cost for distances d (m), written independently of the C++ code."""
    with np.errstate(over="ignore"):
        decay = np.floor(252.0 * np.exp(-SCALING * (d - INSCRIBED_M)))
    cost = np.where(d <= INSCRIBED_M + 1e-9, 253.0, decay)
    cost = np.where(d > RADIUS_M + 1e-9, 0.0, cost)
    return np.where(d == 0.0, 254.0, cost).astype(np.int64)


class CostmapInflationTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_costmap_inflation")
        cls.footprint: PolygonStamped | None = None

        def on_footprint(msg: PolygonStamped) -> None:
            cls.footprint = msg

        rospy.Subscriber("/costmap/footprint", PolygonStamped, on_footprint, queue_size=1)
        watch = CostmapWatch("inflation")
        cls.watch = watch
        watch.wait_for_drive_end()
        time.sleep(1.5)  # a map published after the last scans
        assert watch.latest is not None, "no costmap was published"
        info = watch.latest.info
        cls.resolution = round(float(info.resolution), 6)  # float32 in the message: 0.05000000075
        cls.grid = np.asarray(watch.latest.data, dtype=np.int64).reshape(info.height, info.width)

    def test_every_cell_follows_the_formula_on_exact_distances(self) -> None:
        lethal = np.argwhere(self.grid == 100)
        self.assertGreater(len(lethal), 500, "the shelves should be lethal after the drive")
        ys, xs = np.indices(self.grid.shape)
        d2 = np.full(self.grid.shape, np.inf)
        for ly, lx in lethal:
            d2 = np.minimum(d2, (ys - ly) ** 2 + (xs - lx) ** 2)
        expected = formula(np.sqrt(d2) * self.resolution)
        occupancy = dp.occupancy_table().astype(np.int64)  # costmap_2d's translation
        known = self.grid >= 0
        mismatch = known & (self.grid != occupancy[expected])
        where = np.argwhere(mismatch)[:8]
        detail = [
            (
                int(y),
                int(x),
                int(self.grid[y, x]),
                int(occupancy[expected][y, x]),
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
        self.assertAlmostEqual(
            float(self.watch.layer_status["inscribed radius (m)"]), 0.3, places=5
        )
        self.assertEqual(self.watch.layer_status["config errors"], "0")
        self.assertGreater(int(self.watch.layer_status["updates"]), 5)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_costmap_inflation", CostmapInflationTest)
