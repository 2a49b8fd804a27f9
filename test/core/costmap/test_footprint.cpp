#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/core/costmap/footprint.h"

using namespace downstream_perception;  // NOLINT

TEST(Footprint, SquareRadiiMatchTheAnchorScenario) {
  // costmap_2d's benchmark footprint: square +-0.25 m -> inscribed 0.25, circumscribed 0.3536.
  const Footprint square = {{0.25, 0.25}, {-0.25, 0.25}, {-0.25, -0.25}, {0.25, -0.25}};
  EXPECT_TRUE(validateFootprint(square).empty());
  EXPECT_NEAR(inscribedRadius(square), 0.25, 1e-12);
  EXPECT_NEAR(circumscribedRadius(square), 0.353553, 1e-6);
  const Footprint padded = padFootprint(square, 0.05);
  EXPECT_NEAR(inscribedRadius(padded), 0.30, 1e-12);
}

TEST(Footprint, OffCentreRectangleAndCircle) {
  // A 1.0 x 0.6 m robot whose base_link sits 0.2 m behind the centre.
  const Footprint rect = {{0.7, 0.3}, {-0.3, 0.3}, {-0.3, -0.3}, {0.7, -0.3}};
  EXPECT_NEAR(inscribedRadius(rect), 0.3, 1e-12);
  EXPECT_NEAR(circumscribedRadius(rect), std::hypot(0.7, 0.3), 1e-12);
  const Footprint circle = circularFootprint(0.46);
  EXPECT_EQ(circle.size(), 16u);
  EXPECT_NEAR(circumscribedRadius(circle), 0.46, 1e-12);
  EXPECT_NEAR(inscribedRadius(circle), 0.46 * std::cos(M_PI / 16), 1e-12);
}

TEST(Footprint, RejectsDegenerateOrAbsurdPolygons) {
  EXPECT_FALSE(validateFootprint({{0, 0}, {1, 0}}).empty());
  EXPECT_FALSE(validateFootprint({{0, 0}, {1, 0}, {NAN, 1}}).empty());
  EXPECT_FALSE(validateFootprint({{0, 0}, {1e6, 0}, {0, 1}}).empty());
}

TEST(Footprint, PolygonCellsOfAnAlignedSquare) {
  // A 0.6 m square centred on a cell corner at 5 cm covers exactly 12 x 12 cell centres.
  const GridGeometry g(100, 100, 0.05, 0.0, 0.0);
  const Footprint square = {{0.3, 0.3}, {-0.3, 0.3}, {-0.3, -0.3}, {0.3, -0.3}};
  std::vector<std::size_t> cells;
  const CellBounds b = polygonCells(transformFootprint(square, Pose2D{2.5, 2.5, 0.0}), g, &cells);
  EXPECT_EQ(cells.size(), 144u);
  EXPECT_EQ(b.min_x, 44);
  EXPECT_EQ(b.max_x, 55);
  EXPECT_EQ(b.min_y, 44);
  EXPECT_EQ(b.max_y, 55);
}

