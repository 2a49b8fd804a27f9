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

namespace {

constexpr double kPlaneZ = 0.013;  // m, off the lattice (5 cm voxels)

// The exact distance field of the horizontal plane z = kPlaneZ (inside below it) over lattice
// x, y in [-12, 12], z in [-6, 6], written where `keep(x, z)` holds.
TsdfMap planeField(const TsdfConfig& c, const std::function<bool(int, int)>& keep) {
  TsdfMap map(c);
  const double mu = c.truncation();
  fill(&map, Eigen::Vector3i(-12, -12, -6), Eigen::Vector3i(12, 12, 6),
       [&](const Eigen::Vector3d& p) {
         const Eigen::Vector3i v = map.voxelAt(p);
         const double sdf = p.z() - kPlaneZ;
         if (std::abs(sdf) > mu || !keep(v.x(), v.z())) return std::nan("");
         return sdf / mu;
       });
  return map;
}

// A slab's top whose edge voxels the guard withheld: the inside voxels (z <= 0) end at x = 3,
// and beyond it only the first free layer (z = 1) is observed.
TsdfMap slabTop(const TsdfConfig& c) {
  return planeField(c, [](int x, int z) { return x <= 3 || z == 1; });
}

float largestX(const TriangleMesh& mesh) {
  float x = -std::numeric_limits<float>::infinity();
  for (const Eigen::Vector3f& v : mesh.vertices) x = std::max(x, v.x());
  return x;
}

TsdfConfig extrapolating(double voxels) {
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.mesh_extrapolate_voxels = voxels;
  return c;
}

}  // namespace

TEST(MarchingCubesExtrapolation, ASlabTopReachesOneVoxelFurtherAlongItsSurface) {
  // The missing inside voxels at x = 4 continue the two before them along x (equal values:
  // the surface runs along x), so the cubes up to x = 4 are complete; those at x = 5 would read
  // a filled voxel, which extrapolation never does, so the mesh stops there. Off it ends at
  // x = 3.
  EXPECT_EQ(TsdfConfig().mesh_extrapolate_voxels, 2.0);  // on by default
  const TriangleMesh before = meshOf(slabTop(extrapolating(0.0)));
  const TriangleMesh after = meshOf(slabTop(extrapolating(2.0)));
  ASSERT_GT(before.triangleCount(), 100u);
  EXPECT_NEAR(largestX(before), 3 * 0.05, 1e-5);
  EXPECT_NEAR(largestX(after), 4 * 0.05, 1e-5);
  for (const Eigen::Vector3f& v : after.vertices) EXPECT_NEAR(v.z(), kPlaneZ, 1e-5);
  // Still one sheet, consistently wound: every directed edge once.
  for (const auto& [edge, count] : meshEdges(after).directed) EXPECT_EQ(count, 1);
}

TEST(MarchingCubesExtrapolation, ASurfaceSeenOnlyFromItsFreeSideIsExtrapolatedAcrossIt) {
  // No inside voxel observed: the voxels below the plane continue the free side's field
  // (stepping one voxel per voxel along z), which crosses zero at the plane; one layer only.
  const TriangleMesh off = meshOf(planeField(extrapolating(0.0), [](int, int z) { return z > 0; }));
  const TriangleMesh on = meshOf(planeField(extrapolating(2.0), [](int, int z) { return z > 0; }));
  EXPECT_EQ(off.triangleCount(), 0u);
  ASSERT_GT(on.triangleCount(), 500u);
  for (const Eigen::Vector3f& v : on.vertices) EXPECT_NEAR(v.z(), kPlaneZ, 1e-5);
}

TEST(MarchingCubesExtrapolation, AFieldSteeperThanADistanceFieldIsNotContinuedAcross) {
  // The free side of the plane as a depth camera sees it 25 degrees off its normal: the ray
  // distance, 1.1 voxels per voxel along z. Its zero still lies on the plane, but continued
  // beyond the observed voxels a projective field's slope changes with the ray: the mesh stays
  // empty rather than guessing (steps up to 1.05 are a distance field's, within noise).
  const auto steep = [](float slope) {
    TsdfConfig c = extrapolating(2.0);
    TsdfMap map = planeField(c, [](int, int z) { return z > 0; });
    for (int z = 1; z <= 6; ++z) {
      for (int y = -12; y <= 12; ++y) {
        for (int x = -12; x <= 12; ++x) {
          const Eigen::Vector3i v(x, y, z);
          TsdfVoxel& voxel = map.allocate(TsdfMap::blockOf(v))->voxels[TsdfMap::localIndex(v)];
          if (voxel.weight > 0.0f) voxel.distance = std::min(1.0f, voxel.distance * slope);
        }
      }
    }
    return meshOf(map);
  };
  EXPECT_GT(steep(1.04).triangleCount(), 500u);
  EXPECT_EQ(steep(1.1).triangleCount(), 0u);
}

