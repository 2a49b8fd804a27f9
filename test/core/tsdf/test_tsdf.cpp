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
#include "tsdf_test_scenes.h"

using namespace downstream_perception;

namespace {

TsdfConfig lessonConfig() {
  TsdfConfig c;
  c.voxel_size_m = 1.0;
  c.truncation_voxels = 4.0;  // mu = 4 m
  c.behind_surface_dropoff = false;
  c.max_weight = 0.0;
  c.max_depth_m = 100.0;
  return c;
}

float distanceAt(const TsdfMap& map, int x, int y = 0, int z = 0) {
  const TsdfVoxel* v = map.voxel({x, y, z});
  return v == nullptr ? std::nanf("") : v->distance;
}

using test::planeDepth;
using test::smallCamera;

// Writes D = value(voxel centre) with weight 1 into every voxel of [lo, hi] (inclusive; NaN
// skips the voxel), then marks every block as changed by one integration.
void fill(TsdfMap* map, const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
          const std::function<double(const Eigen::Vector3d&)>& value) {
  for (int z = lo.z(); z <= hi.z(); ++z) {
    for (int y = lo.y(); y <= hi.y(); ++y) {
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const Eigen::Vector3i v(x, y, z);
        const double d = value(map->voxelCenter(v));
        if (std::isnan(d)) continue;
        TsdfVoxel& voxel = map->allocate(TsdfMap::blockOf(v))->voxels[TsdfMap::localIndex(v)];
        voxel.distance = static_cast<float>(d);
        voxel.weight = 1.0f;
      }
    }
  }
  const std::uint64_t generation = map->beginIntegration();
  for (const auto& kv : map->blocks()) kv.second->updated_stamp = generation;
}

TriangleMesh meshOf(const TsdfMap& map) {
  TsdfMesher mesher;
  mesher.update(map);
  return mesher.combined();
}

// Mesh vertices merged by position (block seams duplicate them, bit-identically) and the count
// of each directed edge over the merged ids.
struct MeshEdges {
  std::vector<int> id;
  std::size_t vertices = 0;
  std::map<std::pair<int, int>, int> directed;
};
MeshEdges meshEdges(const TriangleMesh& mesh) {
  MeshEdges e;
  std::map<std::tuple<float, float, float>, int> id_of;
  for (const Eigen::Vector3f& p : mesh.vertices) {
    e.id.push_back(
        id_of.emplace(std::make_tuple(p.x(), p.y(), p.z()), static_cast<int>(id_of.size()))
            .first->second);
  }
  e.vertices = id_of.size();
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      ++e.directed[{e.id[mesh.triangles[3 * t + k]], e.id[mesh.triangles[3 * t + (k + 1) % 3]]}];
    }
  }
  return e;
}

}  // namespace

TEST(Tsdf, LessonFusionTableTwoWrongCamerasOneRightSurface) {
  // The lesson's 1-D example: surface at x = 5, mu = 4, camera A measures 4.5, camera B 5.5,
  // both looking along +x from the origin.
  TsdfMap map(lessonConfig());
  integratePoints(&map, {Eigen::Vector3d(4.5, 0, 0)}, Eigen::Vector3d::Zero());
  const std::vector<float> camera_a = {0.375f, 0.125f, -0.125f, -0.375f, -0.625f};
  for (int x = 3; x <= 7; ++x) EXPECT_NEAR(distanceAt(map, x), camera_a[x - 3], 1e-6) << x;
  integratePoints(&map, {Eigen::Vector3d(5.5, 0, 0)}, Eigen::Vector3d::Zero());
  const std::vector<float> fused = {0.5f, 0.25f, 0.0f, -0.25f, -0.5f};
  for (int x = 3; x <= 7; ++x) {
    EXPECT_NEAR(distanceAt(map, x), fused[x - 3], 1e-6) << x;
    EXPECT_FLOAT_EQ(map.voxel({x, 0, 0})->weight, 2.0f);
  }
  // Sub-voxel crossing between x = 4 (+0.25) and x = 6 (-0.25): exactly 5.0.
  const float d4 = distanceAt(map, 4), d6 = distanceAt(map, 6);
  EXPECT_NEAR(4.0 + 2.0 * d4 / (d4 - d6), 5.0, 1e-9);
  // Unequal weights move the crossing toward the heavier camera: A twice -> 4.833.
  TsdfMap weighted(lessonConfig());
  integratePoints(&weighted, {Eigen::Vector3d(4.5, 0, 0)}, Eigen::Vector3d::Zero());
  integratePoints(&weighted, {Eigen::Vector3d(4.5, 0, 0)}, Eigen::Vector3d::Zero());
  integratePoints(&weighted, {Eigen::Vector3d(5.5, 0, 0)}, Eigen::Vector3d::Zero());
  const float w4 = distanceAt(weighted, 4), w5 = distanceAt(weighted, 5);
  EXPECT_NEAR(4.0 + w4 / (w4 - w5), 4.0 + 0.5 / 0.6, 1e-6);  // D4 = 5/24, D5 = -1/24
}

