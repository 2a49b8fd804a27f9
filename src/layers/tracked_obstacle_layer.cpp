#include "downstream_perception/layers/tracked_obstacle_layer.h"

#include <tf2/utils.h>
#include <pluginlib/class_list_macros.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "downstream_perception/config_errors.h"
#include "downstream_perception/core/cost_values.h"
#include "downstream_perception/layered_costmap.h"
#include "downstream_perception/tf_failure.h"
#include "downstream_perception/track_transform.h"

namespace downstream_perception {

namespace {

Eigen::Matrix2d covariance2(const boost::array<double, 4>& row_major) {
  Eigen::Matrix2d m;
  m << row_major[0], row_major[1], row_major[2], row_major[3];
  return m;
}

}  // namespace

void TrackedObstacleLayer::onInitialize() {
  nh_.param("topic", topic_, std::string("/tracker/tracks"));
  nh_.param("enabled", enabled_, true);
  nh_.param("prediction_horizon_s", prediction_.prediction_horizon_s,
            prediction_.prediction_horizon_s);
  nh_.param("uncertainty_sigmas", prediction_.uncertainty_sigmas, prediction_.uncertainty_sigmas);
  nh_.param("max_uncertainty_m", prediction_.max_uncertainty_m, prediction_.max_uncertainty_m);
  nh_.param("min_object_size_m", prediction_.min_object_size_m, prediction_.min_object_size_m);
  nh_.param("max_object_size_m", prediction_.max_object_size_m, prediction_.max_object_size_m);
  nh_.param("max_speed_mps", prediction_.max_speed_mps, prediction_.max_speed_mps);
  nh_.param("track_timeout_s", track_timeout_s_, track_timeout_s_);
  nh_.param("include_tentative", include_tentative_, include_tentative_);
  nh_.param("include_coasting", include_coasting_, include_coasting_);
  nh_.param("tf_queue_size", tf_queue_size_, tf_queue_size_);
  const std::string why = prediction_.validate();
  if (!why.empty()) {
    config_errors_.push_back(why + "; using the defaults");
    prediction_ = PredictionConfig();
  }
  if (!(std::isfinite(track_timeout_s_) && track_timeout_s_ > 0.0)) {
    config_errors_.push_back("parameter track_timeout_s = " + toText(track_timeout_s_) +
                             " must be > 0 s; using 1.0");
    track_timeout_s_ = 1.0;
  }
  if (tf_queue_size_ < 1) {
    config_errors_.push_back("parameter tf_queue_size = " + toText(tf_queue_size_) +
                             " must be >= 1; using 20");
    tf_queue_size_ = 20;
  }
  for (const std::string& e : config_errors_) ROS_ERROR("layer '%s': %s", name_.c_str(), e.c_str());
  current_ = false;
  subscribe();
  ROS_INFO("layer '%s': tracks from %s, horizon %.2f s, timeout %.2f s", name_.c_str(),
           ros::names::resolve(nh_.getNamespace(), topic_).c_str(),
           prediction_.prediction_horizon_s, track_timeout_s_);
}

void TrackedObstacleLayer::subscribe() {
  subscription_.subscribe(
      nh_, topic_, *tf_, layered_costmap_->globalFrame(), tf_queue_size_,
      [this](const TrackedObjectArrayConstPtr& msg) { onTracks(msg); },
      [this](const TrackedObjectArrayConstPtr& msg,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        std::ostringstream detail;
        detail << "frame '" << msg->header.frame_id << "' -> '" << layered_costmap_->globalFrame()
               << "' at stamp " << msg->header.stamp;
        reject(tfFailureReason(reason), detail.str());
      });
}

void TrackedObstacleLayer::reject(const std::string& reason, const std::string& detail) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++rejected_[reason];
    last_rejection_ = reason + ": " + detail;
  }
  ROS_WARN_THROTTLE(2.0, "layer '%s' (%s): %s: %s", name_.c_str(), topic_.c_str(), reason.c_str(),
                    detail.c_str());
}

void TrackedObstacleLayer::onTracks(const TrackedObjectArrayConstPtr& msg) {
  const std::string& global = layered_costmap_->globalFrame();
  geometry_msgs::TransformStamped transform;
  try {
    transform = tf_->lookupTransform(global, msg->header.frame_id, msg->header.stamp);
  } catch (const tf2::TransformException& e) {
    reject("tf: lookup at stamp failed", e.what());
    return;
  }
  const double box_yaw = tf2::getYaw(transform.transform.rotation);
  std::vector<PlanarTrack> tracks;
  std::size_t skipped_state = 0;
  for (const TrackedObject& object : msg->tracks) {
    const bool wanted = object.state == TrackedObject::CONFIRMED ||
                        (include_coasting_ && object.state == TrackedObject::COASTING) ||
                        (include_tentative_ && object.state == TrackedObject::TENTATIVE);
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
      reject("bad track", "id " + std::to_string(object.id) + ": " + why);
      continue;
    }
    tracks.push_back(t);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (!tracks_stamp_.isZero() && msg->header.stamp < tracks_stamp_) {
    ++rejected_["older than the tracks already drawn"];
    return;
  }
  tracks_ = std::move(tracks);
  tracks_stamp_ = msg->header.stamp;
  tracks_skipped_state_ += skipped_state;
  ++arrays_received_;
  transform_age_s_.add((ros::Time::now() - msg->header.stamp).toSec());
}

