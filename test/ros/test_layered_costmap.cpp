// LayeredCostmap::lockSizeTo(): a static map fixes the master's geometry (costmap_2d's
// size_locked), or hands the request to the host that owns the real master (the costmap_2d
// adapter). Needs no ROS master (no layers, so no NodeHandles).
#include <gtest/gtest.h>

#include <vector>

#include "downstream_perception/layered_costmap.h"

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
