// The OctoMap fed from the same frames.
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

TEST(OccupancyOctree, LessonLogOddsAlongARay) {
  // One ray along x to a point at 1.0 m: the end leaf gets the lesson's +0.847 (p_hit 0.7), the
  // leaves passed -0.405 (p_miss 0.4); a second identical ray doubles both.
  OccupancyOctree tree;  // 5 cm leaves
  const std::vector<Eigen::Vector3d> end = {Eigen::Vector3d(1.01, 0.01, 0.01)};
  tree.insertPoints(end, Eigen::Vector3d(0.01, 0.01, 0.01));
  double l = 0.0;
  ASSERT_TRUE(tree.logOdds(end[0], &l));
  EXPECT_NEAR(l, std::log(0.7 / 0.3), 1e-4);  // 0.847
  ASSERT_TRUE(tree.logOdds(Eigen::Vector3d(0.5, 0.01, 0.01), &l));
  EXPECT_NEAR(l, std::log(0.4 / 0.6), 1e-4);                        // -0.405
  EXPECT_FALSE(tree.logOdds(Eigen::Vector3d(0.5, 1.0, 0.01), &l));  // never observed
  tree.insertPoints(end, Eigen::Vector3d(0.01, 0.01, 0.01));
  ASSERT_TRUE(tree.logOdds(end[0], &l));
  EXPECT_NEAR(l, 2.0 * std::log(0.7 / 0.3), 1e-4);
  const std::vector<Eigen::Vector3d> occupied = tree.occupiedCenters();
  ASSERT_EQ(occupied.size(), 1u);
  EXPECT_LT((occupied[0] - end[0]).norm(), 0.05);
  const std::string path = "/tmp/dp_octree_test.bt";
  EXPECT_EQ(tree.writeBinary(path), "");
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first.rfind("# Octomap OcTree binary file", 0), 0u);
  OctreeConfig bad;
  bad.prob_hit = 0.3;
  EXPECT_THROW(OccupancyOctree{bad}, std::invalid_argument);
}

TEST(OccupancyOctree, DepthImageOfAPlaneMarksThePlane) {
  OccupancyOctree tree;
  const PinholeCamera camera = smallCamera();
  const std::vector<float> depth = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.5);
  tree.insertDepth(depth.data(), camera, Eigen::Isometry3d::Identity());
  const std::vector<Eigen::Vector3d> occupied = tree.occupiedCenters();
  ASSERT_GT(occupied.size(), 100u);
  for (const Eigen::Vector3d& p : occupied) EXPECT_NEAR(p.z(), 1.5, 0.05);
  double l = 0.0;
  ASSERT_TRUE(tree.logOdds(Eigen::Vector3d(0.0, 0.0, 0.8), &l));
  EXPECT_LT(l, 0.0);  // free space in front of it
}
