#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "downstream_perception/core/costmap/cloud_beams.h"

using namespace downstream_perception;  // NOLINT

namespace {
struct PointXYZI {  // a typical PointCloud2 layout: x, y, z, intensity (16-byte point_step)
  float x, y, z, intensity;
};
}  // namespace

TEST(CloudBeams, HeightBandOriginAndInvalidPoints) {
  ScanIntegratorConfig ic;
  ic.obstacle_max_range = 4.0;
  ic.raytrace_max_range = 5.0;
  ScanIntegrator integrator(ic);
  CloudBeamsConfig cc;
  cc.min_obstacle_height = 0.1;
  cc.max_obstacle_height = 1.5;
  // Sensor 0.5 m up at (1, 2), looking along +x (identity rotation).
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(1.0, 2.0, 0.5);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<PointXYZI> cloud = {
      {2.0f, 0.0f, 0.0f, 1.0f},    // z = 0.5 in the band: marks at (3, 2)
      {2.0f, 0.0f, -0.45f, 1.0f},  // z = 0.05: floor, skipped
      {2.0f, 0.0f, 1.2f, 1.0f},    // z = 1.7: above the band, skipped
      {nan, 0.0f, 0.0f, 1.0f},     // depth hole: invalid
      {0.0f, 4.5f, 0.0f, 1.0f},    // beyond obstacle_max_range: clears only
      {0.0f, 0.0f, 0.5f, 1.0f},    // z = 1.0, straight above the sensor: marks its cell
  };
  std::vector<BeamUpdate> beams;
  IntegrationStats stats;
  beamsFromCloud(integrator, cc, reinterpret_cast<const unsigned char*>(&cloud[0].x), cloud.size(),
                 sizeof(PointXYZI), pose, &beams, &stats);
  ASSERT_EQ(beams.size(), 3u);
  EXPECT_EQ(stats.points_outside_height, 2u);
  EXPECT_EQ(stats.beams_invalid, 1u);
  EXPECT_EQ(stats.beams_beyond_obstacle_range, 1u);
  EXPECT_TRUE(beams[0].mark);
  EXPECT_NEAR(beams[0].hit_x, 3.0, 1e-9);
  EXPECT_NEAR(beams[0].hit_y, 2.0, 1e-9);
  EXPECT_NEAR(beams[0].start_x, 1.0, 1e-9);  // rays start at the sensor origin
  EXPECT_NEAR(beams[0].start_y, 2.0, 1e-9);
  EXPECT_FALSE(beams[1].mark);
  EXPECT_TRUE(beams[1].clear);
  EXPECT_NEAR(beams[1].end_y, 6.5, 1e-9);  // 4.5 m up the +y axis
  // Zero horizontal range: a hit at the sensor's own position, and nothing to clear.
  EXPECT_TRUE(beams[2].mark);
  EXPECT_FALSE(beams[2].clear);
  EXPECT_EQ(beams[2].hit_x, 1.0);
  EXPECT_EQ(beams[2].hit_y, 2.0);
}

TEST(CloudBeams, RotatedSensorAndIntegration) {
  // A camera looking down the -y axis of the grid (yaw -90 deg): a point 2.025 m ahead and
  // 0.025 m to its right lands at (-0.025, -2.025), a cell centre, which becomes occupied.
  ScanIntegrator integrator(ScanIntegratorConfig{});
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation().z() = 0.3;
  const std::vector<PointXYZI> cloud = {{2.025f, -0.025f, 0.0f, 0.0f}};
  LogOddsGrid grid(GridGeometry(100, 100, 0.05, -2.5, -2.5));
  for (int k = 0; k < 6; ++k) {  // 6 misses: -2.43 < -2 (free); 6 hits: +5.08 (occupied)
    std::vector<BeamUpdate> beams;
    IntegrationStats stats;
    beamsFromCloud(integrator, CloudBeamsConfig{},
                   reinterpret_cast<const unsigned char*>(&cloud[0].x), 1, sizeof(PointXYZI), pose,
                   &beams, &stats);
    ASSERT_EQ(beams.size(), 1u);
    EXPECT_NEAR(beams[0].hit_x, -0.025, 1e-6);
    EXPECT_NEAR(beams[0].hit_y, -2.025, 1e-6);
    integrator.integrate(grid, beams, stats);
  }
  CellIndex c;
  ASSERT_TRUE(grid.geometry().worldToCell(-0.025, -2.025, &c));
  EXPECT_EQ(grid.state(grid.geometry().index(c.x, c.y)), CellState::kOccupied);
  ASSERT_TRUE(grid.geometry().worldToCell(-0.025, -1.025, &c));
  EXPECT_EQ(grid.state(grid.geometry().index(c.x, c.y)), CellState::kFree);
  EXPECT_FALSE((CloudBeamsConfig{1.0, 0.5, std::nullopt}).validate().empty());
  EXPECT_TRUE(CloudBeamsConfig{}.validate().empty());
}

