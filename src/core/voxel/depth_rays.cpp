#include "downstream_perception/core/voxel/depth_rays.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace downstream_perception {

void depthToRays(const float* depth_m, const PinholeCamera& camera,
                 const Eigen::Isometry3d& T_world_camera, bool zero_is_no_return, int stride,
                 DepthRays* out) {
  const std::string why = camera.validate();
  if (!why.empty()) throw std::invalid_argument("depth image: " + why);
  if (stride < 1) throw std::invalid_argument("depth image: stride must be >= 1");
  if (depth_m == nullptr) throw std::invalid_argument("depth image: null image");
  if (!T_world_camera.matrix().allFinite()) {
    throw std::invalid_argument("depth image: camera pose is not finite");
  }
  out->hits.clear();
  out->no_returns.clear();
  out->invalid = 0;
  const Eigen::Matrix3f R = T_world_camera.linear().cast<float>();
  const Eigen::Vector3f t = T_world_camera.translation().cast<float>();
  const auto push = [](std::vector<float>* v, const Eigen::Vector3f& p) {
    v->push_back(p.x());
    v->push_back(p.y());
    v->push_back(p.z());
  };
  const auto ifx = static_cast<float>(1.0 / camera.fx);
  const auto ify = static_cast<float>(1.0 / camera.fy);
  for (int v = 0; v < camera.height; v += stride) {
    const float ry = (static_cast<float>(v) - static_cast<float>(camera.cy)) * ify;
    const float* row = depth_m + static_cast<std::size_t>(v) * camera.width;
    for (int u = 0; u < camera.width; u += stride) {
      const float d = row[u];
      const float rx = (static_cast<float>(u) - static_cast<float>(camera.cx)) * ifx;
      const Eigen::Vector3f ray(rx, ry, 1.0f);
      if (d > 0.0f && std::isfinite(d)) {
        push(&out->hits, R * (ray * d) + t);
      } else if (d == std::numeric_limits<float>::infinity() || (d == 0.0f && zero_is_no_return)) {
        push(&out->no_returns, R * ray.normalized() + t);
      } else {
        ++out->invalid;
      }
    }
  }
}

std::size_t dropOutsideHeightBand(std::vector<float>* xyz, double min_z_m, double max_z_m) {
  std::size_t kept = 0;
  const std::size_t n = xyz->size() / 3;
  for (std::size_t i = 0; i < n; ++i) {
    const float z = (*xyz)[3 * i + 2];
    if (std::isfinite(z) && (z < min_z_m || z > max_z_m)) continue;
    if (kept != i) std::copy_n(xyz->begin() + 3 * i, 3, xyz->begin() + 3 * kept);
    ++kept;
  }
  xyz->resize(3 * kept);
  return n - kept;
}

}  // namespace downstream_perception
