// The costmap host's parameters (names = the YAML keys = the dynamic_reconfigure keys) and their
// validation: an absurd value is reported and replaced by the fallback's, never used.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/param_reader.h"

namespace downstream_perception {

struct CostmapRosConfig {
  std::string global_frame = "map";
  std::string robot_base_frame = "base_link";
  double update_frequency = 5.0;          ///< Hz
  double publish_frequency = 0.0;         ///< Hz; 0 = never publish (costmap_2d's default)
  double width = 10.0;                    ///< m
  double height = 10.0;                   ///< m
  double resolution = 0.05;               ///< m / cell
  double origin_x = 0.0;                  ///< m, lower-left corner in global_frame
  double origin_y = 0.0;                  ///< m
  double transform_tolerance = 0.3;       ///< s: oldest acceptable robot pose
  bool track_unknown_space = false;       ///< costmap_2d's default: unknown cells are free
  bool rolling_window = false;            ///< keep the map centred on the robot (whole-cell shifts)
  bool always_send_full_costmap = false;  ///< no ~costmap_updates: the whole grid every time
  // Our keys (costmap_2d has no such mode): update and publish as soon as a layer has integrated
  // new data, besides the update_frequency timer (which keeps running: rolling, decay,
  // timeouts). Off by default, so costmap_2d's timer semantics hold unless asked for.
  bool update_on_data = false;
  double update_on_data_max_rate_hz = 50.0;  ///< Hz: data-driven updates at most this often

  int sizeXCells() const;
  int sizeYCells() const;
};

/// Reads every field through `params` (defaults for the missing ones; a value of the wrong type
/// is named and the default used), then validates.
CostmapRosConfig readCostmapConfig(ParamReader& params, ConfigErrorLog* errors);

/// The host-level keys readCostmapConfig() reads (for the unknown-key audit).
const std::vector<std::string>& costmapConfigKeys();

/// Replaces each invalid field of *config by the one of `fallback`, reporting each into *errors
/// (which logs it) by parameter name, value and what is used instead. Every key it checks that is
/// valid now has its entry erased from *errors.
void validateCostmapConfig(CostmapRosConfig* config, const CostmapRosConfig& fallback,
                           ConfigErrorLog* errors);

}  // namespace downstream_perception
