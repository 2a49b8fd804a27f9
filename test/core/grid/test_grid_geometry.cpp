#include <gtest/gtest.h>

#include <stdexcept>

#include "downstream_perception/core/grid/grid_geometry.h"

using downstream_perception::CellIndex;
using downstream_perception::GridGeometry;

TEST(GridGeometry, LessonWorkedExampleFloorsToCell20) {
  // Robot at (2, 5), beam along +x with r = 3.2 m, 0.25 m cells: endpoint (5.2, 5.0) -> (20, 20).
  const GridGeometry g(100, 100, 0.25, 0.0, 0.0);
  CellIndex c;
  ASSERT_TRUE(g.worldToCell(2.0 + 3.2, 5.0, &c));
  EXPECT_EQ(c.x, 20);
  EXPECT_EQ(c.y, 20);
}

TEST(GridGeometry, EndpointOnCellEdgeBelongsToTheNextCell) {
  const GridGeometry g(100, 100, 0.25, 0.0, 0.0);
  CellIndex c;
  ASSERT_TRUE(g.worldToCell(5.25, 0.1, &c));
  EXPECT_EQ(c.x, 21);  // not 20: the classic off-by-one at a cell edge
}

TEST(GridGeometry, NegativeCoordinatesFloorTowardMinusInfinity) {
  const GridGeometry g(100, 100, 0.25, -10.0, -10.0);
  EXPECT_EQ(g.worldToCellUnbounded(-0.1, -0.1).x, 39);  // (-0.1 + 10) / 0.25 = 39.6
  const GridGeometry h(10, 10, 1.0, 0.0, 0.0);
  EXPECT_EQ(h.worldToCellUnbounded(-0.5, 0.0).x, -1);  // truncation would say 0
  CellIndex c;
  EXPECT_FALSE(h.worldToCell(-0.5, 0.0, &c));
}

TEST(GridGeometry, BoundsAndNonFinite) {
  const GridGeometry g(10, 20, 0.5, 1.0, 2.0);
  CellIndex c;
  EXPECT_TRUE(g.worldToCell(1.0, 2.0, &c));
  EXPECT_FALSE(g.worldToCell(6.0, 2.0, &c));  // x = 1 + 10 * 0.5 is the first cell outside
  EXPECT_TRUE(g.worldToCell(5.999, 11.999, &c));
  EXPECT_EQ(c.x, 9);
  EXPECT_EQ(c.y, 19);
  EXPECT_FALSE(g.worldToCell(std::nan(""), 3.0, &c));
  EXPECT_FALSE(g.worldToCell(1e300, 3.0, &c));
  double wx = 0;
  double wy = 0;
  g.cellCentre(0, 0, &wx, &wy);
  EXPECT_DOUBLE_EQ(wx, 1.25);
  EXPECT_DOUBLE_EQ(wy, 2.25);
  EXPECT_EQ(g.index(3, 2), 23u);
  EXPECT_EQ(g.cellOf(23).x, 3);
  EXPECT_EQ(g.cellOf(23).y, 2);
}

TEST(GridGeometry, RejectsAbsurdParameters) {
  EXPECT_THROW(GridGeometry(0, 10, 0.05, 0, 0), std::invalid_argument);
  EXPECT_THROW(GridGeometry(10, 10, 0.0, 0, 0), std::invalid_argument);
  EXPECT_THROW(GridGeometry(10, 10, -1.0, 0, 0), std::invalid_argument);
  EXPECT_THROW(GridGeometry(10, 10, std::nan(""), 0, 0), std::invalid_argument);
  EXPECT_THROW(GridGeometry(100000, 100000, 0.05, 0, 0), std::invalid_argument);
  EXPECT_THROW(GridGeometry(10, 10, 0.05, std::numeric_limits<double>::infinity(), 0),
               std::invalid_argument);
  EXPECT_FALSE(GridGeometry::validate(0, 1, 0.05, 0, 0).empty());
  EXPECT_TRUE(GridGeometry::validate(1, 1, 0.05, 0, 0).empty());
}

TEST(GridGeometry, WorldBoxToCellsClamps) {
  const GridGeometry g(10, 10, 1.0, 0.0, 0.0);
  auto b = g.worldBoxToCells(-5.0, 2.5, 3.5, 50.0);
  EXPECT_EQ(b.min_x, 0);
  EXPECT_EQ(b.min_y, 2);
  EXPECT_EQ(b.max_x, 3);
  EXPECT_EQ(b.max_y, 9);
  EXPECT_TRUE(g.worldBoxToCells(20.0, 20.0, 30.0, 30.0).empty());
}
