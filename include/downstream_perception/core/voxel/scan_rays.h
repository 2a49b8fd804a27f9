// A LaserScan (REP 117) to the rays VoxelMap::integrate takes: the beams are a fan of 3-D rays in
// the sensor's x-y plane (z = 0), transformed by the sensor's full 3-D pose, so a tilted or
// upside-down scanner marks and clears where its beams really go.
#pragma once

#include <Eigen/Geometry>

#include "downstream_perception/core/costmap/scan_integrator.h"  // LaserScanView
#include "downstream_perception/core/voxel/depth_rays.h"         // DepthRays

namespace downstream_perception {

/// How +Inf and range_max readings are read (the obstacle layer's keys and meanings).
struct ScanRayOptions {
  /// costmap_2d's key: +Inf is a return just inside range_max (costmap_2d substitutes
  /// range_max - 0.1 mm), so it clears to there and marks if within the obstacle range.
  bool inf_is_valid = false;
  /// Ours (REP-117): +Inf is a no-return ray (clears to the no-return range, never marks); wins
  /// over inf_is_valid.
  bool inf_is_no_return = false;
  /// r == range_max is a no-return ray too (drivers that report range_max for nothing).
  bool range_max_is_no_return = false;
};

/// REP-117 range semantics, as the obstacle layer's laser source (ScanIntegrator) reads them:
/// NaN, -Inf ("too close"), r < range_min and r > range_max are skipped and counted invalid; +Inf
/// per the options (else invalid); r == range_max is a no-return ray when range_max_is_no_return;
/// any other r is a return at r. No-return points lie 1 m along their ray. Throws
/// std::invalid_argument for a scan that fails LaserScanView::validate() or a non-finite pose.
void scanToRays(const LaserScanView& scan, const Eigen::Isometry3d& T_world_sensor,
                const ScanRayOptions& options, DepthRays* out);
/// The same for a sensor that moves during the sweep: beam k's pose is interpolated between the
/// first beam's (T_world_first, at the header stamp) and the last beam's (T_world_last), linearly
/// in translation and by slerp in rotation, at k / (count - 1). Throws as above.
void scanToRays(const LaserScanView& scan, const Eigen::Isometry3d& T_world_first,
                const Eigen::Isometry3d& T_world_last, const ScanRayOptions& options,
                DepthRays* out);

}  // namespace downstream_perception
