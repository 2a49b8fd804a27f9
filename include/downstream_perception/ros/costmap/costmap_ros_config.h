// The costmap host's parameters (names = the YAML keys = the dynamic_reconfigure keys) and their
// validation: an absurd value is reported and replaced by the fallback's, never used.
#pragma once

#include <string>
#include <utility>
#include <vector>

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

  int sizeXCells() const;
  int sizeYCells() const;
};

/// Parameter problems by key, in the order they were found (the first is the diagnostics
/// summary); a later valid value for a key clears its entry.
class ConfigErrors {
 public:
  /// Replaces the entry of `key` in place, or appends one.
  void set(const std::string& key, const std::string& msg) {
    for (auto& entry : entries_) {
      if (entry.first == key) {
        entry.second = msg;
        return;
      }
    }
    entries_.emplace_back(key, msg);
  }
  /// Erases every entry whose key starts with `prefix` (a key is its own prefix).
  void eraseWithPrefix(const std::string& prefix) {
    std::vector<std::pair<std::string, std::string>> kept;
    for (auto& entry : entries_) {
      if (entry.first.rfind(prefix, 0) != 0) kept.push_back(std::move(entry));
    }
    entries_ = std::move(kept);
  }
  void merge(const ConfigErrors& other) {
    for (const auto& entry : other.entries_) set(entry.first, entry.second);
  }
  std::vector<std::string> messages() const {
    std::vector<std::string> out;
    for (const auto& entry : entries_) out.push_back(entry.second);
    return out;
  }
  bool empty() const { return entries_.empty(); }

 private:
  std::vector<std::pair<std::string, std::string>> entries_;
};

/// Reads every field through `params` (defaults for the missing ones; a value of the wrong type
/// is named and the default used), then validates.
CostmapRosConfig readCostmapConfig(ParamReader& params, ConfigErrors* errors);

/// The host-level keys readCostmapConfig() reads (for the unknown-key audit).
const std::vector<std::string>& costmapConfigKeys();

/// Replaces each invalid field of *config by the one of `fallback`, reporting each into *errors
/// (and the log) by parameter name, value and what is used instead. Every key it checks that is
/// valid now has its entry erased from *errors.
void validateCostmapConfig(CostmapRosConfig* config, const CostmapRosConfig& fallback,
                           ConfigErrors* errors);

}  // namespace downstream_perception
