// downstream_perception/StaticLayer: map_server's nav_msgs/OccupancyGrid (and, optionally,
// map_msgs/OccupancyGridUpdate windows) drawn into the costmap with costmap_2d's StaticLayer
// parameters and meaning (see core/static_map.h for the value mapping).
//
// Differences from costmap_2d, each on purpose:
//  - onInitialize() never waits for the map (costmap_2d spins until it arrives, which would hold
//    up a whole nodelet manager). Until the first map the layer is not current, diagnostics say
//    "waiting for map on <topic>" and a WARN names the topic every few seconds.
//  - Malformed maps and updates (sizes, resolution, NaN origin, a rotated origin, more than
//    max_cells, an update window outside the map) are refused with a reason; the previous map
//    stays. costmap_2d writes out of bounds on such an update.
//  - A non-rolling costmap whose global_frame is not the map's frame refuses the map (costmap_2d
//    copies it cell by cell as if the frames were the same).
//  - use_maximum on a rolling window combines as costmap_2d's updateWithMax() does everywhere
//    (an unknown map cell never overrides), where costmap_2d's rolling path takes a plain max
//    in which unknown (255) wins.
#pragma once

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/StaticLayerConfig.h"
#include "downstream_perception/core/costmap/static_map.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/costmap/layer.h"

namespace downstream_perception {

class StaticLayer : public Layer {
 public:
  ~StaticLayer() override;

  void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x, double* min_y,
                    double* max_x, double* max_y) override;
  void updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) override;
  void matchSize() override;
  void reset() override;
  void activate() override;
  void deactivate() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;

  /// Seconds without a map before the first WARN (then every kWaitWarnRepeatS).
  static constexpr double kWaitWarnFirstS = 5.0;
  static constexpr double kWaitWarnRepeatS = 30.0;

 protected:
  void onInitialize() override;

 private:
  void readParameters();
  void subscribe();
  void onMap(const nav_msgs::OccupancyGridConstPtr& msg);
  void onUpdate(const map_msgs::OccupancyGridUpdateConstPtr& msg);
  void reconfigure(StaticLayerConfig& cfg, std::uint32_t level);
  void waitWarn(const ros::WallTimerEvent&);
  /// Records a refused map or update (log line + diagnostics). Caller holds mutex_.
  void refuse(const std::string& what, const std::string& why);
  /// The map frame as tf2 names it (no leading '/'; empty = the costmap's global frame).
  std::string mapFrameOf(const std::string& frame_id) const;
  /// Rolling window: master frame -> map frame, looked up now. Caller holds mutex_.
  bool lookUpTransform();

  // Parameters (start-up values, as costmap_2d reads them once).
  std::string map_topic_ = "map";
  std::string resolved_topic_;
  bool first_map_only_ = false;
  bool subscribe_to_updates_ = false;
  StaticMapConfig config_;
  std::vector<std::string> param_warnings_;

  std::mutex mutex_;  ///< guards everything below; never held while taking the host's mutex
  StaticMap map_;
  std::string map_frame_;
  CellBounds pending_;       ///< map cells changed since the last updateBounds()
  bool redraw_all_ = false;  ///< the whole map (matchSize, reset, enable)
  bool have_transform_ = false;
  Affine2D map_from_global_;  ///< rolling window: the transform used by the last draw
  std::size_t maps_received_ = 0;
  std::size_t maps_refused_ = 0;
  std::size_t updates_received_ = 0;
  std::size_t updates_refused_ = 0;
  std::size_t tf_failures_ = 0;
  std::string last_refusal_;
  bool last_map_refused_ = false;  ///< the latest map was refused (an older one may be drawn)
  std::string last_tf_error_;

  ros::Subscriber map_sub_;
  ros::Subscriber update_sub_;
  ros::WallTimer wait_timer_;
  ros::WallTime subscribed_at_;
  ReconfigureHost<StaticLayerConfig> reconfigure_;
};

}  // namespace downstream_perception
