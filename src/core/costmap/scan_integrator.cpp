#include "downstream_perception/core/costmap/scan_integrator.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace downstream_perception {

void IntegrationStats::accumulate(const IntegrationStats& o) {
  beams += o.beams;
  beams_marked += o.beams_marked;
  beams_no_return += o.beams_no_return;
  beams_invalid += o.beams_invalid;
  beams_beyond_obstacle_range += o.beams_beyond_obstacle_range;
  points_outside_height += o.points_outside_height;
  points_merged += o.points_merged;
  cells_cleared += o.cells_cleared;
  cells_marked += o.cells_marked;
  cells_changed += o.cells_changed;
  touched.expand(o.touched);
  changed.expand(o.changed);
}

std::string ScanIntegratorConfig::validate() const {
  std::ostringstream why;
  const auto ok = [](double v) { return std::isfinite(v) && v >= 0.0 && v <= kMaxRangeM; };
  if (!ok(obstacle_min_range) || !ok(obstacle_max_range) ||
      obstacle_min_range > obstacle_max_range) {
    why << "need 0 <= obstacle_min_range <= obstacle_max_range <= " << kMaxRangeM << " m, got ["
        << obstacle_min_range << ", " << obstacle_max_range << "]";
  } else if (!ok(raytrace_min_range) || !ok(raytrace_max_range) ||
             raytrace_min_range > raytrace_max_range) {
    why << "need 0 <= raytrace_min_range <= raytrace_max_range <= " << kMaxRangeM << " m, got ["
        << raytrace_min_range << ", " << raytrace_max_range << "]";
  }
  return why.str();
}

std::string LaserScanView::validate() const {
  std::ostringstream why;
  if (count == 0 || ranges == nullptr) {
    why << "scan has no ranges";
  } else if (!std::isfinite(angle_min) || !std::isfinite(angle_increment) ||
             angle_increment == 0.0) {
    why << "angle_min (" << angle_min << ") and angle_increment (" << angle_increment
        << ") must be finite and the increment non-zero";
  } else if (std::abs(angle_increment) * static_cast<double>(count) > 2.0 * M_PI + 1e-3) {
    why << count << " beams of " << angle_increment << " rad span more than a full turn";
  } else if (!std::isfinite(range_min) || !std::isfinite(range_max) || range_min < 0.0 ||
             range_max <= range_min) {
    why << "need finite 0 <= range_min < range_max, got [" << range_min << ", " << range_max << "]";
  }
  return why.str();
}

ScanIntegrator::ScanIntegrator(const ScanIntegratorConfig& config) : config_(config) {
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument(why);
}

void ScanIntegrator::beamFromRange(double origin_x, double origin_y, double direction_rad,
                                   double range, double range_min, double range_max,
                                   std::vector<BeamUpdate>* beams, IntegrationStats* stats) const {
  beamFromDirection(origin_x, origin_y, std::cos(direction_rad), std::sin(direction_rad), range,
                    range_min, range_max, beams, stats);
}

void ScanIntegrator::beamFromDirection(double origin_x, double origin_y, double c, double s,
                                       double range, double range_min, double range_max,
                                       std::vector<BeamUpdate>* beams,
                                       IntegrationStats* stats) const {
  makeBeam(origin_x, origin_y, c, s, range, range_min, range_max, nullptr, beams, stats);
}

void ScanIntegrator::beamToPoint(double origin_x, double origin_y, double point_x, double point_y,
                                 double range_min, double range_max, std::vector<BeamUpdate>* beams,
                                 IntegrationStats* stats) const {
  const double dx = point_x - origin_x;
  const double dy = point_y - origin_y;
  const double range = std::hypot(dx, dy);
  const double point[2] = {point_x, point_y};
  if (!(range > 0.0)) {
    // No horizontal direction (or not finite: makeBeam refuses NaN). Any direction will do: a
    // return at range 0 marks where it is and clears nothing.
    makeBeam(origin_x, origin_y, 1.0, 0.0, range, range_min, range_max, point, beams, stats);
    return;
  }
  makeBeam(origin_x, origin_y, dx / range, dy / range, range, range_min, range_max, point, beams,
           stats);
}