TEST(Tsdf, MaxWeightKeepsTheMapResponsive) {
  TsdfConfig c = lessonConfig();
  c.max_weight = 2.0;
  TsdfMap map(c);
  for (int k = 0; k < 10; ++k) integratePoints(&map, {Eigen::Vector3d(4.5, 0, 0)}, {0, 0, 0});
  EXPECT_FLOAT_EQ(map.voxel({5, 0, 0})->weight, 2.0f);
  // The surface moves to 5.5: with the cap a few frames pull the field over (w 2 vs 1 each).
  for (int k = 0; k < 6; ++k) integratePoints(&map, {Eigen::Vector3d(5.5, 0, 0)}, {0, 0, 0});
  EXPECT_GT(distanceAt(map, 5), 0.1f);  // 5 is now in front of the surface
}

TEST(Tsdf, LiveSettingsChangeButTheLatticeDoesNot) {
  TsdfConfig c = lessonConfig();
  c.max_weight = 0.0;
  TsdfMap map(c);
  for (int k = 0; k < 5; ++k) integratePoints(&map, {Eigen::Vector3d(4.5, 0, 0)}, {0, 0, 0});
  EXPECT_FLOAT_EQ(map.voxel({5, 0, 0})->weight, 5.0f);
  // A cap set live applies to the next fusion.
  TsdfConfig capped = map.config();
  capped.max_weight = 3.0;
  EXPECT_EQ(map.setConfig(capped), "");
  integratePoints(&map, {Eigen::Vector3d(4.5, 0, 0)}, {0, 0, 0});
  EXPECT_FLOAT_EQ(map.voxel({5, 0, 0})->weight, 3.0f);
  // The lattice is fixed, and an invalid config changes nothing.
  TsdfConfig other = map.config();
  other.voxel_size_m *= 2.0;
  EXPECT_NE(map.setConfig(other).find("fixed"), std::string::npos);
  other = map.config();
  other.min_depth_m = other.max_depth_m + 1.0;
  EXPECT_FALSE(map.setConfig(other).empty());
  EXPECT_EQ(map.config().max_weight, 3.0);
  EXPECT_EQ(map.config().min_depth_m, capped.min_depth_m);
}

TEST(Tsdf, DepthImageOfAFrontoParallelPlaneMeshesAtItsDepth) {
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  TsdfMap map(c);
  const PinholeCamera camera = smallCamera();
  const double plane_z = 1.013;  // deliberately between voxel centres
  const std::vector<float> depth = planeDepth(camera, Eigen::Vector3d::UnitZ(), plane_z);
  const TsdfIntegrationStats stats =
      integrateDepth(&map, depth.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_EQ(stats.pixels_valid, 160u * 120u);
  EXPECT_GT(stats.voxels_updated, 0u);
  EXPECT_EQ(stats.blocks_allocated, map.blockCount());
  TsdfMesher mesher;
  mesher.update(map);
  const TriangleMesh mesh = mesher.combined();
  ASSERT_GT(mesh.triangleCount(), 100u);
  double worst = 0.0;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    worst = std::max(worst, std::abs(mesh.vertices[i].z() - plane_z));
    EXPECT_LT(mesh.normals[i].z(), -0.99f);  // toward the camera (free space)
  }
  EXPECT_LT(worst, 2e-4);  // 0.2 mm at 5 cm voxels
}

