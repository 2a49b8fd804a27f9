// The seam-health metrics of a TSDF (|grad D|, double crossings).
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

TEST(TsdfHealth, CleanPlaneHasUnitGradientDriftDoublesTheSurface) {
  // A plane fused from consistent views: |grad (D mu)| = 1 at its crossings, no double crossing.
  // The same plane with half of the views shifted by 0.3 m along its normal (pose drift beyond
  // mu = 0.2 m): two shells, double crossings, and a gradient far from 1.
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.max_weight = 0.0;
  const PinholeCamera camera = smallCamera();
  TsdfMap clean(c), drift(c);
  for (int k = 0; k < 6; ++k) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(0.02 * k, -0.01 * k, 0.0);
    const std::vector<float> depth = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.51);
    integrateDepth(&clean, depth.data(), camera, pose);
    const std::vector<float> shifted =
        planeDepth(camera, Eigen::Vector3d::UnitZ(), k < 3 ? 1.51 : 1.51 + 0.3);
    integrateDepth(&drift, shifted.data(), camera, pose);
  }
  const TsdfHealth good = tsdfHealth(clean);
  ASSERT_GT(good.crossings, 100u);
  EXPECT_NEAR(good.mean_gradient_ratio, 1.0, 0.1);
  EXPECT_EQ(good.double_crossings, 0u);
  EXPECT_LT(good.low_gradient_fraction, 0.01);
  const TsdfHealth bad = tsdfHealth(drift);
  ASSERT_GT(bad.crossings, 100u);
  // Measured: 682 double crossings of 2,465, gradient ratio 1.53 (steep where a shell ends).
  EXPECT_GT(bad.double_crossings, 100u);
  EXPECT_GT(std::abs(bad.mean_gradient_ratio - 1.0), 0.3);
}
