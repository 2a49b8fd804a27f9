#include "downstream_perception/core/handoff/seam_health.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace downstream_perception {

double expectedSmear(double range_m, double yaw_rate_rps, double age_s) {
  const double angle = std::abs(yaw_rate_rps) * std::max(0.0, age_s);
  // Beyond a quarter turn "sideways" has no meaning; report the range itself.
  if (!(angle < 0.5 * M_PI)) return std::abs(range_m);
  return std::abs(range_m) * std::tan(angle);
}

SeamLimits SeamLimits::acceptValid(const SeamLimits& proposed, const SeamLimits& current,
                                   std::vector<std::string>* refused) {
  SeamLimits out = current;
  const auto take = [refused](const char* name, double value, double* target) {
    if (std::isfinite(value) && value > 0.0) {
      *target = value;
      return;
    }
    std::ostringstream why;
    why << "parameter " << name << " = " << value << " must be > 0; keeping " << *target;
    refused->push_back(why.str());
  };
  take("reference_range_m", proposed.reference_range_m, &out.reference_range_m);
  take("max_transform_age_s", proposed.max_transform_age_s, &out.max_transform_age_s);
  take("max_smear_m", proposed.max_smear_m, &out.max_smear_m);
  take("max_map_odom_age_s", proposed.max_map_odom_age_s, &out.max_map_odom_age_s);
  return out;
}

std::string CorrectionMonitorConfig::validate() const {
  std::ostringstream why;
  const auto bad = [](double v) { return !(std::isfinite(v) && v > 0.0); };
  if (bad(window_s))
    why << "window_s must be > 0 s, got " << window_s;
  else if (bad(reset_drop_m))
    why << "reset_drop_m must be > 0 m, got " << reset_drop_m;
  else if (bad(max_correction_m))
    why << "max_correction_m must be > 0 m, got " << max_correction_m;
  else if (bad(zero_epsilon_m))
    why << "zero_epsilon_m must be > 0 m, got " << zero_epsilon_m;
  else if (bad(min_travel_m))
    why << "min_travel_m must be > 0 m, got " << min_travel_m;
  else if (bad(ramp_m))
    why << "ramp_m must be > 0 m, got " << ramp_m;
  return why.str();
}

void CorrectionMonitor::add(double time_s, double correction_m, double travelled_m) {
  if (!std::isfinite(time_s) || !std::isfinite(correction_m) || !std::isfinite(travelled_m)) {
    return;
  }
  if (!samples_.empty() && time_s < samples_.back().time) samples_.clear();  // time jumped back
  if (!samples_.empty() && samples_.back().correction - correction_m >= config_.reset_drop_m) {
    ++resets_;
    reset_times_.push_back(time_s);
  }
  samples_.push_back({time_s, correction_m, travelled_m});
  while (!samples_.empty() && samples_.front().time < time_s - config_.window_s) {
    samples_.pop_front();
  }
  while (!reset_times_.empty() && reset_times_.front() < time_s - config_.window_s) {
    reset_times_.pop_front();
  }
}

bool CorrectionMonitor::stuckAtZero() const {
  if (samples_.size() < 2) return false;
  const double travelled = samples_.back().travelled - samples_.front().travelled;
  if (travelled < config_.min_travel_m) return false;
  return std::all_of(samples_.begin(), samples_.end(),
                     [&](const Sample& s) { return s.correction <= config_.zero_epsilon_m; });
}

bool CorrectionMonitor::neverResets() const {
  if (samples_.size() < 2 || !reset_times_.empty()) return false;
  double lowest = samples_.front().correction;
  for (const Sample& s : samples_) lowest = std::min(lowest, s.correction);
  return samples_.back().correction - lowest >= config_.ramp_m;
}

std::vector<std::string> CorrectionMonitor::findings() const {
  std::vector<std::string> out;
  std::ostringstream s;
  if (tooLarge()) {
    s << "map<-odom correction " << latest() << " m exceeds max_correction_m "
      << config_.max_correction_m << " m";
    out.push_back(s.str());
  }
  if (neverResets()) {
    out.push_back("map<-odom correction grows without ever resetting (corrections not firing?)");
  }
  if (stuckAtZero()) {
    out.push_back("map<-odom correction stays zero while the robot travels (fixes rejected?)");
  }
  return out;
}

}  // namespace downstream_perception