TEST(Tsdf, CarvingErasesWhatMovedAway) {
  // A wall 1.013 m ahead, seen 5 times, then gone: 10 frames see the wall behind it at 2.013 m.
  // Only the band around each depth is updated by default, so the first wall stays in the map
  // (its voxels are more than mu in front of the second); carving updates whole rays and
  // erases it. An all-"no return" frame carves up to max_depth_m.
  const PinholeCamera camera = smallCamera();
  const std::vector<float> near_wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.013);
  const std::vector<float> far_wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 2.013);
  const auto run = [&](bool carve, std::size_t* blocks) {
    TsdfConfig c;
    c.voxel_size_m = 0.05;
    c.carve_free_space = carve;
    TsdfMap map(c);
    DepthIntegrator integrator;
    for (int k = 0; k < 5; ++k) {
      integrator.integrate(&map, near_wall.data(), camera, Eigen::Isometry3d::Identity());
    }
    for (int k = 0; k < 10; ++k) {
      integrator.integrate(&map, far_wall.data(), camera, Eigen::Isometry3d::Identity());
    }
    *blocks = map.blockCount();
    TsdfMesher mesher;
    mesher.update(map);
    const TriangleMesh mesh = mesher.combined();
    std::size_t near = 0, far = 0;
    for (const Eigen::Vector3f& v : mesh.vertices) {
      near += std::abs(v.z() - 1.013f) < 0.03f;
      far += std::abs(v.z() - 2.013f) < 0.03f;
    }
    return std::make_pair(near, far);
  };
  std::size_t band_blocks = 0, carved_blocks = 0;
  const auto [band_near, band_far] = run(false, &band_blocks);
  const auto [carved_near, carved_far] = run(true, &carved_blocks);
  EXPECT_GT(band_near, 100u);  // the ghost of the first wall
  EXPECT_GT(band_far, 100u);
  EXPECT_EQ(carved_near, 0u);  // erased
  EXPECT_GT(carved_far, 100u);
  EXPECT_GT(carved_blocks, band_blocks);  // the free space in front of the walls is allocated

  // No return anywhere: free along every ray up to max_depth_m, only with carving, and only
  // when the frame's returns need not be evidence (no_return_carve_min_valid_fraction 0; see
  // NoReturnFrameWithoutReturnsCarvesNothing for the default).
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.max_depth_m = 3.0;
  const std::vector<float> nothing(near_wall.size(), std::numeric_limits<float>::infinity());
  TsdfMap plain(c);
  integrateDepth(&plain, nothing.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_EQ(plain.blockCount(), 0u);
  c.carve_free_space = true;
  c.no_return_carve_min_valid_fraction = 0.0;
  TsdfMap carved(c);
  const TsdfIntegrationStats stats =
      integrateDepth(&carved, nothing.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_GT(stats.voxels_updated, 1000u);
  for (const double z : {0.5, 1.5, 2.9}) {  // on the optical axis, up to max_depth_m
    const TsdfVoxel* v = carved.voxel(carved.voxelAt({0.0, 0.0, z}));
    ASSERT_NE(v, nullptr) << z;
    EXPECT_EQ(v->distance, 1.0f) << z;
  }
  EXPECT_EQ(carved.voxel(carved.voxelAt({0.0, 0.0, 3.3})), nullptr);
}

TEST(Tsdf, DepthIntegratorReusedAcrossFramesEqualsFreshIntegration) {
  // One DepthIntegrator keeps its per-pixel buffers between frames. Frames of another size,
  // with the edge guard and interpolation switched off and on again between them, must give
  // bit for bit the maps a fresh integration of each frame gives: nothing stale may leak.
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  TsdfMap reused(c), fresh(c);
  DepthIntegrator integrator;
  const PinholeCamera big = smallCamera();
  PinholeCamera little = big;
  little.width = 80;
  little.height = 60;
  little.fx = little.fy = 75.0;
  little.cx = 39.5;
  little.cy = 29.5;
  // A slanted wall with a nearer box in front of it (depth edges), a hole and a no-return
  // patch.
  const auto scene = [](const PinholeCamera& camera, double wall_z) {
    std::vector<float> depth =
        planeDepth(camera, Eigen::Vector3d(0.3, 0.2, 1.0).normalized(), wall_z);
    for (int v = camera.height / 4; v < camera.height / 2; ++v) {
      for (int u = camera.width / 3; u < camera.width / 2; ++u) {
        depth[static_cast<std::size_t>(v) * camera.width + u] = static_cast<float>(wall_z - 0.6);
      }
    }
    depth[5] = std::nanf("");
    for (int u = 0; u < camera.width / 4; ++u) {
      depth[static_cast<std::size_t>(camera.height - 1) * camera.width + u] =
          std::numeric_limits<float>::infinity();
    }
    return depth;
  };
  struct Frame {
    PinholeCamera camera;
    double wall_z;
    bool guard_and_interpolation;
  };
  const Frame frames[] = {
      {big, 2.0, true}, {little, 2.2, false}, {big, 1.9, true}, {little, 2.1, true}};
  for (const Frame& f : frames) {
    TsdfConfig next = c;
    next.edge_guard_rad = f.guard_and_interpolation ? 0.02 : 0.0;
    next.interpolate_depth = f.guard_and_interpolation;
    ASSERT_TRUE(reused.setConfig(next).empty());
    ASSERT_TRUE(fresh.setConfig(next).empty());
    const std::vector<float> depth = scene(f.camera, f.wall_z);
    Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
    T_map_camera.translation().x() = 0.03 * f.wall_z;
    const TsdfIntegrationStats a =
        integrator.integrate(&reused, depth.data(), f.camera, T_map_camera);
    const TsdfIntegrationStats b = integrateDepth(&fresh, depth.data(), f.camera, T_map_camera);
    EXPECT_EQ(a.voxels_updated, b.voxels_updated);
    EXPECT_EQ(a.pixels_valid, b.pixels_valid);
    EXPECT_EQ(a.pixels_invalid, b.pixels_invalid);
    EXPECT_EQ(a.pixels_no_return, b.pixels_no_return);
    EXPECT_GT(a.voxels_updated, 0u);
  }
  ASSERT_EQ(reused.blockCount(), fresh.blockCount());
  std::size_t compared = 0;
  for (const auto& kv : fresh.blocks()) {
    const TsdfBlock* other = reused.find(kv.first);
    ASSERT_NE(other, nullptr);
    for (int i = 0; i < kTsdfBlockVoxels; ++i) {
      ASSERT_EQ(kv.second->voxels[i].distance, other->voxels[i].distance);
      ASSERT_EQ(kv.second->voxels[i].weight, other->voxels[i].weight);
      compared += kv.second->voxels[i].weight > 0.0f;
    }
  }
  EXPECT_GT(compared, 1000u);
}

TEST(Tsdf, EveryVoxelHoldsTheProjectiveUpdateOfItsPixel) {
  // The integrator works on rows of eight voxels in passes and keeps earlier rows' values in
  // its per-voxel scratch. Checked here against the update written out voxel by voxel in double
  // precision: after one frame every voxel of every allocated block holds what its own pixel
  // gives (or is untouched). Voxels within rounding of a decision (a pixel border, the band's
  // end) are left out.
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.edge_guard_rad = 0.0;
  const PinholeCamera camera = smallCamera();
  std::vector<float> depth = planeDepth(camera, Eigen::Vector3d(0.3, 0.2, 1.0).normalized(), 2.0);
  for (int v = 20; v < 60; ++v) {
    for (int u = 50; u < 80; ++u) depth[static_cast<std::size_t>(v) * camera.width + u] = 1.3f;
  }
  for (int u = 0; u < 40; ++u) {
    depth[static_cast<std::size_t>(camera.height - 1) * camera.width + u] =
        std::numeric_limits<float>::infinity();
    depth[static_cast<std::size_t>(u + 30) * camera.width + 100] = std::nanf("");
  }
  Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
  T_map_camera.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.4).normalized()).toRotationMatrix();
  T_map_camera.translation() = Eigen::Vector3d(0.11, -0.07, 0.23);
  const double s = c.voxel_size_m, mu = c.truncation();
  const auto valid = [&](float d) { return d >= c.min_depth_m && d <= c.max_depth_m; };
  for (const bool interpolate : {false, true}) {
    c.interpolate_depth = interpolate;
    TsdfMap map(c);
    const TsdfIntegrationStats stats = integrateDepth(&map, depth.data(), camera, T_map_camera);
    std::size_t checked = 0, updated = 0;
    for (const auto& kv : map.blocks()) {
      for (int i = 0; i < kTsdfBlockVoxels; ++i) {
        const Eigen::Vector3i voxel =
            kv.first * kTsdfBlockSide + Eigen::Vector3i(i % 8, (i / 8) % 8, i / 64);
        const Eigen::Vector3d p = T_map_camera.inverse() * map.voxelCenter(voxel);
        const double u = camera.fx * p.x() / p.z() + camera.cx + 0.5;
        const double v = camera.fy * p.y() / p.z() + camera.cy + 0.5;
        const auto nearInteger = [](double a) { return std::abs(a - std::round(a)) < 1e-3; };
        if (nearInteger(u) || nearInteger(v) || std::abs(p.z() - c.min_depth_m) < 1e-4) continue;
        double expected_d = 0.0, expected_w = 0.0;  // weight 0: not updated
        const bool in_view =
            p.z() >= c.min_depth_m && u >= 0.0 && v >= 0.0 && u < camera.width && v < camera.height;
        const std::size_t px =
            in_view ? static_cast<std::size_t>(v) * camera.width + static_cast<std::size_t>(u) : 0;
        const float nearest = depth[px];
        double sdf = std::nan("");
        if (in_view && nearest == std::numeric_limits<float>::infinity()) {
          if (p.z() <= c.max_depth_m) sdf = mu;  // no return: free space
        } else if (in_view && valid(nearest)) {
          double d = nearest;
          const double uf = u - 0.5, vf = v - 0.5;
          const int u0 = static_cast<int>(uf), v0 = static_cast<int>(vf);
          if (interpolate && uf >= 0.0 && vf >= 0.0 && u0 + 1 < camera.width &&
              v0 + 1 < camera.height) {
            const std::size_t k = static_cast<std::size_t>(v0) * camera.width + u0;
            const float q[4] = {depth[k], depth[k + 1], depth[k + camera.width],
                                depth[k + camera.width + 1]};
            if (std::all_of(q, q + 4, valid) &&
                *std::max_element(q, q + 4) - *std::min_element(q, q + 4) <= s) {
              const double a = uf - u0, b = vf - v0;
              d = 1.0 / ((1 - b) * ((1 - a) / q[0] + a / q[1]) + b * ((1 - a) / q[2] + a / q[3]));
            }
          }
          const double x = (static_cast<int>(u) - camera.cx) / camera.fx;
          const double y = (static_cast<int>(v) - camera.cy) / camera.fy;
          sdf = std::min(mu, (d - p.z()) * std::sqrt(1.0 + x * x + y * y));
          if (std::abs(sdf + mu) < 1e-4) continue;
          if (sdf < -mu) sdf = std::nan("");
        }
        if (!std::isnan(sdf)) {
          expected_d = std::min(1.0, sdf / mu);
          expected_w = sdf < -s ? (mu + sdf) / (mu - s) : 1.0;  // behind-surface drop-off
        }
        const TsdfVoxel& got = kv.second->voxels[i];
        ASSERT_NEAR(got.weight, expected_w, 1e-4) << "voxel " << voxel.transpose();
        if (expected_w > 0.0) {
          ASSERT_NEAR(got.distance, expected_d, 1e-4) << "voxel " << voxel.transpose();
          ++updated;
        }
        ++checked;
      }
    }
    EXPECT_GT(updated, 15000u);
    EXPECT_GT(checked, updated + 15000u);  // also many voxels the frame leaves untouched
    EXPECT_GE(stats.voxels_updated, updated);
  }
}