TEST(MarchingCubesExtrapolation, AColumnOutOfStepWithItsNeighboursIsNotContinuedAcross) {
  // The free side with the column x = 0 raised by 0.6 voxels (its step along z unchanged): the
  // surface there would face 37 degrees or more off z, or the column is a projective ramp's
  // noise (a far floor at grazing: a voxel under the floor read positive). Its own fill and its
  // neighbours' (x = +-1, whose D1 has the raised column beside it) stay missing; continued, the
  // column would have meshed 3 cm under the plane.
  TsdfMap map = planeField(extrapolating(2.0), [](int, int z) { return z > 0; });
  for (int z = 1; z <= 2; ++z) {
    for (int y = -12; y <= 12; ++y) {
      const Eigen::Vector3i v(0, y, z);
      map.allocate(TsdfMap::blockOf(v))->voxels[TsdfMap::localIndex(v)].distance += 0.6f * 0.25f;
    }
  }
  const TriangleMesh mesh = meshOf(map);
  ASSERT_GT(mesh.triangleCount(), 500u);
  std::size_t in_gap = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    EXPECT_NEAR(v.z(), kPlaneZ, 1e-5);
    in_gap += std::abs(v.x()) < 1.5f * 0.05f;
  }
  EXPECT_EQ(in_gap, 0u);
}

TEST(MarchingCubesExtrapolation, NoValueIsFilledNextToAVoxelAWholeBandAway) {
  // The same free side with the column x = 0 of the layer under the plane observed as far free
  // space (D = +1: a whole band from any surface): a surface within a voxel of it would be a
  // jump, so its neighbours at x = +-1 stay missing and the mesh has a gap there.
  TsdfMap map = planeField(extrapolating(2.0), [](int, int z) { return z > 0; });
  for (int y = -12; y <= 12; ++y) {
    const Eigen::Vector3i v(0, y, 0);
    TsdfVoxel& voxel = map.allocate(TsdfMap::blockOf(v))->voxels[TsdfMap::localIndex(v)];
    voxel.distance = 1.0f;
    voxel.weight = 1.0f;
  }
  const TriangleMesh mesh = meshOf(map);
  ASSERT_GT(mesh.triangleCount(), 500u);
  std::size_t in_gap = 0, beside = 0;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    in_gap += std::abs(v.x()) < 1.5f * 0.05f;
    beside += std::abs(v.x()) >= 2.0f * 0.05f - 1e-5f && std::abs(v.x()) < 2.5f * 0.05f;
  }
  EXPECT_EQ(in_gap, 0u);
  EXPECT_GT(beside, 0u);
}

TEST(MarchingCubesExtrapolation, UnconfirmedVoxelsAreNotFilled) {
  // The slab with its withheld edge voxels unconfirmed (negative weight, as
  // confirm_depth_voxels marks what was only seen deep behind a surface) instead of missing:
  // the mesh leaves them out, and extrapolation does not put them back.
  TsdfMap map = slabTop(extrapolating(2.0));
  for (int z = -6; z <= 0; ++z) {
    for (int y = -12; y <= 12; ++y) {
      const Eigen::Vector3i v(4, y, z);
      TsdfVoxel& voxel = map.allocate(TsdfMap::blockOf(v))->voxels[TsdfMap::localIndex(v)];
      voxel.distance = static_cast<float>((map.voxelCenter(v).z() - kPlaneZ) / 0.2);
      voxel.weight = -1.0f;
    }
  }
  const TriangleMesh mesh = meshOf(map);
  ASSERT_GT(mesh.triangleCount(), 100u);
  EXPECT_NEAR(largestX(mesh), 3 * 0.05, 1e-5);
}

TEST(MarchingCubesExtrapolation, ChangingAMeshSettingReExtractsEveryBlock) {
  TsdfConfig c = extrapolating(2.0);
  TsdfMap map = slabTop(c);
  TsdfMesher mesher;
  EXPECT_EQ(mesher.update(map), map.blockCount());
  EXPECT_NEAR(largestX(mesher.combined()), 4 * 0.05, 1e-5);
  EXPECT_EQ(mesher.update(map), 0u);
  c.mesh_extrapolate_voxels = 0.0;
  ASSERT_EQ(map.setConfig(c), "");
  EXPECT_EQ(mesher.update(map), map.blockCount());
  EXPECT_NEAR(largestX(mesher.combined()), 3 * 0.05, 1e-5);
  c.min_weight = 0.5;
  ASSERT_EQ(map.setConfig(c), "");
  EXPECT_EQ(mesher.update(map), map.blockCount());
  EXPECT_EQ(mesher.update(map), 0u);
}

TEST(MarchingCubesExtrapolation, ConfigBoundsTheSetting) {
  TsdfConfig c;
  for (const double bad : {-0.5, 64.5, std::nan(""), std::numeric_limits<double>::infinity()}) {
    c.mesh_extrapolate_voxels = bad;
    EXPECT_NE(c.validate().find("mesh_extrapolate_voxels"), std::string::npos) << bad;
  }
  // The default must not refuse a map truncated closer than it reaches (a configuration valid
  // before it was on), nor be named as inert there.
  TsdfConfig thin;
  thin.truncation_voxels = 1.5;
  EXPECT_EQ(thin.validate(), "");
  EXPECT_EQ(thin.inertSettings(), "");
  // Set beyond truncation_voxels, it acts as truncation_voxels (said once by the nodelet).
  c.mesh_extrapolate_voxels = 6.0;
  EXPECT_EQ(c.validate(), "");
  EXPECT_NE(c.inertSettings().find("mesh_extrapolate_voxels 6 acts as truncation_voxels 4"),
            std::string::npos);
  const TriangleMesh capped = meshOf(slabTop(extrapolating(6.0)));
  const TriangleMesh at_truncation = meshOf(slabTop(extrapolating(4.0)));
  EXPECT_EQ(capped.vertices, at_truncation.vertices);
  EXPECT_EQ(capped.triangles, at_truncation.triangles);
}
