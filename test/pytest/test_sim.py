"""The simulator's rays hit where the geometry says."""

from __future__ import annotations

import math

import numpy as np
import pytest

from downstream_perception.sim import (
    Lidar,
    LidarConfig,
    MovingCircle,
    Trajectory,
    World,
    aisle_drive,
    box_segments,
    open_field,
    warehouse_aisle,
)
from downstream_perception.sim import world as w
from downstream_perception.sim.depth_camera import (
    CORRIDOR_PERIOD_M,
    DepthCamera,
    box_signed_distance,
    corridor_poses,
    corridor_scene,
)
from downstream_perception.sim.scenes import ACCURACY_SCENES, accuracy_scene


def cast(world: World, origin: tuple[float, float], angle_deg: float, t: float = 0.0) -> float:
    return float(world.raycast(np.array(origin), np.array([math.radians(angle_deg)]), 30.0, t)[0])


def test_end_wall_and_doorway() -> None:
    world = warehouse_aisle()
    # From (5, 0.8) along +x: the end wall at x = 20 (0.8 m is beside the 1 m doorway).
    assert cast(world, (5.0, 0.8), 0.0) == pytest.approx(15.0)
    # Along y = 0 the beam leaves through the doorway: nothing behind it.
    assert math.isinf(cast(world, (5.0, 0.0), 0.0))
    # The open end at x = 0.
    assert math.isinf(cast(world, (5.0, 0.0), 180.0))


def test_shelf_walls_straight_and_diagonal() -> None:
    world = warehouse_aisle()
    assert cast(world, (5.0, 0.0), 90.0) == pytest.approx(w.AISLE_HALF_WIDTH_M)
    assert cast(world, (5.0, 0.0), -90.0) == pytest.approx(w.AISLE_HALF_WIDTH_M)
    assert cast(world, (3.0, 0.0), 45.0) == pytest.approx(1.5 * math.sqrt(2.0))


def test_pillar_and_pallet() -> None:
    world = warehouse_aisle()
    px, py, pr = w.PILLARS[0]
    # From straight above the pillar's centre line: distance = centre distance - radius.
    assert cast(world, (px, 0.0), -90.0) == pytest.approx(abs(py) - pr)
    # The pallet's aisle-facing face at y = 1.2 - 0.3 = 0.9.
    cx, cy = w.PALLET_CENTRE
    assert cast(world, (cx, 0.0), 90.0) == pytest.approx(cy - w.PALLET_HALF_M)
    # Its near face at x = 7.7, seen along +x from inside the pallet's y band.
    assert cast(world, (5.0, 1.2), 0.0) == pytest.approx(cx - w.PALLET_HALF_M - 5.0)


def test_person_present_only_while_crossing() -> None:
    world = warehouse_aisle()
    # At t = 6 s the person is at (10, 0): seen from (5, 0) at 10 - 0.25 - 5 = 4.75 m.
    assert cast(world, (5.0, 0.0), 0.0, t=6.0) == pytest.approx(4.75)
    assert math.isinf(cast(world, (5.0, 0.0), 0.0, t=9.0))
    assert math.isinf(cast(world, (5.0, 0.0), 0.0, t=3.0))
    mover = MovingCircle(0.2, np.array([[0.0, 0.0, 0.0], [2.0, 2.0, 0.0]]))
    assert mover.position(1.0) == pytest.approx((1.0, 0.0))
    assert mover.position(2.5) is None


def test_sensor_inside_a_circle_sees_through_it() -> None:
    world = World(circles=np.array([[0.0, 0.0, 1.0]]))
    assert math.isinf(cast(world, (0.0, 0.0), 30.0))


def test_open_field_is_all_no_return() -> None:
    ranges = Lidar(LidarConfig(num_beams=720)).scan(open_field(), (0.0, 0.0, 0.0))
    assert ranges.dtype == np.float32
    assert np.all(np.isposinf(ranges))


def test_noise_dropouts_and_determinism() -> None:
    world = World(segments=box_segments(0.0, 0.0, 5.0, 5.0))
    config = LidarConfig(num_beams=3600, noise_std_m=0.05, dropout_prob=0.1, seed=7)
    lidar = Lidar(config)
    truth = world.raycast(np.zeros(2), lidar.angles(), 30.0)
    ranges = lidar.scan(world, (0.0, 0.0, 0.0))
    valid = ~np.isnan(ranges)
    assert 0.08 < 1.0 - valid.mean() < 0.12
    err = ranges[valid] - truth[valid]
    assert abs(err.std() - 0.05) < 0.01
    assert abs(err.mean()) < 0.005
    again = Lidar(config).scan(world, (0.0, 0.0, 0.0))
    np.testing.assert_array_equal(np.isnan(ranges), np.isnan(again))
    np.testing.assert_array_equal(ranges[valid], again[valid])


