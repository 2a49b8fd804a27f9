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

/// A width x height camera with focal length f (px), its principal point at the image's centre.
inline PinholeCamera centredCamera(int width, int height, double f) {
  PinholeCamera c;
  c.width = width;
  c.height = height;
  c.fx = c.fy = f;
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  return c;
}

/// 160 x 120, f = 150 px.
inline PinholeCamera smallCamera() {
  return centredCamera(160, 120, 150.0);
}

/// The accuracy benchmark's 320 x 240 camera (f = 262.5 px).
inline PinholeCamera benchmarkCamera() {
  return centredCamera(320, 240, 262.5);
}

/// The accuracy benchmark's 640 x 480 camera (f = 525 px).
inline PinholeCamera vgaCamera() {
  return centredCamera(640, 480, 525.0);
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
