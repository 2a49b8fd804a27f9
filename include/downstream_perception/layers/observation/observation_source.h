// One observation source of the obstacle layer (a LaserScan, PointCloud or PointCloud2 topic):
// subscription through a tf2 MessageFilter (a message is released only once the transform at its
// own stamp exists), message checks, and per-source health counters. A source turns each accepted
// message into beams in the layer's global frame; the layer integrates them. Parameters live in
// <layer ns>/<source name> (costmap_2d's keys with costmap_2d's defaults, see readSources()).
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "downstream_perception/core/costmap/cloud_beams.h"
#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/ros/common/filtered_subscription.h"
#include "downstream_perception/ros/common/rejection_counter.h"

namespace downstream_perception {

struct ObservationSourceConfig {
  std::string topic;                     ///< defaults to the source name
  std::string sensor_frame;              ///< overrides the message's frame_id when non-empty
  double expected_update_rate = 0;       ///< s between observations before "not current"; 0 = off
  double observation_persistence = 0;    ///< s, costmap_2d's key: accepted, see readSources()
  int tf_queue_size = 20;                ///< messages held while waiting for tf
  ScanIntegratorConfig integrator;       ///< marking, clearing, ranges, +Inf as no return, ...
  CloudBeamsConfig cloud;                ///< the obstacle height band (every source type)
  bool per_beam_time_correction = true;  ///< LaserScan only: de-skew with time_increment
  /// LaserScan only, costmap_2d's inf_is_valid: +Inf becomes a return at range_max - 0.1 mm.
  bool costmap2d_inf_is_valid = false;
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
  /// "LaserScan", "PointCloud" or "PointCloud2".
  virtual const char* dataType() const = 0;
  /// Messages held back for their transform for a while, per frame, with the reason.
  virtual std::vector<TfWait> waitingForTf() const = 0;
  /// The resolved topic while subscribed, else "".
  virtual std::string resolvedTopic() const = 0;
  /// Publishers connected to the topic while subscribed.
  virtual std::uint32_t numPublishers() const = 0;

  const std::string& name() const { return name_; }
  const ObservationSourceConfig& config() const { return config_; }
  ScanIntegrator& integrator() { return integrator_; }

  /// Counters for diagnostics; take the lock returned by mutex() while reading them.
  struct Health {
    std::size_t received = 0;
    std::size_t integrated = 0;
    std::map<std::string, std::size_t> notes;  ///< accepted, but e.g. de-skew skipped
    RunningStats transform_age_s;              ///< now - stamp when integrated
    TimingStats integrate_ms;
    IntegrationStats last;   ///< the last message's integration
    IntegrationStats total;  ///< since start
    ros::WallTime last_received;
    ros::WallTime last_integrated;
  };
  const Health& health() const { return health_; }
  /// Messages refused, by reason (bad message, tf, ...); has its own lock.
  const RejectionCounter& rejections() const { return rejected_; }
  std::mutex& mutex() { return mutex_; }
  void recordIntegration(const IntegrationStats& stats, double integrate_ms, double age_s);
  /// True if observations arrive as often as expected_update_rate demands (costmap_2d's rule:
  /// the time since the last observation, or since subscribing, is at most expected_update_rate).
  bool isCurrent() const;
  /// "" while current, else why not, naming the source and its topic.
  std::string notCurrentReason() const;
  /// "" while a publisher is connected (or subscribed for less than `grace_s`), else the WARN text
  /// naming the topic.
  std::string noPublisherReason(double grace_s) const;
  /// The layer's marking limit in the global frame (m): max_obstacle_height of the layer, for a
  /// voxel layer also the top of its voxel column. Points above it neither mark nor clear.
  void setMarkHeightLimit(double max_z) { mark_max_z_ = max_z; }
  /// [min_obstacle_height, min(max_obstacle_height, the layer's marking limit)] (m).
  CloudBeamsConfig heightBand() const;
  /// The geometry of the grid this source's observations are integrated into: a cloud gives one
  /// beam per cell of it (CloudBeamsConfig::merge_grid). The layer sets it whenever its grid is
  /// made or resized; rolling-window shifts keep the cells (the grid's lattice).
  void setMergeGrid(const GridGeometry& grid);
  /// The grid set by setMergeGrid (unset until then: one beam per point).
  std::optional<GridGeometry> mergeGrid() const;

 protected:
  ObservationSource(std::string name, const ObservationSourceConfig& config, ros::NodeHandle nh,
                    tf2_ros::Buffer& tf, std::string global_frame, Callback on_observation);

  void countReceived();
  /// Subscribed now: expected_update_rate and the publisher check count from here.
  void markSubscribed();
  void markUnsubscribed();
  /// Counts a refused message by reason (throttled WARN naming the source and its topic).
  void reject(const std::string& reason, const std::string& detail) {
    rejected_.reject(reason, detail);
  }
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
  RejectionCounter rejected_;
  ros::WallTime subscribed_since_;  ///< zero while unsubscribed; guarded by mutex_
  std::atomic<double> mark_max_z_{std::numeric_limits<double>::infinity()};
  mutable std::mutex merge_grid_mutex_;
  std::optional<GridGeometry> merge_grid_;  ///< guarded by merge_grid_mutex_
};

}  // namespace downstream_perception
