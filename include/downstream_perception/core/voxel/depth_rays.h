// Depth image (REP 118, metres) to the rays VoxelMap::integrate takes: returns and no-return
// directions, in the world frame.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "downstream_perception/core/tsdf/tsdf_integrator.h"  // PinholeCamera

namespace downstream_perception {

struct DepthRays {
  std::vector<float> hits;        ///< x, y, z triplets, world frame, m
  std::vector<float> no_returns;  ///< a point 1 m along each no-return pixel's ray, world frame
  std::size_t invalid = 0;        ///< pixels with no usable value (NaN, -Inf, <= 0 unless below)
};

/// Back-projects every `stride`-th pixel (in x and y) of a row-major depth image (metres, optical
/// frame: z forward) through T_world_camera. +Inf is a no-return (REP 118: nothing within range);
/// 0 is a no-return only when zero_is_no_return (many drivers write 0 for "too far" and "no data"
/// alike, so by default it is skipped); NaN, -Inf and negative values are skipped and counted.
/// Throws std::invalid_argument for an invalid camera, stride < 1, a non-finite pose or a null
/// image.
void depthToRays(const float* depth_m, const PinholeCamera& camera,
                 const Eigen::Isometry3d& T_world_camera, bool zero_is_no_return, int stride,
                 DepthRays* out);

/// costmap_2d's per-source height band: removes the points (x, y, z triplets, world frame) whose
/// finite z lies outside [min_z_m, max_z_m], so that they neither mark nor clear (costmap_2d's
/// observation buffer drops them). Non-finite points are kept (integrate() counts them invalid).
/// Returns the number removed; the order of the points kept is unchanged.
std::size_t dropOutsideHeightBand(std::vector<float>* xyz, double min_z_m, double max_z_m);

}  // namespace downstream_perception
