// Messages a node or layer refused, counted by reason: one counter instead of a private
// reject() and reason -> count map in every class, so each writes the same diagnostics keys
// ("rejected (<reason>)") and logs the same throttled WARN.
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/console.h>
#include <ros/time.h>

#include <cstddef>
#include <map>
#include <mutex>
#include <string>
#include <utility>

namespace downstream_perception {

/// Thread-safe reason -> count, with a WARN per rejection throttled per counter (each component
/// keeps its own throttle, as its own ROS_WARN_THROTTLE call site did).
class RejectionCounter {
 public:
  static constexpr double kWarnPeriodS = 2.0;

  /// `log_prefix` starts every WARN ("tracker: detections rejected").
  explicit RejectionCounter(std::string log_prefix = "rejected") : prefix_(std::move(log_prefix)) {}

  /// For a prefix that names something that can change (a reconfigured topic).
  void setLogPrefix(std::string log_prefix) {
    std::lock_guard<std::mutex> lock(mutex_);
    prefix_ = std::move(log_prefix);
  }

  /// Counts one rejection and WARNs "<prefix>: <reason>: <detail>" (throttled).
  void reject(const std::string& reason, const std::string& detail) {
    std::string prefix;
    bool warn = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++counts_[reason];
      last_ = detail.empty() ? reason : reason + ": " + detail;
      prefix = prefix_;
      warn = warnDue();
    }
    if (!warn) return;
    if (detail.empty()) {
      ROS_WARN("%s: %s", prefix.c_str(), reason.c_str());
    } else {
      ROS_WARN("%s: %s: %s", prefix.c_str(), reason.c_str(), detail.c_str());
    }
  }

  /// Counts one rejection without a WARN (the caller logged it its own way).
  void count(const std::string& reason) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counts_[reason];
  }

  std::size_t total() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t sum = 0;
    for (const auto& entry : counts_) sum += entry.second;
    return sum;
  }

  std::map<std::string, std::size_t> counts() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return counts_;
  }

  /// "<reason>: <detail>" of the latest rejection; empty if none.
  std::string last() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_;
  }

  /// "<key_prefix>rejected (<reason>)" = count, for each reason in order; returns the total.
  std::size_t report(diagnostic_updater::DiagnosticStatusWrapper& status,
                     const std::string& key_prefix = "") const {
    std::size_t sum = 0;
    for (const auto& [reason, n] : counts()) {
      status.add(key_prefix + "rejected (" + reason + ")", n);
      sum += n;
    }
    return sum;
  }

 private:
  /// Caller holds mutex_. Wall time: works without a master or a sim clock.
  bool warnDue() {
    const double now = ros::WallTime::now().toSec();
    if (last_warn_s_ >= 0.0 && now >= last_warn_s_ && now < last_warn_s_ + kWarnPeriodS) {
      return false;
    }
    last_warn_s_ = now;
    return true;
  }

  mutable std::mutex mutex_;
  std::string prefix_;
  std::map<std::string, std::size_t> counts_;
  std::string last_;
  double last_warn_s_ = -1.0;
};

}  // namespace downstream_perception
