#include "downstream_perception/core/voxel/scan_rays.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace downstream_perception {

void scanToRays(const LaserScanView& scan, const Eigen::Isometry3d& T_world_sensor,
                const ScanRayOptions& options, DepthRays* out) {
  const std::string why = scan.validate();
  if (!why.empty()) throw std::invalid_argument("laser scan: " + why);
  if (!T_world_sensor.matrix().allFinite()) {
    throw std::invalid_argument("laser scan: sensor pose is not finite");
  }
  out->hits.clear();
  out->no_returns.clear();
  out->invalid = 0;
  const auto push = [](std::vector<float>* v, const Eigen::Vector3d& p) {
    v->insert(v->end(),
              {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
  };
  for (std::size_t k = 0; k < scan.count; ++k) {
    const double a = scan.angle_min + static_cast<double>(k) * scan.angle_increment;
    const Eigen::Vector3d dir(std::cos(a), std::sin(a), 0.0);
    const double r = scan.ranges[k];
    const bool inf = r == std::numeric_limits<double>::infinity();
    if ((inf && options.inf_is_no_return) ||
        (options.range_max_is_no_return && r == scan.range_max)) {
      push(&out->no_returns, T_world_sensor * dir);
    } else if (inf && options.inf_is_valid) {
      push(&out->hits, T_world_sensor * (dir * (scan.range_max - 1e-4)));
    } else if (std::isfinite(r) && r >= scan.range_min && r <= scan.range_max) {
      push(&out->hits, T_world_sensor * (dir * r));
    } else {
      ++out->invalid;
    }
  }
}

}  // namespace downstream_perception