TEST(CloudBeams, MergeCellsGiveOneBeamPerCellAndTheSameMarks) {
  // A dense patch of a wall (20 x 20 points within one 5 cm cell, plus one point in the next
  // cell): merged, 2 beams instead of 401, and the grid ends up the same for the hit cells.
  std::vector<PointXYZI> cloud;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      cloud.push_back({2.005f + 0.002f * i, 0.005f + 0.002f * j, 0.0f, 0.0f});
    }
  }
  cloud.push_back({2.075f, 0.025f, 0.0f, 0.0f});
  ScanIntegrator integrator(ScanIntegratorConfig{});
  const Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  CloudBeamsConfig merged;
  merged.min_obstacle_height = -1.0;
  merged.merge_grid = GridGeometry(100, 100, 0.05, -2.5, -2.5);
  CloudBeamsConfig each = merged;
  each.merge_grid.reset();
  std::vector<BeamUpdate> merged_beams, each_beams;
  IntegrationStats merged_stats, each_stats;
  const auto* data = reinterpret_cast<const unsigned char*>(&cloud[0].x);
  beamsFromCloud(integrator, merged, data, cloud.size(), sizeof(PointXYZI), pose, &merged_beams,
                 &merged_stats);
  beamsFromCloud(integrator, each, data, cloud.size(), sizeof(PointXYZI), pose, &each_beams,
                 &each_stats);
  EXPECT_EQ(merged_beams.size(), 2u);
  EXPECT_EQ(merged_stats.points_merged, 399u);
  EXPECT_EQ(each_beams.size(), 401u);
  LogOddsGrid a(GridGeometry(100, 100, 0.05, -2.5, -2.5));
  LogOddsGrid b(GridGeometry(100, 100, 0.05, -2.5, -2.5));
  integrator.integrate(a, merged_beams, merged_stats);
  integrator.integrate(b, each_beams, each_stats);
  for (const double x : {2.025, 2.075}) {
    CellIndex c;
    ASSERT_TRUE(a.geometry().worldToCell(x, 0.025, &c));
    EXPECT_EQ(a.units(a.geometry().index(c.x, c.y)), b.units(b.geometry().index(c.x, c.y)));
    EXPECT_GT(a.units(a.geometry().index(c.x, c.y)), 0);
  }
  EXPECT_FALSE((CloudBeamsConfig{1.0, 0.0, std::nullopt}).validate().empty());
}

