#include <gtest/gtest.h>

#include <cmath>

#include <limits>
#include <stdexcept>

#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/core/grid/costmap.h"

using namespace downstream_perception;  // NOLINT

TEST(CostValues, OccupancyTranslationMatchesCostmap2d) {
  EXPECT_EQ(cost::toOccupancyValue(0), 0);
  EXPECT_EQ(cost::toOccupancyValue(253), 99);
  EXPECT_EQ(cost::toOccupancyValue(254), 100);
  EXPECT_EQ(cost::toOccupancyValue(255), -1);
  EXPECT_EQ(cost::toOccupancyValue(1), 1);
  EXPECT_EQ(cost::toOccupancyValue(252), 1 + 97 * 251 / 251);
  const auto table = cost::occupancyTable();
  for (int c = 1; c < 253; ++c) {
    EXPECT_GE(table[c], 1);
    EXPECT_LE(table[c], 98);
    if (c > 1) {
      EXPECT_GE(table[c], table[c - 1]);
    }
  }
}

TEST(Costmap, ResetWindowAndShift) {
  Costmap m(GridGeometry(5, 4, 1.0, 0, 0), cost::kNoInformation);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) m.setCost(x, y, static_cast<std::uint8_t>(10 * y + x));
  CellBounds w;
  w.expand(1, 1);
  w.expand(2, 7);  // clamped to the grid
  m.resetWindow(w);
  EXPECT_EQ(m.cost(1, 3), cost::kNoInformation);
  EXPECT_EQ(m.cost(0, 3), 30);
  EXPECT_EQ(m.cost(3, 1), 13);
  m.shift(-1, 2);  // origin moves -1 cell in x, +2 in y
  EXPECT_DOUBLE_EQ(m.geometry().originX(), -1.0);
  EXPECT_DOUBLE_EQ(m.geometry().originY(), 2.0);
  EXPECT_EQ(m.cost(1, 0), 20);                    // old (0, 2)
  EXPECT_EQ(m.cost(4, 1), 33);                    // old (3, 3)
  EXPECT_EQ(m.cost(0, 0), cost::kNoInformation);  // newly exposed column
  EXPECT_EQ(m.cost(2, 3), cost::kNoInformation);  // newly exposed rows
}

// Issue 17 item 8: size + shift overflowed an int for a shift of 2^31 - 1 (undefined behaviour;
// UBSan reports it). Any shift of at least the grid's size drops everything.
TEST(Costmap, ExtremeShiftsDropEverythingWithoutOverflow) {
  const int int_max = std::numeric_limits<int>::max();
  const int int_min = std::numeric_limits<int>::min();
  for (const int d : {int_max, int_min, -int_max, int_max - 4, int_min + 4, 1 << 30, 5, -5}) {
    for (const bool along_x : {true, false}) {
      Costmap m(GridGeometry(5, 4, 0.5, 0.0, 0.0), cost::kNoInformation);
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 5; ++x) m.setCost(x, y, cost::kLethalObstacle);
      m.shift(along_x ? d : 0, along_x ? 0 : d);
      for (const std::uint8_t c : m.cells()) ASSERT_EQ(c, cost::kNoInformation) << d;
      EXPECT_DOUBLE_EQ(along_x ? m.geometry().originX() : m.geometry().originY(), 0.5 * d);
    }
  }
  // Cells so large that a shift could push the origin past the doubles are refused up front;
  // the largest allowed cell shifted by the largest int stays finite.
  EXPECT_THROW(GridGeometry(3, 3, 1e300, 0.0, 0.0), std::invalid_argument);
  Costmap big(GridGeometry(3, 3, GridGeometry::kMaxResolutionM, 0.0, 0.0), cost::kFreeSpace);
  big.setCost(1, 1, cost::kLethalObstacle);
  big.shift(int_max, 0);
  EXPECT_TRUE(std::isfinite(big.geometry().originX()));
  for (const std::uint8_t c : big.cells()) EXPECT_EQ(c, cost::kFreeSpace);  // the fill value
}
