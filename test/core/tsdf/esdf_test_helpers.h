// The ESDF gtests' fixtures: the anchors' room as an exact signed distance function (walls, a
// box, a floating sphere, a thin pole), a sphere-tracing depth renderer of it, camera poses on a
// circle, and the brute-force oracle the ESDF must match voxel for voxel.
#pragma once

#include <Eigen/Geometry>

#include <algorithm>
#include <climits>
#include <cmath>
#include <vector>

#include "downstream_perception/core/tsdf/distance_transform_3d.h"
#include "downstream_perception/core/tsdf/esdf.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "tsdf_test_helpers.h"

namespace downstream_perception {
namespace test {

inline double boxSdf(const Eigen::Vector3d& p, const Eigen::Vector3d& c, const Eigen::Vector3d& h) {
  const Eigen::Vector3d q = (p - c).cwiseAbs() - h;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

/// The room of sim.depth_camera.room_scene (4 x 4 x 3 m; box, table top, floating sphere, 3 cm
/// pole), shifted by `offset`; exact signed distance, positive in free space. `with_box`
/// false: the box has been taken away.
struct RoomScene {
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  bool with_box = true;

  double operator()(const Eigen::Vector3d& world) const {
    const Eigen::Vector3d p = world - offset;
    const Eigen::Vector3d room_lo(-2.0, -2.0, 0.0), room_hi(2.0, 2.0, 3.0);
    double d = std::min((p - room_lo).minCoeff(), (room_hi - p).minCoeff());
    if (with_box) d = std::min(d, boxSdf(p, {0.8, 0.6, 0.35}, {0.3, 0.25, 0.35}));
    d = std::min(d, boxSdf(p, {-0.8, 0.7, 0.74}, {0.4, 0.3, 0.02}));
    d = std::min(d, (p - Eigen::Vector3d(-0.5, -0.6, 1.2)).norm() - 0.3);
    const double radial = (p.head<2>() - Eigen::Vector2d(0.4, -0.9)).norm() - 0.03;
    const double vertical = std::abs(p.z() - 1.0) - 1.0;
    const double outside = Eigen::Vector2d(std::max(radial, 0.0), std::max(vertical, 0.0)).norm();
    return std::min(d, outside + std::min(std::max(radial, vertical), 0.0));
  }
};

/// The room's exact SDF written into a TSDF at `voxel_m`: D = clamp(sdf / mu), observed down to
/// mu behind every surface (deeper voxels stay unknown, as the weight drop-off leaves them).
inline TsdfMap filledRoom(double voxel_m, const RoomScene& scene) {
  TsdfConfig c;
  c.voxel_size_m = voxel_m;
  TsdfMap map(c);
  const double mu = c.truncation();
  const int lo = static_cast<int>(std::floor(-2.4 / voxel_m));
  const int hi = static_cast<int>(std::ceil(2.4 / voxel_m));
  fill(&map, {lo, lo, static_cast<int>(std::floor(-0.4 / voxel_m))},
       {hi, hi, static_cast<int>(std::ceil(3.4 / voxel_m))}, [&](const Eigen::Vector3d& p) {
         const double sdf = scene(p);
         return sdf < -mu ? std::nan("") : std::clamp(sdf / mu, -1.0, 1.0);
       });
  return map;
}

/// T_map_camera of an optical frame (z forward, y down) at `eye` looking at `target`.
inline Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() << x, z.cross(x), z;
  t.translation() = eye;
  return t;
}

/// Pose `i` of `n` on sim.depth_camera.circle_poses' circle (radius 1.4 m, 1.5 m high, looking
/// at (0, 0, 0.6)).
inline Eigen::Isometry3d circlePose(int i, int n) {
  const double a = 2.0 * M_PI * i / n;
  return lookAt({1.4 * std::cos(a), 1.4 * std::sin(a), 1.5}, {0.0, 0.0, 0.6});
}

/// z-depth image of `scene` by sphere tracing each pixel's ray (NaN where nothing is hit).
template <class Sdf>
std::vector<float> renderDepth(const PinholeCamera& camera, const Eigen::Isometry3d& pose,
                               const Sdf& scene) {
  std::vector<float> depth(static_cast<std::size_t>(camera.width) * camera.height, std::nanf(""));
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      const Eigen::Vector3d d = pose.linear() * ray;
      const double len = d.norm();
      double t = 0.0;
      for (int step = 0; step < 400 && t < 10.0; ++step) {
        const double s = scene(pose.translation() + t * d);
        if (s < 1e-5) {
          depth[static_cast<std::size_t>(v) * camera.width + u] = static_cast<float>(t);
          break;
        }
        t += s / len;
      }
    }
  }
  return depth;
}