def test_yaw_rotates_the_scan() -> None:
    world = World(segments=np.array([[3.0, -10.0, 3.0, 10.0]]))  # wall x = 3
    lidar = Lidar(LidarConfig(num_beams=4, angle_min=0.0, noise_std_m=0.0))
    r = lidar.scan(world, (0.0, 0.0, math.pi / 2))  # beam 3 (270 deg) now points along +x
    assert r[3] == pytest.approx(3.0, abs=1e-5)
    assert np.isinf(r[1])


def test_occupied_cells_marks_walls_not_the_aisle() -> None:
    world = warehouse_aisle()
    res, ox, oy = 0.05, -2.0, -4.0
    occ = world.occupied_cells(ox, oy, res, 480, 160)
    row = lambda y: int(math.floor((y - oy) / res))  # noqa: E731
    col = lambda x: int(math.floor((x - ox) / res))  # noqa: E731
    assert occ[row(1.5), col(5.0)]
    assert occ[row(-1.5) - 1 : row(-1.5) + 1, col(5.0)].any()
    assert not occ[row(0.0), col(1.0) : col(19.0)].any()  # aisle centre line
    assert occ[row(-1.25), col(12.0) + 2] or occ[row(-1.25), col(12.0) - 3]  # pillar rim


def test_trajectory() -> None:
    traj = aisle_drive(2.0)
    assert traj.duration == pytest.approx(8.5)
    assert traj.pose(0.0) == pytest.approx((1.0, 0.0, 0.0))
    assert traj.pose(4.25) == pytest.approx((9.5, 0.0, 0.0))
    assert traj.pose(100.0) == pytest.approx((18.0, 0.0, 0.0))
    assert traj.velocity(1.0) == pytest.approx((2.0, 0.0, 0.0))
    turn = Trajectory(np.array([[0, 0, 0], [1, 1, 0], [2, 1, 1], [3, 1, 1]]))
    assert turn.pose(1.5)[2] == pytest.approx(math.pi / 2)
    assert turn.pose(2.5)[2] == pytest.approx(math.pi / 2)  # stopped: keeps heading
    with pytest.raises(ValueError):
        Trajectory(np.array([[0, 0, 0]]))


def test_many_beams_vectorised() -> None:
    ranges = Lidar(LidarConfig(num_beams=3600)).scan(warehouse_aisle(), (5.0, 0.0, 0.3), 5.0)
    assert ranges.shape == (3600,)
    # No return only through the open end (x = 0) and the doorway (|y| < 0.5 at x = 20).
    open_end = 2 * math.atan(1.5 / 5.0)
    doorway = 2 * math.atan(0.5 / 15.0)
    expected = 1.0 - (open_end + doorway) / (2 * math.pi)
    assert np.isfinite(ranges).mean() == pytest.approx(expected, abs=0.002)


def test_moving_box_is_hit_where_it_is_and_reported_with_its_size() -> None:
    from downstream_perception.sim import MovingBox, aisle_traffic, stand

    box = MovingBox(0.6, 0.4, np.array([[0.0, 10.0, 0.0], [10.0, 0.0, 0.0]]))  # -1 m/s along x
    world = World(boxes=[box], labels=["forklift"])
    # At t = 4 s its centre is at x = 6: the near face at 5.4, seen from the origin along +x.
    assert cast(world, (0.0, 0.0), 0.0, t=4.0) == pytest.approx(5.4)
    assert math.isinf(cast(world, (0.0, 0.0), 0.0, t=11.0))  # gone after its path
    (seen,) = world.objects_at(4.0)
    assert (seen.label, seen.x, seen.y, seen.size_x, seen.size_y) == pytest.approx(
        ("forklift", 6.0, 0.0, 1.2, 0.8)
    )
    assert world.objects_at(11.0) == []

    traffic = aisle_traffic()
    labels = sorted(o.label for o in traffic.objects_at(5.0))
    assert labels == ["forklift", "person", "person"]
    # The robot's stand-still trajectory keeps its pose.
    assert stand(2.0, 0.0, 10.0).pose(5.0) == pytest.approx((2.0, 0.0, 0.0))
    with pytest.raises(ValueError):
        stand(2.0, 0.0, 0.0)


def small_camera() -> DepthCamera:
    """A quarter of the QVGA camera (same field of view): quick renders."""
    return DepthCamera(80, 60, 65.625, 65.625, 39.5, 29.5)


