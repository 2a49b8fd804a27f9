// The height band's 2-D ESDF (esdf_band.h, the nodelet's ~slice_distance): hand-derived values
// on a wall with a floor and a shelf outside the band, a brute-force oracle on the room (filled
// from its exact SDF at two lattice offsets, and integrated from depth frames), its occupied
// columns against the slice's, and the validation of its settings.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "downstream_perception/core/tsdf/esdf.h"
#include "downstream_perception/core/tsdf/esdf_band.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "esdf_test_helpers.h"
#include "tsdf_test_helpers.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

namespace {

/// The value at column (x, y) of a band slice.
float at(const EsdfBandSlice& band, int x, int y) {
  return band.distance_m[band.grid.index(x, y)];
}

struct BandOracle {
  std::size_t known = 0;
  std::size_t off = 0;
  std::size_t occupied = 0;
  std::size_t below_cap = 0;  ///< free columns closer to an obstacle than the cap
};

/// Brute force, written independently of esdf_band.cpp: the band's voxel layers and column
/// states straight from the TSDF's voxels, then for each known column the nearest column of the
/// other state by scanning all of them.
BandOracle compareBandWithOracle(const TsdfMap& map, const EsdfBandConfig& c,
                                 const EsdfBandSlice& band) {
  BandOracle result;
  const double s = map.voxelSize();
  const GridGeometry& g = band.grid;
  const int first = static_cast<int>(std::ceil(c.min_z_m / s));
  const int last = static_cast<int>(std::floor(c.max_z_m / s));
  // Column (cx, cy) holds the voxels (i, j) whose centre lies in the cell.
  const int i0 = static_cast<int>(std::lround(g.originX() / s + 0.5));
  const int j0 = static_cast<int>(std::lround(g.originY() / s + 0.5));
  std::vector<int> state(static_cast<std::size_t>(g.sizeX()) * g.sizeY(), 0);
  for (int cy = 0; cy < g.sizeY(); ++cy) {
    for (int cx = 0; cx < g.sizeX(); ++cx) {
      int& st = state[g.index(cx, cy)];
      for (int k = first; k <= last; ++k) {
        const TsdfVoxel* v = map.voxel({i0 + cx, j0 + cy, k});
        if (v == nullptr || !(v->observedWeight() > map.config().min_weight)) continue;
        st = std::max(st, v->distance < 0.0f ? 2 : 1);
      }
    }
  }
  for (int cy = 0; cy < g.sizeY(); ++cy) {
    for (int cx = 0; cx < g.sizeX(); ++cx) {
      const int st = state[g.index(cx, cy)];
      const float got = at(band, cx, cy);
      if (st == 0) {
        result.off += !std::isnan(got);
        continue;
      }
      ++result.known;
      result.occupied += st == 2;
      std::int64_t best = INT64_MAX;
      for (int oy = 0; oy < g.sizeY(); ++oy) {
        for (int ox = 0; ox < g.sizeX(); ++ox) {
          if (state[g.index(ox, oy)] != 3 - st) continue;
          const std::int64_t dx = ox - cx, dy = oy - cy;
          best = std::min(best, dx * dx + dy * dy);
        }
      }
      const double magnitude =
          best == INT64_MAX
              ? c.max_distance_m
              : std::min(c.max_distance_m, (std::sqrt(static_cast<double>(best)) - 0.5) * s);
      const auto expected = static_cast<float>(st == 2 ? -magnitude : magnitude);
      result.off += !(got == expected);
      result.below_cap += st == 1 && magnitude < c.max_distance_m;
    }
  }
  return result;
}

}  // namespace

