#!/usr/bin/env python3
"""rostest: the TSDF nodelet on 20 simulated 16UC1 depth frames of the analytic room.

The mesh it publishes (per-block TRIANGLE_LIST markers) must lie on the room's true surfaces;
~slice_distance is the band's exact 2-D ESDF and the room's clearance; ~save_mesh writes a PLY
with as many vertices as it reports; frames with a wrong encoding, a size that disagrees with
CameraInfo or a frame nobody publishes tf for are rejected and counted without stopping the node;
~clear empties the map and deletes the markers.
"""

from __future__ import annotations

import os
import tempfile
import time
import unittest
from collections.abc import Callable

import numpy as np
import rospy
import rostest
import tf2_ros
from diagnostic_msgs.msg import DiagnosticArray
from dynamic_reconfigure.client import Client as ReconfigureClient
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import OccupancyGrid
from sensor_msgs import point_cloud2
from sensor_msgs.msg import CameraInfo, Image, PointCloud2
from std_msgs.msg import Bool, Header
from std_srvs.srv import Empty

from downstream_perception.ros.mesh_collector import MeshCollector
from downstream_perception.ros.util import wait_until
from downstream_perception.sim.depth_camera import circle_poses, room_scene
from downstream_perception.srv import SaveMap


class TsdfRoomTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tsdf_room")
        cls.mesh = MeshCollector("/tsdf/mesh")
        cls.status: dict[str, str] = {}
        cls.done = False

        def on_diag(msg: DiagnosticArray) -> None:
            for s in msg.status:
                if s.name.endswith("tsdf: tsdf"):
                    cls.status = {kv.key: kv.value for kv in s.values}

        def on_done(msg: Bool) -> None:
            cls.done = cls.done or msg.data

        cls.octomap: PointCloud2 | None = None

        def on_octomap(msg: PointCloud2) -> None:
            cls.octomap = msg

        cls.slice: OccupancyGrid | None = None

        def on_slice(msg: OccupancyGrid) -> None:
            cls.slice = msg

        # Slices and clearance clouds by stamp: a pair published by one mesh tick shares it.
        cls.slices: dict[rospy.Time, OccupancyGrid] = {}
        cls.distances: dict[rospy.Time, PointCloud2] = {}

        def on_slice_kept(msg: OccupancyGrid) -> None:
            cls.slices[msg.header.stamp] = msg

        def on_distance(msg: PointCloud2) -> None:
            cls.distances[msg.header.stamp] = msg

        rospy.Subscriber("/tsdf/slice", OccupancyGrid, on_slice, queue_size=1)
        rospy.Subscriber("/tsdf/slice", OccupancyGrid, on_slice_kept, queue_size=10)
        rospy.Subscriber("/tsdf/slice_distance", PointCloud2, on_distance, queue_size=10)
        rospy.Subscriber("/tsdf/octomap_occupied", PointCloud2, on_octomap, queue_size=1)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=20)
        rospy.Subscriber("/depth_sim/done", Bool, on_done, queue_size=1)

    def test_1_mesh_lies_on_the_true_surfaces(self) -> None:
        self.assertTrue(wait_until(lambda: self.done, 40.0), "the simulator did not finish")
        time.sleep(1.5)  # the next mesh update (2 Hz) after the last frame
        self.assertGreater(self.mesh.messages, 0)
        self.assertEqual(int(self.status.get("frames integrated", 0)), 20, self.status)
        self.assertGreater(int(self.status.get("health: zero crossings", 0)), 1000, self.status)
        corners = self.mesh.corners()
        self.assertGreater(len(corners), 30000)
        error = np.abs(room_scene().signed_distance(corners))
        # 4 cm voxels: sub-voxel surfaces (the 320x240 2 cm figures are 0.7 mm mean).
        self.assertLess(float(error.mean()), 0.003)
        self.assertLess(float(np.percentile(error, 99)), 0.04)
        self.assertLess(float(np.mean(error > 0.04)), 0.005)  # ghosts: more than a voxel off

    def test_2_save_mesh_writes_a_ply(self) -> None:
        rospy.wait_for_service("/tsdf/save_mesh", 5.0)
        save = rospy.ServiceProxy("/tsdf/save_mesh", SaveMap)
        out_dir = rospy.get_param("/tsdf/output_dir")
        run = f"run-{os.getpid()}-{time.time_ns()}"  # a fresh subdirectory of ~output_dir
        reply = save(f"{run}/room.ply", False)
        self.assertTrue(reply.success, reply.message)
        path = os.path.join(out_dir, run, "room.ply")
        self.assertEqual(reply.written_path, path)
        with open(path, "rb") as f:
            header = f.read(400).split(b"end_header")[0].decode()
        vertices = int(header.split("element vertex ")[1].split()[0])
        self.assertGreater(vertices, 10000)
        self.assertIn(f"wrote {vertices} vertices", reply.message)
        self.assertIn(path, reply.message)
        refused = save(f"{run}/room.obj", False)
        self.assertFalse(refused.success)
        self.assertIn(".ply", refused.message)

        # An existing file is kept unless the caller asks to overwrite it.
        size = os.path.getsize(path)
        with open(path, "ab") as f:
            f.write(b"marker")
        kept = save(f"{run}/room.ply", False)
        self.assertFalse(kept.success)
        self.assertIn("exists", kept.message)
        self.assertEqual(os.path.getsize(path), size + 6)
        self.assertTrue(save(f"{run}/room.ply", True).success)
        self.assertEqual(os.path.getsize(path), size)

    def test_2d_save_services_write_only_inside_the_output_directory(self) -> None:
        rospy.wait_for_service("/tsdf/save_mesh", 5.0)
        save = rospy.ServiceProxy("/tsdf/save_mesh", SaveMap)
        save_octomap = rospy.ServiceProxy("/tsdf/save_octomap", SaveMap)
        out_dir = rospy.get_param("/tsdf/output_dir")
        run = f"run-{os.getpid()}-{time.time_ns()}"
        outside = tempfile.mkdtemp()
        victim = os.path.join(outside, "victim.txt")
        with open(victim, "w") as f:
            f.write("precious")
        os.makedirs(os.path.join(out_dir, run))
        os.symlink(victim, os.path.join(out_dir, run, "link.ply"))
        os.symlink(victim, os.path.join(out_dir, run, "link.bt"))
        os.symlink(outside, os.path.join(out_dir, run, "up"))
        crafted = {
            "NUL hiding the extension": victim + "\0.ply",
            "absolute path": os.path.join(outside, "victim.ply"),
            "escape with ..": f"{run}/../../../{os.path.relpath(outside, '/')}/victim.ply",
            "symlinked file": f"{run}/link.ply",
            "symlinked directory": f"{run}/up/victim.ply",
            "1 MB name": "a" * (1 << 20) + ".ply",
        }
        for what, name in crafted.items():
            for service in (save, save_octomap):
                ext_name = name if service is save else name[: -len(".ply")] + ".bt"
                reply = service(ext_name, True)
                self.assertFalse(reply.success, f"{what}: {reply.message}")
                self.assertEqual(reply.written_path, "")
                self.assertLess(len(reply.message), 400, what)
        with open(victim) as f:
            self.assertEqual(f.read(), "precious")
        self.assertEqual(sorted(os.listdir(outside)), ["victim.txt"])
        self.assertEqual(
            sorted(os.listdir(os.path.join(out_dir, run))), ["link.bt", "link.ply", "up"]
        )

    def test_2a_slice_distance_is_the_band_esdf(self) -> None:
        # ~slice_distance: the height band's 2-D ESDF over the slice's cells (esdf_band.h), one
        # point per known column. Occupied columns (a band voxel with D < 0) read negative and
        # are slice obstacles too (the slice's shell is a voxel thicker); every other column
        # reads (sqrt(k) - 1/2) * voxel, k its squared cell distance to the nearest occupied
        # column, capped at ~slice_distance_max_m (2 m), and occupied ones the same towards the
        # nearest free column. Near objects it is the room's true clearance.
        from scipy.ndimage import distance_transform_edt

        self.assertTrue(wait_until(lambda: self.done, 60.0), "the depth simulator never finished")
        self.assertTrue(
            wait_until(lambda: set(self.slices) & set(self.distances), 10.0),
            f"{len(self.slices)} slices, {len(self.distances)} distance clouds",
        )
        stamp = max(set(self.slices) & set(self.distances))
        grid, cloud = self.slices[stamp], self.distances[stamp]
        self.assertEqual(self.status.get("slice distance cap (m)"), "2", self.status)
        # The padding beyond the slice's grid: ceil(2 m / 4 cm + 1/2) = 51 columns, not narrowed
        # (the room is far below 2 x ~slice_max_cells).
        self.assertEqual(self.status.get("slice distance: padding (voxels)"), "51", self.status)
        cuts = "slice distance: padding narrowed to 2 x slice_max_cells (total)"
        self.assertEqual(self.status.get(cuts), "0", self.status)
        names = [f.name for f in cloud.fields]
        self.assertEqual(names, ["x", "y", "z", "distance"])
        points = np.array(list(point_cloud2.read_points(cloud, field_names=names)))
        cells = np.array(grid.data, dtype=np.int8).reshape(grid.info.height, grid.info.width)
        self.assertEqual(len(points), int((cells >= 0).sum()))
        res = grid.info.resolution
        col = np.floor((points[:, 0] - grid.info.origin.position.x) / res).astype(int)
        row = np.floor((points[:, 1] - grid.info.origin.position.y) / res).astype(int)
        self.assertTrue((cells[row, col] >= 0).all())
        distance = points[:, 3]
        inside = distance < 0.0
        self.assertGreater(int(inside.sum()), 300)
        self.assertTrue((cells[row[inside], col[inside]] == 100).all())
        occupied = np.zeros(cells.shape, dtype=bool)
        occupied[row[inside], col[inside]] = True
        free = np.zeros(cells.shape, dtype=bool)
        free[row[~inside], col[~inside]] = True
        to_occupied = distance_transform_edt(~occupied)[row, col]
        to_free = distance_transform_edt(~free)[row, col]
        expected = np.where(
            inside,
            -np.minimum(2.0, res * (to_free - 0.5)),
            np.minimum(2.0, res * (to_occupied - 0.5)),
        )
        np.testing.assert_allclose(distance, expected, atol=1e-5)
        # Against the room itself: the clearance from the objects (the minimum of the scene's
        # distance over heights 0.6 .. 1.8 m, where the floor is farther than they are).
        heights = np.linspace(0.6, 1.8, 25)
        xy = points[:, :2]
        truth = np.min(
            [room_scene().signed_distance(np.c_[xy, np.full(len(xy), z)]) for z in heights],
            axis=0,
        )
        near = (~inside) & (truth > 0.1) & (truth < 0.5)
        self.assertGreater(int(near.sum()), 500)
        error = np.abs(distance[near] - truth[near])
        # A voxel field: its zero level lies halfway between voxel centres, the true surface
        # anywhere in between.
        self.assertLess(float(np.median(error)), 0.6 * res, np.percentile(error, [50, 90, 99]))
        self.assertGreater(int((distance > 0.3).sum()), 100)  # open floor: clearance

    def test_2b_octomap_is_published_and_saved(self) -> None:
        self.assertIsNotNone(self.octomap, "no ~octomap_occupied cloud")
        points = np.array(list(point_cloud2.read_points(self.octomap, ("x", "y", "z"))))
        self.assertGreater(len(points), 1000)
        # 5 cm leaves: a leaf centre lies within half a leaf diagonal of the surface it holds.
        error = np.abs(room_scene().signed_distance(points))
        self.assertLess(float(np.percentile(error, 99)), 0.044)
        rospy.wait_for_service("/tsdf/save_octomap", 5.0)
        save = rospy.ServiceProxy("/tsdf/save_octomap", SaveMap)
        reply = save(f"run-{os.getpid()}-{time.time_ns()}/room.bt", False)
        self.assertTrue(reply.success, reply.message)
        path = reply.written_path
        self.assertTrue(path.startswith(rospy.get_param("/tsdf/output_dir") + "/"), path)
        with open(path, "rb") as f:
            self.assertTrue(f.readline().startswith(b"# Octomap OcTree binary file"))

        # Inserted on its own thread: every integrated frame is inserted or, when insertion
        # falls behind, dropped from its queue (and counted).
        def accounted() -> bool:
            s = self.status
            return "octomap: observations inserted" in s and int(
                s["octomap: observations inserted"]
            ) + int(
                s["octomap: observations dropped (queue full: insertion slower than the sensor)"]
            ) == int(s["frames integrated"])

        self.assertTrue(wait_until(accounted, 10.0), f"diagnostics: {self.status}")
        self.assertGreater(int(self.status["octomap: observations inserted"]), 0)
        self.assertGreater(int(self.status["octomap: leaves"]), 1000)

    def occupied_xy(self, band_bottom: float) -> np.ndarray:
        """Centres (x, y) of the occupied cells of the first slice whose band starts at
        band_bottom (the grid's origin z)."""
        self.assertTrue(
            wait_until(
                lambda: self.slice is not None
                and abs(self.slice.info.origin.position.z - band_bottom) < 1e-6,
                10.0,
            ),
            f"no slice with its band at {band_bottom} m",
        )
        msg = self.slice
        info = msg.info
        grid = np.asarray(msg.data, dtype=np.int8).reshape(info.height, info.width)
        rows, cols = np.nonzero(grid == 100)
        x = info.origin.position.x + (cols + 0.5) * info.resolution
        y = info.origin.position.y + (rows + 0.5) * info.resolution
        return np.c_[x, y]

    def test_2c_slice_band_changes_live(self) -> None:
        self.assertTrue(wait_until(lambda: self.done, 60.0), "the depth simulator never finished")

        def near(xy: np.ndarray, cx: float, cy: float, half_x: float, half_y: float) -> int:
            return int(((np.abs(xy[:, 0] - cx) < half_x) & (np.abs(xy[:, 1] - cy) < half_y)).sum())

        # The box (top at 0.70 m) and the table top (0.72-0.76 m) are in the default band...
        default = self.occupied_xy(0.05)
        self.assertGreater(near(default, 0.8, 0.6, 0.35, 0.3), 5, "the box is not in the slice")
        self.assertGreater(near(default, -0.8, 0.7, 0.45, 0.35), 5, "the table is not in it")
        # ... and a band above them, set live, leaves both out (the sphere, pole, walls remain).
        client = ReconfigureClient("/tsdf", timeout=10.0)
        client.update_configuration({"slice_min_z_m": 0.85, "slice_max_z_m": 0.95})
        high = self.occupied_xy(0.85)
        self.assertGreater(len(high), 20)
        self.assertEqual(near(high, 0.8, 0.6, 0.35, 0.3), 0, "the box is still in the slice")
        self.assertEqual(near(high, -0.8, 0.7, 0.45, 0.35), 0, "the table is still in it")
        # An inverted band is refused, counted, and the live band kept.
        errors = int(self.status.get("config errors", 0))
        client.update_configuration({"slice_min_z_m": 1.0, "slice_max_z_m": 0.5})
        self.assertTrue(
            wait_until(lambda: int(self.status.get("config errors", 0)) > errors, 10.0),
            f"diagnostics: {self.status}",
        )
        self.assertEqual(self.status["slice band (m)"], "0.85 .. 0.95")
        client.update_configuration({"slice_min_z_m": 0.05, "slice_max_z_m": 1.8})
        self.assertTrue(
            wait_until(lambda: self.status.get("slice band (m)") == "0.05 .. 1.8", 10.0)
        )

    def slice_where(self, ready: Callable[[OccupancyGrid], bool], what: str) -> OccupancyGrid:
        """The latest slice once `ready` holds for it (10 s)."""
        self.assertTrue(
            wait_until(lambda: self.slice is not None and ready(self.slice), 10.0),
            f"no slice with {what}",
        )
        assert self.slice is not None
        return self.slice

    def test_2e_window_and_cap_crop_the_slice(self) -> None:
        # ~slice_window_m: a square of round(side / voxel) columns around the sensor's latest
        # position (the last depth frame's camera), the column holding it at index n / 2, so the
        # grid's origin is (column - n // 2 - 1/2) voxels. Both windows lie inside the room.
        self.assertTrue(wait_until(lambda: self.done, 60.0), "the depth simulator never finished")
        res = 0.04
        eye = circle_poses(20)[-1][:2, 3]  # frame 19 of the simulator's 20
        column = np.floor(eye / res + 0.5)
        client = ReconfigureClient("/tsdf", timeout=10.0)
        cut_key = "slices cut to slice_max_cells (total)"
        cut_before = int(self.status.get(cut_key, -1))
        self.assertGreaterEqual(cut_before, 0, self.status)

        def check(grid: OccupancyGrid, n: int) -> None:
            origin = (column - n // 2 - 0.5) * res
            info = grid.info
            self.assertEqual((info.width, info.height), (n, n))
            self.assertAlmostEqual(info.resolution, res, places=6)
            self.assertAlmostEqual(info.origin.position.x, origin[0], places=6)
            self.assertAlmostEqual(info.origin.position.y, origin[1], places=6)
            self.assertEqual(self.status.get("slice: cells"), str(n * n), self.status)

        client.update_configuration({"slice_window_m": 1.0})  # 25 columns
        windowed = self.slice_where(lambda g: g.info.width == 25, "a 1 m window")
        self.assertTrue(wait_until(lambda: self.status.get("slice window (m)") == "1", 10.0))
        self.assertTrue(wait_until(lambda: self.status.get("slice: cells") == "625", 10.0))
        check(windowed, 25)
        grid = np.asarray(windowed.data, dtype=np.int8)
        self.assertGreater(int((grid >= 0).sum()), 300)  # the room's floor, observed
        # Its clearance covers the same cells, one point per known cell.
        stamp = windowed.header.stamp
        self.assertTrue(wait_until(lambda: stamp in self.distances, 10.0))
        points = np.array(
            list(point_cloud2.read_points(self.distances[stamp], field_names=("x", "y")))
        )
        self.assertEqual(len(points), int((grid >= 0).sum()))
        lo = (column - 12 - 0.5) * res
        self.assertTrue(((points >= lo) & (points <= lo + 25 * res)).all())
        # The cap: 400 cells cut the whole extent to 20 x 20 around the sensor, counted.
        client.update_configuration({"slice_window_m": 0.0, "slice_max_cells": 400})
        capped = self.slice_where(lambda g: g.info.width == 20, "the 400-cell cap")
        self.assertTrue(wait_until(lambda: self.status.get("slice: cells") == "400", 10.0))
        check(capped, 20)
        self.assertGreater(int(self.status[cut_key]), cut_before)
        # Absurd values are refused, counted, and the live ones kept.
        errors = int(self.status.get("config errors", 0))
        client.update_configuration({"slice_window_m": -1.0, "slice_max_cells": 0})
        self.assertTrue(
            wait_until(lambda: int(self.status.get("config errors", 0)) > errors, 10.0),
            f"diagnostics: {self.status}",
        )
        self.assertEqual(self.status["slice max cells"], "400")
        client.update_configuration({"slice_window_m": 0.0, "slice_max_cells": 4000000})
        whole = self.slice_where(lambda g: g.info.width > 100, "the whole room")
        self.assertGreater(whole.info.height, 100)

    def test_3_bad_frames_are_counted_and_survived(self) -> None:
        images = rospy.Publisher("/depth/image", Image, queue_size=50)
        infos = rospy.Publisher("/depth/camera_info", CameraInfo, queue_size=50)
        time.sleep(1.0)
        now = rospy.Time.now()
        rgb = Image(header=Header(stamp=now, frame_id="depth_optical"), height=2, width=2)
        rgb.encoding, rgb.step, rgb.data = "rgb8", 6, bytes(12)
        images.publish(rgb)
        small = Image(header=Header(stamp=now, frame_id="depth_optical"), height=10, width=10)
        small.encoding, small.step, small.data = "32FC1", 40, bytes(400)
        images.publish(small)  # CameraInfo for depth_optical says 320 x 240
        # A camera whose frame nobody publishes tf for: its (valid) frames wait for tf until the
        # queue (10) overflows.
        k = [100.0, 0.0, 1.0, 0.0, 100.0, 1.0, 0.0, 0.0, 1.0]
        infos.publish(
            CameraInfo(header=Header(stamp=now, frame_id="nowhere"), width=2, height=2, K=k)
        )
        time.sleep(0.5)
        for _ in range(15):
            lost = Image(header=Header(stamp=rospy.Time.now(), frame_id="nowhere"), height=2)
            lost.width, lost.encoding, lost.step, lost.data = 2, "32FC1", 8, bytes(16)
            images.publish(lost)
            time.sleep(0.02)
        self.assertTrue(
            wait_until(
                lambda: int(self.status.get("rejected (bad depth image)", 0)) >= 1
                and int(self.status.get("rejected (camera_info missing or inconsistent)", 0)) >= 1
                and any(k.startswith("rejected (tf") for k in self.status),
                15.0,
            ),
            f"diagnostics: {self.status}",
        )
        self.assertEqual(int(self.status["frames integrated"]), 20)

    def test_3b_an_image_before_its_first_camera_info_waits_for_it(self) -> None:
        # Image and CameraInfo travel on separate connections: at start-up (or in a replay) the
        # first image can arrive first. It waits for its frame's CameraInfo, then is fused.
        images = rospy.Publisher("/depth/image", Image, queue_size=5)
        infos = rospy.Publisher("/depth/camera_info", CameraInfo, queue_size=5)
        self.assertTrue(wait_until(lambda: images.get_num_connections() > 0, 5.0))
        self.assertTrue(wait_until(lambda: infos.get_num_connections() > 0, 5.0))
        self.assertTrue(wait_until(lambda: "frames integrated" in self.status, 10.0))
        before = int(self.status["frames integrated"])
        stamp = rospy.Time.now()
        pose = TransformStamped(header=Header(stamp=stamp, frame_id="odom"))
        pose.child_frame_id = "late_optical"
        pose.transform.translation.z = 1.0
        pose.transform.rotation.w = 1.0
        broadcaster = tf2_ros.TransformBroadcaster()
        time.sleep(0.5)  # the nodelet's tf listener connects to this node's /tf
        broadcaster.sendTransform(pose)
        depth = Image(header=Header(stamp=stamp, frame_id="late_optical"), height=4, width=4)
        depth.encoding, depth.step = "32FC1", 16
        depth.data = np.full((4, 4), 1.5, np.float32).tobytes()
        images.publish(depth)
        key = "depth images waiting for their first CameraInfo"
        self.assertTrue(wait_until(lambda: self.status.get(key) == "1", 5.0), self.status)
        self.assertEqual(int(self.status["frames integrated"]), before, self.status)
        k = [4.0, 0.0, 1.5, 0.0, 4.0, 1.5, 0.0, 0.0, 1.0]
        infos.publish(
            CameraInfo(header=Header(stamp=stamp, frame_id="late_optical"), width=4, height=4, K=k)
        )
        self.assertTrue(
            wait_until(lambda: int(self.status.get("frames integrated", 0)) == before + 1, 5.0),
            self.status,
        )
        self.assertEqual(self.status[key], "0")

    def test_4_clear_empties_the_map(self) -> None:
        rospy.wait_for_service("/tsdf/clear", 5.0)
        rospy.ServiceProxy("/tsdf/clear", Empty)()
        self.assertTrue(wait_until(lambda: self.mesh.deleted_all, 5.0), "DELETEALL marker")
        self.assertTrue(wait_until(lambda: int(self.status.get("blocks", -1)) == 0, 5.0))
        self.assertTrue(wait_until(lambda: int(self.status.get("octomap: leaves", -1)) == 0, 5.0))

    def test_5_a_map_too_wide_for_a_slice_grid_is_cut_to_the_cap(self) -> None:
        # Two point clouds 700 m apart (a long drive at fine voxels): no slice grid holds that
        # extent at 4 cm (17,500^2 cells > 2^28). The mesh tick used to throw out of the timer
        # and take the nodelet down, then to skip the slice; now ~slice_max_cells (4,000,000)
        # cuts it to the 2,000-column square around the sensor (then to the blocks), counted.
        import tf2_ros
        from geometry_msgs.msg import TransformStamped

        refused = "slices refused (map extent beyond a grid)"
        key = "slices cut to slice_max_cells (total)"
        self.assertTrue(wait_until(lambda: self.status.get(refused) == "0", 10.0), self.status)
        cut_before = int(self.status[key])
        broadcaster = tf2_ros.StaticTransformBroadcaster()
        transforms = []
        for name, x in (("near_sensor", 0.0), ("far_sensor", 700.0)):
            t = TransformStamped()
            t.header.stamp = rospy.Time.now()
            t.header.frame_id, t.child_frame_id = "odom", name
            t.transform.translation.x = t.transform.translation.y = x
            t.transform.rotation.w = 1.0
            transforms.append(t)
        broadcaster.sendTransform(transforms)
        clouds = rospy.Publisher("/points", PointCloud2, queue_size=10)
        time.sleep(1.0)
        integrated = int(self.status.get("frames integrated", 0))
        wall = [[1.0, y, z] for y in np.linspace(-0.3, 0.3, 13) for z in np.linspace(-0.3, 0.3, 13)]
        for name in ("near_sensor", "far_sensor"):
            header = Header(stamp=rospy.Time.now(), frame_id=name)
            clouds.publish(point_cloud2.create_cloud_xyz32(header, wall))
            time.sleep(0.3)
        self.assertTrue(
            wait_until(lambda: int(self.status.get(key, 0)) > cut_before, 10.0),
            f"diagnostics: {self.status}",
        )
        self.assertEqual(int(self.status["frames integrated"]), integrated + 2)
        self.assertEqual(self.status[refused], "0")
        # Around the far sensor (700, 700): columns from 17,500 - 1,000, up to the far blocks.
        far = self.slice_where(lambda g: g.info.origin.position.x > 600.0, "the far window")
        self.assertAlmostEqual(far.info.origin.position.x, (16500 - 0.5) * 0.04, places=6)
        self.assertAlmostEqual(far.info.origin.position.y, (16500 - 0.5) * 0.04, places=6)
        self.assertLess(far.info.width, 2000)
        self.assertLess(far.info.height, 2000)
        self.assertLessEqual(int(self.status["slice: cells"]), 4000000)
        # Still alive: a later cloud near the first is integrated and the diagnostics go on.
        clouds.publish(
            point_cloud2.create_cloud_xyz32(
                Header(stamp=rospy.Time.now(), frame_id="near_sensor"), wall
            )
        )
        self.assertTrue(
            wait_until(
                lambda: int(self.status.get("frames integrated", 0)) == integrated + 3, 10.0
            ),
            f"diagnostics: {self.status}",
        )


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_tsdf_room", TsdfRoomTest)