void TrackedObstacleLayer::updateBounds(double, double, double, double* min_x, double* min_y,
                                        double* max_x, double* max_y) {
  std::lock_guard<std::mutex> lock(mutex_);
  const ros::Time now = ros::Time::now();
  const bool fresh = !tracks_stamp_.isZero() && (now - tracks_stamp_).toSec() <= track_timeout_s_;
  current_ = fresh;
  if (!fresh && !tracks_.empty()) {
    tracks_.clear();  // a stale track never stays in the map
    ++arrays_expired_;
  }
  const auto grow = [&](double x0, double y0, double x1, double y1) {
    if (x0 > x1) return;
    *min_x = std::min(*min_x, x0);
    *min_y = std::min(*min_y, y0);
    *max_x = std::max(*max_x, x1);
    *max_y = std::max(*max_y, y1);
  };
  // Cells drawn last time must be redrawn (the object moved on), and the new ones drawn.
  grow(drawn_min_x_, drawn_min_y_, drawn_max_x_, drawn_max_y_);
  cells_.clear();
  tracks_drawn_ = 0;
  CellBounds bounds;
  const GridGeometry& g = layered_costmap_->costmap().geometry();
  if (enabled_ && g.cellCount() > 0) {
    const double age = std::max(0.0, (now - tracks_stamp_).toSec());
    for (const PlanarTrack& t : tracks_) {
      const CellBounds b = predictedCells(t, age, prediction_, g, &cells_);
      tracks_drawn_ += !b.empty();
      bounds.expand(b);
    }
  }
  // Remembered in metres: still right after a rolling-window shift of the cells.
  drawn_min_x_ = drawn_min_y_ = std::numeric_limits<double>::infinity();
  drawn_max_x_ = drawn_max_y_ = -std::numeric_limits<double>::infinity();
  g.expandWorldBox(bounds, &drawn_min_x_, &drawn_min_y_, &drawn_max_x_, &drawn_max_y_);
  grow(drawn_min_x_, drawn_min_y_, drawn_max_x_, drawn_max_y_);
}

void TrackedObstacleLayer::updateCosts(Costmap& master, int min_i, int min_j, int max_i,
                                       int max_j) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!enabled_) return;
  const GridGeometry& g = master.geometry();
  for (const std::size_t i : cells_) {
    if (i >= g.cellCount()) continue;  // drawn before a resize; redrawn at the next update
    const CellIndex c = g.cellOf(i);
    if (c.x >= min_i && c.x < max_i && c.y >= min_j && c.y < max_j) {
      master.setCost(c.x, c.y, cost::kLethalObstacle);
    }
  }
}

void TrackedObstacleLayer::matchSize() {
  std::lock_guard<std::mutex> lock(mutex_);
  cells_.clear();  // indices of the old geometry; recomputed at the next updateBounds
}

void TrackedObstacleLayer::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  tracks_.clear();
  cells_.clear();
}

void TrackedObstacleLayer::activate() {
  subscribe();
}

void TrackedObstacleLayer::deactivate() {
  subscription_.unsubscribe();
}

void TrackedObstacleLayer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("topic", topic_);
  status.add("track arrays received", arrays_received_);
  status.add("track arrays expired (older than track_timeout_s)", arrays_expired_);
  status.add("tracks skipped by state", tracks_skipped_state_);
  std::size_t rejected = 0;
  for (const auto& [reason, count] : rejected_) {
    status.add("rejected (" + reason + ")", count);
    rejected += count;
  }
  if (!last_rejection_.empty()) status.add("last rejection", last_rejection_);
  status.add("tracks drawn (last update)", tracks_drawn_);
  status.add("lethal cells drawn (last update)", cells_.size());
  status.add("transform age mean (s)", transform_age_s_.mean());
  status.add("transform age max (s)", transform_age_s_.max);
  status.add("prediction_horizon_s", prediction_.prediction_horizon_s);
  addConfigErrors(status, config_errors_);
  if (!config_errors_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, config_errors_.front());
  } else if (arrays_received_ == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   rejected > 0 ? "every track array rejected: " + last_rejection_
                                : "no track array received yet");
  } else if (!current_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "tracks older than track_timeout_s: none drawn");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   "drawing " + std::to_string(tracks_drawn_) + " predicted tracks");
  }
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::TrackedObstacleLayer, downstream_perception::Layer)
