// A ROS clock that goes backwards (a bag played in a loop, a restarted simulator, /use_sim_time
// with a new /clock): everything that compares a stamp with the last one seen would wait until
// the clock passes its old maximum. Each component checks ros::Time::now() here on its update
// path and resets what depends on time when it jumped.
#pragma once

#include <ros/console.h>
#include <ros/node_handle.h>
#include <ros/time.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <cstddef>
#include <memory>
#include <mutex>

namespace downstream_perception {

/// How often the nodes compare the ROS clock with its last reading (steady-clock timer).
constexpr double kClockWatchPeriodS = 0.25;

class ClockJumpDetector {
 public:
  /// The seconds the clock went back since the previous call (0 if it did not); logs a WARN
  /// naming `component` when it did. Thread-safe.
  double check(const ros::Time& now, const char* component) {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::Time previous = last_;
    last_ = now;
    if (previous.isZero() || now >= previous) return 0.0;
    ++jumps_;
    const double back = (previous - now).toSec();
    ROS_WARN(
        "%s: the clock jumped back %.3f s (from %.3f to %.3f): resetting what depends on "
        "time (stamps seen, decay and track ages, waiting messages)",
        component, back, previous.toSec(), now.toSec());
    return back;
  }
  std::size_t jumps() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return jumps_;
  }

 private:
  mutable std::mutex mutex_;
  ros::Time last_;
  std::size_t jumps_ = 0;
};

/// After a clock jump: empties the tf buffer (transforms of the old timeline would answer
/// lookups at the new one's stamps) and subscribes anew, with a listener that has no
/// old-timeline update time. Static transforms survive the clear (tf2's static caches ignore
/// it), and the new subscription receives the latched /tf_static again.
inline void restartTf(tf2_ros::Buffer& buffer,
                      std::unique_ptr<tf2_ros::TransformListener>& listener, ros::NodeHandle& nh) {
  listener.reset();
  buffer.clear();
  listener = std::make_unique<tf2_ros::TransformListener>(buffer, nh);
}

}  // namespace downstream_perception
