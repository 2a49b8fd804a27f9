#include "downstream_perception/core/costmap/scan_integrator.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "downstream_perception/core/grid/ray_traversal.h"

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

namespace {

// The state class of a value in quanta: -1 free, 0 unknown, +1 occupied.
inline int stateClass(int v, int free_units, int occupied_units) {
  return (v > occupied_units) - (v < free_units);
}

// The cells of one scan's integration: applies a delta to an unflagged cell and flags it, and
// the miss of pass 2 with its statistics. Passed by value (a few words) into the out-of-line walk
// below, so that the walk's loop keeps its state in registers: the walks used to be inlined into
// integrateBeams as lambdas capturing its locals by reference, and once a second (corner) walk
// took those lambdas out of line, every cleared cell reloaded the locals through the closures
// (7-13 % more instructions in the scan benchmark).
struct ScanCells {
  std::int16_t* cells;
  std::vector<std::uint32_t>* flagged;
  IntegrationStats* stats;
  std::ptrdiff_t size_x;
  int lo;
  int hi;
  int free_units;
  int occupied_units;
  int miss;
  /// Raw (value * 2 + flag) of an unflagged cell sitting at the lower clamp: another miss cannot
  /// change it, so the clearing walk skips it without writing or flagging (the common case in
  /// free space that has been seen before, which is most of every scan).
  std::int16_t saturated_free_raw;

  /// Applies delta to an unflagged cell and flags it; returns whether its state class changed.
  bool update(std::size_t i, int delta) const {
    const int old_v = cells[i] / 2;  // unflagged: raw is even, the division is exact
    const int v = std::min(hi, std::max(lo, old_v + delta));
    cells[i] = static_cast<std::int16_t>(v * 2 + 1);
    flagged->push_back(static_cast<std::uint32_t>(i));
    return stateClass(old_v, free_units, occupied_units) !=
           stateClass(v, free_units, occupied_units);
  }
  /// A cell takes a miss unless it is flagged (hit or cleared in this scan) or already saturated
  /// free: one combined, almost always true test.
  bool skipsMiss(std::int16_t raw) const {
    return static_cast<bool>((raw & 1) | (raw == saturated_free_raw));
  }
  /// The miss of a pass-through cell (not skipped).
  void clear(std::int16_t* p) const {
    const std::size_t i = static_cast<std::size_t>(p - cells);
    if (update(i, miss)) {
      ++stats->cells_changed;
      stats->changed.expand(static_cast<int>(i % size_x), static_cast<int>(i / size_x));
    }
  }
};

// A ray that may pass exactly through cell corners (lattice-exact points): the walk of
// RayWalk::walk on the cell pointer, crossing a corner diagonally (see RayWalk); clears every
// cell before the end cell and returns the end cell's pointer; *visited counts the cells visited.
// Its own function, so the common loop below stays the plain two-way step.
__attribute__((noinline)) std::int16_t* clearThroughCorners(const RayWalk& walk, std::int16_t* p,
                                                            const ScanCells sc,
                                                            std::size_t* visited) {
  const std::ptrdiff_t dpx = walk.sx;
  const std::ptrdiff_t dpy = walk.sy * sc.size_x;
  std::int64_t err = walk.err;
  for (int left = walk.stepsLeft(); left > 0; --left) {
    if (!sc.skipsMiss(*p)) sc.clear(p);
    ++*visited;
    if (err == walk.tie && left >= 2) {  // both edges of the corner in one step
      p += dpx + dpy;
      err += walk.err_step_x - walk.err_step_y;
      --left;
    } else if (err <= 0) {
      p += dpx;
      err += walk.err_step_x;
    } else {
      p += dpy;
      err -= walk.err_step_y;
    }
  }
  return p;
}

// Clears every cell of a ray before its end cell and returns the end cell's pointer; the cells
// visited are added to *walked. The walk moves a cell pointer (+-1 along x, +-size_x along y) and
// keeps its state in registers; the rare update (a cell not yet saturated free) leaves the hot
// loop. Out of line (once per ray): its registers are its own. Aligned to a cache line, so the
// loop's placement does not move with whatever the linker puts before it (that alone changed the
// 360-beam benchmark by up to 15 % between builds of the same code).
__attribute__((noinline, aligned(64))) std::int16_t* clearAlong(const RayWalk& walk,
                                                                std::int16_t* p, const ScanCells sc,
                                                                std::size_t* walked) {
  if (__builtin_expect(walk.corners, 0)) return clearThroughCorners(walk, p, sc, walked);
  // Pointer steps: +-1 along x, +-size_x along y (see RayWalk for why this is a branch).
  const std::ptrdiff_t dpx = walk.sx;
  const std::ptrdiff_t dpy = walk.sy * sc.size_x;
  const std::int64_t esx = walk.err_step_x;
  const std::int64_t esy = walk.err_step_y;
  std::int64_t err = walk.err;
  int left = walk.stepsLeft();
  *walked += static_cast<std::size_t>(left);
  for (; left > 0; --left) {
    if (__builtin_expect(!sc.skipsMiss(*p), 0)) sc.clear(p);
    if (err <= 0) {
      p += dpx;
      err += esx;
    } else {
      p += dpy;
      err -= esy;
    }
  }
  return p;
}

}  // namespace

