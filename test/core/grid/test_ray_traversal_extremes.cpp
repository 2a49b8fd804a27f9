// Ray traversal at the extremes (issue 17): far-away sensors, non-finite ends, rays along the
// grid's edges, huge grids and extreme integers never leave the grid or overflow.
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
// Every cell in the grid, 8-connected (a diagonal step is a corner passed exactly), none twice:
// what the scan integrator's pointer walk relies on (a cell outside the grid is a read and write
// past the cell array).
void expectWalkInGrid(const GridGeometry& g, const std::vector<CellIndex>& cells,
                      const std::string& what) {
  std::set<std::pair<int, int>> unique;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    ASSERT_TRUE(g.inBounds(cells[i].x, cells[i].y))
        << what << ": cell " << i << " (" << cells[i].x << ", " << cells[i].y << ") is outside";
    ASSERT_TRUE(unique.insert({cells[i].x, cells[i].y}).second) << what << ": cell visited twice";
    if (i > 0) {
      const int step_x = std::abs(cells[i].x - cells[i - 1].x);
      const int step_y = std::abs(cells[i].y - cells[i - 1].y);
      ASSERT_TRUE(step_x <= 1 && step_y <= 1 && step_x + step_y > 0) << what;
    }
  }
}
}  // namespace

// Issue 17 item 4: with the sensor far away, sx + t0 * dx cancels catastrophically and the clipped
// start landed a cell (at 1e12 m) to dozens of cells (at 1e18 m) outside the grid.
TEST(ClipSegment, FarAwaySensorNeverLeavesTheGrid) {
  const GridGeometry g(200, 200, 0.05, -5.0, -5.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const double far : {1e6, 1e12, 1e15, 1e18, 1e20, 1e300}) {
    for (int n = 0; n < 3000; ++n) {
      const double a = M_PI * unit(rng);
      const double sx = far * std::cos(a), sy = far * std::sin(a);
      const double tx = 4.9 * unit(rng), ty = 4.9 * unit(rng);  // a target inside the grid
      const auto in = rayCells(g, sx, sy, tx, ty);
      ASSERT_FALSE(in.empty());
      expectWalkInGrid(g, in, "sensor at " + std::to_string(far) + " m");
      ASSERT_EQ(in.back(), g.worldToCellUnbounded(tx, ty));  // the unclipped end is exact
      expectWalkInGrid(g, rayCells(g, tx, ty, sx, sy), "toward " + std::to_string(far) + " m");
      // Both ends far away, on opposite sides.
      expectWalkInGrid(g, rayCells(g, sx, sy, -sx + tx, -sy + ty), "through the grid");
    }
  }
  // A segment from -1e18 to 1e18 along a row crosses the whole row (t0 == t1 in double: the
  // clipped ends are put on the edges they were moved to, not computed from t).
  const auto row = rayCells(g, -1e18, 0.32, 1e18, 0.32);
  ASSERT_EQ(row.size(), 200u);
  expectWalkInGrid(g, row, "row");
  EXPECT_EQ(row.front().x, 0);
  EXPECT_EQ(row.back().x, 199);
  EXPECT_EQ(row.front().y, g.worldToCellUnbounded(0.0, 0.32).y);
}

TEST(ClipSegment, NonFiniteEndsGiveNoCells) {
  const GridGeometry g(20, 20, 0.5, 0.0, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {nan, inf, -inf}) {
    EXPECT_TRUE(rayCells(g, bad, 1.0, 2.0, 2.0).empty());
    EXPECT_TRUE(rayCells(g, 1.0, bad, 2.0, 2.0).empty());
    EXPECT_TRUE(rayCells(g, 1.0, 1.0, bad, 2.0).empty());
    EXPECT_TRUE(rayCells(g, 1.0, 1.0, 2.0, bad).empty());
  }
}

TEST(ClipSegment, RaysAlongTheGridEdgesStayInside) {
  const GridGeometry g(30, 20, 0.1, -1.0, 2.0);
  const double x_lo = -1.0, x_hi = 2.0, y_lo = 2.0, y_hi = 4.0;
  const double offsets[] = {-1e-3, -1e-9, 0.0, 1e-9, 1e-3};
  for (const double o : offsets) {
    for (const double far : {5.0, 1e18}) {
      expectWalkInGrid(g, rayCells(g, x_lo - far, y_lo + o, x_hi + far, y_lo + o), "bottom");
      expectWalkInGrid(g, rayCells(g, x_hi + far, y_hi + o, x_lo - far, y_hi + o), "top");
      expectWalkInGrid(g, rayCells(g, x_lo + o, y_lo - far, x_lo + o, y_hi + far), "left");
      expectWalkInGrid(g, rayCells(g, x_hi + o, y_hi + far, x_hi + o, y_lo - far), "right");
      expectWalkInGrid(g, rayCells(g, x_lo - far, y_lo - far, x_hi + far, y_hi + far), "diag");
    }
  }
  // Just inside the bottom and left edges the whole row / column is crossed.
  EXPECT_EQ(rayCells(g, x_lo - 5.0, y_lo + 1e-3, x_hi + 5.0, y_lo + 1e-3).size(), 30u);
  EXPECT_EQ(rayCells(g, x_lo + 1e-3, y_lo - 5.0, x_lo + 1e-3, y_hi + 5.0).size(), 20u);
}

