#!/usr/bin/env python3
"""rostest: a real move_base costmap pair (test/rostest/real_configs/<robot>/, unchanged) in a
costmap host, fed by real_config_sim.py. Every expected number comes from the robot's YAML through
move_base_config (costmap_2d's lookups and formulas), none is written here:

- geometry: a non-rolling costmap with a static layer takes the map's size, resolution and
  origin; otherwise the YAML's (costmap_2d's defaults where unset); a rolling window is centred
  on the robot, and follows it when it moves;
- the box inside every source's obstacle_range is lethal, the box beyond the longest one is not;
- every wall cell of the static map is lethal in a costmap with a static layer;
- inflated costs along a line from a lethal cell follow costmap_2d's computeCost and its
  OccupancyGrid translation (distance = to the nearest lethal cell of the published grid);
- our host's diagnostics for each costmap are not ERROR.

Each failure names the robot, the costmap, the cell, what was expected and what was got.
Parameters: ~robot (a label), /real_config/* (see real_configs.launch).
"""

from __future__ import annotations

import math
import time
import unittest
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import Pose2D
from move_base_config import (
    Costmap,
    Scene,
    build_scene,
    costmaps_of,
    inflation_of,
    load_pair_from,
    translate,
)
from nav_msgs.msg import OccupancyGrid

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import wait_until

LETHAL_VALUE = 100


@dataclass
class Snapshot:
    grid: np.ndarray  # int8 (rows, cols)
    resolution: float
    origin: tuple[float, float]

    def index(self, x: float, y: float) -> tuple[int, int] | None:
        """(col, row) of the cell holding (x, y) in the grid's frame, None outside."""
        col = int(math.floor((x - self.origin[0]) / self.resolution))
        row = int(math.floor((y - self.origin[1]) / self.resolution))
        rows, cols = self.grid.shape
        return (col, row) if 0 <= col < cols and 0 <= row < rows else None

    def centre(self, col: int, row: int) -> tuple[float, float]:
        return (
            self.origin[0] + (col + 0.5) * self.resolution,
            self.origin[1] + (row + 0.5) * self.resolution,
        )