TEST(Tsdf, ObliquePlaneFromSeveralViewsIsUnbiased) {
  // Nearest-pixel rounding (not truncation) and the range-along-ray sdf: vertices of a plane
  // tilted 40 degrees, fused from three camera positions, lie on it (no half-pixel bias).
  TsdfConfig c;
  c.voxel_size_m = 0.02;
  TsdfMap map(c);
  const PinholeCamera camera = smallCamera();
  const Eigen::Vector3d n_map = Eigen::Vector3d(0.0, std::sin(0.7), -std::cos(0.7));
  const double offset_map = -1.5;  // plane n . p = offset in the map frame
  for (double shift : {-0.2, 0.0, 0.2}) {
    Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
    T_map_camera.translation() = Eigen::Vector3d(shift, 0.0, 0.0);
    // In the camera frame (translation only): n . (p_c + t) = offset.
    const double offset_camera = offset_map - n_map.dot(T_map_camera.translation());
    const std::vector<float> depth = planeDepth(camera, n_map, offset_camera);
    integrateDepth(&map, depth.data(), camera, T_map_camera);
  }
  TsdfMesher mesher;
  mesher.update(map);
  const TriangleMesh mesh = mesher.combined();
  ASSERT_GT(mesh.vertices.size(), 1000u);
  double sum = 0.0, sum_abs = 0.0;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    const double e = n_map.dot(v.cast<double>()) - offset_map;
    sum += e;
    sum_abs += std::abs(e);
  }
  const double n = static_cast<double>(mesh.vertices.size());
  EXPECT_LT(std::abs(sum / n), 2e-4);  // bias < 0.2 mm
  EXPECT_LT(sum_abs / n, 1e-3);        // mean error < 1 mm at 2 cm voxels
}

