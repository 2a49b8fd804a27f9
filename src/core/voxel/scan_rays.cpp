#include "downstream_perception/core/voxel/scan_rays.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace downstream_perception {

void scanToRays(const LaserScanView& scan, const Eigen::Isometry3d& T_world_sensor,
                const ScanRayOptions& options, DepthRays* out) {
  scanToRays(scan, T_world_sensor, T_world_sensor, options, out);
}

void scanToRays(const LaserScanView& scan, const Eigen::Isometry3d& T_world_first,
                const Eigen::Isometry3d& T_world_last, const ScanRayOptions& options,
                DepthRays* out) {
  const std::string why = scan.validate();
  if (!why.empty()) throw std::invalid_argument("laser scan: " + why);
  if (!T_world_first.matrix().allFinite() || !T_world_last.matrix().allFinite()) {
    throw std::invalid_argument("laser scan: sensor pose is not finite");
  }
  out->hits.clear();
  out->no_returns.clear();
  out->invalid = 0;
  const auto push = [](std::vector<float>* v, const Eigen::Vector3d& p) {
    v->insert(v->end(),
              {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
  };
  // Beam k is measured k / (count - 1) of the way through the sweep: its pose is interpolated
  // (translation linearly, rotation by slerp), as laser_geometry's high-fidelity projection does
  // for costmap_2d. A still sensor skips the interpolation.
  const bool moving = T_world_first.matrix() != T_world_last.matrix();
  const Eigen::Quaterniond q0(T_world_first.linear());
  const Eigen::Quaterniond q1(T_world_last.linear());
  const double last_index = scan.count > 1 ? static_cast<double>(scan.count - 1) : 1.0;
  Eigen::Isometry3d pose = T_world_first;
  for (std::size_t k = 0; k < scan.count; ++k) {
    if (moving) {
      const double f = static_cast<double>(k) / last_index;
      pose.linear() = q0.slerp(f, q1).toRotationMatrix();
      pose.translation() = (1.0 - f) * T_world_first.translation() + f * T_world_last.translation();
    }
    const double a = scan.angle_min + static_cast<double>(k) * scan.angle_increment;
    const Eigen::Vector3d dir(std::cos(a), std::sin(a), 0.0);
    const double r = scan.ranges[k];
    const bool inf = r == std::numeric_limits<double>::infinity();
    if ((inf && options.inf_is_no_return) ||
        (options.range_max_is_no_return && r == scan.range_max)) {
      push(&out->no_returns, pose * dir);
    } else if (inf && options.inf_is_valid) {
      push(&out->hits, pose * (dir * (scan.range_max - 1e-4)));
    } else if (std::isfinite(r) && r >= scan.range_min && r <= scan.range_max) {
      push(&out->hits, pose * (dir * r));
    } else {
      ++out->invalid;
    }
  }
}

}  // namespace downstream_perception
