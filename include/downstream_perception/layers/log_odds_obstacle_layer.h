// downstream_perception/LogOddsObstacleLayer: LaserScan sources integrated into a log-odds grid
// (hit/miss increments, clamp, exact ray clearing, REP-117 semantics), each scan placed with the
// transform at its own stamp. The master gets LETHAL (l > occupied_log_odds), FREE
// (l < free_log_odds) or, for cells in between, nothing (they keep the master's default:
// NO_INFORMATION when tracking unknown space, else FREE).
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "downstream_perception/core/log_odds_grid.h"
#include "downstream_perception/layer.h"
#include "downstream_perception/layers/laser_scan_source.h"

namespace downstream_perception {

class LogOddsObstacleLayer : public Layer {
 public:
  LogOddsObstacleLayer() = default;
  ~LogOddsObstacleLayer() override;

  void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x, double* min_y,
                    double* max_x, double* max_y) override;
  void updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) override;
  void matchSize() override;
  void reset() override;
  void activate() override;
  void deactivate() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;

 protected:
  void onInitialize() override;

 private:
  void readSources();
  void integrateScan(LaserScanSource& source, const AcceptedScan& scan);

  std::mutex grid_mutex_;  ///< guards grid_ and dirty_
  LogOddsGrid grid_;
  LogOddsConfig grid_config_;
  CellBounds dirty_;  ///< cells updated since the last updateBounds
  bool track_unknown_space_ = true;
  std::vector<std::unique_ptr<LaserScanSource>> sources_;
  std::vector<std::string> config_errors_;
};

}  // namespace downstream_perception
