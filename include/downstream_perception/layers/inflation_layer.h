// downstream_perception/InflationLayer: costmap_2d's inflation costs from exact distances, updated
// only where the set of lethal cells changed (see core/inflation.h). Must be the last layer.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/InflationLayerConfig.h"
#include "downstream_perception/core/costmap/inflation.h"
#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/costmap/layer.h"

namespace downstream_perception {

class InflationLayer : public Layer {
 public:
  void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x, double* min_y,
                    double* max_x, double* max_y) override;
  void updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) override;
  void matchSize() override;
  void shiftOrigin(int dx, int dy) override;
  void reset() override;
  void onFootprintChanged() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;

 protected:
  void onInitialize() override;

 private:
  void reconfigure(InflationLayerConfig& config, std::uint32_t level);
  /// Validates `candidate` (with the footprint's inscribed radius) and rebuilds the Inflator;
  /// an invalid candidate is logged, kept under `error_key` in diagnostics (until a valid one
  /// clears it) and the previous valid settings stay. Returns whether it was accepted.
  bool applyConfig(InflationConfig candidate, const std::string& error_key);
  /// WARNs (once per value) when costmap_2d's ceil(radius / resolution) cells reach further.
  void noteRadiusDifference(double resolution);

  std::mutex mutex_;
  InflationConfig config_;  ///< inscribed_radius comes from the footprint
  std::unique_ptr<Inflator> inflator_;
  ConfigErrorLog config_errors_;
  bool need_full_window_ = true;   ///< after (re)configuration: update the whole map once
  std::string radius_note_;        ///< how this radius differs from costmap_2d's, or ""
  std::string small_radius_note_;  ///< the radius is below the inscribed one (warned once), or ""
  std::vector<std::string> param_warnings_;  ///< wrong types, unknown keys (start-up)
  InflationStats last_;
  std::size_t updates_ = 0;
  RunningStats update_ms_;
  ReconfigureHost<InflationLayerConfig> reconfigure_;
};

}  // namespace downstream_perception
