#include "downstream_perception/core/tracking/predicted_footprint.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "downstream_perception/core/grid/ray_traversal.h"

namespace downstream_perception {

std::string PredictionConfig::validate() const {
  std::ostringstream why;
  const auto bad = [](double v, double lo) { return !(std::isfinite(v) && v >= lo); };
  if (bad(prediction_horizon_s, 0.0) || prediction_horizon_s > 60.0) {
    why << "prediction_horizon_s must be in [0, 60] s, got " << prediction_horizon_s;
  } else if (bad(uncertainty_sigmas, 0.0) || uncertainty_sigmas > 10.0) {
    why << "uncertainty_sigmas must be in [0, 10], got " << uncertainty_sigmas;
  } else if (bad(max_uncertainty_m, 0.0)) {
    why << "max_uncertainty_m must be finite and >= 0 m, got " << max_uncertainty_m;
  } else if (bad(min_object_size_m, 0.0) || bad(max_object_size_m, min_object_size_m)) {
    why << "object sizes must satisfy 0 <= min_object_size_m <= max_object_size_m, got "
        << min_object_size_m << " and " << max_object_size_m;
  } else if (bad(max_speed_mps, 0.0)) {
    why << "max_speed_mps must be finite and >= 0 m/s, got " << max_speed_mps;
  }
  return why.str();
}

std::string PlanarTrack::validate() const {
  if (!position.allFinite()) return "position is not finite";
  if (!velocity.allFinite()) return "velocity is not finite";
  if (!position_covariance.allFinite() || !velocity_covariance.allFinite()) {
    return "covariance is not finite";
  }
  if (!std::isfinite(size_x) || !std::isfinite(size_y) || !std::isfinite(box_yaw)) {
    return "size or orientation is not finite";
  }
  if (size_x < 0.0 || size_y < 0.0) return "negative size";
  const auto asymmetric = [](const Eigen::Matrix2d& m) {
    return std::abs(m(0, 1) - m(1, 0)) > 1e-9 * (1.0 + m.cwiseAbs().maxCoeff());
  };
  if (asymmetric(position_covariance) || asymmetric(velocity_covariance)) {
    return "covariance is not symmetric";
  }
  return {};
}

namespace {

// Bounds that keep every product below the double range: no object outruns 1e3 m/s, and a
// prediction (or a look back) an hour out says nothing.
constexpr double kMaxPredictionTimeS = 3600.0;
constexpr double kMaxSpeedMps = 1e3;
constexpr double kMaxPositionM = 1e8;

std::string trackBoundsReason(const PlanarTrack& track) {
  if (!(track.velocity.norm() <= kMaxSpeedMps)) {
    return "track speed beyond 1e3 m/s: " + std::to_string(track.velocity.norm());
  }
  if (!(track.position.cwiseAbs().maxCoeff() <= kMaxPositionM)) {
    return "track position beyond 1e8 m";
  }
  return {};
}

}  // namespace

std::string validatePrediction(const PlanarTrack& track, double time_s,
                               const PredictionConfig& config) {
  std::string why = track.validate();
  if (!why.empty()) return "track: " + why;
  why = config.validate();
  if (!why.empty()) return "config: " + why;
  if (!(time_s >= 0.0 && time_s <= kMaxPredictionTimeS)) {
    return "time must be in [0, 3600] s, got " + std::to_string(time_s);
  }
  return trackBoundsReason(track);
  return {};
}

Eigen::Vector2d predictPosition(const PlanarTrack& track, double dt_s) {
  return track.position + track.velocity * dt_s;
}

namespace {

void throwIfInvalid(const PlanarTrack& track, double time_s, const PredictionConfig& config) {
  const std::string why = validatePrediction(track, time_s, config);
  if (!why.empty()) throw std::invalid_argument(why);
}

// The unchecked helpers: every public function validates first (the config recentCells builds
// for itself has no speed limit, which validate() would refuse).
double radiusOf(const PlanarTrack& track, double dt_s, const PredictionConfig& config) {
  if (config.uncertainty_sigmas <= 0.0) return 0.0;
  const Eigen::Matrix2d sigma = track.position_covariance + dt_s * dt_s * track.velocity_covariance;
  // Largest eigenvalue of a symmetric 2 x 2, in closed form.
  const double mean = 0.5 * (sigma(0, 0) + sigma(1, 1));
  const double half_gap = 0.5 * (sigma(0, 0) - sigma(1, 1));
  const double eigen = mean + std::hypot(half_gap, sigma(0, 1));
  // NaN only when dt^2 * Σv overflowed (inf * 0, inf - inf): an uncertainty beyond any cap.
  if (std::isnan(eigen)) return config.max_uncertainty_m;
  const double largest = std::max(0.0, eigen);
  return std::min(config.max_uncertainty_m, config.uncertainty_sigmas * std::sqrt(largest));
}

double cross(const FootprintPoint& o, const FootprintPoint& a, const FootprintPoint& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

/// Andrew's monotone chain: the convex hull, counter-clockwise, collinear points dropped.
Footprint convexHull(Footprint points) {
  std::sort(points.begin(), points.end(), [](const FootprintPoint& a, const FootprintPoint& b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
  });
  if (points.size() < 3) return points;
  Footprint hull(2 * points.size());
  std::size_t k = 0;
  for (const FootprintPoint& p : points) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0.0) --k;
    hull[k++] = p;
  }
  const std::size_t lower = k + 1;
  for (auto it = points.rbegin() + 1; it != points.rend(); ++it) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], *it) <= 0.0) --k;
    hull[k++] = *it;
  }
  hull.resize(k - 1);  // the last point repeats the first
  return hull;
}

