"""CostmapClient rebuilds the grid from full grids and updates, and drops an update that does not
fit the current grid (one sent before a resize that arrives after the new full grid)."""

from __future__ import annotations

import numpy as np
import pytest

rospy = pytest.importorskip("rospy")
from map_msgs.msg import OccupancyGridUpdate  # noqa: E402
from nav_msgs.msg import OccupancyGrid  # noqa: E402

from downstream_perception.ros.costmap_client import CostmapClient  # noqa: E402


def full(width: int, height: int, value: int) -> OccupancyGrid:
    msg = OccupancyGrid()
    msg.info.width, msg.info.height = width, height
    msg.data = [value] * (width * height)
    return msg


def update(x: int, y: int, width: int, height: int, value: int) -> OccupancyGridUpdate:
    msg = OccupancyGridUpdate()
    msg.x, msg.y, msg.width, msg.height = x, y, width, height
    msg.data = [value] * (width * height)
    return msg


@pytest.fixture
def client(monkeypatch: pytest.MonkeyPatch) -> CostmapClient:
    # No master: the subscriptions are not needed to feed the callbacks directly.
    monkeypatch.setattr(rospy, "Subscriber", lambda *args, **kwargs: None)
    return CostmapClient("/costmap/costmap")


def test_updates_are_applied_in_their_window(client: CostmapClient) -> None:
    client._on_full(full(4, 3, 0))
    client._on_update(update(1, 2, 2, 1, 100))
    grid = client.grid()
    assert grid.shape == (3, 4)
    assert grid[2, 1] == 100 and grid[2, 2] == 100
    assert int(np.count_nonzero(grid)) == 2
    assert client.updates == 1


def test_an_update_for_the_old_size_is_dropped(client: CostmapClient) -> None:
    client._on_full(full(800, 800, 0))
    client._on_full(full(132, 133, 0))  # resized to the map
    client._on_update(update(0, 0, 800, 800, 50))  # sent before the resize, arrived after
    client._on_update(update(130, 0, 5, 1, 50))  # sticks out of the grid
    bad = update(0, 0, 2, 2, 50)
    bad.data = [50] * 3  # inconsistent size
    client._on_update(bad)
    assert client.updates_dropped == 3
    assert client.updates == 0
    assert int(np.count_nonzero(client.grid())) == 0
