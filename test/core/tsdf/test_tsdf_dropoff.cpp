// The behind-surface weight drop-off's ramp and its start (issue 22; the default under pose
// noise: BoxFromJitteredPosesStaysWholeWithoutTheBehindSurfaceDropoff in test_tsdf_integrator).
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <utility>
#include <vector>

#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "tsdf_test_helpers.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

namespace {

// One ray along +x from the origin to a point at x = 4.5 (1 m voxels, mu = 4 m): voxel x has
// sdf = 4.5 - x, so voxels 5..8 lie 0.5, 1.5, 2.5, 3.5 m behind the surface; the weight of one
// observation is the ramp's value there.
std::vector<float> rampWeights(bool dropoff, double start_voxels) {
  TsdfConfig c = lessonConfig();
  c.behind_surface_dropoff = dropoff;
  c.behind_surface_dropoff_start_voxels = start_voxels;
  TsdfMap map(c);
  integratePoints(&map, {Eigen::Vector3d(4.5, 0, 0)}, Eigen::Vector3d::Zero());
  std::vector<float> w;
  for (int x = 4; x <= 8; ++x) w.push_back(map.voxel({x, 0, 0})->weight);
  return w;
}

}  // namespace

TEST(TsdfDropoff, RampStartsAtTheConfiguredDepthAndEndsAtMu) {
  // Hand-computed: w = 1 for sdf >= -start, else (mu + sdf) / (mu - start).
  const std::vector<std::pair<double, std::vector<float>>> cases = {
      {0.0, {1.0f, 3.5f / 4, 2.5f / 4, 1.5f / 4, 0.5f / 4}},
      {1.0, {1.0f, 1.0f, 2.5f / 3, 1.5f / 3, 0.5f / 3}},  // the ramp before issue 22
      {2.0, {1.0f, 1.0f, 1.0f, 1.5f / 2, 0.5f / 2}},
      {3.0, {1.0f, 1.0f, 1.0f, 1.0f, 0.5f / 1}},
      {4.0, {1.0f, 1.0f, 1.0f, 1.0f, 1.0f}},  // start at mu: no ramp
      {9.0, {1.0f, 1.0f, 1.0f, 1.0f, 1.0f}},
  };
  for (const auto& [start, expected] : cases) {
    const std::vector<float> w = rampWeights(true, start);
    for (std::size_t i = 0; i < w.size(); ++i) EXPECT_FLOAT_EQ(w[i], expected[i]) << start << i;
  }
  // Off: no ramp whatever the start.
  for (const float w : rampWeights(false, 1.0)) EXPECT_FLOAT_EQ(w, 1.0f);
}

TEST(TsdfDropoff, StartIsValidated) {
  TsdfConfig c;
  c.behind_surface_dropoff_start_voxels = -0.5;
  EXPECT_NE(c.validate().find("behind_surface_dropoff_start_voxels"), std::string::npos);
  c.behind_surface_dropoff_start_voxels = std::nan("");
  EXPECT_FALSE(c.validate().empty());
  c.behind_surface_dropoff_start_voxels = 100.0;  // beyond mu: valid, no ramp
  EXPECT_EQ(c.validate(), "");
}