double segmentDistance(double px, double py, const FootprintPoint& a, const FootprintPoint& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0.0 ? ((px - a.x) * dx + (py - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(px - (a.x + t * dx), py - (a.y + t * dy));
}

/// Distance from a point to a convex counter-clockwise polygon (0 inside); a polygon of one or
/// two vertices is a point or a segment.
double convexDistance(double px, double py, const Footprint& hull) {
  if (hull.size() == 1) return std::hypot(px - hull[0].x, py - hull[0].y);
  if (hull.size() == 2) return segmentDistance(px, py, hull[0], hull[1]);
  bool inside = true;
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const FootprintPoint& a = hull[i];
    const FootprintPoint& b = hull[(i + 1) % hull.size()];
    if (cross(a, b, {px, py}) < 0.0) inside = false;
    nearest = std::min(nearest, segmentDistance(px, py, a, b));
  }
  return inside ? 0.0 : nearest;
}

Footprint sweptHull(const PlanarTrack& track, double duration_s, const PredictionConfig& config) {
  const double hx =
      0.5 * std::clamp(track.size_x, config.min_object_size_m, config.max_object_size_m);
  const double hy =
      0.5 * std::clamp(track.size_y, config.min_object_size_m, config.max_object_size_m);
  const double c = std::cos(track.box_yaw), s = std::sin(track.box_yaw);
  Footprint corners;
  for (const Eigen::Vector2d& centre :
       {predictPosition(track, 0.0), predictPosition(track, duration_s)}) {
    for (const double sx : {-hx, hx}) {
      for (const double sy : {-hy, hy}) {
        corners.push_back({centre.x() + c * sx - s * sy, centre.y() + s * sx + c * sy});
      }
    }
  }
  return convexHull(std::move(corners));
}

// predictedCells() once the track and the config are known to be valid.
CellBounds sweptCells(const PlanarTrack& track, double age_s, const PredictionConfig& config,
                      const GridGeometry& geometry, std::vector<std::size_t>* cells) {
  CellBounds bounds;
  if (track.velocity.norm() > config.max_speed_mps) return bounds;
  const double duration = age_s + config.prediction_horizon_s;
  const Footprint hull = sweptHull(track, duration, config);
  const double grow = radiusOf(track, duration, config);
  const std::size_t first = cells->size();

  // Cells whose centre lies within `grow` of the hull, over the hull's bounding box.
  double min_x = hull[0].x, max_x = hull[0].x, min_y = hull[0].y, max_y = hull[0].y;
  for (const FootprintPoint& p : hull) {
    min_x = std::min(min_x, p.x), max_x = std::max(max_x, p.x);
    min_y = std::min(min_y, p.y), max_y = std::max(max_y, p.y);
  }
  const CellBounds box =
      geometry.worldBoxToCells(min_x - grow, min_y - grow, max_x + grow, max_y + grow);
  for (int cy = box.min_y; cy <= box.max_y; ++cy) {
    for (int cx = box.min_x; cx <= box.max_x; ++cx) {
      double wx = 0.0, wy = 0.0;
      geometry.cellCentre(cx, cy, &wx, &wy);
      if (convexDistance(wx, wy, hull) <= grow) cells->push_back(geometry.index(cx, cy));
    }
  }
  // Every cell the centre path crosses (Amanatides-Woo, both ends included).
  const Eigen::Vector2d a = predictPosition(track, 0.0), b = predictPosition(track, duration);
  double x0 = a.x(), y0 = a.y(), x1 = b.x(), y1 = b.y();
  if (clipSegmentToGrid(geometry, &x0, &y0, &x1, &y1)) {
    traverseRay(geometry, x0, y0, x1, y1, true,
                [&](int cx, int cy) { cells->push_back(geometry.index(cx, cy)); });
  }
  std::sort(cells->begin() + first, cells->end());
  cells->erase(std::unique(cells->begin() + first, cells->end()), cells->end());
  for (std::size_t i = first; i < cells->size(); ++i) {
    const CellIndex cell = geometry.cellOf((*cells)[i]);
    bounds.expand(cell.x, cell.y);
  }
  return bounds;
}

}  // namespace

