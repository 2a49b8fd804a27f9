// Runs the costmap's update as soon as a layer has integrated new data (update_on_data: true),
// on a thread of its own, at most max_rate_hz times per second: notifications that arrive while
// an update waits or runs are merged into the next one. No ROS types: unit-tested without a
// master (test/ros/costmap/test_data_update_trigger.cpp).
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
  DataUpdateTrigger() = default;
  ~DataUpdateTrigger() { stop(); }
  DataUpdateTrigger(const DataUpdateTrigger&) = delete;
  DataUpdateTrigger& operator=(const DataUpdateTrigger&) = delete;

  /// Starts the thread that calls `update` after notify(), no sooner than 1 / max_rate_hz after
  /// the previous call began. max_rate_hz must be finite and > 0 (the caller validates).
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
  std::chrono::steady_clock::duration min_period_{};
  std::thread thread_;
  bool running_ = false;
  bool pending_ = false;
  std::size_t notifications_ = 0;
  std::size_t updates_ = 0;
};

}  // namespace downstream_perception
