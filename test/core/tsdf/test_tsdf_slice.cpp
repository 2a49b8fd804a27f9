// The height-band slice for the costmap and its clearance distances.
#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "downstream_perception/core/tsdf/marching_cubes.h"
#include "downstream_perception/core/tsdf/occupancy_octree.h"
#include "downstream_perception/core/tsdf/tsdf_health.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "tsdf_test_helpers.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

TEST(TsdfSlice, TableTopInTheBandIsAnObstacleTheFloorIsNot) {
  // Exact SDF of a floor (z = 0) and a table top (z 0.72 .. 0.76 over x 1 .. 2, |y| <= 0.5),
  // observed within x, y in [-1, 3) x [-1, 1), z in [-0.2, 1.2].
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  TsdfMap map(c);
  const double mu = c.truncation();
  const auto slab = [](const Eigen::Vector3d& p) {
    const Eigen::Vector3d q =
        (p - Eigen::Vector3d(1.5, 0.0, 0.74)).cwiseAbs() - Eigen::Vector3d(0.5, 0.5, 0.02);
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  };
  fill(&map, Eigen::Vector3i(-20, -20, -4), Eigen::Vector3i(59, 19, 24),
       [&](const Eigen::Vector3d& p) {
         return std::clamp(std::min(p.z(), slab(p)) / mu, -1.0, 1.0);
       });
  // Voxel centres on the cell edges: each must still land in a cell of its own.
  const GridGeometry grid(100, 60, 0.05, -2.0, -1.5);
  TsdfSliceConfig band;  // 0.05 .. 1.8 m
  TsdfSliceStats stats;
  const std::vector<SliceCell> slice = sliceTsdf(map, grid, band, &stats);
  const auto at = [&](double x, double y) {
    const CellIndex cell = grid.worldToCellUnbounded(x, y);
    return slice[grid.index(cell.x, cell.y)];
  };
  EXPECT_EQ(at(1.5, 0.0), SliceCell::kOccupied);    // under the table top
  EXPECT_EQ(at(1.02, 0.48), SliceCell::kOccupied);  // its corner
  EXPECT_EQ(at(0.0, 0.0), SliceCell::kFree);        // floor only: below the band
  EXPECT_EQ(at(2.2, 0.0), SliceCell::kFree);        // beside the table, beyond one voxel
  EXPECT_EQ(at(-1.8, 1.3), SliceCell::kUnknown);    // never observed
  EXPECT_EQ(stats.cells_occupied, 21u * 21u);       // 1 .. 2 m in 5 cm cells, edges included
  // A band above the table: it is gone from the slice.
  band.min_z_m = 0.9;
  EXPECT_EQ(sliceTsdf(map, grid, band)[grid.index(grid.worldToCellUnbounded(1.5, 0.0).x,
                                                  grid.worldToCellUnbounded(1.5, 0.0).y)],
            SliceCell::kFree);
  band.max_z_m = 0.5;  // below min_z_m
  EXPECT_THROW(sliceTsdf(map, grid, band), std::invalid_argument);
}

TEST(TsdfSlice, DistanceIsEuclideanToTheNearestOccupiedCell) {
  // 0.1 m cells; occupied: one cell and a short wall; unknown: a block the distance may not
  // report but must see through (it treats unknown as free).
  const GridGeometry grid(30, 20, 0.1, -1.0, -1.0);
  std::vector<SliceCell> cells(30 * 20, SliceCell::kFree);
  std::vector<CellIndex> occupied = {{4, 5}};
  for (int y = 10; y < 16; ++y) occupied.push_back({22, y});
  for (const CellIndex& c : occupied) cells[grid.index(c.x, c.y)] = SliceCell::kOccupied;
  for (int y = 0; y < 4; ++y) {
    for (int x = 10; x < 14; ++x) cells[grid.index(x, y)] = SliceCell::kUnknown;
  }
  const double cap = 1.25;
  const std::vector<float> distance = sliceDistance(cells, grid, cap);
  ASSERT_EQ(distance.size(), cells.size());
  std::size_t capped = 0;
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 30; ++x) {
      const float d = distance[grid.index(x, y)];
      if (cells[grid.index(x, y)] == SliceCell::kUnknown) {
        EXPECT_TRUE(std::isnan(d)) << x << ", " << y;
        continue;
      }
      double nearest = std::numeric_limits<double>::infinity();
      for (const CellIndex& c : occupied) nearest = std::min(nearest, std::hypot(x - c.x, y - c.y));
      const double expected = std::min(cap, 0.1 * nearest);
      EXPECT_NEAR(d, expected, 1e-6) << x << ", " << y;
      capped += expected == cap;
    }
  }
  EXPECT_GT(capped, 10u);                               // the cap applies
  EXPECT_NEAR(distance[grid.index(7, 9)], 0.5, 1e-6);   // (3, 4) cells from the single one
  EXPECT_NEAR(distance[grid.index(12, 5)], 0.8, 1e-6);  // beside the unknown block
  EXPECT_THROW(sliceDistance(cells, grid, -0.1), std::invalid_argument);
  EXPECT_THROW(sliceDistance(cells, grid, std::nan("")), std::invalid_argument);
  EXPECT_THROW(sliceDistance(cells, grid, std::numeric_limits<double>::infinity()),
               std::invalid_argument);
  cells.pop_back();
  EXPECT_THROW(sliceDistance(cells, grid, cap), std::invalid_argument);
}
