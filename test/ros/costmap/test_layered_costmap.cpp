// LayeredCostmap::lockSizeTo(): a static map fixes the master's geometry (costmap_2d's
// size_locked), or hands the request to the host that owns the real master (the costmap_2d
// adapter). Needs no ROS master (no layers, so no NodeHandles).
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "downstream_perception/ros/costmap/layered_costmap.h"

using namespace downstream_perception;  // NOLINT

TEST(LayeredCostmapSizeLock, LockSizeToResizesAndLocks) {
  LayeredCostmap lc("map", true);
  lc.resizeMap(GridGeometry(40, 40, 0.1, -2.0, -2.0));
  EXPECT_FALSE(lc.sizeLocked());
  const GridGeometry map(60, 40, 0.05, -1.0, -0.5);
  lc.lockSizeTo(map);
  EXPECT_TRUE(lc.sizeLocked());
  EXPECT_EQ(lc.costmap().geometry(), map);
  EXPECT_EQ(lc.costmap().cells().size(), 2400u);
  EXPECT_EQ(lc.costmap().cost(59, 39), cost::kNoInformation);  // the default of a new master
  // The same geometry again: no resize (the master keeps what is drawn).
  lc.costmap().setCost(3, 3, cost::kLethalObstacle);
  lc.lockSizeTo(map);
  EXPECT_EQ(lc.costmap().cost(3, 3), cost::kLethalObstacle);
}

TEST(LayeredCostmapSizeLock, HandlerTakesTheRequest) {
  LayeredCostmap lc("map", false);
  const GridGeometry start(10, 10, 0.1, 0.0, 0.0);
  lc.resizeMap(start);
  std::vector<GridGeometry> asked;
  lc.setSizeLockHandler([&](const GridGeometry& g) { asked.push_back(g); });
  const GridGeometry map(20, 5, 0.05, 1.0, 2.0);
  lc.lockSizeTo(map);
  ASSERT_EQ(asked.size(), 1u);
  EXPECT_EQ(asked[0], map);
  EXPECT_EQ(lc.costmap().geometry(), start);  // the handler's host resizes, not this one
}

TEST(LayeredCostmapRolling, TheOriginFollowsTheRobotByCostmap2dsRule) {
  // costmap_2d: new origin = robot - (cells - 0.5) * resolution / 2, shifted by whole cells
  // truncated toward zero. A 200-cell window at 0.05 m around a robot at 0 lies at -4.95 (not
  // -5.00), as costmap_2d's does; the same poses give the same cells.
  LayeredCostmap lc("odom", false);
  lc.setRollingWindow(true);
  lc.resizeMap(GridGeometry(200, 200, 0.05, 0.0, 0.0));
  const auto origin = [&lc] {
    return std::make_pair(lc.costmap().geometry().originX(), lc.costmap().geometry().originY());
  };
  lc.updateMap(0.0, 0.0, 0.0);
  EXPECT_NEAR(origin().first, -4.95, 1e-9);
  EXPECT_NEAR(origin().second, -4.95, 1e-9);
  lc.updateMap(0.03, 0.03, 0.0);  // (0.03 - 4.9875 + 4.95) / 0.05 = -0.15 cells: no shift
  EXPECT_NEAR(origin().first, -4.95, 1e-9);
  EXPECT_NEAR(origin().second, -4.95, 1e-9);
  lc.updateMap(0.1, -0.1, 0.0);  // +1.25 cells -> 1, and -2.75 cells -> -2 (toward zero)
  EXPECT_NEAR(origin().first, -4.90, 1e-9);
  EXPECT_NEAR(origin().second, -5.05, 1e-9);
  // Without a robot pose the window stays where it is.
  lc.updateMap(5.0, 5.0, 0.0, false);
  EXPECT_NEAR(origin().first, -4.90, 1e-9);
}
