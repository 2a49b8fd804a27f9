// One observation source of the obstacle layer (a LaserScan or PointCloud2 topic): subscription
// through a tf2 MessageFilter (a message is released only once the transform at its own stamp
// exists), message checks, and per-source health counters. A source turns each accepted message
// into beams in the layer's global frame; the layer integrates them. Parameters live in
// <layer ns>/<source name>.
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/core/cloud_beams.h"
#include "downstream_perception/core/scan_integrator.h"
#include "downstream_perception/filtered_subscription.h"
#include "downstream_perception/running_stats.h"

namespace downstream_perception {

struct ObservationSourceConfig {
  std::string topic;                     ///< defaults to the source name
  std::string sensor_frame;              ///< overrides the message's frame_id when non-empty
  double expected_update_rate = 0;       ///< s between messages before "not current"; 0 = off
  int tf_queue_size = 20;                ///< messages held while waiting for tf
  ScanIntegratorConfig integrator;       ///< marking, clearing, ranges, inf_is_valid, ...
  CloudBeamsConfig cloud;                ///< PointCloud2 only: the obstacle height band
  bool per_beam_time_correction = true;  ///< LaserScan only: de-skew with time_increment
};

/// The beams of one accepted message, in the layer's global frame.
struct Observation {
  ros::Time stamp;
  std::vector<BeamUpdate> beams;
  IntegrationStats decisions;  ///< beam counts from making the beams (invalid, no return, ...)
};

class ObservationSource {
 public:
  using Callback = std::function<void(ObservationSource&, const Observation&)>;

  virtual ~ObservationSource() = default;
  virtual void subscribe() = 0;
  virtual void unsubscribe() = 0;
  /// "LaserScan" or "PointCloud2".
  virtual const char* dataType() const = 0;
  /// Messages held back for their transform for a while, per frame, with the reason.
  virtual std::vector<TfWait> waitingForTf() const = 0;

  const std::string& name() const { return name_; }
  const ObservationSourceConfig& config() const { return config_; }
  ScanIntegrator& integrator() { return integrator_; }

  /// Counters for diagnostics; take the lock returned by mutex() while reading them.
  struct Health {
    std::size_t received = 0;
    std::size_t integrated = 0;
    std::map<std::string, std::size_t> rejected;  ///< reason -> count (bad message, tf, ...)
    std::map<std::string, std::size_t> notes;     ///< accepted, but e.g. de-skew skipped
    RunningStats transform_age_s;                 ///< now - stamp when integrated
    RunningStats integrate_ms;
    IntegrationStats last;   ///< the last message's integration
    IntegrationStats total;  ///< since start
    ros::WallTime last_received;
  };
  const Health& health() const { return health_; }
  std::mutex& mutex() { return mutex_; }
  void recordIntegration(const IntegrationStats& stats, double integrate_ms, double age_s);
  /// True if messages arrive as often as expected_update_rate demands.
  bool isCurrent() const;

 protected:
  ObservationSource(std::string name, const ObservationSourceConfig& config, ros::NodeHandle nh,
                    tf2_ros::Buffer& tf, std::string global_frame, Callback on_observation);

  void countReceived();
  void reject(const std::string& reason, const std::string& detail);
  void note(const std::string& what);
  void onTfFailure(const std::string& frame, const ros::Time& stamp,
                   tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  /// global_frame <- frame at `stamp`; on failure rejects with the reason and returns false.
  bool lookup(const std::string& frame, const ros::Time& stamp, geometry_msgs::TransformStamped* t,
              bool reject_on_failure = true);
  /// The frame to use for a message: sensor_frame if set, else the message's frame_id.
  const std::string& frameOf(const std::string& frame_id) const {
    return config_.sensor_frame.empty() ? frame_id : config_.sensor_frame;
  }

  std::string name_;
  ObservationSourceConfig config_;
  ros::NodeHandle nh_;
  tf2_ros::Buffer& tf_;
  std::string global_frame_;
  Callback on_observation_;
  ScanIntegrator integrator_;

 private:
  mutable std::mutex mutex_;
  Health health_;
};

}  // namespace downstream_perception
