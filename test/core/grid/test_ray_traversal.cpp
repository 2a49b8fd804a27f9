#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/core/grid/ray_traversal.h"

using namespace downstream_perception;  // NOLINT

namespace {
std::vector<std::pair<int, int>> pairs(const std::vector<CellIndex>& cells) {
  std::vector<std::pair<int, int>> out;
  for (const auto& c : cells) out.emplace_back(c.x, c.y);
  return out;
}

// Whether the segment passes through cell (cx, cy) grown by `margin` cells, in grid units. The
// walker decides on fixed-point coordinates (2^-20 cell), so a segment passing within ~1e-6 cell
// of a corner may take the other side of that corner: a margin of 1e-5 cell (0.5 um at 5 cm)
// accepts exactly that and nothing more.
bool segmentCrossesCell(double x0, double y0, double x1, double y1, int cx, int cy,
                        double margin = 1e-5) {
  double t0 = 0.0;
  double t1 = 1.0;
  const double dx = x1 - x0;
  const double dy = y1 - y0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {x0 - cx + margin, cx + 1 + margin - x0, y0 - cy + margin,
                       cy + 1 + margin - y0};
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0.0) {
      if (q[k] <= 0.0) return false;
      continue;
    }
    const double t = q[k] / p[k];
    if (p[k] < 0)
      t0 = std::max(t0, t);
    else
      t1 = std::min(t1, t);
  }
  return t1 - t0 > 0.0;
}
}  // namespace

TEST(Bresenham, LessonGoldenLine) {
  const auto cells = pairs(bresenhamLine(2, 2, 7, 5));
  const std::vector<std::pair<int, int>> expected = {{2, 2}, {3, 3}, {4, 3},
                                                     {5, 4}, {6, 4}, {7, 5}};
  EXPECT_EQ(cells, expected);
}

TEST(Bresenham, EndpointsIncludedAndConnected) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> d(-50, 50);
  for (int n = 0; n < 2000; ++n) {
    const int x0 = d(rng), y0 = d(rng), x1 = d(rng), y1 = d(rng);
    const auto cells = bresenhamLine(x0, y0, x1, y1);
    ASSERT_EQ(cells.front().x, x0);
    ASSERT_EQ(cells.front().y, y0);
    ASSERT_EQ(cells.back().x, x1);
    ASSERT_EQ(cells.back().y, y1);
    ASSERT_EQ(cells.size(),
              static_cast<size_t>(std::max(std::abs(x1 - x0), std::abs(y1 - y0))) + 1);
    for (size_t i = 1; i < cells.size(); ++i) {
      ASSERT_LE(std::abs(cells[i].x - cells[i - 1].x), 1);
      ASSERT_LE(std::abs(cells[i].y - cells[i - 1].y), 1);
    }
  }
}

TEST(TraverseRay, GoldenLineThroughCellCentresVisitsEveryCrossedCell) {
  // The same beam as the Bresenham example, from the centre of (2,2) to the centre of (7,5), in a
  // 1 m grid. It really crosses 8 cells; Bresenham lists 6 and skips 2. At x = 5 it passes
  // exactly through the corner (5, 4): (5, 3) and (4, 4) are touched at that point only, so
  // neither is crossed (an x-first tie-break used to list (5, 3)).
  const GridGeometry g(20, 20, 1.0, 0.0, 0.0);
  const auto cells = pairs(rayCells(g, 2.5, 2.5, 7.5, 5.5));
  const std::vector<std::pair<int, int>> expected = {{2, 2}, {3, 2}, {3, 3}, {4, 3},
                                                     {5, 4}, {6, 4}, {6, 5}, {7, 5}};
  EXPECT_EQ(cells, expected);
  // Every Bresenham cell except the corner-adjacent ones is on the exact path.
  for (const auto& c : bresenhamLine(2, 2, 7, 5)) {
    const bool on_path =
        std::find(cells.begin(), cells.end(), std::make_pair(c.x, c.y)) != cells.end();
    EXPECT_TRUE(on_path) << c.x << "," << c.y;
  }
}

TEST(TraverseRay, DiagonalHasNoGapsAndNoRepeats) {
  const GridGeometry g(100, 100, 0.05, -2.5, -2.5);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-2.49, 2.49);
  for (int n = 0; n < 3000; ++n) {
    const double x0 = u(rng), y0 = u(rng), x1 = u(rng), y1 = u(rng);
    const auto cells = rayCells(g, x0, y0, x1, y1);
    ASSERT_FALSE(cells.empty());
    // Starts in the start cell, ends in the end cell.
    EXPECT_EQ(cells.front(), g.worldToCellUnbounded(x0, y0));
    EXPECT_EQ(cells.back(), g.worldToCellUnbounded(x1, y1));
    std::set<std::pair<int, int>> unique;
    for (size_t i = 0; i < cells.size(); ++i) {
      ASSERT_TRUE(unique.insert({cells[i].x, cells[i].y}).second) << "cell visited twice";
      if (i > 0) {  // 4-connected: exactly one axis steps by one
        ASSERT_EQ(std::abs(cells[i].x - cells[i - 1].x) + std::abs(cells[i].y - cells[i - 1].y), 1);
      }
    }
    // Every visited cell is really crossed (in grid units), and the count matches the exact
    // number of crossed cells: |dx cells| + |dy cells| + 1.
    const double gx0 = (x0 + 2.5) / 0.05, gy0 = (y0 + 2.5) / 0.05;
    const double gx1 = (x1 + 2.5) / 0.05, gy1 = (y1 + 2.5) / 0.05;
    for (const auto& c : cells) {
      EXPECT_TRUE(segmentCrossesCell(gx0, gy0, gx1, gy1, c.x, c.y) || c == cells.front() ||
                  c == cells.back());
    }
    const int expected =
        std::abs(static_cast<int>(std::floor(gx1)) - static_cast<int>(std::floor(gx0))) +
        std::abs(static_cast<int>(std::floor(gy1)) - static_cast<int>(std::floor(gy0))) + 1;
    EXPECT_EQ(static_cast<int>(cells.size()), expected);
  }
}

