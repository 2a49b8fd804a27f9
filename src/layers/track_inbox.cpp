#include "downstream_perception/layers/track_inbox.h"

#include <sstream>

#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/tf_failure.h"

namespace downstream_perception {

namespace {

Eigen::Matrix2d covariance2(const boost::array<double, 4>& row_major) {
  Eigen::Matrix2d m;
  m << row_major[0], row_major[1], row_major[2], row_major[3];
  return m;
}

}  // namespace

std::string TrackInboxConfig::validate() const {
  if (topic.empty()) return "the tracks topic is empty";
  if (!(std::isfinite(track_timeout_s) && track_timeout_s > 0.0)) {
    return "track_timeout_s must be > 0 s, got " + toText(track_timeout_s);
  }
  if (tf_queue_size < 1 || tf_queue_size > 10000) {
    return "tf_queue_size must be in [1, 10000], got " + toText(tf_queue_size);
  }
  return {};
}

void TrackInbox::subscribe(ros::NodeHandle& nh, tf2_ros::Buffer& tf,
                           const std::string& global_frame, const std::string& owner) {
  owner_ = owner;
  tf_ = &tf;
  global_frame_ = global_frame;
  const TrackInboxConfig c = config();
  setLogPrefix(c.topic);
  subscription_.subscribe(
      nh, c.topic, tf, global_frame, c.tf_queue_size,
      [this](const TrackedObjectArrayConstPtr& msg) { onTracks(msg); },
      [this](const TrackedObjectArrayConstPtr& msg,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        std::ostringstream detail;
        detail << "frame '" << msg->header.frame_id << "' -> '" << global_frame_ << "' at stamp "
               << msg->header.stamp;
        rejected_.reject(tfFailureReason(reason), detail.str());
      });
}

void TrackInbox::unsubscribe() {
  subscription_.unsubscribe();
}

void TrackInbox::setConfig(const TrackInboxConfig& config) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    config_ = config;
  }
  setLogPrefix(config.topic);
}

void TrackInbox::setLogPrefix(const std::string& topic) {
  rejected_.setLogPrefix("layer '" + owner_ + "' (" + topic + ")");
}

TrackInboxConfig TrackInbox::config() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return config_;
}

void TrackInbox::onTracks(const TrackedObjectArrayConstPtr& msg) {
  geometry_msgs::TransformStamped transform;
  try {
    transform = tf_->lookupTransform(global_frame_, msg->header.frame_id, msg->header.stamp);
  } catch (const tf2::TransformException& e) {
    rejected_.reject("tf: lookup at stamp failed", e.what());
    return;
  }
  const TrackInboxConfig c = config();
  const double box_yaw = yawOf(transform.transform.rotation);
  std::vector<PlanarTrack> tracks;
  std::size_t skipped_state = 0;
  for (const TrackedObject& object : msg->tracks) {
    const bool wanted = object.state == TrackedObject::CONFIRMED ||
                        (c.include_coasting && object.state == TrackedObject::COASTING) ||
                        (c.include_tentative && object.state == TrackedObject::TENTATIVE);
    if (!wanted) {
      ++skipped_state;
      continue;
    }
    const TrackedObject placed = transformTrack(object, transform);
    PlanarTrack t;
    t.position = {placed.position.x, placed.position.y};
    t.velocity = {placed.velocity.x, placed.velocity.y};
    t.position_covariance = covariance2(placed.position_covariance);
    t.velocity_covariance = covariance2(placed.velocity_covariance);
    t.size_x = object.size_x;
    t.size_y = object.size_y;
    t.box_yaw = box_yaw;
    const std::string why = t.validate();
    if (!why.empty()) {
      rejected_.reject("bad track", "id " + std::to_string(object.id) + ": " + why);
      continue;
    }
    tracks.push_back(t);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!stamp_.isZero() && msg->header.stamp < stamp_) {
      rejected_.count("older than the tracks already held");
      return;
    }
    tracks_ = std::move(tracks);
    stamp_ = msg->header.stamp;
    tracks_skipped_state_ += skipped_state;
    ++arrays_received_;
    transform_age_s_.add((ros::Time::now() - msg->header.stamp).toSec());
  }
  if (on_arrival_) on_arrival_(msg->header.stamp);
}

FreshTracks TrackInbox::fresh(const ros::Time& now) {
  std::lock_guard<std::mutex> lock(mutex_);
  FreshTracks out;
  out.stamp = stamp_;
  if (stamp_.isZero()) return out;
  out.age_s = std::max(0.0, (now - stamp_).toSec());
  if (out.age_s > config_.track_timeout_s) {
    if (!tracks_.empty()) {
      tracks_.clear();  // a stale track never stays in the map
      ++arrays_expired_;
    }
    return out;
  }
  out.current = true;
  out.tracks = tracks_;
  return out;
}

void TrackInbox::onClockJump() {
  std::lock_guard<std::mutex> lock(mutex_);
  tracks_.clear();
  stamp_ = ros::Time();
}

void TrackInbox::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  tracks_.clear();
}

std::size_t TrackInbox::arraysReceived() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return arrays_received_;
}

std::string TrackInbox::lastRejection() const {
  return rejected_.last();
}

void TrackInbox::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status,
                          const std::string& prefix) const {
  std::lock_guard<std::mutex> lock(mutex_);
  status.add(prefix + "topic", config_.topic);
  status.add(prefix + "track arrays received", arrays_received_);
  status.add(prefix + "track arrays expired (older than track_timeout_s)", arrays_expired_);
  status.add(prefix + "tracks skipped by state", tracks_skipped_state_);
  rejected_.report(status, prefix);
  const std::string last = rejected_.last();
  if (!last.empty()) status.add(prefix + "last rejection", last);
  status.add(prefix + "transform age mean (s)", transform_age_s_.mean());
  status.add(prefix + "transform age max (s)", transform_age_s_.max);
  status.add(prefix + "track_timeout_s", config_.track_timeout_s);
  addTfWaits(status, prefix, subscription_.waitingForTf());
}

}  // namespace downstream_perception
