#include "downstream_perception/core/costmap/cloud_beams.h"

#include <tsl/robin_set.h>

#include <algorithm>
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
  }
  return why.str();
}

namespace {

// The merge key of a lattice coordinate on one axis: floor((w - anchor) / resolution), exactly
// the floor GridGeometry takes (so the key's cell is the cell the beam's hit marks), without a
// division per point. The product with the reciprocal is within 2 ulp of the quotient: below 2^31
// cells that is under 2^-20 cell, so its floor is the quotient's unless it lies within 2^-19 cell
// of an integer (a point on a cell edge, e.g. a simulated wall on the lattice); there, and far
// out, the division decides, and its last answer is kept (a wall on an edge gives the same
// coordinate point after point). Clamped to 32 bits: |key| < 2^31 holds every cell of any grid;
// points beyond are far outside it and only clear.
struct LatticeAxis {
  double anchor;
  double resolution;
  double inv_resolution;
  double last_offset = std::numeric_limits<double>::quiet_NaN();
  std::int64_t last_key = 0;

  std::int64_t key(double w) {
    const double offset = w - anchor;
    const double u = offset * inv_resolution;
    const double whole = std::floor(u);
    // fraction u - whole in (2^-19, 1 - 2^-19), as one compare
    if (std::abs(u - whole - 0.5) < 0.5 - 0x1p-19 && std::abs(u) < 0x1p31) {
      return static_cast<std::int64_t>(whole);
    }
    if (offset != last_offset) {
      last_offset = offset;
      last_key = static_cast<std::int64_t>(
          std::clamp(std::floor(offset / resolution), -0x1p31, 0x1p31 - 1.0));
    }
    return last_key;
  }
};

}  // namespace

void beamsFromCloud(const ScanIntegrator& integrator, const CloudBeamsConfig& config,
                    const unsigned char* xyz, std::size_t count, std::size_t stride_bytes,
                    const Eigen::Isometry3d& grid_from_sensor, std::vector<BeamUpdate>* beams,
                    IntegrationStats* stats) {
  beams->reserve(beams->size() + count);
  const Eigen::Matrix3d r = grid_from_sensor.linear();
  const Eigen::Vector3d t = grid_from_sensor.translation();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const bool merge = config.merge_grid.has_value();
  // The grid's lattice: cell = floor((w - anchor) / resolution) - shift (GridGeometry). The
  // shift is the same for every point, so floor(...) alone is the key.
  const double resolution = merge ? config.merge_grid->resolution() : 1.0;
  LatticeAxis axis_x{merge ? config.merge_grid->latticeAnchorX() : 0.0, resolution,
                     1.0 / resolution};
  LatticeAxis axis_y{merge ? config.merge_grid->latticeAnchorY() : 0.0, resolution,
                     1.0 / resolution};
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
      const std::int64_t cx = axis_x.key(q.x());
      const std::int64_t cy = axis_y.key(q.y());
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
