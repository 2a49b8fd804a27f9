// TsdfConfig from ROS parameters (names = TsdfConfig fields, units in the names).
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <vector>

#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {

/// Reads ~voxel_size_m, ~truncation_voxels, ... into a TsdfConfig. An invalid value (or an
/// invalid combination) is reported in `errors` (the caller logs it) and the defaults are used for
/// the whole config, so a map is never built from half-valid settings.
TsdfConfig loadTsdfConfig(const ros::NodeHandle& pnh, std::vector<std::string>* errors);

}  // namespace downstream_perception