// The merge cells are the grid's cells: a grid whose origin is not a multiple of its resolution
// (-2.97 m at 0.05 m), or that rolled by whole cells since it was built, must still get a mark in
// every cell that holds an in-band point (squares counted from the world origin put points of two
// neighbouring cells into one square, and the second cell went unmarked).
TEST(CloudBeams, MergeCellsAreTheGridsCellsWhateverItsOriginAndShifts) {
  ScanIntegratorConfig ic;
  ic.obstacle_max_range = 5e3;  // the sensor sits at the world origin, the grids up to 1.5 km off
  ic.raytrace_max_range = 5e3;
  ScanIntegrator integrator(ic);
  std::mt19937 rng(5);
  struct Case {
    double resolution, origin_x, origin_y;
    std::vector<std::pair<int, int>> shifts;  ///< rolling-window shifts applied after building
  };
  const std::vector<Case> cases = {
      {0.05, -2.97, -2.97, {}},
      {0.05, -2.5, -2.5, {}},  // aligned to the world: the control
      {0.05, 0.013, -1.0071, {{3, -2}}},
      {0.1, 0.33, -7.77, {{1, 1}, {-5, 2}, {7, -3}}},
      {0.025, -1.0123, 0.0049, {{40, 0}, {-1, 13}}},
      {0.3, 12.1, -3.05, {{-2, -2}}},
      {0.05, 1000.0371, -999.9913, {{2, 2}, {2, 2}, {2, 2}, {-1, 5}}},
      {0.07, -3.1, 2.2, {{11, -4}, {3, 3}}},
  };
  for (const Case& c : cases) {
    GridGeometry geometry(40, 30, c.resolution, c.origin_x, c.origin_y);
    for (const auto& [dx, dy] : c.shifts) geometry = geometry.shiftedBy(dx, dy);
    SCOPED_TRACE(::testing::Message()
                 << "resolution " << c.resolution << " origin (" << geometry.originX() << ", "
                 << geometry.originY() << "), " << c.shifts.size() << " shifts");
    std::uniform_real_distribution<double> ux(geometry.originX(),
                                              geometry.originX() + geometry.sizeXMetres());
    std::uniform_real_distribution<double> uy(geometry.originY(),
                                              geometry.originY() + geometry.sizeYMetres());
    std::vector<PointXYZI> cloud;
    for (int k = 0; k < 6000; ++k) {
      cloud.push_back({static_cast<float>(ux(rng)), static_cast<float>(uy(rng)), 0.5f, 0.0f});
    }
    // And points on (the float nearest to) each cell edge and one float either side of it, where
    // the merge cell and the grid cell must agree to the last bit.
    for (int k = 0; k <= geometry.sizeX(); ++k) {
      const auto edge = static_cast<float>(geometry.originX() + k * geometry.resolution());
      const auto row_y = static_cast<float>(geometry.originY() + 3.5 * geometry.resolution());
      for (const float x :
           {std::nextafter(edge, -INFINITY), edge, std::nextafter(edge, INFINITY)}) {
        cloud.push_back({x, row_y, 0.5f, 0.0f});
      }
    }
    for (int k = 0; k <= geometry.sizeY(); ++k) {
      const auto edge = static_cast<float>(geometry.originY() + k * geometry.resolution());
      const auto column_x = static_cast<float>(geometry.originX() + 5.5 * geometry.resolution());
      for (const float y :
           {std::nextafter(edge, -INFINITY), edge, std::nextafter(edge, INFINITY)}) {
        cloud.push_back({column_x, y, 0.5f, 0.0f});
      }
    }
    CloudBeamsConfig cc;
    cc.merge_grid = geometry;
    std::vector<BeamUpdate> beams;
    IntegrationStats stats;
    beamsFromCloud(integrator, cc, reinterpret_cast<const unsigned char*>(&cloud[0].x),
                   cloud.size(), sizeof(PointXYZI), Eigen::Isometry3d::Identity(), &beams, &stats);
    LogOddsGrid grid(geometry);
    integrator.integrate(grid, beams, stats);
    std::set<std::size_t> holding;  // cells holding a point (the sensor is at the world origin)
    for (const PointXYZI& p : cloud) {
      CellIndex cell;
      if (geometry.worldToCell(p.x, p.y, &cell)) holding.insert(geometry.index(cell.x, cell.y));
    }
    ASSERT_GT(holding.size(), 600u);
    std::size_t unmarked = 0;
    for (const std::size_t i : holding) unmarked += grid.units(i) <= 0 ? 1 : 0;
    EXPECT_EQ(unmarked, 0u) << "of " << holding.size() << " cells holding a point";
    // Merging happened: about one beam per cell (points on the grid's border may fall outside).
    EXPECT_LT(beams.size(), holding.size() + 100);
    EXPECT_EQ(beams.size() + stats.points_merged, cloud.size());
  }
}
