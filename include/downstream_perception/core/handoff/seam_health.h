// Health of the perception-to-planning seam, ROS-free: how old the transforms that place each
// input are, how far that age throws an obstacle when the robot turns, and whether the
// localisation correction map <- odom behaves (it should sawtooth: ramp up as odometry drifts,
// snap back at each correction).
#pragma once

#include <cstddef>
#include <deque>
#include <string>
#include <vector>

#include "downstream_perception/core/running_stats.h"

namespace downstream_perception {

/// Sideways throw (m) of an obstacle at range_m placed with a transform age_s old while the robot
/// yaws at yaw_rate_rps: range * tan(|yaw_rate| * age) (the lesson's 5 m * tan(90 deg/s * 30 ms)
/// = 0.236 m).
double expectedSmear(double range_m, double yaw_rate_rps, double age_s);

/// The seam health's warning limits (the handoff's dynamic_reconfigure keys; cfg/Handoff.cfg's
/// defaults equal these, a pytest compares them).
struct SeamLimits {
  double reference_range_m = 5.0;    ///< m: the range at which the smear is judged
  double max_transform_age_s = 0.1;  ///< s: warn when an input's p95 transform age exceeds it
  double max_smear_m = 0.05;         ///< m: warn when the expected smear exceeds it
  double max_map_odom_age_s = 2.0;   ///< s: warn when map <- odom is older

  /// `proposed`, field by field, where the field is finite and > 0; `current`'s value elsewhere,
  /// with one line per refused field in `refused` ("<name> = <value> must be > 0; keeping <v>").
  /// Field by field: one bad key must not undo the user's other, valid ones.
  static SeamLimits acceptValid(const SeamLimits& proposed, const SeamLimits& current,
                                std::vector<std::string>* refused);
};

struct CorrectionMonitorConfig {
  double window_s = 120.0;        ///< s of history judged
  double reset_drop_m = 0.05;     ///< m: a fall of the correction this large is a correction event
  double max_correction_m = 2.0;  ///< m: warn above (the lesson: 2 m ~ 100 m of 2 % drift)
  double zero_epsilon_m = 1e-3;   ///< m: a correction this small counts as zero
  /// m of robot travel within the window after which a correction stuck at zero is suspicious
  /// (the localiser may be silently rejecting fixes).
  double min_travel_m = 20.0;
  /// m the correction must grow within the window without a single reset before it counts as
  /// "never resets" (loop closures not firing).
  double ramp_m = 0.5;

  std::string validate() const;
};

/// Watches |map <- odom| over time.
class CorrectionMonitor {
 public:
  explicit CorrectionMonitor(const CorrectionMonitorConfig& config = {}) : config_(config) {}
  /// One sample: time (s), the correction's translation magnitude (m) and the robot's travelled
  /// distance so far (m, from odometry).
  void add(double time_s, double correction_m, double travelled_m);

  std::size_t resets() const { return resets_; }
  double latest() const { return samples_.empty() ? 0.0 : samples_.back().correction; }
  bool tooLarge() const { return latest() > config_.max_correction_m; }
  /// The correction stayed ~0 over the window while the robot travelled min_travel_m.
  bool stuckAtZero() const;
  /// The correction grew by ramp_m over the window without a reset.
  bool neverResets() const;
  /// Empty if healthy, else what is wrong (one line per finding).
  std::vector<std::string> findings() const;

 private:
  struct Sample {
    double time, correction, travelled;
  };
  CorrectionMonitorConfig config_;
  std::deque<Sample> samples_;
  std::deque<double> reset_times_;
  std::size_t resets_ = 0;
};

}  // namespace downstream_perception
