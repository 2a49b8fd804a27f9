// costmap_2d's treatment of a LaserScan before it reaches the map, on a copy of its ranges (no
// ROS types: unit-tested without a master).
//
// costmap_2d projects every scan into a point cloud in the global frame and keeps only the
// points whose height z lies in [min_obstacle_height, max_obstacle_height]; a point outside the
// band neither marks nor clears. With its inf_is_valid, a +Inf range first becomes a return just
// inside range_max (range_max - 0.1 mm): it clears up to there and marks when that lies within
// obstacle_range.
#pragma once

#include <cstddef>
#include <vector>

namespace downstream_perception {

/// The height band of a source, in the global frame (m).
struct ScanHeightBand {
  double min_z = 0.0;
  double max_z = 2.0;
};

/// A beam's end height from the sensor pose: z(r, a) = origin_z + r * (zx cos a + zy sin a), with
/// a the beam angle in the sensor frame and (zx, zy) the global z components of the sensor's x
/// and y axes (0 for a level scanner).
struct ScanHeightModel {
  double origin_z = 0.0;
  double zx = 0.0;
  double zy = 0.0;
};

struct ScanPrefilterStats {
  std::size_t outside_band = 0;     ///< beams set to NaN: their end point is outside the band
  std::size_t inf_substituted = 0;  ///< +Inf beams turned into returns at range_max - 0.1 mm
};

/// costmap_2d's inf_is_valid substitution distance below range_max (m).
constexpr double kCostmap2dInfEpsilonM = 1e-4;

/// Applies both rules to `ranges` (beam k at angle_min + k * angle_increment). Finite positive
/// ranges are height-tested at their own end; +Inf (when not substituted) at
/// `no_return_range_m`, where its clearing would end. NaN, -Inf and other ranges are left as
/// they are (the integrator ignores them).
ScanPrefilterStats prefilterScanRanges(std::vector<float>* ranges, double angle_min,
                                       double angle_increment, double range_max,
                                       bool costmap2d_inf_is_valid, double no_return_range_m,
                                       const ScanHeightModel& model, const ScanHeightBand& band);

}  // namespace downstream_perception