TEST(Tsdf, InvalidDepthsAreCountedNotFused) {
  TsdfMap map;
  PinholeCamera camera = smallCamera();
  camera.width = 4;
  camera.height = 1;
  camera.cx = 1.5;
  camera.cy = 0.0;
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> depth = {std::nanf(""), 0.0f, -inf, inf};
  const TsdfIntegrationStats s =
      integrateDepth(&map, depth.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_EQ(s.pixels_invalid, 3u);
  EXPECT_EQ(s.pixels_no_return, 1u);
  EXPECT_EQ(s.pixels_valid, 0u);
  EXPECT_EQ(map.blockCount(), 0u);  // no return alone allocates nothing
  PinholeCamera bad = camera;
  bad.fx = std::nan("");
  EXPECT_FALSE(bad.validate().empty());
  TsdfConfig absurd;
  absurd.voxel_size_m = -1.0;
  EXPECT_THROW(TsdfMap{absurd}, std::invalid_argument);
  absurd = TsdfConfig{};
  absurd.min_depth_m = 5.0;
  absurd.max_depth_m = 1.0;
  EXPECT_FALSE(absurd.validate().empty());
}

TEST(Tsdf, MemoryIsBoundedByMaxBlocksAndDistance) {
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.max_blocks = 10;
  TsdfMap capped(c);
  const PinholeCamera camera = smallCamera();
  const std::vector<float> depth = planeDepth(camera, Eigen::Vector3d::UnitZ(), 2.0);
  const TsdfIntegrationStats s =
      integrateDepth(&capped, depth.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_EQ(capped.blockCount(), 10u);
  EXPECT_GT(s.blocks_refused, 0u);
  EXPECT_GT(capped.memoryBytes(), 10 * sizeof(TsdfBlock) - 1);

  c.max_blocks = 100000;
  c.max_block_distance_m = 1.0;  // the plane at 2 m is beyond: all evicted
  TsdfMap near(c);
  const TsdfIntegrationStats e =
      integrateDepth(&near, depth.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_GT(e.blocks_evicted, 0u);
  EXPECT_EQ(near.blockCount(), 0u);
  // Evicted blocks' memory stays for reuse (the pool keeps its peak); clear() returns it.
  EXPECT_GE(near.memoryBytes(), TsdfBlockPool::kChunkBytes);
  capped.clear();
  EXPECT_LT(capped.memoryBytes(), TsdfBlockPool::kChunkBytes);
}

TEST(TsdfBlockPool, ReusesReleasedBlocksZeroedAndFreesChunksWhenEmpty) {
  TsdfBlockPool pool;
  const std::size_t per_chunk = TsdfBlockPool::blocksPerChunk();
  EXPECT_GE(per_chunk, 500u);  // 2 MiB of 4,104-byte blocks
  std::vector<TsdfBlockPool::Ptr> blocks;
  for (std::size_t i = 0; i < per_chunk + 3; ++i) {
    blocks.push_back(pool.acquire());
    blocks.back()->voxels[7].distance = static_cast<float>(i);
    blocks.back()->voxels[kTsdfBlockVoxels - 1].weight = 1.0f;
    blocks.back()->updated_stamp = i + 1;
  }
  EXPECT_EQ(pool.bytesReserved(), 2 * TsdfBlockPool::kChunkBytes);
  EXPECT_EQ(pool.blocksInUse(), per_chunk + 3);
  for (std::size_t i = 0; i < blocks.size(); ++i) {  // no block overlaps another
    ASSERT_EQ(blocks[i]->voxels[7].distance, static_cast<float>(i));
    ASSERT_EQ(blocks[i]->updated_stamp, i + 1);
  }
  for (std::size_t i = 0; i < blocks.size(); i += 2) blocks[i].reset();
  pool.trim();  // blocks in use: nothing to give back
  EXPECT_EQ(pool.bytesReserved(), 2 * TsdfBlockPool::kChunkBytes);
  for (std::size_t i = 0; i < blocks.size(); i += 2) {
    blocks[i] = pool.acquire();  // a reused slot, zeroed
    EXPECT_EQ(blocks[i]->voxels[7].distance, 0.0f);
    EXPECT_EQ(blocks[i]->voxels[kTsdfBlockVoxels - 1].weight, 0.0f);
    EXPECT_EQ(blocks[i]->updated_stamp, 0u);
  }
  EXPECT_EQ(pool.bytesReserved(), 2 * TsdfBlockPool::kChunkBytes);
  blocks.clear();
  EXPECT_EQ(pool.blocksInUse(), 0u);
  pool.trim();
  EXPECT_EQ(pool.bytesReserved(), 0u);
}

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
  EXPECT_THROW(sliceDistance(cells, grid, 1.8e308), std::invalid_argument);  // +Inf as float
  cells.pop_back();
  EXPECT_THROW(sliceDistance(cells, grid, cap), std::invalid_argument);
}

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

namespace {

/// Voxels (weight or distance) that differ between two maps, over the union of their blocks.
std::size_t differingVoxels(const TsdfMap& a, const TsdfMap& b) {
  std::size_t n = 0;
  const auto count = [&n](const TsdfMap& x, const TsdfMap& y, bool both_ways) {
    for (const auto& kv : x.blocks()) {
      const TsdfBlock* other = y.find(kv.first);
      if (other == nullptr) {
        n += kTsdfBlockVoxels;
        continue;
      }
      if (!both_ways) continue;
      for (int i = 0; i < kTsdfBlockVoxels; ++i) {
        n += kv.second->voxels[i].distance != other->voxels[i].distance ||
             kv.second->voxels[i].weight != other->voxels[i].weight;
      }
    }
  };
  count(a, b, true);
  count(b, a, false);
  return n;
}

}  // namespace

TEST(Tsdf, NoReturnFrameWithoutReturnsCarvesNothing) {
  // Carving, ten frames of a wall 1.013 m ahead with one frame without any return (+Inf
  // everywhere: a failing sensor) in the middle. That frame carries no evidence (no valid depth):
  // its +Inf pixels are ignored and counted, and the map is bit for bit the map without it.
  // With no_return_carve_min_valid_fraction 0 the frame carves through the wall.
  const PinholeCamera camera = smallCamera();
  const std::vector<float> wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.013);
  const std::vector<float> nothing(wall.size(), std::numeric_limits<float>::infinity());
  const auto run = [&](bool bad_frame, double fraction, TsdfIntegrationStats* bad_stats) {
    TsdfConfig c;
    c.voxel_size_m = 0.05;
    c.carve_free_space = true;
    c.no_return_carve_min_valid_fraction = fraction;
    auto map = std::make_unique<TsdfMap>(c);
    DepthIntegrator integrator;
    for (int k = 0; k < 10; ++k) {
      integrator.integrate(map.get(), wall.data(), camera, Eigen::Isometry3d::Identity());
      if (bad_frame && k == 4) {
        *bad_stats =
            integrator.integrate(map.get(), nothing.data(), camera, Eigen::Isometry3d::Identity());
      }
    }
    return map;
  };
  TsdfIntegrationStats bad;
  const auto reference = run(false, 0.5, &bad);
  const auto guarded = run(true, 0.5, &bad);
  EXPECT_EQ(bad.pixels_no_return, wall.size());
  EXPECT_EQ(bad.pixels_no_return_ignored, wall.size());
  EXPECT_EQ(bad.voxels_updated, 0u);
  EXPECT_EQ(bad.blocks_allocated, 0u);
  EXPECT_EQ(guarded->blockCount(), reference->blockCount());
  EXPECT_EQ(differingVoxels(*reference, *guarded), 0u);
  const auto unguarded = run(true, 0.0, &bad);
  EXPECT_EQ(bad.pixels_no_return_ignored, 0u);
  EXPECT_GT(differingVoxels(*reference, *unguarded), 1000u);  // carved through the wall

  // Half the frame returns (the left half sees the wall), half is +Inf: at the default 0.5 the
  // returns are evidence enough, the +Inf rays carve; at 0.6 they do not.
  std::vector<float> half = wall;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = camera.width / 2; u < camera.width; ++u) {
      half[static_cast<std::size_t>(v) * camera.width + u] = std::numeric_limits<float>::infinity();
    }
  }
  const Eigen::Vector3d on_inf_ray(1.2, 0.0, 2.5);  // x/z = 0.48: the image's right half
  for (const double fraction : {0.5, 0.6}) {
    TsdfConfig c;
    c.voxel_size_m = 0.05;
    c.carve_free_space = true;
    c.no_return_carve_min_valid_fraction = fraction;
    TsdfMap map(c);
    const TsdfIntegrationStats s =
        integrateDepth(&map, half.data(), camera, Eigen::Isometry3d::Identity());
    const TsdfVoxel* v = map.voxelNear(on_inf_ray);
    if (fraction == 0.5) {
      EXPECT_EQ(s.pixels_no_return_ignored, 0u);
      ASSERT_NE(v, nullptr);
      EXPECT_EQ(v->distance, 1.0f);
    } else {
      EXPECT_EQ(s.pixels_no_return_ignored, half.size() / 2);
      EXPECT_TRUE(v == nullptr || v->weight == 0.0f);
    }
  }
  TsdfConfig bad_fraction;
  bad_fraction.no_return_carve_min_valid_fraction = 1.5;
  EXPECT_NE(bad_fraction.validate().find("no_return_carve_min_valid_fraction"), std::string::npos);
}

