#include "downstream_perception/core/cloud_beams.h"

#include <tsl/robin_set.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

namespace downstream_perception {

std::string CloudBeamsConfig::validate() const {
  std::ostringstream why;
  if (!std::isfinite(min_obstacle_height) || !std::isfinite(max_obstacle_height) ||
      min_obstacle_height > max_obstacle_height) {
    why << "need finite min_obstacle_height <= max_obstacle_height, got " << min_obstacle_height
        << " and " << max_obstacle_height;
  } else if (!std::isfinite(merge_cell_m) || merge_cell_m < 0.0) {
    why << "merge_cell_m must be finite and >= 0, got " << merge_cell_m;
  }
  return why.str();
}

void beamsFromCloud(const ScanIntegrator& integrator, const CloudBeamsConfig& config,
                    const unsigned char* xyz, std::size_t count, std::size_t stride_bytes,
                    const Eigen::Isometry3d& grid_from_sensor, std::vector<BeamUpdate>* beams,
                    IntegrationStats* stats) {
  beams->reserve(beams->size() + count);
  const Eigen::Matrix3d r = grid_from_sensor.linear();
  const Eigen::Vector3d t = grid_from_sensor.translation();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const bool merge = config.merge_cell_m > 0.0;
  const double inv_merge = merge ? 1.0 / config.merge_cell_m : 0.0;
  tsl::robin_set<std::uint64_t> seen;
  if (merge) seen.reserve(4096);
  for (std::size_t k = 0; k < count; ++k) {
    float p[3];
    std::memcpy(p, xyz + k * stride_bytes, sizeof(p));  // PointCloud2 data need not be aligned
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      ++stats->beams;
      ++stats->beams_invalid;
      continue;
    }
    const Eigen::Vector3d q = r * Eigen::Vector3d(p[0], p[1], p[2]) + t;
    if (q.z() < config.min_obstacle_height || q.z() > config.max_obstacle_height) {
      ++stats->points_outside_height;
      continue;
    }
    if (merge) {
      const auto cx = static_cast<std::int64_t>(std::floor(q.x() * inv_merge));
      const auto cy = static_cast<std::int64_t>(std::floor(q.y() * inv_merge));
      const std::uint64_t key =
          (static_cast<std::uint64_t>(cx) << 32) ^ (static_cast<std::uint64_t>(cy) & 0xffffffffu);
      if (!seen.insert(key).second) {
        ++stats->points_merged;
        continue;
      }
    }
    // The point itself is the hit (a point straight above or below the sensor marks the
    // sensor's cell, as in costmap_2d).
    integrator.beamToPoint(t.x(), t.y(), q.x(), q.y(), 0.0, kInf, beams, stats);
  }
}

}  // namespace downstream_perception