TEST(EsdfBand, WallDistancesAreHandDerivedAndTheFloorAndAShelfAboveAreNoObstacles) {
  // 10 cm voxels; a wall filling x > 0.237 m, a floor below z = 0.03 m and a shelf above
  // z = 2.0 m, observed over x, y in [-1.0, 0.9] m. The band 0.05 .. 1.8 m holds layers 1..17 (1.8
  // / 0.1 rounds to 17.99..): the floor's layer 0 (centre z = 0, D < 0) and the shelf (layers >=
  // 21) lie outside it. Columns i <= 2 (centres x = 0.1 i) are free, i >= 3 occupied; a free column
  // is 3 - i voxels from the wall's first column: (3 - i - 1/2) * 0.1 = 0.25 - x; an occupied one i
  // - 2 voxels from the last free column: -(i - 2 - 1/2) * 0.1 = 0.25 - x too. The cap (0.4 m)
  // holds from x <= -0.2 m on. (The 3-D ESDF at (x, z) = (-0.5, 0.1) would read 0.05: the floor.)
  TsdfConfig tc;
  tc.voxel_size_m = 0.1;
  TsdfMap map(tc);
  const double mu = tc.truncation();
  fill(&map, {-10, -10, -2}, {9, 9, 24}, [&](const Eigen::Vector3d& p) {
    const double sdf = std::min({0.237 - p.x(), p.z() - 0.03, 2.0 - p.z()});
    return std::clamp(sdf / mu, -1.0, 1.0);
  });
  EsdfBandConfig c;
  c.max_distance_m = 0.4;
  const EsdfBandSlice band = esdfBandSlice(map, c);
  // sliceGeometry: blocks -2..1 along x and y, so 32 x 32 columns from voxel -16.
  ASSERT_EQ(band.grid.sizeX(), 32);
  ASSERT_EQ(band.grid.sizeY(), 32);
  std::size_t checked = 0;
  for (int j = -10; j <= 9; ++j) {
    for (int i = -10; i <= 9; ++i) {
      const double x = 0.1 * i;
      const float expected = static_cast<float>(std::max(-0.4, std::min(0.4, 0.25 - x)));
      const float got = at(band, i + 16, j + 16);
      EXPECT_NEAR(got, expected, 1e-6) << "column " << i << ", " << j;
      EXPECT_EQ(got < 0.0f, i >= 3);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 400u);
  EXPECT_EQ(band.stats.columns_occupied, 7u * 20u);  // i = 3..9
  EXPECT_EQ(band.stats.columns_free, 13u * 20u);     // i = -10..2
  // Columns outside the filled box are unknown.
  EXPECT_TRUE(std::isnan(at(band, 2, 2)));
  EXPECT_TRUE(std::isnan(at(band, 31, 31)));
  // The 3-D ESDF of the same map sees the floor instead.
  EsdfConfig ec;
  ec.max_distance_m = 0.4;
  Esdf esdf(ec, 0.1);
  esdf.update(map);
  EXPECT_NEAR(esdf.voxelDistance({-5, 0, 1}), 0.05f, 1e-6);
  EXPECT_NEAR(at(band, -5 + 16, 16), 0.4f, 1e-6);
}

class EsdfBandRoomOffsets : public ::testing::TestWithParam<Eigen::Vector3d> {};

TEST_P(EsdfBandRoomOffsets, FilledRoomMatchesTheOracle) {
  RoomScene scene;
  scene.offset = GetParam();
  const TsdfMap map = filledRoom(0.05, scene);
  EsdfBandConfig c;  // 0.05 .. 1.8 m, cap 2 m
  const EsdfBandSlice band = esdfBandSlice(map, c);
  const BandOracle o = compareBandWithOracle(map, c, band);
  EXPECT_EQ(o.off, 0u);
  EXPECT_GT(o.known, 6000u);
  EXPECT_GT(o.occupied, 800u);  // walls, box, table top, sphere, pole
  EXPECT_GT(o.below_cap, 3000u);
  EXPECT_EQ(o.occupied, band.stats.columns_occupied);
  EXPECT_EQ(o.known - o.occupied, band.stats.columns_free);
  // The open floor between the objects is clear by decimetres, not by the floor's few
  // centimetres: the room's centre column.
  const CellIndex centre = band.grid.worldToCellUnbounded(scene.offset.x(), scene.offset.y());
  EXPECT_GT(at(band, centre.x, centre.y), 0.3f);
}

INSTANTIATE_TEST_SUITE_P(Lattice, EsdfBandRoomOffsets,
                         ::testing::Values(Eigen::Vector3d::Zero(),
                                           Eigen::Vector3d(0.037, 0.061, 0.023)));

TEST(EsdfBand, IntegratedRoomMatchesTheOracleAndItsObstaclesAreInTheSlice) {
  // Real integration (depth frames around the room): columns the camera never saw are unknown,
  // and bands of other heights and caps agree with the oracle too. Every column the band calls
  // occupied (a voxel with D < 0) is occupied in the slice, whose shell is a voxel thicker.
  RoomScene scene;
  scene.offset = Eigen::Vector3d(0.0073, -0.0041, 0.0029);
  TsdfConfig tc;
  tc.voxel_size_m = 0.05;
  TsdfMap map(tc);
  DepthIntegrator integrator;
  const PinholeCamera camera = smallCamera();
  for (int i = 0; i < 8; ++i) {
    const Eigen::Isometry3d pose = circlePose(i, 8);
    integrator.integrate(&map, renderDepth(camera, pose, scene).data(), camera, pose);
  }
  // The last band sees the sphere and the pole, and walls only where the camera looked up
  // to them: fewer obstacles.
  for (const auto& [lo, hi, cap, min_occupied] :
       {std::tuple<double, double, double, std::size_t>{0.05, 1.8, 2.0, 300},
        {0.3, 0.9, 0.5, 300},
        {1.0, 1.45, 0.05, 60}}) {
    EsdfBandConfig c;
    c.min_z_m = lo;
    c.max_z_m = hi;
    c.max_distance_m = cap;
    const EsdfBandSlice band = esdfBandSlice(map, c);
    const BandOracle o = compareBandWithOracle(map, c, band);
    EXPECT_EQ(o.off, 0u) << lo << " .. " << hi;
    EXPECT_GT(o.occupied, min_occupied) << lo << " .. " << hi;
    EXPECT_LT(o.known, static_cast<std::size_t>(band.grid.sizeX()) * band.grid.sizeY());
    TsdfSliceConfig sc;
    sc.min_z_m = lo;
    sc.max_z_m = hi;
    const std::vector<SliceCell> slice = sliceTsdf(map, band.grid, sc);
    std::size_t band_occupied = 0, also_in_slice = 0;
    for (std::size_t k = 0; k < slice.size(); ++k) {
      if (!(band.distance_m[k] < 0.0f)) continue;
      ++band_occupied;
      also_in_slice += slice[k] == SliceCell::kOccupied;
    }
    EXPECT_EQ(band_occupied, o.occupied);
    EXPECT_EQ(also_in_slice, band_occupied) << lo << " .. " << hi;
  }
}

TEST(EsdfBand, EmptyMapAndInvalidSettings) {
  TsdfMap map{TsdfConfig{}};
  const EsdfBandSlice empty = esdfBandSlice(map, EsdfBandConfig{});
  EXPECT_EQ(empty.grid.sizeX(), 0);
  EXPECT_TRUE(empty.distance_m.empty());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [lo, hi, cap] : {std::tuple<double, double, double>{1.0, 0.5, 2.0},
                                    {0.5, 0.5, 2.0},
                                    {nan, 1.0, 2.0},
                                    {0.0, inf, 2.0},
                                    {0.0, 1.0, 0.0},
                                    {0.0, 1.0, -1.0},
                                    {0.0, 1.0, nan},
                                    {0.0, 1.0, inf},
                                    {0.0, 1.0, 2e6},
                                    {0.0, 1.0, 0.019}}) {  // below one 2 cm voxel
    EsdfBandConfig c;
    c.min_z_m = lo;
    c.max_z_m = hi;
    c.max_distance_m = cap;
    EXPECT_FALSE(c.validate(map.voxelSize()).empty()) << lo << " " << hi << " " << cap;
    EXPECT_THROW(esdfBandSlice(map, c), std::invalid_argument);
  }
  EXPECT_TRUE(EsdfBandConfig{}.validate(map.voxelSize()).empty());
  EsdfBandConfig one_voxel;
  one_voxel.max_distance_m = map.voxelSize();
  EXPECT_TRUE(one_voxel.validate(map.voxelSize()).empty());
}
