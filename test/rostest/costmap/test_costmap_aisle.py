#!/usr/bin/env python3
"""rostest: the costmap nodelet's output after the simulated robot drove the warehouse aisle."""

from __future__ import annotations

import time
import unittest

import numpy as np
import rospy
import rostest
from costmap_watch import CostmapWatch

from downstream_perception.sim import warehouse_aisle

PERSON_GONE_S = 8.0  # the simulated person leaves the aisle 8 s after the robot starts


class CostmapAisleTest(unittest.TestCase):
    grid: np.ndarray
    info: object

    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_costmap_aisle")
        watch = CostmapWatch("obstacles")
        cls.watch = watch
        watch.wait_for_drive_end()
        # The run at 2.5 m/s ends near t = 7 s; the person leaves at t = 8 s. Give the robot a few
        # scans of the empty crossing from its final pose, then take a map published after that.
        time.sleep(max(0.0, PERSON_GONE_S - 6.0) + 2.5)
        taken = time.time()
        while watch.latest_wall <= taken and time.time() < taken + 10.0:
            time.sleep(0.1)
        assert watch.latest is not None, "no costmap was published"
        info = watch.latest.info
        cls.info = info
        cls.grid = np.asarray(watch.latest.data, dtype=np.int8).reshape(info.height, info.width)
        ys, xs = np.mgrid[0 : info.height, 0 : info.width]
        cls.wx = info.origin.position.x + (xs + 0.5) * info.resolution
        cls.wy = info.origin.position.y + (ys + 0.5) * info.resolution

    def region(self, x0: float, x1: float, y0: float, y1: float) -> np.ndarray:
        mask = (self.wx >= x0) & (self.wx <= x1) & (self.wy >= y0) & (self.wy <= y1)
        self.assertGreater(mask.sum(), 0)
        return self.grid[mask]

    def test_shelf_walls_are_lethal(self) -> None:
        # In every 5 cm column along both shelves, a lethal cell within 10 cm of the wall line.
        for wall_y in (1.5, -1.5):
            band = (np.abs(self.wy - wall_y) <= 0.1) & (self.wx > 2.0) & (self.wx < 17.0)
            band &= ~((np.abs(self.wx - 8.0) < 0.45) & (wall_y > 0))  # the pallet hides the wall
            cols = np.unique(np.nonzero(band)[1])
            hit = [(self.grid[:, c][band[:, c]] == 100).any() for c in cols]
            self.assertGreater(np.mean(hit), 0.95, f"wall at y={wall_y}: {np.mean(hit):.3f}")

    def test_aisle_is_free(self) -> None:
        aisle = self.region(1.0, 17.0, -1.0, 0.8)
        self.assertGreater((aisle == 0).mean(), 0.97)
        self.assertLess((aisle == 100).mean(), 0.003)

    def test_never_seen_cells_are_unknown(self) -> None:
        behind = self.region(3.0, 17.0, 2.2, 3.9)
        self.assertGreater((behind == -1).mean(), 0.99)

    def test_person_left_no_trail(self) -> None:
        crossing = self.region(9.6, 10.4, -1.0, 1.0)
        self.assertEqual(int((crossing == 100).sum()), 0, "cells of the departed person remain")
        self.assertGreater((crossing == 0).mean(), 0.9)

    def test_no_return_beams_clear_the_open_end(self) -> None:
        # Nothing lies beyond x = 0: those beams are +Inf and must clear up to raytrace range.
        beyond = self.region(-1.9, -0.2, -1.0, 1.0)
        self.assertGreater((beyond == 0).mean(), 0.9)

    def test_ground_truth_obstacles_found(self) -> None:
        truth = warehouse_aisle().occupied_cells(
            self.info.origin.position.x,
            self.info.origin.position.y,
            self.info.resolution,
            self.info.width,
            self.info.height,
        )
        seen = truth & (self.grid != -1) & (self.wx > 2.0) & (self.wx < 17.0)
        lethal = self.grid == 100
        near = np.zeros_like(lethal)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                near |= np.roll(np.roll(lethal, dy, axis=0), dx, axis=1)
        self.assertGreater(seen.sum(), 100)
        self.assertGreater((near & seen).sum() / seen.sum(), 0.9)

    def test_diagnostics_report_integration(self) -> None:
        deadline = time.time() + 5.0
        while "scan: messages integrated" not in self.watch.layer_status and time.time() < deadline:
            time.sleep(0.1)
        self.assertGreater(int(self.watch.layer_status["scan: messages integrated"]), 20)
        self.assertEqual(int(self.watch.layer_status["scan: messages rejected"]), 0)
        self.assertGreater(
            float(self.watch.layer_status["scan: clear:mark ratio (all messages)"]), 5.0
        )
        # The timed choice of clearing walk (walk_chooser.h): over the aisle, seen after the
        # first scans, every scan runs one of them, and each walk is measured at least twice.
        key = "scan: clearing walks run (per ray / blocks / reverse query / first visit / shared)"
        runs = [int(n) for n in self.watch.layer_status[key].split(" / ")]
        self.assertEqual(len(runs), 5, runs)
        self.assertGreaterEqual(sum(runs), 10, runs)
        self.assertTrue(all(n >= 2 for n in runs[:4]), runs)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "costmap_aisle", CostmapAisleTest)
