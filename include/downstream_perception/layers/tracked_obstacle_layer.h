// Tracked-obstacle layer: the tracker's confirmed tracks drawn as LETHAL where they will be over
// the next prediction_horizon_s, so the inflation layer grows a corridor around each moving
// object's path and the planner routes around where it is heading, not where it was.
//
// Each TrackedObjectArray is released by a tf2 MessageFilter once the transform into the
// costmap's global frame at the array's own stamp exists, and is transformed with that transform
// (never "latest"). Each update sweeps every track from its stamp over (now - stamp) +
// prediction_horizon_s (core/tracking/predicted_footprint.h). A newer array replaces the older;
// an array older than track_timeout_s is dropped, so a stale track never stays in the map.
#pragma once

#include <ros/ros.h>

#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/TrackedObjectArray.h"
#include "downstream_perception/core/tracking/predicted_footprint.h"
#include "downstream_perception/filtered_subscription.h"
#include "downstream_perception/layer.h"
#include "downstream_perception/running_stats.h"

namespace downstream_perception {

class TrackedObstacleLayer : public Layer {
 public:
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
  void onTracks(const TrackedObjectArrayConstPtr& msg);
  void reject(const std::string& reason, const std::string& detail);
  void subscribe();

  std::mutex mutex_;
  FilteredSubscription<TrackedObjectArray> subscription_;
  std::string topic_;
  PredictionConfig prediction_;
  double track_timeout_s_ = 1.0;
  bool include_tentative_ = false;
  bool include_coasting_ = true;
  int tf_queue_size_ = 20;

  ros::Time tracks_stamp_;           ///< stamp of the array the tracks came from
  std::vector<PlanarTrack> tracks_;  ///< in the global frame at tracks_stamp_
  std::vector<std::size_t> cells_;   ///< cells drawn at the last update
  double drawn_min_x_ = 0.0, drawn_min_y_ = 0.0, drawn_max_x_ = -1.0, drawn_max_y_ = -1.0;

  std::size_t arrays_received_ = 0;
  std::size_t arrays_expired_ = 0;
  std::size_t tracks_skipped_state_ = 0;
  std::map<std::string, std::size_t> rejected_;
  std::string last_rejection_;
  RunningStats transform_age_s_;  ///< now - stamp when an array is transformed
  std::size_t tracks_drawn_ = 0;
  std::vector<std::string> config_errors_;
};

}  // namespace downstream_perception
