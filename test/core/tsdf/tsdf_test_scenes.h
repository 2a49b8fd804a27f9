// Depth images of simple scenes, shared by the TSDF and OctoMap gtests.
#pragma once

#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>
#include <vector>

#include "downstream_perception/core/tsdf/tsdf_integrator.h"

namespace downstream_perception {
namespace test {

/// Depth (m) of the plane n . p = offset (camera frame) seen by `camera`; NaN where the ray
/// misses it.
inline std::vector<float> planeDepth(const PinholeCamera& camera, const Eigen::Vector3d& n,
                                     double offset) {
  std::vector<float> depth(static_cast<std::size_t>(camera.width) * camera.height);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      const double t = offset / n.dot(ray);  // ray * t lies on the plane; t is the depth z
      depth[static_cast<std::size_t>(v) * camera.width + u] =
          t > 0.0 ? static_cast<float>(t) : std::nanf("");
    }
  }
  return depth;
}

/// 160 x 120, f = 150 px.
inline PinholeCamera smallCamera() {
  PinholeCamera c;
  c.width = 160;
  c.height = 120;
  c.fx = c.fy = 150.0;
  c.cx = 79.5;
  c.cy = 59.5;
  return c;
}

/// The accuracy benchmark's 320 x 240 camera (f = 262.5 px).
inline PinholeCamera benchmarkCamera() {
  PinholeCamera c;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 262.5;
  c.cx = 159.5;
  c.cy = 119.5;
  return c;
}

/// Whether some frame saw world point p: its depth at p's nearest pixel matches p's within 1 cm
/// (so p is not hidden behind nearer surfaces there).
inline bool seenBySomeFrame(const PinholeCamera& camera,
                            const std::vector<Eigen::Isometry3d>& poses,
                            const std::vector<std::vector<float>>& depths,
                            const Eigen::Vector3d& p) {
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Vector3d q = poses[k].inverse() * p;
    const int u = static_cast<int>(std::lround(camera.fx * q.x() / q.z() + camera.cx));
    const int v = static_cast<int>(std::lround(camera.fy * q.y() / q.z() + camera.cy));
    if (q.z() <= 0.0 || u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
    if (std::abs(depths[k][static_cast<std::size_t>(v) * camera.width + u] - q.z()) < 0.01) {
      return true;
    }
  }
  return false;
}

}  // namespace test
}  // namespace downstream_perception
