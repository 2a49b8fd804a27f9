// A LaserScan (REP 117) to the rays VoxelMap::integrate takes: the beams are a fan of 3-D rays in
// the sensor's x-y plane (z = 0), transformed by the sensor's full 3-D pose, so a tilted or
// upside-down scanner marks and clears where its beams really go.
#pragma once

#include <Eigen/Geometry>

#include "downstream_perception/core/costmap/scan_integrator.h"  // LaserScanView
#include "downstream_perception/core/voxel/depth_rays.h"         // DepthRays

namespace downstream_perception {

/// REP-117 range semantics, as the obstacle layer's laser source (ScanIntegrator) reads them:
/// NaN, -Inf ("too close"), r < range_min and r > range_max are skipped and counted invalid; +Inf
/// is a no-return ray when inf_is_valid (else invalid); r == range_max is a no-return ray when
/// range_max_is_no_return; any other r is a return at r. No-return points lie 1 m along their
/// ray. Throws std::invalid_argument for a scan that fails LaserScanView::validate() or a
/// non-finite pose.
void scanToRays(const LaserScanView& scan, const Eigen::Isometry3d& T_world_sensor,
                bool inf_is_valid, bool range_max_is_no_return, DepthRays* out);

}  // namespace downstream_perception
