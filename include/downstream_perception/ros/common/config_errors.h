// Parameter problems in diagnostics: the count and every message, so a user sees all of them in
// rqt_runtime_monitor, not only the first (which is the status summary).
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/console.h>

#include <mutex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace downstream_perception {

/// A value as it would print (for "parameter ~x = <value> is invalid" messages).
template <class T>
std::string toText(const T& value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

inline void addConfigErrors(diagnostic_updater::DiagnosticStatusWrapper& status,
                            const std::vector<std::string>& errors) {
  status.add("config errors", errors.size());
  for (std::size_t k = 0; k < errors.size(); ++k) {
    status.add("config error " + std::to_string(k + 1), errors[k]);
  }
}

/// Parameter warnings (wrong types, unknown or unsupported keys: ParamReader) into a status.
inline void addParamWarnings(diagnostic_updater::DiagnosticStatusWrapper& status,
                             const std::vector<std::string>& warnings) {
  status.add("parameter warnings", warnings.size());
  for (std::size_t k = 0; k < warnings.size(); ++k) {
    status.add("parameter warning " + std::to_string(k + 1), warnings[k]);
  }
}

/// The parameter problems of one component (a layer, a nodelet): each logged once as an error
/// with the component's prefix and kept for its diagnostics. Safe from any thread (start-up,
/// dynamic_reconfigure callbacks, the diagnostics timer).
///
/// add() keeps a problem for the component's lifetime (a start-up value that cannot change).
/// set(key, ...) keeps at most one problem per key (a dynamic_reconfigure parameter or group) and
/// clear(key) drops it: a later reconfigure that fixes the value removes the error.
class ConfigErrorLog {
 public:
  /// `prefix` starts each logged error ("costmap", "layer 'obstacles'").
  explicit ConfigErrorLog(std::string prefix = "config") : prefix_(std::move(prefix)) {}

  void setPrefix(std::string prefix) { prefix_ = std::move(prefix); }
  void add(const std::string& msg) {
    ROS_ERROR("%s: %s", prefix_.c_str(), msg.c_str());
    std::lock_guard<std::mutex> lock(mutex_);
    errors_.push_back(msg);
  }
  /// The current problem of `key`, replacing the previous one (logged as an error).
  void set(const std::string& key, const std::string& msg) {
    ROS_ERROR("%s: %s", prefix_.c_str(), msg.c_str());
    keep(key, msg);
  }
  /// As set(), for a problem the caller has logged already.
  void keep(const std::string& key, const std::string& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& entry : keyed_) {
      if (entry.first == key) {
        entry.second = msg;
        return;
      }
    }
    keyed_.emplace_back(key, msg);
  }
  /// `key` is fine now: its problem (if any) leaves the diagnostics.
  void clear(const std::string& key) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = keyed_.begin(); it != keyed_.end(); ++it) {
      if (it->first == key) {
        keyed_.erase(it);
        return;
      }
    }
  }
  /// Every key starting with `prefix` is fine now (a key is its own prefix): for a group of
  /// numbered keys ("footprint 0", "footprint 1", ...) read again as a whole.
  void clearWithPrefix(const std::string& prefix) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::pair<std::string, std::string>> kept;
    for (auto& entry : keyed_) {
      if (entry.first.rfind(prefix, 0) != 0) kept.push_back(std::move(entry));
    }
    keyed_ = std::move(kept);
  }
  /// Takes over the problems of `other` (found into a scratch log, logged there already).
  void merge(const ConfigErrorLog& other) {
    std::vector<std::string> lasting;
    std::vector<std::pair<std::string, std::string>> keyed;
    {
      std::lock_guard<std::mutex> lock(other.mutex_);
      lasting = other.errors_;
      keyed = other.keyed_;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      errors_.insert(errors_.end(), lasting.begin(), lasting.end());
    }
    for (const auto& entry : keyed) keep(entry.first, entry.second);
  }
  bool empty() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return errors_.empty() && keyed_.empty();
  }
  /// Every current problem: the lasting ones first, then the keyed ones in the order they arose.
  std::vector<std::string> all() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out = errors_;
    for (const auto& entry : keyed_) out.push_back(entry.second);
    return out;
  }
  /// The count and every message into the status; if any, an ERROR summary with the first one.
  /// Returns whether there was any.
  bool report(diagnostic_updater::DiagnosticStatusWrapper& status) const {
    const std::vector<std::string> errors = all();
    addConfigErrors(status, errors);
    if (errors.empty()) return false;
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, errors.front());
    return true;
  }

 private:
  std::string prefix_ = "config";
  mutable std::mutex mutex_;
  std::vector<std::string> errors_;
  std::vector<std::pair<std::string, std::string>> keyed_;  ///< key -> its current problem
};

}  // namespace downstream_perception