TEST(TraverseRay, ExcludingEndAndAxisAlignedAndDegenerate) {
  const GridGeometry g(10, 10, 1.0, 0.0, 0.0);
  EXPECT_EQ(rayCells(g, 0.5, 0.5, 4.5, 0.5, false).size(), 4u);  // (0..3, 0)
  EXPECT_EQ(rayCells(g, 4.5, 0.5, 0.5, 0.5, true).size(), 5u);
  EXPECT_EQ(rayCells(g, 0.5, 4.5, 0.5, 0.5, true).back().y, 0);
  EXPECT_EQ(rayCells(g, 3.2, 3.7, 3.8, 3.1, true).size(), 1u);  // same cell
  EXPECT_TRUE(rayCells(g, 3.2, 3.7, 3.8, 3.1, false).empty());
}

TEST(ClipSegment, ClipsToGridAndRejectsMisses) {
  const GridGeometry g(10, 10, 1.0, 0.0, 0.0);
  double x0 = -5, y0 = 5.5, x1 = 15, y1 = 5.5;
  bool sc = false, ec = false;
  ASSERT_TRUE(clipSegmentToGrid(g, &x0, &y0, &x1, &y1, &sc, &ec));
  EXPECT_TRUE(sc);
  EXPECT_TRUE(ec);
  EXPECT_NEAR(x0, 0.0, 1e-5);
  EXPECT_NEAR(x1, 10.0, 1e-5);
  EXPECT_LT(x1, 10.0);  // inside the last cell
  double a = -5, b = -5, c = -1, d = 20;
  EXPECT_FALSE(clipSegmentToGrid(g, &a, &b, &c, &d));
  double n0 = std::nan(""), n1 = 0, n2 = 1, n3 = 1;
  EXPECT_FALSE(clipSegmentToGrid(g, &n0, &n1, &n2, &n3));
  // A segment leaving from outside and ending inside: the whole crossed part is walked.
  const auto cells = rayCells(g, -3.0, 0.5, 2.5, 0.5);
  ASSERT_EQ(cells.size(), 3u);
  EXPECT_EQ(cells.front().x, 0);
}

// The walker has no per-axis guards: it relies on exact fixed-point arithmetic to end in the end
// cell. End points on cell edges and corners, axis-parallel segments lying on an edge, and every
// direction are where a wrong tie-break would step out of the box (and out of the grid).
TEST(TraverseRay, EndpointsOnEdgesAndCornersEndInTheEndCell) {
  // Binary-exact resolutions, so the lattice points lie exactly on edges in double as well (at
  // 0.05 m a point "on" an edge is 1e-16 m off it, and which side it falls is rounding).
  for (const double res : {1.0, 0.25, 0.0625}) {
    const GridGeometry g(40, 40, res, -1.0, 3.0);
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> lattice(2, 76);  // half-cell lattice inside the grid
    for (int n = 0; n < 20000; ++n) {
      const int a = lattice(rng), b = lattice(rng), c = lattice(rng);
      const int d = n % 3 == 0 ? b : lattice(rng);  // a third lie on one horizontal line
      const double x0 = -1.0 + 0.5 * a * res, y0 = 3.0 + 0.5 * b * res;
      const double x1 = -1.0 + 0.5 * c * res, y1 = 3.0 + 0.5 * d * res;
      const auto cells = rayCells(g, x0, y0, x1, y1);
      ASSERT_FALSE(cells.empty());
      ASSERT_EQ(cells.front(), g.worldToCellUnbounded(x0, y0));
      ASSERT_EQ(cells.back(), g.worldToCellUnbounded(x1, y1))
          << x0 << "," << y0 << " -> " << x1 << "," << y1;
      for (std::size_t i = 0; i < cells.size(); ++i) {
        ASSERT_TRUE(g.inBounds(cells[i].x, cells[i].y));
        if (i == 0) continue;
        const int step_x = cells[i].x - cells[i - 1].x;
        const int step_y = cells[i].y - cells[i - 1].y;
        ASSERT_TRUE(std::abs(step_x) <= 1 && std::abs(step_y) <= 1 && (step_x | step_y) != 0);
        if (step_x != 0 && step_y != 0) {
          // A diagonal step only where the segment passes exactly through the corner the two
          // cells share (exact in integers: in half cells from the grid's origin the ends are
          // (a, b) and (c, d), the corner is at twice its cell coordinates).
          const long corner_x = 2L * std::max(cells[i].x, cells[i - 1].x);
          const long corner_y = 2L * std::max(cells[i].y, cells[i - 1].y);
          const long ax = a, ay = b, bx = c, by = d;
          ASSERT_EQ((corner_x - ax) * (by - ay) - (corner_y - ay) * (bx - ax), 0)
              << "diagonal step off a corner: " << x0 << "," << y0 << " -> " << x1 << "," << y1;
        }
      }
    }
  }
}