void ScanIntegrator::makeBeam(double origin_x, double origin_y, double c, double s, double range,
                              double range_min, double range_max, const double* point,
                              std::vector<BeamUpdate>* beams, IntegrationStats* stats) const {
  ++stats->beams;
  bool no_return = false;
  if (std::isnan(range) || range == -std::numeric_limits<double>::infinity()) {
    ++stats->beams_invalid;
    return;
  }
  if (range == std::numeric_limits<double>::infinity() ||
      (config_.range_max_is_no_return && range >= range_max)) {
    if (!config_.inf_is_valid) {
      ++stats->beams_invalid;
      return;
    }
    no_return = true;
  } else if (range < range_min || range > range_max) {
    ++stats->beams_invalid;
    return;
  }

  BeamUpdate beam;
  if (no_return) {
    ++stats->beams_no_return;
  } else {
    const bool in_obstacle_range =
        range >= config_.obstacle_min_range && range <= config_.obstacle_max_range;
    if (config_.marking && in_obstacle_range) {
      beam.mark = true;
      beam.hit_x = point != nullptr ? point[0] : origin_x + range * c;
      beam.hit_y = point != nullptr ? point[1] : origin_y + range * s;
    } else if (!in_obstacle_range) {
      ++stats->beams_beyond_obstacle_range;
    }
  }
  if (config_.clearing) {
    const double start = config_.raytrace_min_range;
    double end = no_return ? config_.raytrace_max_range : range;
    bool end_is_hit = !no_return;
    if (end > config_.raytrace_max_range) {
      end = config_.raytrace_max_range;
      end_is_hit = false;
    }
    if (end > start) {
      beam.clear = true;
      beam.start_x = origin_x + start * c;
      beam.start_y = origin_y + start * s;
      // A clearing ray that ends at a measured point ends exactly there: its end cell is then the
      // cell the hit marks (origin + range * direction can round across a cell edge).
      beam.end_x = end_is_hit && point != nullptr ? point[0] : origin_x + end * c;
      beam.end_y = end_is_hit && point != nullptr ? point[1] : origin_y + end * s;
      beam.clear_end_cell = !end_is_hit;
    }
  }
  if (beam.mark || beam.clear) beams->push_back(beam);
}

void ScanIntegrator::beamsFromScan(const LaserScanView& scan, const Pose2D& sensor_pose,
                                   std::vector<BeamUpdate>* beams, IntegrationStats* stats) const {
  beams->reserve(beams->size() + scan.count);
  // Beam directions by rotation recurrence (two trig calls per scan instead of two per beam);
  // re-anchored every 256 beams so rounding cannot accumulate (error stays ~1e-15 rad).
  const double step_c = std::cos(scan.angle_increment);
  const double step_s = std::sin(scan.angle_increment);
  double c = 0.0;
  double s = 0.0;
  for (std::size_t k = 0; k < scan.count; ++k) {
    if (k % 256 == 0) {
      const double angle =
          sensor_pose.yaw + scan.angle_min + static_cast<double>(k) * scan.angle_increment;
      c = std::cos(angle);
      s = std::sin(angle);
    }
    beamFromDirection(sensor_pose.x, sensor_pose.y, c, s, static_cast<double>(scan.ranges[k]),
                      scan.range_min, scan.range_max, beams, stats);
    const double next_c = c * step_c - s * step_s;
    s = s * step_c + c * step_s;
    c = next_c;
  }
}

void ScanIntegrator::beamsFromMovingScan(const LaserScanView& scan, const Pose2D& first_beam_pose,
                                         const Pose2D& last_beam_pose,
                                         std::vector<BeamUpdate>* beams,
                                         IntegrationStats* stats) const {
  beams->reserve(beams->size() + scan.count);
  const double last = scan.count > 1 ? static_cast<double>(scan.count - 1) : 1.0;
  for (std::size_t k = 0; k < scan.count; ++k) {
    const Pose2D pose =
        interpolate(first_beam_pose, 0.0, last_beam_pose, last, static_cast<double>(k));
    const double angle = pose.yaw + scan.angle_min + static_cast<double>(k) * scan.angle_increment;
    beamFromDirection(pose.x, pose.y, std::cos(angle), std::sin(angle),
                      static_cast<double>(scan.ranges[k]), scan.range_min, scan.range_max, beams,
                      stats);
  }
}

IntegrationStats ScanIntegrator::integrate(LogOddsGrid& grid, const std::vector<BeamUpdate>& beams,
                                           const IntegrationStats& decisions) {
  IntegrationStats stats = integrateBeams(grid, beams, &integration_scratch_, walk_, threads_);
  stats.beams = decisions.beams;
  stats.beams_invalid = decisions.beams_invalid;
  stats.beams_no_return = decisions.beams_no_return;
  stats.beams_beyond_obstacle_range = decisions.beams_beyond_obstacle_range;
  stats.points_outside_height = decisions.points_outside_height;
  stats.points_merged = decisions.points_merged;
  return stats;
}

IntegrationStats ScanIntegrator::integrate(LogOddsGrid& grid, const LaserScanView& scan,
                                           const Pose2D& sensor_pose) {
  const std::string why = scan.validate();
  if (!why.empty()) throw std::invalid_argument(why);
  scratch_.clear();
  IntegrationStats decisions;
  beamsFromScan(scan, sensor_pose, &scratch_, &decisions);
  return integrate(grid, scratch_, decisions);
}

}  // namespace downstream_perception
