// The costmap host's parameters (names = the YAML keys = the dynamic_reconfigure keys) and their
// validation: an absurd value is reported and replaced by the fallback's, never used.
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <vector>

namespace downstream_perception {

struct CostmapRosConfig {
  std::string global_frame = "map";
  std::string robot_base_frame = "base_link";
  double update_frequency = 5.0;     ///< Hz
  double publish_frequency = 1.0;    ///< Hz; 0 = never publish
  double width = 10.0;               ///< m
  double height = 10.0;              ///< m
  double resolution = 0.05;          ///< m / cell
  double origin_x = 0.0;             ///< m, lower-left corner in global_frame
  double origin_y = 0.0;             ///< m
  double transform_tolerance = 0.3;  ///< s: oldest acceptable robot pose
  bool track_unknown_space = true;
  bool rolling_window = false;            ///< keep the map centred on the robot (whole-cell shifts)
  bool always_send_full_costmap = false;  ///< no ~costmap_updates: the whole grid every time

  int sizeXCells() const;
  int sizeYCells() const;
};

/// Reads every field from `pnh` (defaults for the missing ones), then validates.
CostmapRosConfig readCostmapConfig(const ros::NodeHandle& pnh, std::vector<std::string>* errors);

/// Replaces each invalid field of *config by the one of `fallback`, reporting each into *errors
/// (and the log) by parameter name, value and what is used instead.
void validateCostmapConfig(CostmapRosConfig* config, const CostmapRosConfig& fallback,
                           std::vector<std::string>* errors);

}  // namespace downstream_perception
