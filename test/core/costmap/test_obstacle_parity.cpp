// costmap_2d's obstacle-layer unit-test scenarios (costmap_2d/test/obstacle_tests.cpp), restated
// in our own words on our core (cloud beams -> scan integrator -> log-odds grid); the
// rolling-window wall of issue 18 item 4 is in test_obstacle_rolling_window.cpp.
//
// The scenarios, as costmap_2d sets them up: a 10 x 10 grid of 1 m cells at the origin; one-point
// clouds with their sensor origin, obstacle and raytrace range 100 m, heights [0, 2] m; an
// optional static map of 20 lethal cells. Where our semantics differ on purpose:
//  * Log-odds: one observation is evidence, not a verdict. costmap_2d marks a cell LETHAL on one
//    hit and frees it on one pass; we need 3 hits (3 * 0.85 > 2) and 6 passes (6 * -0.41 < -2)
//    with the default model. costmap_2d's static observations are re-integrated on every
//    updateMap, so integrating the same observations kUpdates times is the same scenario.
//  * The static map is another layer: it is kept here as a set of cells and merged by max.
//  * Clearing walks the cells the segment crosses (Amanatides-Woo), costmap_2d walks Bresenham
//    between cell centres. On the scenarios' diagonals both give the same cells; elsewhere we
//    clear what the beam crosses (see WaveInterferenceInEveryDirection).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/core/costmap/cloud_beams.h"
#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/grid/grid_shift.h"
#include "downstream_perception/core/grid/ray_traversal.h"

using namespace downstream_perception;  // NOLINT

namespace {

constexpr double kMaxZ = 1.0;  // the scenarios' sensor height and "top" point height
constexpr int kUpdates = 6;    // enough for one hit to be occupied and one pass to be free

using Cell = std::pair<int, int>;

// costmap_2d's 10 x 10 test map: the 20 lethal cells (x, y) of its static layer.
std::set<Cell> staticLethal() {
  std::set<Cell> cells;
  for (int y : {0, 1, 5, 6, 7}) {
    for (int x = 7; x <= 9; ++x) cells.insert({x, y});
  }
  for (int x = 3; x <= 5; ++x) cells.insert({x, 2});
  cells.insert({4, 5});
  cells.insert({4, 6});
  return cells;
}

struct Observation {
  float x, y, z;      // the point (world)
  double ox, oy, oz;  // the sensor origin (world)
};

// One obstacle layer with costmap_2d's test settings, fed static observations.
struct ParityLayer {
  explicit ParityLayer(const GridGeometry& g) : grid(g) {
    ScanIntegratorConfig c;
    c.obstacle_max_range = 100.0;
    c.raytrace_max_range = 100.0;
    integrator = ScanIntegrator(c);
  }
  LogOddsGrid grid;
  ScanIntegrator integrator;
  std::vector<Observation> observations;

