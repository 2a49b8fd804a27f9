// Marching cubes: the case table, closed oriented surfaces, incremental re-extraction.
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

TEST(MarchingCubes, EveryCaseUsesExactlyItsCrossingEdges) {
  for (int mask = 0; mask < 256; ++mask) {
    std::set<int> crossing, used;
    for (int e = 0; e < 12; ++e) {
      const bool a = (mask >> kCubeEdges[e][0]) & 1, b = (mask >> kCubeEdges[e][1]) & 1;
      if (a != b) crossing.insert(e);
    }
    for (const auto& tri : marchingCubesCase(mask)) used.insert(tri.begin(), tri.end());
    EXPECT_EQ(crossing, used) << "case " << mask;
  }
  EXPECT_TRUE(marchingCubesCase(0).empty());
  EXPECT_TRUE(marchingCubesCase(255).empty());
  EXPECT_EQ(marchingCubesCase(1).size(), 1u);   // one corner: one triangle
  EXPECT_EQ(marchingCubesCase(15).size(), 2u);  // a face's four corners: a quad
}

TEST(MarchingCubes, SphereIsClosedOrientedAndOnTheSurface) {
  // Write the exact signed distance of a sphere (radius 0.37 m, centre off the lattice) into
  // the map and extract: a closed, consistently wound surface (Euler characteristic 2).
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  TsdfMap map(c);
  const double mu = c.truncation(), radius = 0.37;
  const Eigen::Vector3d centre(0.013, -0.021, 0.007);
  fill(&map, Eigen::Vector3i::Constant(-14), Eigen::Vector3i::Constant(14),
       [&](const Eigen::Vector3d& p) {
         const double sdf = (p - centre).norm() - radius;
         return std::abs(sdf) > mu ? std::nan("") : sdf / mu;
       });
  const TriangleMesh mesh = meshOf(map);
  ASSERT_GT(mesh.triangleCount(), 500u);
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d q = mesh.vertices[i].cast<double>() - centre;
    EXPECT_NEAR(q.norm(), radius, 0.004);                                 // 4 mm at 5 cm voxels
    EXPECT_GT(mesh.normals[i].cast<double>().dot(q.normalized()), 0.98);  // outward
  }
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    // Winding agrees with the outward normal.
    const auto& v = mesh.vertices;
    const std::uint32_t* tri = &mesh.triangles[3 * t];
    const Eigen::Vector3f n = (v[tri[1]] - v[tri[0]]).cross(v[tri[2]] - v[tri[0]]);
    EXPECT_GT(n.dot(mesh.normals[tri[0]]), 0.0f);
  }
  // Closed and consistently oriented: every directed edge once, its reverse once.
  const MeshEdges edges = meshEdges(mesh);
  std::size_t undirected = 0;
  for (const auto& [edge, count] : edges.directed) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.directed.count({edge.second, edge.first}), 1u);
    undirected += edge.first < edge.second;
  }
  const long euler = static_cast<long>(edges.vertices) - static_cast<long>(undirected) +
                     static_cast<long>(mesh.triangleCount());
  EXPECT_EQ(euler, 2);
  EXPECT_EQ(mesh.writePly("/tmp/dp_sphere_test.ply"), "");
}

TEST(MarchingCubes, RandomFieldsGiveClosedOrientedSurfaces) {
  // Random signs exercise every case, ambiguous faces included: away from the edge of the
  // filled region, every directed edge must meet its reverse exactly once (no cracks, no
  // flipped triangles), whatever the sign pattern.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(-1.0f, 1.0f);
  for (int trial = 0; trial < 3; ++trial) {
    TsdfConfig c;
    c.voxel_size_m = 0.1;
    TsdfMap map(c);
    const int n = 2 * kTsdfBlockSide;  // voxels 0 .. n-1 per axis filled
    fill(&map, Eigen::Vector3i::Zero(), Eigen::Vector3i::Constant(n - 1),
         [&](const Eigen::Vector3d&) {
           return trial == 2 ? 1e-7 * value(rng) : value(rng);  // trial 2: +-0 noise
         });
    const TriangleMesh mesh = meshOf(map);
    ASSERT_GT(mesh.triangleCount(), 100u);
    const MeshEdges edges = meshEdges(mesh);
    // Only edges whose cube lies fully inside the filled region (both ends off the region's
    // faces by half a voxel) can be required to close.
    std::vector<bool> interior(edges.vertices, false);
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      const Eigen::Vector3f p = mesh.vertices[i] / 0.1f;  // voxel units
      interior[edges.id[i]] = p.minCoeff() > 0.5f && p.maxCoeff() < n - 1.5f;
    }
    std::set<std::pair<int, int>> checked;
    for (const auto& [edge, count] : edges.directed) {
      if (interior[edge.first] && interior[edge.second]) checked.insert(edge);
    }
    const auto& directed = edges.directed;
    std::size_t open = 0;
    for (const auto& e : checked) {
      const auto fwd = directed.find(e);
      const auto rev = directed.find({e.second, e.first});
      if (fwd->second != 1 || rev == directed.end() || rev->second != 1) ++open;
    }
    EXPECT_EQ(open, 0u) << "trial " << trial << ": " << checked.size() << " edges checked";
  }
}

TEST(MarchingCubes, MesherReExtractsOnlyChangedBlocks) {
  TsdfConfig c;
  c.voxel_size_m = 0.02;
  TsdfMap map(c);
  const PinholeCamera camera = smallCamera();
  const std::vector<float> depth = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.5);
  integrateDepth(&map, depth.data(), camera, Eigen::Isometry3d::Identity());
  TsdfMesher mesher;
  const std::size_t first = mesher.update(map);
  EXPECT_EQ(first, map.blockCount());
  EXPECT_EQ(mesher.update(map), 0u);  // nothing changed
  // A small patch: one point seen again touches a few blocks, re-extracting their neighbours.
  integratePoints(&map, {Eigen::Vector3d(0.0, 0.0, 1.5)}, Eigen::Vector3d::Zero());
  const std::size_t second = mesher.update(map);
  EXPECT_GT(second, 0u);
  EXPECT_LT(second, first / 4);
}
