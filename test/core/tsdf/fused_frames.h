// Frames ray cast from exact scenes, fused into a TSDF map, and how much of a surface the mesh
// covers: shared by the gtests of the integrator's depth rules (rims, creases).
#pragma once

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "downstream_perception/core/tsdf/marching_cubes.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "tsdf_test_scenes.h"

namespace downstream_perception {
namespace test {

/// z-depth image from an exact ray caster: `hit(origin, direction)` returns the ray parameter
/// of the nearest hit (the direction's camera z is 1, so that is the depth), +Inf for none.
template <class Hit>
std::vector<float> castDepth(const PinholeCamera& camera, const Eigen::Isometry3d& pose,
                             const Hit& hit) {
  std::vector<float> depth(static_cast<std::size_t>(camera.width) * camera.height);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      const double t = hit(pose.translation(), pose.linear() * ray);
      depth[static_cast<std::size_t>(v) * camera.width + u] =
          t < 20.0 ? static_cast<float>(t) : std::nanf("");
    }
  }
  return depth;
}

/// A ray caster for castDepth over axis-aligned planes (a floor, walls), each seen from one
/// side: plane k is {p[axis] = offset}, hit by rays moving along `towards` (+1 or -1) on its axis.
struct AxisPlanes {
  struct Plane {
    int axis;
    double offset;
    int towards;
  };
  std::vector<Plane> planes;

  double operator()(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
    double t = std::numeric_limits<double>::infinity();
    for (const Plane& p : planes) {
      if (d[p.axis] * p.towards > 0.0) t = std::min(t, (p.offset - o[p.axis]) / d[p.axis]);
    }
    return t;
  }
};

/// Frames fused into one map, kept for coverage checks.
struct FusedFrames {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<std::vector<float>> depths;
};

/// Each pose's depth image (`render(pose)`) fused into `map` in turn.
template <class Render>
FusedFrames fuseFrames(TsdfMap* map, const PinholeCamera& camera,
                       const std::vector<Eigen::Isometry3d>& poses, const Render& render) {
  FusedFrames frames;
  DepthIntegrator integrator;
  for (const Eigen::Isometry3d& pose : poses) {
    frames.poses.push_back(pose);
    frames.depths.push_back(render(pose));
    integrator.integrate(map, frames.depths.back().data(), camera, pose);
  }
  return frames;
}

/// How many of `samples` some frame saw (*seen), and the share of those with a mesh vertex
/// within 2 cm.
inline double coveredShare(const PinholeCamera& camera, const std::vector<Eigen::Isometry3d>& poses,
                           const std::vector<std::vector<float>>& depths, const TriangleMesh& mesh,
                           const std::vector<Eigen::Vector3d>& samples, std::size_t* seen) {
  *seen = 0;
  std::size_t covered = 0;
  for (const Eigen::Vector3d& p : samples) {
    if (!seenBySomeFrame(camera, poses, depths, p)) continue;
    ++*seen;
    for (const Eigen::Vector3f& v : mesh.vertices) {
      if ((v.cast<double>() - p).norm() <= 0.02) {
        ++covered;
        break;
      }
    }
  }
  return *seen > 0 ? static_cast<double>(covered) / *seen : 0.0;
}

/// Points every 2 cm on the rectangle from `corner` along `along_a` and `along_b` (inclusive).
inline std::vector<Eigen::Vector3d> gridOn(const Eigen::Vector3d& corner,
                                           const Eigen::Vector3d& along_a,
                                           const Eigen::Vector3d& along_b) {
  std::vector<Eigen::Vector3d> points;
  const int na = static_cast<int>(std::floor(along_a.norm() / 0.02 + 1e-9));
  const int nb = static_cast<int>(std::floor(along_b.norm() / 0.02 + 1e-9));
  for (int a = 0; a <= na; ++a) {
    for (int b = 0; b <= nb; ++b) {
      points.push_back(corner + along_a.normalized() * (0.02 * a) +
                       along_b.normalized() * (0.02 * b));
    }
  }
  return points;
}

}  // namespace test
}  // namespace downstream_perception