TEST(Footprint, PolygonCellsRotatedClippedAndConcave) {
  const GridGeometry g(100, 100, 0.05, 0.0, 0.0);
  const Footprint square = {{0.3, 0.3}, {-0.3, 0.3}, {-0.3, -0.3}, {0.3, -0.3}};
  // Rotated 45 deg: a diamond of half-diagonal 0.424 m; every chosen centre is inside.
  std::vector<std::size_t> cells;
  const Footprint diamond = transformFootprint(square, Pose2D{2.5, 2.5, M_PI / 4});
  polygonCells(diamond, g, &cells);
  const double area_cells = 0.36 / (0.05 * 0.05);  // 144
  EXPECT_NEAR(static_cast<double>(cells.size()), area_cells, 0.1 * area_cells);
  for (const std::size_t i : cells) {
    const CellIndex c = g.cellOf(i);
    double x = 0.0, y = 0.0;
    g.cellCentre(c.x, c.y, &x, &y);
    EXPECT_LE(std::abs(x - 2.5) + std::abs(y - 2.5), 0.3 * std::sqrt(2.0) + 1e-9);
  }
  // Clipped at the grid's corner: only the quarter inside the grid.
  cells.clear();
  polygonCells(transformFootprint(square, Pose2D{0.0, 0.0, 0.0}), g, &cells);
  EXPECT_EQ(cells.size(), 36u);
  // Entirely outside: nothing, empty window.
  cells.clear();
  EXPECT_TRUE(polygonCells(transformFootprint(square, Pose2D{-5.0, 2.0, 0.0}), g, &cells).empty());
  EXPECT_TRUE(cells.empty());
  // A concave "U" (even-odd rule): the notch stays out.
  const Footprint u = {{0.0, 0.0}, {0.6, 0.0}, {0.6, 0.6}, {0.4, 0.6},
                       {0.4, 0.2}, {0.2, 0.2}, {0.2, 0.6}, {0.0, 0.6}};
  cells.clear();
  polygonCells(transformFootprint(u, Pose2D{1.0, 1.0, 0.0}), g, &cells);
  EXPECT_EQ(cells.size(), 144u - 4u * 8u);  // 12 x 12 minus the 4 x 8 notch
  // Non-finite vertices: nothing.
  cells.clear();
  Footprint bad = square;
  bad[1].x = std::nan("");
  EXPECT_TRUE(polygonCells(bad, g, &cells).empty());
}

TEST(FootprintPadding, ACoordinateThatIsExactlyZeroStaysZero) {
  // costmap_2d's sign0: (0.46, 0) padded by 0.01 is (0.47, 0), not (0.47, 0.01).
  const Footprint padded = padFootprint({{0.46, 0.0}, {0.0, -0.3}, {-0.2, 0.25}}, 0.01);
  EXPECT_DOUBLE_EQ(padded[0].x, 0.47);
  EXPECT_DOUBLE_EQ(padded[0].y, 0.0);
  EXPECT_DOUBLE_EQ(padded[1].x, 0.0);
  EXPECT_DOUBLE_EQ(padded[1].y, -0.31);
  EXPECT_DOUBLE_EQ(padded[2].x, -0.21);
  EXPECT_DOUBLE_EQ(padded[2].y, 0.26);
}

TEST(FootprintString, ParsesCostmap2dSyntax) {
  std::string error;
  const Footprint f =
      parseFootprintString("[[0.3, -0.25],[0.3,0.25], [-.3, 0.25],\t[-0.3,-2e-1]]", &error);
  EXPECT_EQ(error, "");
  ASSERT_EQ(f.size(), 4u);
  EXPECT_DOUBLE_EQ(f[2].x, -0.3);
  EXPECT_DOUBLE_EQ(f[3].y, -0.2);
}

TEST(FootprintString, RefusesWhatCostmap2dRefuses) {
  // Each of these is an error in costmap_2d's parser; ours used to accept the first two.
  const std::vector<std::pair<std::string, std::string>> cases{
      {"[1, 2.2], [.3, -4], [0, 1]]", "outside a point"},
      {"[[1,2,3],[4,5,6]]", "at least 3 points, got 2"},
      {"[[1,2,3],[4,5,6],[7,8,9]]", "point 1 has 3 numbers"},
      {"[[[1,2],[3,4],[5,6]]]", "nested deeper"},
      {"[[1,2],[3,4],[5,6]]]", "more ']' than '['"},
      {"[[1,2],[3,4],[5,6]", "unterminated"},
      {"[[1,2],[3,x],[5,6]]", "'x' is not part of a number"},
  };
  for (const auto& c : cases) {
    std::string error;
    const Footprint f = parseFootprintString(c.first, &error);
    EXPECT_TRUE(f.empty()) << c.first;
    EXPECT_NE(error.find(c.second), std::string::npos) << c.first << " -> " << error;
  }
}
