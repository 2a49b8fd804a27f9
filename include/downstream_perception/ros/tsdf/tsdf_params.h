// TsdfConfig from ROS parameters (names = TsdfConfig fields, units in the names).
#pragma once

#include <ros/node_handle.h>

#include <string>

#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "downstream_perception/ros/common/config_errors.h"

namespace downstream_perception {

/// Reads ~voxel_size_m, ~truncation_voxels, ... into a TsdfConfig. An invalid value (or an
/// invalid combination) is added to `errors` and the defaults are used for the whole config, so
/// a map is never built from half-valid settings.
TsdfConfig loadTsdfConfig(const ros::NodeHandle& pnh, ConfigErrorLog* errors);

/// The two settings whose parameter type differs from the field's (the weighting by name, the
/// block cap as an int), checked and stored into `c`. Empty on success, else the reason (and `c`
/// keeps its values). Shared by the start-up parameters and dynamic_reconfigure.
std::string setNamedTsdfSettings(const std::string& weighting, int max_blocks, TsdfConfig* c);

}  // namespace downstream_perception