  void add(float x, float y, float z = 0.0f, double ox = 0.0, double oy = 0.0, double oz = kMaxZ) {
    observations.push_back({x, y, z, ox, oy, oz});
  }
  // One updateMap: every observation of the buffer, as one batch.
  void update() {
    std::vector<BeamUpdate> beams;
    IntegrationStats decisions;
    for (const Observation& o : observations) {
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() = Eigen::Vector3d(o.ox, o.oy, o.oz);
      // The point in the sensor frame: exact for the scenarios' (small, binary) coordinates.
      const float p[3] = {static_cast<float>(o.x - o.ox), static_cast<float>(o.y - o.oy),
                          static_cast<float>(o.z - o.oz)};
      beamsFromCloud(integrator, CloudBeamsConfig{}, reinterpret_cast<const unsigned char*>(p), 1,
                     sizeof(p), pose, &beams, &decisions);
    }
    integrator.integrate(grid, beams, decisions);
  }
  void updates(int n = kUpdates) {
    for (int i = 0; i < n; ++i) update();
  }
  std::set<Cell> cellsIn(CellState state) const {
    std::set<Cell> out;
    const GridGeometry& g = grid.geometry();
    for (int y = 0; y < g.sizeY(); ++y) {
      for (int x = 0; x < g.sizeX(); ++x) {
        if (grid.state(g.index(x, y)) == state) out.insert({x, y});
      }
    }
    return out;
  }
  // Lethal cells of the master: ours (occupied) merged with a static layer's.
  std::size_t lethalWith(const std::set<Cell>& static_cells) const {
    std::set<Cell> all = cellsIn(CellState::kOccupied);
    all.insert(static_cells.begin(), static_cells.end());
    return all.size();
  }
};

GridGeometry tenByTen() {
  return GridGeometry(10, 10, 1.0, 0.0, 0.0);
}

// Exact test in integers: does the segment (a, b) -> (c, d) cross the open square
// (x, x + 1) x (y, y + 1)? All coordinates in units of 1/scale cell.
bool crossesInterior(long a, long b, long c, long d, long x, long y, long scale) {
  // Liang-Barsky with strict inequalities, t kept as a fraction num / den (den > 0).
  long t0n = 0, t0d = 1, t1n = 1, t1d = 1;
  const long p[4] = {-(c - a), c - a, -(d - b), d - b};
  const long q[4] = {a - x * scale, (x + 1) * scale - a, b - y * scale, (y + 1) * scale - b};
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0) {
      if (q[k] <= 0) return false;  // parallel, on or outside the edge
      continue;
    }
    long n = q[k], den = p[k];
    if (den < 0) {
      n = -n;
      den = -den;
    }
    if (p[k] < 0) {  // entering: t > n / den
      if (n * t0d > t0n * den) t0n = n, t0d = den;
    } else {  // leaving: t < n / den
      if (n * t1d < t1n * den) t1n = n, t1d = den;
    }
  }
  return t0n * t1d < t1n * t0d;
}

}  // namespace

// costmap_2d testRaytracing: a point at the sensor's own position (zero range) marks its cell:
// 20 static + 1 lethal.
TEST(ObstacleParity, PointAtTheSensorMarksItsCell) {
  ParityLayer layer(tenByTen());
  layer.add(0.0f, 0.0f, kMaxZ / 2, 0.0, 0.0, kMaxZ / 2);
  layer.updates();
  EXPECT_EQ(layer.lethalWith(staticLethal()), 21u);
  EXPECT_EQ(layer.cellsIn(CellState::kOccupied), (std::set<Cell>{{0, 0}}));
  EXPECT_TRUE(layer.cellsIn(CellState::kFree).empty());  // nothing to clear: no direction
}

// costmap_2d testDynamicObstacles: three identical points straight below the sensor (z 0, the
// band's lower limit): one new lethal cell.
TEST(ObstacleParity, RepeatedPointBelowTheSensorIsOneObstacle) {
  ParityLayer layer(tenByTen());
  for (int i = 0; i < 3; ++i) layer.add(0.0f, 0.0f);
  layer.updates();
  EXPECT_EQ(layer.lethalWith(staticLethal()), 21u);
  layer.updates();  // again: no insertion, no deletion
  EXPECT_EQ(layer.lethalWith(staticLethal()), 21u);
}

// The same off the lattice: sensors anywhere in a cell, points straight above or below them,
// grids with other origins and resolutions. Each marks the cell containing the sensor.
TEST(ObstacleParity, ZeroRangePointsMarkTheSensorCellOnAnyLattice) {
  std::mt19937 rng(18);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const double res : {1.0, 0.05, 0.1, 0.025}) {
    for (const double origin : {0.0, -2.5, 0.013, 7.3}) {
      const GridGeometry g(40, 40, res, origin, -origin);
      ParityLayer layer(g);
      const double ox = origin + (3 + 30 * unit(rng)) * res;
      const double oy = -origin + (3 + 30 * unit(rng)) * res;
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() = Eigen::Vector3d(ox, oy, 0.8);
      const float below[3] = {0.0f, 0.0f, -0.5f};  // z = 0.3, in the band
      std::vector<BeamUpdate> beams;
      IntegrationStats decisions;
      for (int i = 0; i < kUpdates; ++i) {
        beams.clear();
        decisions = IntegrationStats{};
        beamsFromCloud(layer.integrator, CloudBeamsConfig{},
                       reinterpret_cast<const unsigned char*>(below), 1, sizeof(below), pose,
                       &beams, &decisions);
        layer.integrator.integrate(layer.grid, beams, decisions);
      }
      EXPECT_EQ(decisions.beams_invalid, 0u);
      const CellIndex c = g.worldToCellUnbounded(ox, oy);
      EXPECT_EQ(layer.cellsIn(CellState::kOccupied), (std::set<Cell>{{c.x, c.y}}))
          << "res " << res << " origin " << origin;
    }
  }
}