TEST(Tsdf, CameraWithAPrincipalPointFarOutsideOrAnAbsurdViewIsRefused) {
  PinholeCamera far = smallCamera();
  far.cx = 1e7;  // made one carving frame allocate every block the map allowed
  EXPECT_NE(far.validate().find("principal point"), std::string::npos) << far.validate();
  PinholeCamera edge = smallCamera();
  edge.cx = 3.0 * edge.width;  // two image widths beyond the image: still accepted
  edge.cy = -2.0 * edge.height;
  EXPECT_EQ(edge.validate(), "");
  edge.cy -= 1.0;
  EXPECT_NE(edge.validate().find("principal point"), std::string::npos);
  PinholeCamera wide = smallCamera();
  wide.fx = 5.0;  // the image's edge 16 focal lengths off the axis
  EXPECT_NE(wide.validate().find("view too wide"), std::string::npos) << wide.validate();

  // The integrator refuses such a frame itself (a caller that did not validate): nothing
  // allocated, every pixel counted invalid.
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.carve_free_space = true;
  c.max_blocks = 2000;
  TsdfMap map(c);
  const std::vector<float> depth(static_cast<std::size_t>(far.width) * far.height, 1.0f);
  const TsdfIntegrationStats s =
      integrateDepth(&map, depth.data(), far, Eigen::Isometry3d::Identity());
  ASSERT_NE(s.refused, nullptr);
  EXPECT_EQ(map.blockCount(), 0u);
  EXPECT_EQ(s.pixels_invalid, depth.size());
  EXPECT_EQ(s.pixels_valid, 0u);
}