IntegrationStats integrateBeams(LogOddsGrid& grid, const std::vector<BeamUpdate>& beams,
                                std::vector<std::uint32_t>* scratch) {
  IntegrationStats stats;
  const GridGeometry& geometry = grid.geometry();
  if (geometry.cellCount() == 0) return stats;
  std::vector<std::uint32_t> local_scratch;
  // Cells flagged in this scan, so the flags can be cleared afterwards (32-bit: the grid is
  // limited to 2^28 cells).
  std::vector<std::uint32_t>& flagged = scratch != nullptr ? *scratch : local_scratch;
  flagged.clear();
  std::int16_t* cells = grid.rawCells();
  const int free_units = grid.freeUnits();
  const int occupied_units = grid.occupiedUnits();
  const ScanCells sc{cells,
                     &flagged,
                     &stats,
                     geometry.sizeX(),
                     grid.clampMinUnits(),
                     grid.clampMaxUnits(),
                     free_units,
                     occupied_units,
                     grid.missUnits(),
                     static_cast<std::int16_t>(grid.clampMinUnits() * 2)};

  // Pass 1: hits. Every hit cell is flagged (even at the clamp) so no beam of this scan clears it.
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
    if (sc.update(i, hit)) {
      ++stats.cells_changed;
      stats.changed.expand(c.x, c.y);
    }
  }

  // Pass 2: pass-throughs, skipping every cell already updated in this scan.
  std::size_t walked = 0;
  for (const BeamUpdate& beam : beams) {
    if (!beam.clear) continue;
    double x0 = beam.start_x;
    double y0 = beam.start_y;
    double x1 = beam.end_x;
    double y1 = beam.end_y;
    bool end_clipped = false;
    if (!clipSegmentToGrid(geometry, &x0, &y0, &x1, &y1, nullptr, &end_clipped)) continue;
    const RayWalk walk(geometry, x0, y0, x1, y1);
    // The walk stays inside the box of its end cells: bound it per beam, not per cell.
    stats.touched.expand(walk.cx, walk.cy);
    stats.touched.expand(walk.endX(), walk.endY());
    std::int16_t* p = clearAlong(walk, cells + walk.cy * sc.size_x + walk.cx, sc, &walked);
    if (beam.clear_end_cell || end_clipped) {
      ++walked;
      if (!sc.skipsMiss(*p)) sc.clear(p);
    }
  }
  stats.cells_cleared = walked;

  for (const std::uint32_t i : flagged) cells[i] = static_cast<std::int16_t>(cells[i] & ~1);
  return stats;
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
  IntegrationStats stats = integrateBeams(grid, beams, &flagged_scratch_);
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
