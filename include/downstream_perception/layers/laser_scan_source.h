// One LaserScan observation source of the obstacle layer: subscription, tf2 MessageFilter (the
// scan is released only once the transform at its own stamp exists), message checks, and the
// per-source health counters. Parameters live in <layer ns>/<source name>.
#pragma once

#include <message_filters/subscriber.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "downstream_perception/core/scan_integrator.h"
#include "downstream_perception/running_stats.h"

namespace downstream_perception {

struct LaserScanSourceConfig {
  std::string topic;                ///< defaults to the source name
  std::string sensor_frame;         ///< overrides the scan's frame_id when non-empty
  double expected_update_rate = 0;  ///< s between scans before the layer is "not current"; 0 = off
  int tf_queue_size = 20;           ///< scans held while waiting for tf
  ScanIntegratorConfig integrator;  ///< marking, clearing, ranges, inf_is_valid, ...
};

/// A scan that passed the checks, with the sensor pose in the layer's global frame at its stamp.
struct AcceptedScan {
  sensor_msgs::LaserScanConstPtr msg;
  LaserScanView view;  ///< angles already mirrored for an upside-down sensor
  Pose2D sensor_pose;  ///< in the global frame, at msg->header.stamp
};

class LaserScanSource {
 public:
  using Callback = std::function<void(LaserScanSource&, const AcceptedScan&)>;

  LaserScanSource(std::string name, const LaserScanSourceConfig& config, ros::NodeHandle nh,
                  tf2_ros::Buffer& tf, std::string global_frame, Callback on_scan);
  ~LaserScanSource();

  void subscribe();
  void unsubscribe();

  const std::string& name() const { return name_; }
  const LaserScanSourceConfig& config() const { return config_; }
  ScanIntegrator& integrator() { return integrator_; }

  /// Counters for diagnostics; take the lock returned by mutex() while reading them.
  struct Health {
    std::size_t received = 0;
    std::size_t integrated = 0;
    std::map<std::string, std::size_t> rejected;  ///< reason -> count (bad message, tf, ...)
    RunningStats transform_age_s;                 ///< now - stamp when integrated
    RunningStats integrate_ms;
    IntegrationStats last;   ///< the last scan's integration
    IntegrationStats total;  ///< since start
    ros::Time last_stamp;
    ros::WallTime last_received;
  };
  const Health& health() const { return health_; }
  std::mutex& mutex() { return mutex_; }
  void recordIntegration(const IntegrationStats& stats, double integrate_ms, double age_s);
  /// True if scans arrive as often as expected_update_rate demands.
  bool isCurrent() const;

 private:
  void onScan(const sensor_msgs::LaserScanConstPtr& msg);
  void onTfFailure(const sensor_msgs::LaserScanConstPtr& msg,
                   tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void reject(const std::string& reason, const std::string& detail);

  std::string name_;
  LaserScanSourceConfig config_;
  ros::NodeHandle nh_;
  tf2_ros::Buffer& tf_;
  std::string global_frame_;
  Callback on_scan_;
  ScanIntegrator integrator_;

  std::unique_ptr<message_filters::Subscriber<sensor_msgs::LaserScan>> subscriber_;
  std::unique_ptr<tf2_ros::MessageFilter<sensor_msgs::LaserScan>> filter_;
  mutable std::mutex mutex_;
  Health health_;
};

}  // namespace downstream_perception
