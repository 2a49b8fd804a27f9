#include "downstream_perception/core/scan_integrator.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "downstream_perception/core/ray_traversal.h"

namespace downstream_perception {

void IntegrationStats::accumulate(const IntegrationStats& o) {
  beams += o.beams;
  beams_marked += o.beams_marked;
  beams_no_return += o.beams_no_return;
  beams_invalid += o.beams_invalid;
  beams_beyond_obstacle_range += o.beams_beyond_obstacle_range;
  cells_cleared += o.cells_cleared;
  cells_marked += o.cells_marked;
  cells_changed += o.cells_changed;
  touched.expand(o.touched);
  changed.expand(o.changed);
}

namespace {

// The state class of a value in quanta: -1 free, 0 unknown, +1 occupied.
inline int stateClass(int v, int free_units, int occupied_units) {
  return (v > occupied_units) - (v < free_units);
}

}  // namespace

IntegrationStats integrateBeams(LogOddsGrid& grid, const std::vector<BeamUpdate>& beams) {
  IntegrationStats stats;
  const GridGeometry& geometry = grid.geometry();
  if (geometry.cellCount() == 0) return stats;
  // Cells updated in this scan, so their flags can be cleared afterwards (32-bit: the grid is
  // limited to 2^28 cells).
  thread_local std::vector<std::uint32_t> touched_cells;
  touched_cells.clear();
  std::int16_t* cells = grid.rawCells();
  const int free_units = grid.freeUnits();
  const int occupied_units = grid.occupiedUnits();
  const int lo = grid.clampMinUnits();
  const int hi = grid.clampMaxUnits();

  // Applies delta to an unflagged cell, flags it; returns whether its state class changed.
  const auto update = [&](std::size_t i, int delta) {
    const int old_v = (cells[i] - (cells[i] & 1)) / 2;
    const int v = std::min(hi, std::max(lo, old_v + delta));
    cells[i] = static_cast<std::int16_t>(v * 2 + 1);
    touched_cells.push_back(static_cast<std::uint32_t>(i));
    return stateClass(old_v, free_units, occupied_units) != stateClass(v, free_units, occupied_units);
  };

  // Pass 1: hits.
  const int hit = grid.hitUnits();
  for (const BeamUpdate& beam : beams) {
    if (!beam.mark) continue;
    CellIndex c;
    if (!geometry.worldToCell(beam.hit_x, beam.hit_y, &c)) continue;
    ++stats.beams_marked;
    const std::size_t i = geometry.index(c.x, c.y);
    if (cells[i] & 1) continue;
    ++stats.cells_marked;
    stats.touched.expand(c.x, c.y);
    if (update(i, hit)) {
      ++stats.cells_changed;
      stats.changed.expand(c.x, c.y);
    }
  }

  // Pass 2: pass-throughs, skipping every cell already updated in this scan.
  const int miss = grid.missUnits();
  const std::size_t size_x = static_cast<std::size_t>(geometry.sizeX());
  for (const BeamUpdate& beam : beams) {
    if (!beam.clear) continue;
    double x0 = beam.start_x;
    double y0 = beam.start_y;
    double x1 = beam.end_x;
    double y1 = beam.end_y;
    bool end_clipped = false;
    if (!clipSegmentToGrid(geometry, &x0, &y0, &x1, &y1, nullptr, &end_clipped)) continue;
    // The walk stays inside the box of its end cells: bound it per beam, not per cell.
    stats.touched.expand(geometry.worldToCellUnbounded(x0, y0).x, geometry.worldToCellUnbounded(x0, y0).y);
    stats.touched.expand(geometry.worldToCellUnbounded(x1, y1).x, geometry.worldToCellUnbounded(x1, y1).y);
    traverseRay(geometry, x0, y0, x1, y1, beam.clear_end_cell || end_clipped, [&](int x, int y) {
      const std::size_t i = static_cast<std::size_t>(y) * size_x + static_cast<std::size_t>(x);
      if (cells[i] & 1) return;
      ++stats.cells_cleared;
      if (update(i, miss)) {
        ++stats.cells_changed;
        stats.changed.expand(x, y);
      }
    });
  }

  for (const std::uint32_t i : touched_cells) cells[i] = static_cast<std::int16_t>(cells[i] & ~1);
  return stats;
}

std::string ScanIntegratorConfig::validate() const {
  std::ostringstream why;
  const auto ok = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!ok(obstacle_min_range) || !ok(obstacle_max_range) ||
      obstacle_min_range > obstacle_max_range) {
    why << "need 0 <= obstacle_min_range <= obstacle_max_range (finite, m), got ["
        << obstacle_min_range << ", " << obstacle_max_range << "]";
  } else if (!ok(raytrace_min_range) || !ok(raytrace_max_range) ||
             raytrace_min_range > raytrace_max_range) {
    why << "need 0 <= raytrace_min_range <= raytrace_max_range (finite, m), got ["
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
    why << "need finite 0 <= range_min < range_max, got [" << range_min << ", " << range_max
        << "]";
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

  const double c = std::cos(direction_rad);
  const double s = std::sin(direction_rad);
  BeamUpdate beam;
  if (no_return) {
    ++stats->beams_no_return;
  } else {
    const bool in_obstacle_range =
        range >= config_.obstacle_min_range && range <= config_.obstacle_max_range;
    if (config_.marking && in_obstacle_range) {
      beam.mark = true;
      beam.hit_x = origin_x + range * c;
      beam.hit_y = origin_y + range * s;
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
      beam.end_x = origin_x + end * c;
      beam.end_y = origin_y + end * s;
      beam.clear_end_cell = !end_is_hit;
    }
  }
  if (beam.mark || beam.clear) beams->push_back(beam);
}

void ScanIntegrator::beamsFromScan(const LaserScanView& scan, const Pose2D& sensor_pose,
                                   std::vector<BeamUpdate>* beams,
                                   IntegrationStats* stats) const {
  beams->reserve(beams->size() + scan.count);
  for (std::size_t k = 0; k < scan.count; ++k) {
    const double angle = sensor_pose.yaw + scan.angle_min + static_cast<double>(k) * scan.angle_increment;
    beamFromRange(sensor_pose.x, sensor_pose.y, angle, static_cast<double>(scan.ranges[k]),
                  scan.range_min, scan.range_max, beams, stats);
  }
}

IntegrationStats ScanIntegrator::integrate(LogOddsGrid& grid, const LaserScanView& scan,
                                           const Pose2D& sensor_pose) {
  const std::string why = scan.validate();
  if (!why.empty()) throw std::invalid_argument(why);
  scratch_.clear();
  IntegrationStats decisions;
  beamsFromScan(scan, sensor_pose, &scratch_, &decisions);
  IntegrationStats stats = integrateBeams(grid, scratch_);
  stats.beams = decisions.beams;
  stats.beams_invalid = decisions.beams_invalid;
  stats.beams_no_return = decisions.beams_no_return;
  stats.beams_beyond_obstacle_range = decisions.beams_beyond_obstacle_range;
  return stats;
}

}  // namespace downstream_perception