// costmap_2d testRaytracing2: a ray along the diagonal from the centre of (0, 0) to the centre of
// (9, 9) passes exactly through the corners of the diagonal cells. It clears the diagonal only
// (costmap_2d: the diagonal, then the layer's re-marked diagonal is cleared again; 79 free).
// With unknown space tracked the cleared cells can be counted: (0,0)..(8,8), nothing beside them.
TEST(ObstacleParity, DiagonalThroughCornersClearsTheDiagonalOnly) {
  ParityLayer layer(tenByTen());
  EXPECT_EQ(layer.lethalWith(staticLethal()), 20u);
  layer.add(9.5f, 9.5f, kMaxZ / 2, 0.5, 0.5, kMaxZ / 2);
  layer.updates();
  const std::size_t obs_after = layer.lethalWith(staticLethal());
  EXPECT_EQ(obs_after, 21u);  // + (9, 9); the static (7, 7) is another layer's
  std::set<Cell> diagonal;
  for (int i = 0; i < 9; ++i) diagonal.insert({i, i});
  EXPECT_EQ(layer.cellsIn(CellState::kFree), diagonal);
  // The layer's diagonal set occupied, then the observation re-integrated: cleared again.
  // (Log-odds: from the clamp, +8, a cell needs 25 passes to fall below -2.)
  const GridGeometry& g = layer.grid.geometry();
  for (int i = 0; i < 10; ++i) layer.grid.setLogOdds(g.index(i, i), layer.grid.config().clamp_max);
  layer.updates(25);
  EXPECT_EQ(layer.lethalWith(staticLethal()), obs_after);
  EXPECT_EQ(layer.cellsIn(CellState::kFree), diagonal);
  // Not tracking unknown space, costmap_2d's 79 free cells are all the cells not lethal.
  EXPECT_EQ(100u - layer.lethalWith(staticLethal()), 79u);
}

// costmap_2d testWaveInterference: three points on the diagonal at exact cell corners (3,3),
// (5,5), (7,7), seen from the corner (0,0): 3 lethal, 5 free ((0,0), (1,1), (2,2), (4,4),
// (6,6)), 92 unknown. A ray through a corner touches the two side cells at one point only: it
// clears neither (an x-first tie-break cleared one side: 12 free).
TEST(ObstacleParity, WaveInterference) {
  ParityLayer layer(tenByTen());
  layer.add(3.0f, 3.0f, kMaxZ);
  layer.add(5.0f, 5.0f, kMaxZ);
  layer.add(7.0f, 7.0f, kMaxZ);
  layer.updates();
  EXPECT_EQ(layer.cellsIn(CellState::kOccupied), (std::set<Cell>{{3, 3}, {5, 5}, {7, 7}}));
  EXPECT_EQ(layer.cellsIn(CellState::kFree),
            (std::set<Cell>{{0, 0}, {1, 1}, {2, 2}, {4, 4}, {6, 6}}));
  EXPECT_EQ(layer.cellsIn(CellState::kUnknown).size(), 92u);
}

