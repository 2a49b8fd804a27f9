// Depth images of simple scenes, shared by the TSDF and OctoMap gtests.
#pragma once

#include <Eigen/Geometry>

#include <cmath>
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

}  // namespace test
}  // namespace downstream_perception