struct OracleComparison {
  std::size_t known = 0;     ///< observed voxels compared
  std::size_t off = 0;       ///< voxels whose ESDF value differs from the oracle's
  std::size_t in_band = 0;   ///< known voxels with |oracle| < max_distance_m
  std::size_t occupied = 0;  ///< known voxels with a negative oracle value
};

/// Brute force: for every voxel of the map's blocks, the state from the TSDF (unknown: observed
/// weight
/// <= min_weight; occupied: D < 0; else free), and for every known voxel the smallest squared
/// lattice distance to a voxel of the other known state, by scanning every voxel of the cube
/// of the ESDF's radius around it (seeds farther away give the clamp anyway).
/// `near_block`, if given, restricts the comparison to the bounding box of the blocks within 16
/// blocks of it (for maps of patches farther apart than that and than the ESDF's reach).
inline OracleComparison compareWithOracle(const TsdfMap& map, const Esdf& esdf,
                                          const Eigen::Vector3i* near_block = nullptr) {
  OracleComparison result;
  if (map.blockCount() == 0) return result;
  Eigen::Vector3i lo = Eigen::Vector3i::Constant(INT_MAX), hi = Eigen::Vector3i::Constant(INT_MIN);
  for (const auto& kv : map.blocks()) {
    if (near_block != nullptr && (kv.first - *near_block).cwiseAbs().maxCoeff() > 16) continue;
    lo = lo.cwiseMin(kv.first * kTsdfBlockSide);
    hi = hi.cwiseMax(kv.first * kTsdfBlockSide + Eigen::Vector3i::Constant(kTsdfBlockSide - 1));
  }
  const Eigen::Vector3i n = hi - lo + Eigen::Vector3i::Ones();
  const auto at = [&](const Eigen::Vector3i& v) {
    const Eigen::Vector3i r = v - lo;
    return (static_cast<std::size_t>(r.z()) * n.y() + r.y()) * n.x() + r.x();
  };
  std::vector<int> state(static_cast<std::size_t>(n.x()) * n.y() * n.z(), 0);  // 0 unknown
  for (int z = lo.z(); z <= hi.z(); ++z) {
    for (int y = lo.y(); y <= hi.y(); ++y) {
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const TsdfVoxel* v = map.voxel({x, y, z});
        if (v != nullptr && v->observedWeight() > map.config().min_weight) {
          state[at({x, y, z})] = v->distance < 0.0f ? 2 : 1;
        }
      }
    }
  }
  const int r = esdf.radiusVoxels();
  const double max = esdf.config().max_distance_m;
  for (int z = lo.z(); z <= hi.z(); ++z) {
    for (int y = lo.y(); y <= hi.y(); ++y) {
      for (int x = lo.x(); x <= hi.x(); ++x) {
        const Eigen::Vector3i v(x, y, z);
        const int s = state[at(v)];
        const float got = esdf.voxelDistance(v);
        if (s == 0) {
          result.off += !std::isnan(got);
          continue;
        }
        ++result.known;
        const int seed = s == 2 ? 1 : 2;
        std::int64_t best = INT64_MAX;
        for (int dz = -r; dz <= r; ++dz) {
          for (int dy = -r; dy <= r; ++dy) {
            for (int dx = -r; dx <= r; ++dx) {
              const Eigen::Vector3i o = v + Eigen::Vector3i(dx, dy, dz);
              if ((o.array() < lo.array()).any() || (o.array() > hi.array()).any()) continue;
              if (state[at(o)] == seed)
                best = std::min<std::int64_t>(best, dx * dx + dy * dy + dz * dz);
            }
          }
        }
        const float expected =
            esdfMetres(best == INT64_MAX ? kEdtFarSquared : static_cast<std::int32_t>(best), s == 2,
                       map.voxelSize(), max);
        result.off += !(got == expected);
        result.in_band += std::abs(expected) < max;
        result.occupied += s == 2;
      }
    }
  }
  return result;
}

}  // namespace test
}  // namespace downstream_perception
