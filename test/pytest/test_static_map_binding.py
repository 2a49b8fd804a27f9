"""The static map binding against an independent numpy restatement of costmap_2d's StaticLayer
value mapping (unsigned-char compares, value / lethal * 254 truncated) and its update window."""

from __future__ import annotations

import numpy as np
import pytest

import downstream_perception as dp


def reference(occ: np.ndarray, track: bool, lethal: int, unknown: int, trinary: bool) -> np.ndarray:
    v = occ.astype(np.int8).view(np.uint8).astype(np.int64)
    lethal = max(min(lethal, 100), 0)
    unk = unknown % 256
    out = np.zeros(v.shape, dtype=np.int64)
    if not trinary and lethal > 0:
        out = np.floor(v / lethal * 254.0).astype(np.int64)
    out = np.where(v >= lethal, 254, out)
    out = np.where(v == unk, 255 if track else 0, out)
    return out.astype(np.uint8)


def config(track: bool, lethal: int, unknown: int, trinary: bool) -> dp.StaticMapConfig:
    c = dp.StaticMapConfig()
    c.track_unknown_space = track
    c.lethal_cost_threshold = lethal
    c.unknown_cost_value = unknown
    c.trinary_costmap = trinary
    return c


@pytest.mark.parametrize("track", [True, False])
@pytest.mark.parametrize("lethal", [100, 65, 0, 150, -3])
@pytest.mark.parametrize("unknown", [-1, 0, 50, 255])
@pytest.mark.parametrize("trinary", [True, False])
def test_every_byte_matches_reference(
    track: bool, lethal: int, unknown: int, trinary: bool
) -> None:
    occ = np.arange(-128, 128, dtype=np.int8).reshape(16, 16)
    got = dp.static_map_values(occ, config(track, lethal, unknown, trinary))
    assert got.dtype == np.uint8 and got.shape == (16, 16)
    np.testing.assert_array_equal(got, reference(occ, track, lethal, unknown, trinary))


def test_defaults_and_golden_values() -> None:
    c = dp.StaticMapConfig()
    assert (c.track_unknown_space, c.use_maximum, c.lethal_cost_threshold) == (True, False, 100)
    assert (c.unknown_cost_value, c.trinary_costmap) == (-1, True)
    occ = np.array([-1, 0, 50, 99, 100, 101], dtype=np.int8)
    np.testing.assert_array_equal(dp.static_map_values(occ), [255, 0, 0, 0, 254, 254])
    c.trinary_costmap = False
    np.testing.assert_array_equal(dp.static_map_values(occ, c), [255, 0, 127, 251, 254, 254])


def test_map_and_update_window() -> None:
    m = dp.StaticMap()
    occ = np.zeros((3, 4), dtype=np.int8)
    occ[0, 1] = 100
    occ[2, 3] = -1
    m.set_map(occ, 0.5, -1.0, 2.0)
    assert m.has_map
    g = m.geometry
    assert (g.size_x, g.size_y, g.resolution, g.origin_x, g.origin_y) == (4, 3, 0.5, -1.0, 2.0)
    expected = reference(occ, True, 100, -1, True)
    np.testing.assert_array_equal(m.costs(), expected)
    assert m.last_change == (0, 0, 3, 2)
    up = np.array([[100, -1], [50, 100]], dtype=np.int8)
    m.apply_update(1, 1, up)
    expected[1:3, 1:3] = reference(up, True, 100, -1, True)
    np.testing.assert_array_equal(m.costs(), expected)
    assert m.last_change == (1, 1, 2, 2)


@pytest.mark.parametrize(
    "x, y, shape",
    [
        (-1, 0, (1, 1)),
        (3, 0, (1, 2)),
        (0, 2, (2, 1)),
        (1 << 40, 0, (1, 1)),
        (0, -(1 << 40), (1, 1)),
    ],
)
def test_update_outside_is_refused_and_writes_nothing(x: int, y: int, shape: tuple) -> None:
    m = dp.StaticMap()
    m.set_map(np.zeros((3, 4), dtype=np.int8), 0.05)
    with pytest.raises(ValueError, match="outside|fit"):
        m.apply_update(x, y, np.full(shape, 100, dtype=np.int8))
    assert not m.costs().any()


def test_refused_map_keeps_previous() -> None:
    m = dp.StaticMap()
    with pytest.raises(ValueError, match="no map"):
        m.apply_update(0, 0, np.zeros((1, 1), dtype=np.int8))
    m.set_map(np.full((2, 2), 100, dtype=np.int8), 0.05)
    for res in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="resolution"):
            m.set_map(np.zeros((5, 5), dtype=np.int8), res)
    c = dp.StaticMapConfig()
    c.max_cells = 10
    small = dp.StaticMap(c)
    with pytest.raises(ValueError, match="max_cells"):
        small.set_map(np.zeros((4, 4), dtype=np.int8), 0.05)
    np.testing.assert_array_equal(m.costs(), np.full((2, 2), 254, dtype=np.uint8))