// The same in all four diagonal directions, on other lattices. Deliberate difference from
// costmap_2d: each point marks the cell containing it (floor, so a point on a corner belongs to
// the cell above and to the right of it), and a ray clears the cells it crosses, not Bresenham's
// cells between cell centres. Moving down in x or y the rays therefore run along the other side
// of the points' cells; the expectation is the exact one: the sensor's cell plus every cell whose
// interior a segment crosses, minus the points' cells.
TEST(ObstacleParity, WaveInterferenceInEveryDirection) {
  for (const double res : {1.0, 0.5, 0.25}) {
    for (const double origin : {0.0, -3.0, 1.5}) {
      for (const int sx : {1, -1}) {
        for (const int sy : {1, -1}) {
          const GridGeometry g(20, 20, res, origin, origin);
          ParityLayer layer(g);
          // The sensor on the corner (10, 10), points 3, 5, 7 cells along the diagonal.
          const double ox = origin + 10 * res, oy = origin + 10 * res;
          std::set<Cell> hits;
          for (const int k : {3, 5, 7}) {
            const int px = 10 + sx * k, py = 10 + sy * k;
            layer.add(static_cast<float>(origin + px * res), static_cast<float>(origin + py * res),
                      kMaxZ, ox, oy, kMaxZ);
            hits.insert({px, py});
          }
          layer.updates();
          std::set<Cell> expected_free = {{10, 10}};
          for (int y = 0; y < 20; ++y) {
            for (int x = 0; x < 20; ++x) {
              if (crossesInterior(10, 10, 10 + 7 * sx, 10 + 7 * sy, x, y, 1)) {
                expected_free.insert({x, y});
              }
            }
          }
          for (const Cell& h : hits) expected_free.erase(h);
          const std::string what = "res " + std::to_string(res) + " origin " +
                                   std::to_string(origin) + " direction " + std::to_string(sx) +
                                   "," + std::to_string(sy);
          EXPECT_EQ(layer.cellsIn(CellState::kOccupied), hits) << what;
          EXPECT_EQ(layer.cellsIn(CellState::kFree), expected_free) << what;
          // Up-up is costmap_2d's scenario: its 5 free cells.
          if (sx > 0 && sy > 0) {
            EXPECT_EQ(expected_free.size(), 5u) << what;
          }
        }
      }
    }
  }
}

// The walker on any segment between points of the quarter-cell lattice (corners, edges and
// interiors; every direction; binary resolutions, so the points are exact): it visits the start
// cell, then exactly the cells whose interior the segment crosses, in order, and ends in the end
// point's cell. Passing through a corner visits neither side cell, in every direction.
TEST(ObstacleParity, WalkVisitsExactlyTheCrossedCells) {
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> lattice(4, 4 * 30 - 4);  // quarter cells
  std::uniform_int_distribution<int> small(-12, 12);
  for (const double res : {1.0, 0.25}) {
    for (const double origin : {0.0, -2.0, 0.75}) {
      const GridGeometry g(30, 30, res, origin, -origin);
      int corners_seen = 0;
      for (int n = 0; n < 4000; ++n) {
        const int a = lattice(rng), b = lattice(rng);
        // Mostly diagonal-ish rays through lattice corners (steps of whole cells in both axes),
        // the rest anywhere.
        int c = lattice(rng), d = lattice(rng);
        if (n % 2 == 0) {
          const int k = small(rng);
          // Inside the grid: an end on its boundary is moved inside by the clip (1e-6 cell).
          c = std::clamp(a + 4 * k, 4, 116);
          d = std::clamp(b + 4 * k * (n % 4 == 0 ? 1 : -1), 4, 116);
        }
        const double x0 = origin + 0.25 * a * res, y0 = -origin + 0.25 * b * res;
        const double x1 = origin + 0.25 * c * res, y1 = -origin + 0.25 * d * res;
        const auto cells = rayCells(g, x0, y0, x1, y1, true);
        ASSERT_FALSE(cells.empty());
        const CellIndex start = g.worldToCellUnbounded(x0, y0);
        const CellIndex end = g.worldToCellUnbounded(x1, y1);
        ASSERT_EQ(cells.front(), start);
        ASSERT_EQ(cells.back(), end) << x0 << "," << y0 << " -> " << x1 << "," << y1 << " (" << a
                                     << "," << b << " -> " << c << "," << d << ")";
        std::set<Cell> walked;
        for (const CellIndex& cell : cells) walked.insert({cell.x, cell.y});
        ASSERT_EQ(walked.size(), cells.size()) << "a cell visited twice";
        std::set<Cell> exact = {{start.x, start.y}, {end.x, end.y}};
        // A segment lying on an edge crosses no interior; its points belong (floor) to the
        // cells above / right of that edge, and those are walked, as costmap_2d's Bresenham
        // walks the row of its end cells. Reference: the segment moved into them by an eighth.
        const long lift_x = (a == c && a % 4 == 0) ? 1 : 0;
        const long lift_y = (b == d && b % 4 == 0) ? 1 : 0;
        for (int y = 0; y < 30; ++y) {
          for (int x = 0; x < 30; ++x) {
            if (crossesInterior(2L * a + lift_x, 2L * b + lift_y, 2L * c + lift_x, 2L * d + lift_y,
                                x, y, 8)) {
              exact.insert({x, y});
            }
          }
        }
        ASSERT_EQ(walked, exact) << x0 << "," << y0 << " -> " << x1 << "," << y1;
        for (std::size_t i = 1; i < cells.size(); ++i) {
          corners_seen += cells[i].x != cells[i - 1].x && cells[i].y != cells[i - 1].y;
        }
      }
      EXPECT_GT(corners_seen, 100);  // the lattice did put rays through corners
    }
  }
}