TEST(Tsdf, CarvedBlocksLieInTheViewFrustum) {
  // An off-axis camera (principal point an image width left of the image: every ray points
  // right), a wall and a no-return patch, carving up to max_depth_m: every allocated block
  // touches the view frustum between the camera and max_depth_m (checked on the frustum grown
  // by a block's half diagonal and mu).
  PinholeCamera camera = smallCamera();
  camera.cx = -camera.width;
  ASSERT_EQ(camera.validate(), "");
  std::vector<float> depth = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.5);
  for (std::size_t i = 0; i < depth.size() / 4; ++i) {
    depth[i] = std::numeric_limits<float>::infinity();
  }
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.carve_free_space = true;
  c.max_depth_m = 3.0;
  TsdfMap map(c);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).matrix();
  T.translation() = Eigen::Vector3d(0.4, -0.2, 0.7);
  const TsdfIntegrationStats s = integrateDepth(&map, depth.data(), camera, T);
  ASSERT_GT(s.blocks_allocated, 100u);
  const double block_m = kTsdfBlockSide * c.voxel_size_m;
  const double margin = 0.5 * std::sqrt(3.0) * block_m + c.truncation();
  const double x_lo = (-0.5 - camera.cx) / camera.fx,
               x_hi = (camera.width - 0.5 - camera.cx) / camera.fx;
  const double y_lo = (-0.5 - camera.cy) / camera.fy,
               y_hi = (camera.height - 0.5 - camera.cy) / camera.fy;
  const Eigen::Isometry3d T_camera_map = T.inverse();
  for (const auto& kv : map.blocks()) {
    const Eigen::Vector3d centre =
        T_camera_map * ((kv.first.cast<double>() + Eigen::Vector3d::Constant(0.5)) * block_m -
                        Eigen::Vector3d::Constant(0.5 * c.voxel_size_m));
    const double z = std::max(centre.z(), 0.0);
    ASSERT_GT(centre.z(), -margin);
    ASSERT_LT(centre.z(), c.max_depth_m + margin);
    ASSERT_GT(centre.x(), x_lo * z - margin) << kv.first.transpose();
    ASSERT_LT(centre.x(), x_hi * z + margin) << kv.first.transpose();
    ASSERT_GT(centre.y(), y_lo * z - margin);
    ASSERT_LT(centre.y(), y_hi * z + margin);
  }
}

