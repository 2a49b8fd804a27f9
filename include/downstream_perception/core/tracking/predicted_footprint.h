// Predicted obstacles: where a tracked object may be over the next seconds, as costmap cells.
//
// A track (position, velocity, their covariances, a box size) is projected with constant
// velocity from its measurement stamp over the time it is already old plus the prediction
// horizon. The swept shape is the convex hull of its box at the start and at the end of that
// interval, grown by k standard deviations of the predicted position (Σp + t² Σv, largest
// eigenvalue, at the end of the interval: the widest it gets). The cells it covers are those
// whose centre lies in that shape, plus every cell the object's centre path crosses (so a small
// or thin object still leaves an unbroken corridor, the lesson's cells 142-160 on row 81).
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

#include "downstream_perception/core/costmap/footprint.h"
#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {

struct PredictionConfig {
  double prediction_horizon_s = 1.5;  ///< s: how far ahead of now the object is swept
  /// k: the shape grows by k standard deviations of the predicted position (0 = box only).
  double uncertainty_sigmas = 2.0;
  /// m: cap on that growth, so a track with an absurd covariance cannot blank the map.
  double max_uncertainty_m = 1.0;
  double min_object_size_m = 0.0;  ///< m: smaller box sides are raised to this
  double max_object_size_m = 5.0;  ///< m: larger box sides are clamped to this (bad sizes)
  double max_speed_mps = 10.0;     ///< m/s: faster tracks are not swept (bad velocities)

  /// Empty if valid, else the reason.
  std::string validate() const;
};

/// One track in the costmap's frame.
struct PlanarTrack {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();             ///< m, at the measurement stamp
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();             ///< m/s
  Eigen::Matrix2d position_covariance = Eigen::Matrix2d::Zero();  ///< m²
  Eigen::Matrix2d velocity_covariance = Eigen::Matrix2d::Zero();  ///< m²/s²
  double size_x = 0.0;   ///< m, box side along the box's x axis
  double size_y = 0.0;   ///< m
  double box_yaw = 0.0;  ///< rad: the box's x axis in the costmap frame

  /// Empty if every field is finite and the covariances are symmetric, else the reason.
  std::string validate() const;
};

/// Empty if a prediction from `track` over `time_s` with `config` is possible (track.validate(),
/// config.validate(), time_s finite and >= 0), else the reason. The functions below check it.
std::string validatePrediction(const PlanarTrack& track, double time_s,
                               const PredictionConfig& config);

/// The track's predicted position after dt_s (constant velocity).
Eigen::Vector2d predictPosition(const PlanarTrack& track, double dt_s);
/// Growth radius (m) for the predicted position dt_s after the stamp: k·sqrt(λmax(Σp + dt² Σv)),
/// capped at max_uncertainty_m. Throws std::invalid_argument if validatePrediction() fails.
double uncertaintyRadius(const PlanarTrack& track, double dt_s, const PredictionConfig& config);

/// The convex polygon swept by the track's box from its stamp over duration_s (counter-clockwise;
/// fewer than 3 vertices when the box has no area: a segment or a point). Throws
/// std::invalid_argument if validatePrediction() fails.
Footprint sweptPolygon(const PlanarTrack& track, double duration_s, const PredictionConfig& config);

/// Cells covered by the track from its stamp over age_s + prediction_horizon_s (age_s = now -
/// stamp, >= 0), clipped to the grid. Appends linear indices to *cells (each once) and returns the
/// window they span (empty if none). Called per track on message data, so it does not throw:
/// nothing is appended (and the window is empty) if validatePrediction() fails or the track is
/// faster than max_speed_mps.
CellBounds predictedCells(const PlanarTrack& track, double age_s, const PredictionConfig& config,
                          const GridGeometry& geometry, std::vector<std::size_t>* cells);

/// Cells under the track's box, each side grown by margin_m (sides clamped to max_object_size_m),
/// swept from lookback_s before its stamp to age_s after it: where the object's own sensor returns
/// have recently landed and where it is now. The obstacle layer clears these cells
/// (clear_tracked_objects) so that a tracked object is drawn once, by its prediction. Appends to
/// *cells like predictedCells(); nothing if recentCellsReason() is not empty.
CellBounds recentCells(const PlanarTrack& track, double lookback_s, double age_s, double margin_m,
                       double max_object_size_m, const GridGeometry& geometry,
                       std::vector<std::size_t>* cells);
/// Empty if recentCells() can sweep `track` with these values (track.validate(), the times,
/// margin and size finite and >= 0), else the reason.
std::string recentCellsReason(const PlanarTrack& track, double lookback_s, double age_s,
                              double margin_m, double max_object_size_m);

}  // namespace downstream_perception