TEST(ClipSegment, HugeAndExtremeGridsStayInside) {
  // Origin 1e17 m: a double's step there (16 m) is larger than the grid (10 m), so even clipped
  // coordinates round outside it; the walker clamps its fixed-point ends.
  const GridGeometry far_origin(200, 200, 0.05, 1e17, -5.0);
  const auto far_cells = rayCells(far_origin, 1e17 - 100.0, 0.0, 1e17 + 100.0, 0.0);
  expectWalkInGrid(far_origin, far_cells, "origin 1e17");
  // The longest axis a grid may have, walked end to end (the fixed-point products reach 2^62).
  const int longest = GridGeometry::kMaxCellsPerAxis;
  const GridGeometry long_grid(longest, 64, 1.0, 0.0, 0.0);
  const auto along = rayCells(long_grid, -10.0, 0.5, longest + 10.0, 63.5);
  // Every crossing is walked: one cell per crossing, except a corner (both edges in one diagonal
  // step). This line passes exactly through lattice corners, e.g. (233008, 4): 7 (x + 10) =
  // (2k - 1) * 233018 has integer solutions.
  std::size_t diagonals = 0;
  for (std::size_t i = 1; i < along.size(); ++i) {
    diagonals += along[i].x != along[i - 1].x && along[i].y != along[i - 1].y;
  }
  EXPECT_GE(diagonals, 1u);
  EXPECT_EQ(along.size() + diagonals, static_cast<std::size_t>(longest) + 63);
  EXPECT_EQ(along.back(), (CellIndex{longest - 1, 63}));
  for (const CellIndex& c : along) ASSERT_TRUE(long_grid.inBounds(c.x, c.y));
  // Resolutions at both ends of the doubles.
  const GridGeometry tiny(50, 50, 5e-324, 0.0, 0.0);
  expectWalkInGrid(tiny, rayCells(tiny, -1.0, -1.0, 1.0, 1.0), "5e-324 m cells");
  EXPECT_THROW(GridGeometry(50, 50, 1e300, 0.0, 0.0), std::invalid_argument);
  const GridGeometry huge(50, 50, GridGeometry::kMaxResolutionM, -1e15, -1e15);
  expectWalkInGrid(huge, rayCells(huge, -1e308, 0.0, 1e308, 1e300), "1000 m cells");
}

TEST(TraverseRay, UnclippedOutOfGridInputStaysInside) {
  // traverseRay expects a clipped segment, but whatever it gets it must not leave the grid (and
  // must not cast an out-of-range double to an integer).
  const GridGeometry g(10, 10, 1.0, 0.0, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double cases[][4] = {{-5.0, 5.5, 15.0, 5.5},
                             {nan, 1.0, 3.0, 3.0},
                             {1e300, -1e300, 2.0, 2.0},
                             {-3.0, -3.0, 30.0, 12.0}};
  for (const auto& c : cases) {
    std::vector<CellIndex> cells;
    traverseRay(g, c[0], c[1], c[2], c[3], true, [&cells](int x, int y) {
      cells.push_back({x, y});
    });
    ASSERT_FALSE(cells.empty());
    expectWalkInGrid(g, cells, "unclipped");
  }
}

TEST(Bresenham, ExtremeIntsDoNotOverflow) {
  // x1 - x0 of INT_MIN and INT_MAX does not fit in an int: with int arithmetic the deltas
  // wrapped (undefined behaviour) and the line went diagonal at once. The first cells of a line
  // 2^32 cells long and 1 cell high stay on its first row.
  const int lo = std::numeric_limits<int>::min();
  const int hi = std::numeric_limits<int>::max();
  struct Enough {};
  std::vector<CellIndex> first;
  try {
    bresenham(lo, 0, hi, 1, [&first](int x, int y) {
      first.push_back({x, y});
      if (first.size() == 8) throw Enough{};
    });
  } catch (const Enough&) {
  }
  ASSERT_EQ(first.size(), 8u);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(first[i], (CellIndex{lo + i, 0}));
  // Short lines at the ends of the range are exact; over-long ones are refused.
  const auto end = bresenhamLine(hi - 2, lo, hi, lo + 1);
  ASSERT_EQ(end.size(), 3u);
  EXPECT_EQ(end.back(), (CellIndex{hi, lo + 1}));
  EXPECT_THROW(bresenhamLine(lo, 0, hi, 0), std::invalid_argument);
  EXPECT_THROW(bresenhamLine(0, lo, 0, hi), std::invalid_argument);
  EXPECT_THROW(bresenhamLine(0, 0, GridGeometry::kMaxCellsPerAxis, 0), std::invalid_argument);
  EXPECT_EQ(bresenhamLine(0, 0, GridGeometry::kMaxCellsPerAxis - 1, 0).size(),
            static_cast<std::size_t>(GridGeometry::kMaxCellsPerAxis));
}
