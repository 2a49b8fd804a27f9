// What a tf2 MessageFilter holds back, made visible. The filter keeps a message until the
// transform at its stamp exists, and reports nothing until its queue overflows: a frame nobody
// publishes, a transform tf2 refused (NaN, a zero quaternion), a stamp far in the future all
// look like silence for as long as the queue takes to fill. The monitor counts each message in
// and out, and on the diagnostics tick says per source frame how many wait, for how long, and
// why (tf2's own answer for the oldest one).
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/time.h>
#include <std_msgs/Header.h>
#include <tf2_ros/buffer.h>

#include <algorithm>
#include <cstddef>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace downstream_perception {

/// Messages held longer than this are reported (diagnostics run at 1 Hz: a message stuck for
/// tf shows within about a second).
constexpr double kTfWaitReportS = 0.5;

/// Messages still waiting for a transform, per source frame.
struct TfWait {
  std::string frame;
  std::size_t count = 0;
  double longest_s = 0.0;  ///< wall time the oldest has waited
  std::string why;         ///< tf2's answer for the oldest one
};

class TfWaitMonitor {
 public:
  static constexpr std::size_t kMaxTracked = 10000;

  /// A message handed to the MessageFilter.
  void arrived(const std_msgs::Header& header) {
    std::lock_guard<std::mutex> lock(mutex_);
    // The filter's own queue bounds what waits; this bound only guards against a filter that
    // forgot to report a message (it would otherwise be remembered forever).
    if (waiting_.size() >= kMaxTracked) waiting_.erase(waiting_.begin());
    waiting_.emplace(Key{header.frame_id, header.stamp}, ros::WallTime::now());
  }
  /// A message the filter released or dropped.
  void left(const std_msgs::Header& header) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = waiting_.find(Key{header.frame_id, header.stamp});
    if (it != waiting_.end()) waiting_.erase(it);
  }
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    waiting_.clear();
  }
  /// The messages that have waited at least `min_wait_s`, grouped by frame, each group with
  /// tf2's reason for the oldest (target_frame <- frame at its stamp).
  std::vector<TfWait> waitingLongerThan(double min_wait_s, const tf2_ros::Buffer& tf,
                                        const std::string& target_frame) const {
    struct Oldest {
      TfWait wait;
      ros::Time stamp;
    };
    std::map<std::string, Oldest> by_frame;
    const ros::WallTime now = ros::WallTime::now();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& [key, since] : waiting_) {
        const double waited = (now - since).toSec();
        if (waited < min_wait_s) continue;
        Oldest& o = by_frame[key.first];
        o.wait.frame = key.first;
        ++o.wait.count;
        if (waited >= o.wait.longest_s) {
          o.wait.longest_s = waited;
          o.stamp = key.second;
        }
      }
    }
    std::vector<TfWait> out;
    for (auto& [frame, o] : by_frame) {
      o.wait.why = reason(tf, target_frame, frame, o.stamp);
      out.push_back(std::move(o.wait));
    }
    return out;
  }

 private:
  using Key = std::pair<std::string, ros::Time>;

  static std::string reason(const tf2_ros::Buffer& tf, const std::string& target,
                            const std::string& frame, const ros::Time& stamp) {
    if (frame.empty()) return "empty frame_id";
    if (!tf._frameExists(frame)) {
      return "frame '" + frame + "' is unknown to tf (nobody publishes it, or tf2 refused its " +
             "transforms: NaN values or a zero quaternion are dropped)";
    }
    std::string error;
    if (tf.canTransform(target, frame, stamp, &error)) {
      return "transformable now (released at the next tf message)";
    }
    const ros::Time now = ros::Time::now();
    if (stamp > now + ros::Duration(1.0)) {
      return "stamp " + std::to_string(stamp.toSec()) + " s is " +
             std::to_string((stamp - now).toSec()) + " s ahead of the clock; tf: " + error;
    }
    return error;
  }

  mutable std::mutex mutex_;
  std::multimap<Key, ros::WallTime> waiting_;
};

/// "<prefix>waiting for tf" (count) and, per frame, the count, longest wait and reason. Returns
/// the number waiting (the caller's status turns WARN on any).
inline std::size_t addTfWaits(diagnostic_updater::DiagnosticStatusWrapper& status,
                              const std::string& prefix, const std::vector<TfWait>& waits) {
  std::size_t total = 0;
  for (const TfWait& w : waits) {
    total += w.count;
    status.add(prefix + "waiting for tf from '" + w.frame + "'",
               std::to_string(w.count) + " message(s), the oldest for " +
                   std::to_string(w.longest_s) + " s: " + w.why);
  }
  status.add(prefix + "waiting for tf (> 0.5 s)", total);
  return total;
}

}  // namespace downstream_perception
