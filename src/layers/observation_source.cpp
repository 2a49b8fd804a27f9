#include "downstream_perception/layers/observation_source.h"

#include <sstream>

#include "downstream_perception/tf_failure.h"

namespace downstream_perception {

ObservationSource::ObservationSource(std::string name, const ObservationSourceConfig& config,
                                     ros::NodeHandle nh, tf2_ros::Buffer& tf,
                                     std::string global_frame, Callback on_observation)
    : name_(std::move(name)),
      config_(config),
      nh_(nh),
      tf_(tf),
      global_frame_(std::move(global_frame)),
      on_observation_(std::move(on_observation)),
      integrator_(config.integrator) {
  if (config_.topic.empty()) config_.topic = name_;
}

void ObservationSource::countReceived() {
  std::lock_guard<std::mutex> lock(mutex_);
  ++health_.received;
  health_.last_received = ros::WallTime::now();
}

void ObservationSource::reject(const std::string& reason, const std::string& detail) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++health_.rejected[reason];
  }
  ROS_WARN_THROTTLE(2.0, "obstacle source '%s' (%s): %s rejected: %s: %s", name_.c_str(),
                    config_.topic.c_str(), dataType(), reason.c_str(), detail.c_str());
}

void ObservationSource::note(const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++health_.notes[what];
}

void ObservationSource::onTfFailure(const std::string& frame, const ros::Time& stamp,
                                    tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++health_.received;
  }
  std::ostringstream detail;
  detail << "frame '" << frame << "' -> '" << global_frame_ << "' at stamp " << stamp;
  reject(tfFailureReason(reason), detail.str());
}

bool ObservationSource::lookup(const std::string& frame, const ros::Time& stamp,
                               geometry_msgs::TransformStamped* t, bool reject_on_failure) {
  try {
    *t = tf_.lookupTransform(global_frame_, frame, stamp);
    return true;
  } catch (const tf2::TransformException& e) {
    if (reject_on_failure) reject("tf: lookup at stamp failed", e.what());
    return false;
  }
}

void ObservationSource::recordIntegration(const IntegrationStats& stats, double integrate_ms,
                                          double age_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++health_.integrated;
  health_.last = stats;
  health_.total.accumulate(stats);
  health_.integrate_ms.add(integrate_ms);
  health_.transform_age_s.add(age_s);
}

bool ObservationSource::isCurrent() const {
  if (config_.expected_update_rate <= 0.0) return true;
  std::lock_guard<std::mutex> lock(mutex_);
  if (health_.integrated == 0) return false;
  return (ros::WallTime::now() - health_.last_received).toSec() <= config_.expected_update_rate;
}

}  // namespace downstream_perception