TEST(Tsdf, FarAndNanPointsAreInvalidNotOverflowed) {
  // Points, sensor origins and camera poses whose voxel index would not fit in an int (5e9
  // voxels at 2 cm: 1e8 m) or NaN are refused and counted as invalid; before, the float-to-int
  // conversion overflowed (undefined; in practice blocks at INT_MIN were allocated).
  TsdfMap map;
  const double far = 1e8;
  const std::vector<Eigen::Vector3d> near_far_origin = {Eigen::Vector3d(far + 1.0, 0.0, 0.0)};
  TsdfIntegrationStats s = integratePoints(&map, near_far_origin, Eigen::Vector3d(far, 0.0, 0.0));
  EXPECT_NE(s.refused, nullptr);
  EXPECT_EQ(s.pixels_invalid, 1u);
  EXPECT_EQ(s.pixels_valid, 0u);
  EXPECT_EQ(map.blockCount(), 0u);
  const double nan = std::nan("");
  s = integratePoints(&map, {Eigen::Vector3d(nan, 0.0, 1.0), Eigen::Vector3d(0.0, 0.0, 1.0)},
                      Eigen::Vector3d::Zero());
  EXPECT_EQ(s.refused, nullptr);
  EXPECT_EQ(s.pixels_invalid, 1u);
  EXPECT_EQ(s.pixels_valid, 1u);
  const std::size_t blocks = map.blockCount();
  EXPECT_GT(blocks, 0u);
  s = integratePoints(&map, near_far_origin, Eigen::Vector3d(nan, 0.0, 0.0));
  EXPECT_NE(s.refused, nullptr);

  const PinholeCamera camera = smallCamera();
  const std::vector<float> wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = far;
  s = integrateDepth(&map, wall.data(), camera, T);
  EXPECT_NE(s.refused, nullptr);
  EXPECT_EQ(s.pixels_invalid, wall.size());
  T.translation().x() = 0.0;
  T.linear()(0, 0) = nan;
  s = integrateDepth(&map, wall.data(), camera, T);
  EXPECT_NE(s.refused, nullptr);
  EXPECT_EQ(map.blockCount(), blocks);

  // Queries: no voxel for far or NaN points (voxelAt clamps instead of overflowing).
  EXPECT_NE(map.voxelNear(Eigen::Vector3d(0.0, 0.0, 1.0)), nullptr);
  EXPECT_EQ(map.voxelNear(Eigen::Vector3d(nan, 0.0, 1.0)), nullptr);
  EXPECT_EQ(map.voxelNear(Eigen::Vector3d(1e300, 0.0, 1.0)), nullptr);
  EXPECT_EQ(map.voxelAt(Eigen::Vector3d(-1e300, nan, 0.02)),
            Eigen::Vector3i(-TsdfMap::kMaxVoxelIndex, 0, 1));
  // Any index, even INT_MIN, gives its block without overflow.
  const int lowest = std::numeric_limits<int>::min();
  EXPECT_EQ(TsdfMap::blockOf(Eigen::Vector3i(lowest, -1, -9)),
            Eigen::Vector3i(lowest / kTsdfBlockSide, -1, -2));
  EXPECT_EQ(TsdfMap::localIndex(Eigen::Vector3i(lowest, -1, -9)), TsdfBlock::linear(0, 7, 7));
  EXPECT_FALSE(map.inBounds(Eigen::Vector3d(far, 0.0, 0.0)));
  EXPECT_TRUE(map.inBounds(Eigen::Vector3d(1e6, -1e6, 1e6)));
}

TEST(Tsdf, LoweringMaxBlocksLiveEvictsTheLeastRecentlyUpdatedFirst) {
  // Two walls seen from cameras 5 m apart, the second later: lowering max_blocks to the number
  // of blocks the second frame updated evicts all others (the first frame's, and blocks
  // allocated but never updated); lowering it further evicts, among the equally recent blocks,
  // the farthest from the last camera.
  const PinholeCamera camera = smallCamera();
  const std::vector<float> wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.0);
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  TsdfMap map(c);
  Eigen::Isometry3d first = Eigen::Isometry3d::Identity(), second = first;
  second.translation().x() = 5.0;
  integrateDepth(&map, wall.data(), camera, first);
  const std::size_t first_count = map.blockCount();
  integrateDepth(&map, wall.data(), camera, second);
  const std::size_t total = map.blockCount();
  std::size_t second_count = 0;
  for (const auto& kv : map.blocks()) second_count += kv.second->updated_stamp == map.generation();
  ASSERT_GT(first_count, 10u);
  ASSERT_GT(second_count, 10u);
  ASSERT_LT(second_count, total - first_count + 1);
  TsdfConfig lower = c;
  lower.max_blocks = second_count;
  ASSERT_EQ(map.setConfig(lower), "");
  EXPECT_EQ(map.blockCount(), second_count);
  EXPECT_EQ(map.blocksEvictedToCap(), total - second_count);
  for (const auto& kv : map.blocks()) EXPECT_EQ(kv.second->updated_stamp, map.generation());
  const auto distances = [&map](const TsdfMap& m) {
    std::vector<double> d;
    const double block_m = kTsdfBlockSide * m.voxelSize();
    for (const auto& kv : m.blocks()) {
      d.push_back(((kv.first.cast<double>() + Eigen::Vector3d::Constant(0.5)) * block_m -
                   map.sensorOrigin())
                      .norm());
    }
    return d;
  };
  const std::vector<double> before = distances(map);
  lower.max_blocks = second_count / 2;
  ASSERT_EQ(map.setConfig(lower), "");
  EXPECT_EQ(map.blockCount(), second_count / 2);
  EXPECT_EQ(map.blocksEvictedToCap(), total - second_count / 2);
  const std::vector<double> after = distances(map);
  std::vector<double> sorted = before;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_LE(*std::max_element(after.begin(), after.end()), sorted[after.size() - 1]);
  // The cap holds from then on: a new frame allocates nothing beyond it.
  const TsdfIntegrationStats s = integrateDepth(&map, wall.data(), camera, first);
  EXPECT_EQ(map.blockCount(), second_count / 2);
  EXPECT_GT(s.blocks_refused, 0u);
}
