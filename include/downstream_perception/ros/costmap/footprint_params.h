// Reads the robot footprint from costmap_2d-style parameters.
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <vector>

#include "downstream_perception/core/costmap/footprint.h"

namespace downstream_perception {

/// `footprint` ([[x, y], ...] as a list or as a string, metres in robot_base_frame) if set,
/// else a circle of `robot_radius` (m, default 0.46); then grown by `footprint_padding` (m,
/// default 0.01). Invalid values are reported into *errors and replaced by the defaults.
Footprint readFootprint(const ros::NodeHandle& pnh, std::vector<std::string>* errors);

}  // namespace downstream_perception