def test_corridor_shows_what_an_endless_corridor_shows() -> None:
    cam = small_camera()
    poses = corridor_poses(12)
    scene = corridor_scene()  # the copies it keeps
    endless = corridor_scene(copies=range(-10, 14))  # as good as endless within 10 m
    shifted = corridor_scene(copies=range(0, 6))  # the kept copies one period further on
    for T in poses:
        depth = cam.render(scene, T)
        np.testing.assert_array_equal(depth, cam.render(endless, T))
        # One period further down the corridor the camera sees the same image: the simulator
        # replays one rendered period.
        ahead = T.copy()
        ahead[0, 3] += CORRIDOR_PERIOD_M
        np.testing.assert_allclose(cam.render(shifted, ahead), depth, rtol=0, atol=1e-5)
        assert np.isfinite(depth).mean() > 0.9  # floor, walls and furniture within range


def test_corridor_poses_walk_ahead_one_period() -> None:
    poses = corridor_poses(20)
    x = np.array([T[0, 3] for T in poses])
    np.testing.assert_allclose(np.diff(x), CORRIDOR_PERIOD_M / 20)
    assert x[0] == 0.0 and x[-1] + CORRIDOR_PERIOD_M / 20 == pytest.approx(CORRIDOR_PERIOD_M)
    for T in poses:
        np.testing.assert_allclose(T[1:3, 3], [0.0, 1.5])
        forward = T[:3, 2]  # the optical axis
        assert forward[0] > 0.5 and forward[2] < 0.0  # ahead and down, never behind
        np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-12)
    with pytest.raises(ValueError):
        corridor_poses(0)


@pytest.mark.parametrize("name", list(ACCURACY_SCENES))
def test_accuracy_scenes_are_seen_from_free_space_and_render_their_surfaces(name: str) -> None:
    cam = small_camera()
    scene, poses = accuracy_scene(name, frames=8)
    assert len(poses) == 8
    rays = cam.rays()
    for T in poses:
        assert scene.signed_distance(T[None, :3, 3])[0] > 0.3  # cameras stand in free space
        depth = cam.render(scene, T).ravel()
        hit = np.isfinite(depth)
        assert hit.mean() > 0.99  # closed scenes: every ray hits within 10 m
        points = (rays[hit] * depth[hit, None]) @ T[:3, :3].T + T[:3, 3]
        # The ray caster and the signed distance agree: hits lie on the surface.
        np.testing.assert_allclose(scene.signed_distance(points), 0.0, atol=1e-5)
    # Every object is seen: some frame's hits lie on it.
    hits = np.vstack(
        [(rays * cam.render(scene, T).ravel()[:, None]) @ T[:3, :3].T + T[:3, 3] for T in poses]
    )
    hits = hits[np.isfinite(hits).all(axis=1)]
    objects = [
        *(box_signed_distance(hits, b) for b in scene.boxes),
        *(np.linalg.norm(hits - np.asarray(s.center), axis=1) - s.radius for s in scene.spheres),
        *(
            np.linalg.norm(hits[:, :2] - np.asarray(c.center_xy), axis=1) - c.radius
            for c in scene.cylinders
        ),
    ]
    assert len(objects) >= 4
    for distance in objects:
        assert np.sum(np.abs(distance) < 1e-4) > 0


@pytest.mark.parametrize("name", list(ACCURACY_SCENES))
def test_accuracy_scene_offsets_move_scene_and_cameras_together(name: str) -> None:
    cam = small_camera()
    offset = (0.005, 0.0125, 0.0375)
    base, base_poses = accuracy_scene(name, frames=4)
    moved, moved_poses = accuracy_scene(name, offset, frames=4)
    for T, M in zip(base_poses, moved_poses, strict=True):
        np.testing.assert_allclose(M[:3, 3] - T[:3, 3], offset, atol=1e-12)
        np.testing.assert_array_equal(M[:3, :3], T[:3, :3])
        # Same images: only the lattice moves under them.
        np.testing.assert_allclose(cam.render(moved, M), cam.render(base, T), atol=1e-5)
    points = np.random.default_rng(0).uniform(-1.5, 1.5, (500, 3)) + [0.0, 0.0, 1.5]
    np.testing.assert_allclose(
        moved.signed_distance(points + offset), base.signed_distance(points), atol=1e-12
    )
    # Offset 0 is the aligned case: the walls lie on multiples of 2 cm and 5 cm.
    walls = np.array([*base.room_min, *base.room_max])
    np.testing.assert_allclose(np.round(walls / 0.1) * 0.1, walls, atol=1e-12)