double uncertaintyRadius(const PlanarTrack& track, double dt_s, const PredictionConfig& config) {
  throwIfInvalid(track, std::abs(dt_s), config);  // dt enters squared: either sign
  return radiusOf(track, dt_s, config);
}

Footprint sweptPolygon(const PlanarTrack& track, double duration_s,
                       const PredictionConfig& config) {
  throwIfInvalid(track, duration_s, config);
  return sweptHull(track, duration_s, config);
}

CellBounds predictedCells(const PlanarTrack& track, double age_s, const PredictionConfig& config,
                          const GridGeometry& geometry, std::vector<std::size_t>* cells) {
  if (!validatePrediction(track, age_s, config).empty()) return {};
  return sweptCells(track, age_s, config, geometry, cells);
}

std::string recentCellsReason(const PlanarTrack& track, double lookback_s, double age_s,
                              double margin_m, double max_object_size_m) {
  const std::string why = track.validate();
  if (!why.empty()) return "track: " + why;
  const std::string bounds = trackBoundsReason(track);
  if (!bounds.empty()) return bounds;
  const auto bad = [](double v) { return !(std::isfinite(v) && v >= 0.0); };
  std::ostringstream out;
  if (!(lookback_s >= 0.0 && lookback_s <= kMaxPredictionTimeS && age_s >= 0.0 &&
        age_s <= kMaxPredictionTimeS)) {
    out << "lookback_s and age_s must be in [0, 3600] s, got " << lookback_s << " and " << age_s;
  } else if (bad(margin_m) || bad(max_object_size_m)) {
    out << "margin_m and max_object_size_m must be finite and >= 0 m, got " << margin_m << " and "
        << max_object_size_m;
  }
  return out.str();
}

CellBounds recentCells(const PlanarTrack& track, double lookback_s, double age_s, double margin_m,
                       double max_object_size_m, const GridGeometry& geometry,
                       std::vector<std::size_t>* cells) {
  if (!recentCellsReason(track, lookback_s, age_s, margin_m, max_object_size_m).empty()) return {};
  // The same sweep as a prediction, started lookback_s earlier, with the box grown and no
  // uncertainty: only where the object has been, not where it may go.
  PlanarTrack earlier = track;
  earlier.position = predictPosition(track, -lookback_s);
  earlier.size_x = std::min(track.size_x, max_object_size_m) + 2.0 * margin_m;
  earlier.size_y = std::min(track.size_y, max_object_size_m) + 2.0 * margin_m;
  PredictionConfig sweep;
  sweep.prediction_horizon_s = 0.0;
  sweep.uncertainty_sigmas = 0.0;
  sweep.max_object_size_m = max_object_size_m + 2.0 * margin_m;
  sweep.max_speed_mps = std::numeric_limits<double>::infinity();
  if (!earlier.validate().empty()) return {};  // a position or size that overflowed
  return sweptCells(earlier, lookback_s + age_s, sweep, geometry, cells);
}

}  // namespace downstream_perception
