// Tracked-obstacle layer: the tracker's confirmed tracks drawn as LETHAL where they will be over
// the next prediction_horizon_s, so the inflation layer grows a corridor around each moving
// object's path and the planner routes around where it is heading, not where it was.
//
// The tracks come through a TrackInbox (transformed into the costmap's global frame at their own
// stamp, never "latest"; dropped after track_timeout_s). Each update sweeps every track from its
// stamp over (now - stamp) + prediction_horizon_s (core/tracking/predicted_footprint.h).
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/TrackedObstacleLayerConfig.h"
#include "downstream_perception/core/tracking/predicted_footprint.h"
#include "downstream_perception/layers/track_inbox.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/costmap/layer.h"

namespace downstream_perception {

class TrackedObstacleLayer : public Layer {
 public:
  TrackedObstacleLayer() = default;
  ~TrackedObstacleLayer() override;

  void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x, double* min_y,
                    double* max_x, double* max_y) override;
  void updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) override;
  void matchSize() override;
  void reset() override;
  void onClockJump() override { inbox_.onClockJump(); }
  void activate() override;
  void deactivate() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;

 protected:
  void onInitialize() override;

 private:
  void reconfigure(TrackedObstacleLayerConfig& config, std::uint32_t level);

  TrackInbox inbox_;
  std::mutex mutex_;  ///< guards everything below
  PredictionConfig prediction_;
  std::vector<std::size_t> cells_;  ///< cells drawn at the last update
  double drawn_min_x_ = 0.0, drawn_min_y_ = 0.0, drawn_max_x_ = -1.0, drawn_max_y_ = -1.0;
  std::size_t tracks_drawn_ = 0;
  bool subscribed_ = false;
  ConfigErrorLog config_errors_;
  std::vector<std::string> param_warnings_;  ///< wrong types, unknown keys (start-up)
  ReconfigureHost<TrackedObstacleLayerConfig> reconfigure_;
};

}  // namespace downstream_perception