class RealConfigTest(unittest.TestCase):
    longMessage = False  # the messages below say everything; unittest's prefix only adds noise
    scene: Scene
    costmaps: list[Costmap]
    clients: dict[str, CostmapClient]

    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_real_configs")
        p = rospy.get_param
        cls.robot = str(p("~robot", "robot"))
        cls.host = str(p("/real_config/host", "nodelet"))
        prefix = str(p("/real_config/prefix", ""))
        tree = load_pair_from(rospy.get_param)
        cls.scene = build_scene(tree)
        cls.costmaps = list(costmaps_of(tree))
        cls.topics = {cm.ns: f"{prefix}/{cm.ns}/costmap" for cm in cls.costmaps}
        # No standing subscription to a costmap with publish_frequency 0 (Freight's global one):
        # nothing is published there, but costmap_2d sends the current grid to each new
        # subscriber (onNewSubscription), so snapshot() subscribes anew (rospy would hand a second
        # subscriber of the same topic the first connection's latched message instead).
        cls.clients = {
            cm.ns: CostmapClient(cls.topics[cm.ns])
            for cm in cls.costmaps
            if float(cm.get("publish_frequency", 0.0)) > 0.0
        }
        cls.diagnostics: dict[str, DiagnosticStatus] = {}
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls._on_diagnostics, queue_size=20)
        cls.pose_pub = rospy.Publisher(
            "/real_config_sim/robot_pose", Pose2D, queue_size=1, latch=True
        )
        cls.robot_xy = cls.scene.start
        wait_until(lambda: all(cls.snapshot(cm) is not None for cm in cls.costmaps), 90.0)
        # Let the slowest costmap integrate a few scans and publish them: the near box lethal in
        # every costmap with an obstacle layer (or 60 s), then two more publish cycles.
        wait_until(lambda: all(cls._near_seen(cm) for cm in cls.costmaps), 60.0)
        slowest = max(
            2.0 / max(float(cm.get("publish_frequency", 0.0)) or 1.0, 0.1) for cm in cls.costmaps
        )
        time.sleep(
            slowest + 2.0 / min(float(cm.get("update_frequency", 5.0)) for cm in cls.costmaps)
        )

    @classmethod
    def _on_diagnostics(cls, msg: DiagnosticArray) -> None:
        for status in msg.status:
            cls.diagnostics[status.name] = status

    def setUp(self) -> None:
        self.problems: list[str] = []

    @contextmanager
    def checking(self) -> Iterator[None]:
        """Like subTest, but the failure is kept for report(): rosunit's XML drops the messages
        of failed subtests."""
        try:
            yield
        except self.failureException as e:
            self.problems.append(str(e))

    def report(self) -> None:
        """One failure listing every problem found, one line each."""
        if self.problems:
            self.fail(f"{len(self.problems)} problem(s):\n" + "\n".join(self.problems))

    # --- helpers ---------------------------------------------------------------------------

    def label(self, cm: Costmap) -> str:
        return f"{self.robot} {cm.ns}"

    @classmethod
    def snapshot(cls, cm: Costmap) -> Snapshot | None:
        client = cls.clients.get(cm.ns)
        if client is None:  # publish_frequency 0: a new subscriber's grid
            try:
                msg = rospy.wait_for_message(cls.topics[cm.ns], OccupancyGrid, timeout=5.0)
            except rospy.ROSException:
                return None
        elif not client.received:
            return None
        else:
            msg = client.message()
        grid = np.asarray(msg.data, dtype=np.int8).reshape(msg.info.height, msg.info.width)
        o = msg.info.origin.position
        return Snapshot(grid, float(msg.info.resolution), (float(o.x), float(o.y)))

    @classmethod
    def to_frame(cls, cm: Costmap, x: float, y: float) -> tuple[float, float]:
        """A map-frame point in the costmap's global_frame (map, or odom = map - odom_in_map)."""
        if cm.global_frame.lstrip("/") == "odom":
            return x - cls.scene.odom_in_map[0], y - cls.scene.odom_in_map[1]
        return x, y

    @classmethod
    def _near_seen(cls, cm: Costmap) -> bool:
        if not cm.layers_of("obstacle"):
            return True
        snap = cls.snapshot(cm)
        if snap is None:
            return False
        x, y = cls.to_frame(cm, cls.scene.near.cx - cls.scene.near.half, cls.scene.near.cy)
        ij = snap.index(x, y)
        if ij is None:
            return True
        c, r = ij
        return bool((snap.grid[max(r - 1, 0) : r + 2, max(c - 1, 0) : c + 2] == LETHAL_VALUE).any())

    def require(self, cm: Costmap) -> Snapshot:
        snap = self.snapshot(cm)
        self.assertIsNotNone(snap, f"{self.label(cm)}: no costmap received")
        assert snap is not None
        return snap

    # --- tests -----------------------------------------------------------------------------

    def test_geometry(self) -> None:
        s = self.scene
        for cm in self.costmaps:
            with self.checking():
                snap = self.require(cm)
                rows, cols = snap.grid.shape
                if cm.layers_of("static") and not cm.rolling:
                    want_res, want_size = s.map_resolution, s.map_cells.shape[::-1]
                    want_origin: tuple[float, float] | None = self.to_frame(cm, *s.map_origin)
                    why = "the static map's"
                else:
                    want_res, want_size = cm.resolution, cm.size_cells()
                    want_origin = (
                        None
                        if cm.rolling
                        else (
                            float(cm.get("origin_x", 0.0)),
                            float(cm.get("origin_y", 0.0)),
                        )
                    )
                    why = "the YAML's"
                self.assertAlmostEqual(
                    snap.resolution,
                    want_res,
                    places=6,
                    msg=f"{self.label(cm)}: resolution: expected {why} {want_res}, "
                    f"got {snap.resolution}",
                )
                self.assertEqual(
                    (cols, rows),
                    tuple(want_size),
                    f"{self.label(cm)}: size in cells: expected {why} {tuple(want_size)}, "
                    f"got {(cols, rows)}",
                )
                if want_origin is not None:
                    got = np.round(snap.origin, 4).tolist()
                    self.assertTrue(
                        np.allclose(snap.origin, want_origin, atol=1e-4),
                        f"{self.label(cm)}: origin: expected {why} {want_origin}, got {got}",
                    )
                if cm.rolling:
                    self.check_centred(cm, snap, self.robot_xy)
        self.report()

    def check_centred(self, cm: Costmap, snap: Snapshot, robot_map: tuple[float, float]) -> None:
        """A rolling window's origin is the robot minus half its size, to within 1.5 cells
        (costmap_2d centres (size - 0.5) cells and moves the origin by whole cells)."""
        rows, cols = snap.grid.shape
        rx, ry = self.to_frame(cm, *robot_map)
        want = (rx - 0.5 * cols * snap.resolution, ry - 0.5 * rows * snap.resolution)
        self.assertTrue(
            np.allclose(snap.origin, want, atol=1.5 * snap.resolution + 1e-6),
            f"{self.label(cm)}: rolling origin with the robot at {(rx, ry)}: expected "
            f"{np.round(want, 3).tolist()} (+- 1.5 cells), got {np.round(snap.origin, 3).tolist()}",
        )

    def test_near_obstacle_lethal(self) -> None:
        s = self.scene
        for cm in self.costmaps:
            if not cm.layers_of("obstacle"):
                continue
            with self.checking():
                snap = self.require(cm)
                x, y = self.to_frame(cm, s.near.cx - s.near.half, s.near.cy)
                ij = snap.index(x, y)
                self.assertIsNotNone(
                    ij, f"{self.label(cm)}: the near box ({x:.2f}, {y:.2f}) is off the grid"
                )
                assert ij is not None
                c, r = ij
                patch = snap.grid[max(r - 1, 0) : r + 2, max(c - 1, 0) : c + 2]
                ranges = sorted({src.obstacle_range for src in cm.sources()})
                self.assertTrue(
                    (patch == LETHAL_VALUE).any(),
                    f"{self.label(cm)}: box face at {s.near.cx - s.near.half:.2f} m, within "
                    f"obstacle_range {ranges}: cell ({c}, {r}) +-1: expected {LETHAL_VALUE}, "
                    f"got {patch.tolist()}",
                )
        self.report()

    def test_far_obstacle_not_lethal(self) -> None:
        s = self.scene
        shown = 0
        for cm in self.costmaps:
            if not cm.layers_of("obstacle"):
                continue
            snap = self.require(cm)
            lo = self.to_frame(cm, s.far.cx - s.far.half, s.far.cy - s.far.half)
            hi = self.to_frame(cm, s.far.cx + s.far.half, s.far.cy + s.far.half)
            a = snap.index(lo[0] - snap.resolution, lo[1] - snap.resolution)
            b = snap.index(hi[0] + snap.resolution, hi[1] + snap.resolution)
            if a is None or b is None:
                continue  # this window does not reach the far box
            shown += 1
            with self.checking():
                block = snap.grid[a[1] : b[1] + 1, a[0] : b[0] + 1]
                lethal = np.argwhere(block == LETHAL_VALUE)
                ranges = sorted({src.obstacle_range for src in cm.sources()})
                dist = math.hypot(s.far.cx, s.far.cy) - s.far.half * math.sqrt(2.0)
                first = (
                    None
                    if not len(lethal)
                    else (int(a[0] + lethal[0][1]), int(a[1] + lethal[0][0]))
                )
                self.assertEqual(
                    len(lethal),
                    0,
                    f"{self.label(cm)}: box at >= {dist:.2f} m, beyond obstacle_range {ranges}: "
                    f"cell {first}: expected not {LETHAL_VALUE}, got {LETHAL_VALUE} "
                    f"({len(lethal)} lethal cells)",
                )
        if not shown:
            self.skipTest(f"{self.robot}: no costmap with an obstacle layer reaches the far box")
        self.report()

    def test_static_walls_lethal(self) -> None:
        s = self.scene
        for cm in self.costmaps:
            if not cm.layers_of("static"):
                continue
            with self.checking():
                snap = self.require(cm)
                rows, cols = np.nonzero(s.map_cells == 100)
                xs = s.map_origin[0] + (cols + 0.5) * s.map_resolution
                ys = s.map_origin[1] + (rows + 0.5) * s.map_resolution
                fx, fy = self.to_frame(cm, 0.0, 0.0)
                ci = np.floor((xs + fx - snap.origin[0]) / snap.resolution).astype(int)
                cj = np.floor((ys + fy - snap.origin[1]) / snap.resolution).astype(int)
                inside = (
                    (ci >= 0) & (cj >= 0) & (ci < snap.grid.shape[1]) & (cj < snap.grid.shape[0])
                )
                self.assertTrue(
                    inside.any(), f"{self.label(cm)}: no wall of the static map on the grid"
                )
                got = snap.grid[cj[inside], ci[inside]]
                bad = np.nonzero(got != LETHAL_VALUE)[0]
                first = (
                    ""
                    if not len(bad)
                    else (
                        f"first cell ({ci[inside][bad[0]]}, {cj[inside][bad[0]]}): "
                        f"expected {LETHAL_VALUE}, got {got[bad[0]]}"
                    )
                )
                self.assertEqual(
                    len(bad),
                    0,
                    f"{self.label(cm)}: {len(bad)} of {inside.sum()} static wall cells "
                    f"not lethal; {first}",
                )
        self.report()

    def probes(
        self, cm: Costmap, snap: Snapshot, radius_cells: int
    ) -> list[tuple[str, list[tuple[int, int]]]]:
        """Lines of cells leaving a lethal cell: up from the static map's interior wall (static
        layer), towards the robot from the near box's face (obstacle layer)."""
        s = self.scene
        out = []
        n = radius_cells + 2
        if cm.layers_of("static"):
            ij = snap.index(*self.to_frame(cm, s.start[0], s.probe_wall_y))
            if ij is not None:
                out.append(("from the static wall", [(ij[0], ij[1] + k) for k in range(n)]))
        if cm.layers_of("obstacle"):
            ij = snap.index(*self.to_frame(cm, s.near.cx - s.near.half, s.near.cy))
            if ij is not None:
                c, r = ij
                # the lethal cell of the face nearest to the hit point, same row first
                for dc in (0, -1, 1):
                    if 0 <= c + dc < snap.grid.shape[1] and snap.grid[r, c + dc] == LETHAL_VALUE:
                        c += dc
                        break
                out.append(("from the near box", [(c - k, r) for k in range(n)]))
        rows, cols = snap.grid.shape
        return [
            (what, [(c, r) for c, r in cells if 0 <= c < cols and 0 <= r < rows])
            for what, cells in out
        ]

    def test_inflation_formula(self) -> None:
        for cm in self.costmaps:
            snap = self.snapshot(cm)
            inflation = inflation_of(
                cm, snap.resolution if snap else cm.resolution, ceil_cells=self.host != "nodelet"
            )
            if inflation is None:
                continue
            with self.checking():
                snap = self.require(cm)
                lethal = np.argwhere(snap.grid == LETHAL_VALUE)  # (row, col)
                self.assertTrue(len(lethal), f"{self.label(cm)}: no lethal cell to inflate from")
                for what, cells in self.probes(cm, snap, inflation.cell_radius):
                    self.assertTrue(cells, f"{self.label(cm)}: probe line {what} is off the grid")
                    ij = np.asarray(cells)
                    d = np.sqrt(
                        (
                            (ij[:, None, 0] - lethal[None, :, 1]) ** 2
                            + (ij[:, None, 1] - lethal[None, :, 0]) ** 2
                        ).min(axis=1)
                    )
                    self.assertEqual(
                        float(d.min()),
                        0.0,
                        f"{self.label(cm)}: probe line {what} starts at cell {cells[0]}, "
                        f"{d.min():.2f} cells from any lethal cell (nothing to inflate)",
                    )
                    for (c, r), dist in zip(cells, d, strict=True):
                        cost = inflation.cost(float(dist))
                        got = int(snap.grid[r, c])
                        if got == -1:  # costmap_2d leaves unknown cells unknown below 253
                            ok = cost < 253
                            want = f"-1 or {translate(cost)}"
                        else:
                            ok = got == translate(cost)
                            want = str(translate(cost))
                        self.assertTrue(
                            ok,
                            f"{self.label(cm)}: inflation {what}: cell ({c}, {r}) at "
                            f"{dist:.3f} cells (radius {inflation.inflation_radius} m = "
                            f"{inflation.cell_radius} cells, factor "
                            f"{inflation.cost_scaling_factor}, inscribed "
                            f"{inflation.inscribed_radius:.4f} m): expected {want} "
                            f"(cost {cost}), got {got}",
                        )
        self.report()

    def test_diagnostics_not_error(self) -> None:
        if self.host != "nodelet":
            self.skipTest("costmap_2d publishes no diagnostics")
        for cm in self.costmaps:
            with self.checking():
                wait_until(lambda cm=cm: any(cm.ns in n for n in self.diagnostics), 10.0)
                mine = {n: st for n, st in dict(self.diagnostics).items() if cm.ns in n}
                self.assertTrue(mine, f"{self.label(cm)}: no diagnostics status naming {cm.ns}")
                errors = {
                    n: st.message for n, st in mine.items() if st.level >= DiagnosticStatus.ERROR
                }
                self.assertFalse(
                    errors, f"{self.label(cm)}: diagnostics ERROR: expected none, got {errors}"
                )
        self.report()

    def test_z_rolling_window_follows_robot(self) -> None:
        """Runs last (name order): the robot steps by Scene.move, every rolling window's origin
        follows it, then it steps back."""
        rolling = [cm for cm in self.costmaps if cm.rolling]
        if not rolling:
            self.skipTest(f"{self.robot}: no rolling costmap")
        before = {cm.ns: self.require(cm).origin for cm in rolling}
        s = self.scene
        target = (s.start[0] + s.move[0], s.start[1] + s.move[1])
        self.pose_pub.publish(Pose2D(x=target[0], y=target[1], theta=0.0))

        def moved(cm: Costmap) -> bool:
            snap = self.snapshot(cm)
            return snap is not None and not np.allclose(snap.origin, before[cm.ns], atol=1e-6)

        try:
            wait_until(lambda: all(moved(cm) for cm in rolling), 30.0)
            time.sleep(1.0)
            for cm in rolling:
                with self.checking():
                    self.check_centred(cm, self.require(cm), target)
        finally:
            self.pose_pub.publish(Pose2D(x=s.start[0], y=s.start[1], theta=0.0))
        self.report()


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "real_configs", RealConfigTest)
