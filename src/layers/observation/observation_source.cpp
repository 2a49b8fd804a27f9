#include "downstream_perception/layers/observation/observation_source.h"

#include <algorithm>
#include <sstream>

#include "downstream_perception/ros/common/tf_failure.h"

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

void ObservationSource::markSubscribed() {
  // Here, not in the constructor: dataType() is the subclass's.
  rejected_.setLogPrefix("obstacle source '" + name_ + "' (" + config_.topic + "): " + dataType() +
                         " rejected");
  std::lock_guard<std::mutex> lock(mutex_);
  subscribed_since_ = ros::WallTime::now();
}

void ObservationSource::markUnsubscribed() {
  std::lock_guard<std::mutex> lock(mutex_);
  subscribed_since_ = ros::WallTime();
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
  health_.last_integrated = ros::WallTime::now();
  health_.transform_age_s.add(age_s);
}

bool ObservationSource::isCurrent() const {
  return notCurrentReason().empty();
}

std::string ObservationSource::notCurrentReason() const {
  if (config_.expected_update_rate <= 0.0) return "";
  const std::string topic = resolvedTopic();
  std::lock_guard<std::mutex> lock(mutex_);
  if (subscribed_since_.isZero()) return "";  // not subscribed (layer disabled)
  // costmap_2d counts from the last observation buffered, and from (re)activation before the
  // first one: a sensor gets expected_update_rate to deliver.
  const ros::WallTime since = std::max(subscribed_since_, health_.last_integrated);
  const double silent_s = (ros::WallTime::now() - since).toSec();
  if (silent_s <= config_.expected_update_rate) return "";
  std::ostringstream why;
  why.precision(2);
  why << std::fixed << "source '" << name_ << "' (" << (topic.empty() ? config_.topic : topic)
      << "): "
      << (health_.integrated == 0 ? "no observation integrated yet, " : "no observation for ")
      << silent_s << " s" << (health_.integrated == 0 ? " after subscribing" : "")
      << ", expected_update_rate " << config_.expected_update_rate << " s";
  return why.str();
}

std::string ObservationSource::noPublisherReason(double grace_s) const {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (subscribed_since_.isZero() ||
        (ros::WallTime::now() - subscribed_since_).toSec() < grace_s) {
      return "";
    }
  }
  if (numPublishers() > 0) return "";
  return "source '" + name_ + "': no publisher on " + resolvedTopic() + " (" + dataType() + ")";
}

void ObservationSource::setMergeGrid(const GridGeometry& grid) {
  std::lock_guard<std::mutex> lock(merge_grid_mutex_);
  merge_grid_ = grid;
}

std::optional<GridGeometry> ObservationSource::mergeGrid() const {
  std::lock_guard<std::mutex> lock(merge_grid_mutex_);
  return merge_grid_;
}

CloudBeamsConfig ObservationSource::heightBand() const {
  CloudBeamsConfig band = config_.cloud;
  band.max_obstacle_height = std::min(band.max_obstacle_height, mark_max_z_.load());
  return band;
}

}  // namespace downstream_perception
