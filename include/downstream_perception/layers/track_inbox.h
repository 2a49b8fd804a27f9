// The tracker's latest track array, placed in the costmap's global frame at the array's own
// stamp: what the TrackedObstacleLayer sweeps and what the obstacle layer clears
// (clear_tracked_objects). Each array is released by a tf2 MessageFilter once the transform at
// its stamp exists, filtered by track state, validated track by track, and kept until a newer
// array replaces it or it is older than track_timeout_s (then it is dropped and counted, so a
// stale track never stays in the map).
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/TrackedObjectArray.h"
#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/core/tracking/predicted_footprint.h"
#include "downstream_perception/ros/common/filtered_subscription.h"
#include "downstream_perception/ros/common/rejection_counter.h"

namespace downstream_perception {

struct TrackInboxConfig {
  std::string topic = "/tracker/tracks";
  double track_timeout_s = 1.0;  ///< s: an array older than this is dropped
  bool include_tentative = false;
  bool include_coasting = true;
  int tf_queue_size = 20;  ///< arrays waiting for their transform

  /// Empty if valid, else the reason.
  std::string validate() const;
};

/// Tracks fresh at one instant, in the global frame.
struct FreshTracks {
  ros::Time stamp;                  ///< the array's measurement stamp
  double age_s = 0.0;               ///< now - stamp, >= 0
  bool current = false;             ///< an array within track_timeout_s exists
  std::vector<PlanarTrack> tracks;  ///< empty when none is fresh
};

class TrackInbox {
 public:
  /// Subscribes to config().topic (idempotent); `owner` (the layer's name) prefixes log lines.
  void subscribe(ros::NodeHandle& nh, tf2_ros::Buffer& tf, const std::string& global_frame,
                 const std::string& owner);
  void unsubscribe();
  /// Called with the array's stamp (on the subscriber's thread, no lock held) after each array
  /// is taken: the owner's cue for the host (update_on_data, latency). Set it before subscribe().
  void setArrivalHandler(std::function<void(const ros::Time&)> handler) {
    on_arrival_ = std::move(handler);
  }
  /// Live part of the configuration (timeout, states); the topic and queue apply at subscribe().
  void setConfig(const TrackInboxConfig& config);
  TrackInboxConfig config() const;
  /// The tracks at `now`: the last array unless it is older than track_timeout_s (then it is
  /// dropped and counted as expired).
  FreshTracks fresh(const ros::Time& now);
  void clear();
  /// Forgets the tracks and the stamp they carried (the clock went back: an array of the new
  /// timeline is older than it).
  void onClockJump();
  /// Counts, rejections by reason and transform ages, each key prefixed with `prefix`.
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status,
                const std::string& prefix = "") const;
  std::size_t arraysReceived() const;
  /// "<reason>: <detail>" of the last rejected array or track; empty if none.
  std::string lastRejection() const;

 private:
  void onTracks(const TrackedObjectArrayConstPtr& msg);
  /// "layer '<owner>' (<topic>)": the rejections' WARN prefix.
  void setLogPrefix(const std::string& topic);

  std::string owner_;
  tf2_ros::Buffer* tf_ = nullptr;
  std::string global_frame_;
  FilteredSubscription<TrackedObjectArray> subscription_;
  mutable std::mutex mutex_;
  TrackInboxConfig config_;
  ros::Time stamp_;                  ///< stamp of the array the tracks came from
  std::vector<PlanarTrack> tracks_;  ///< in the global frame at stamp_
  std::size_t arrays_received_ = 0;
  std::size_t arrays_expired_ = 0;
  std::size_t tracks_skipped_state_ = 0;
  RejectionCounter rejected_;
  RunningStats transform_age_s_;  ///< now - stamp when an array is transformed
  std::function<void(const ros::Time&)> on_arrival_;
};

}  // namespace downstream_perception
