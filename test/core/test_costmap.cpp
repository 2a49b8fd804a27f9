#include <gtest/gtest.h>

#include "downstream_perception/core/cost_values.h"
#include "downstream_perception/core/costmap.h"

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
