// Runs the costmap's update as soon as a layer has integrated new data (update_on_data: true),
// on a thread of its own, at most max_rate_hz times per second on average: a token bucket that
// holds up to kBurst updates, so that two sensors whose messages happen to arrive close together
// (a scan 5 ms after a track array) are both published at once, while a sustained flood is held
// to the rate. Notifications that arrive while an update waits or runs are merged into the next
// one. No ROS types: unit-tested without a master (test/ros/costmap/test_data_update_trigger.cpp).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>

namespace downstream_perception {

class DataUpdateTrigger {
 public:
  static constexpr double kBurst = 3.0;  ///< updates that may run back to back

  DataUpdateTrigger() = default;
  ~DataUpdateTrigger() { stop(); }
  DataUpdateTrigger(const DataUpdateTrigger&) = delete;
  DataUpdateTrigger& operator=(const DataUpdateTrigger&) = delete;

  /// Starts the thread that calls `update` after notify(): at once while the bucket holds a
  /// token (it starts full, refills at max_rate_hz up to kBurst), else when the next token is
  /// due. max_rate_hz must be finite and > 0 (the caller validates).
  void start(double max_rate_hz, std::function<void()> update);
  /// Stops the thread (waits for a running update; a pending one is dropped). Idempotent.
  void stop();
  /// New data: an update is due. Cheap and non-blocking; a no-op unless started.
  void notify();

  std::size_t notifications() const;
  std::size_t updates() const;  ///< calls of `update` so far

 private:
  void run();

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::function<void()> update_;
  double rate_hz_ = 1.0;
  std::thread thread_;
  bool running_ = false;
  bool pending_ = false;
  std::size_t notifications_ = 0;
  std::size_t updates_ = 0;
};

}  // namespace downstream_perception