// costmap_2d testZThreshold: of two points, the one above max_obstacle_height (2.2 > 2 m) is not
// an obstacle: 1 lethal.
TEST(ObstacleParity, PointsAboveTheHeightBandAreIgnored) {
  ParityLayer layer(tenByTen());
  layer.add(0.0f, 5.0f, 0.4f);
  layer.add(1.0f, 5.0f, 2.2f);
  layer.updates();
  EXPECT_EQ(layer.cellsIn(CellState::kOccupied), (std::set<Cell>{{0, 5}}));
}

// costmap_2d testMultipleAdditions: a point on a static obstacle adds no lethal cell.
TEST(ObstacleParity, PointOnAStaticObstacleAddsNothing) {
  ParityLayer layer(tenByTen());
  layer.add(9.5f, 0.0f);
  layer.updates();
  EXPECT_EQ(layer.lethalWith(staticLethal()), 20u);
  EXPECT_EQ(layer.cellsIn(CellState::kOccupied), (std::set<Cell>{{9, 0}}));
}

// The ray's end cell is the cell its end point is marked in, also a hair below an edge (the
// walker rounds to 2^-20 cell; rounding a point up across an edge made the walk end in the
// cell above while the hit marked the cell below, and that end cell was never cleared).
TEST(ObstacleParity, WalkEndsInTheCellTheHitMarks) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const double res : {0.05, 0.1, 1.0}) {
    const GridGeometry g(100, 100, res, -2.5, 1.25);
    for (int n = 0; n < 2000; ++n) {
      const double x0 = -2.5 + (20 + 60 * unit(rng)) * res;
      const double y0 = 1.25 + (20 + 60 * unit(rng)) * res;
      // An end 1e-9 cell (and a few ulps) either side of an edge, in x or y.
      const int edge = 5 + static_cast<int>(90 * unit(rng));
      const double off = (n % 4 - 1.5) * 1e-9 * res;
      double x1 = -2.5 + (edge + off / res) * res;
      double y1 = 1.25 + (5 + 90 * unit(rng)) * res;
      if (n % 8 >= 4) {  // the edge in y instead
        std::swap(x1, y1);
        x1 += -2.5 - 1.25;
        y1 += 1.25 + 2.5;
      }
      CellIndex hit;
      if (!g.worldToCell(x1, y1, &hit)) continue;
      const auto cells = rayCells(g, x0, y0, x1, y1, true);
      ASSERT_EQ(cells.back(), hit) << "res " << res << " end " << x1 << "," << y1;
    }
  }
}

// A world point exactly on a cell edge stays in the same world cell however often the rolling
// window shifts (the origin moves by adding dx * resolution, which rounds).
TEST(ObstacleParity, ShiftedGridsKeepEdgePointsInTheirWorldCell) {
  for (const double res : {0.05, 0.1, 0.025, 0.3}) {
    const GridGeometry start(100, 100, res, -2.5, -2.5);
    const double edge_x = -2.5 + 60 * res;  // on an edge of the starting lattice
    const CellIndex first = start.worldToCellUnbounded(edge_x, edge_x);
    GridGeometry g = start;
    std::int64_t moved = 0;
    for (int k = 0; k < 400; ++k) {
      const int d = (k % 3 == 0) ? 2 : 1;
      g = shiftedGeometry(g, d, d);
      moved += d;
      const CellIndex c = g.worldToCellUnbounded(edge_x, edge_x);
      ASSERT_EQ(c.x + moved, first.x) << "res " << res << " after " << k + 1 << " shifts";
      ASSERT_EQ(c.y + moved, first.y);
    }
  }
}
