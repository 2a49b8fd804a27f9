#include "downstream_perception/layers/tracked_obstacle_layer.h"

#include <pluginlib/class_list_macros.hpp>

#include <algorithm>
#include <limits>

#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

TrackedObstacleLayer::~TrackedObstacleLayer() {
  // Stop the callbacks before the state they write into goes away.
  reconfigure_.stop();
  inbox_.unsubscribe();
}

void TrackedObstacleLayer::onInitialize() {
  inbox_.setArrivalHandler(
      [this](const ros::Time& stamp) { layered_costmap_->notifyDataArrived(stamp); });
  config_errors_.setPrefix("layer '" + name_ + "'");
  TrackInboxConfig inbox;
  ParamReader params(nh_, "layer '" + name_ + "'");
  params.get("topic", &inbox.topic);
  params.get("tf_queue_size", &inbox.tf_queue_size);
  params.reconfigureKeys<TrackedObstacleLayerConfig>();
  params.warnUnknown();
  param_warnings_ = params.warnings();
  const std::string why = inbox.validate();
  if (!why.empty()) {
    config_errors_.add(why + "; using the defaults");
    inbox = TrackInboxConfig();
  }
  inbox_.setConfig(inbox);
  current_ = false;
  // The server reads the YAML values (or the .cfg defaults, equal to the C++ ones) and calls
  // reconfigure() at once: one code path for start-up and live changes.
  reconfigure_.start(nh_, this, &TrackedObstacleLayer::reconfigure);
}

void TrackedObstacleLayer::reconfigure(TrackedObstacleLayerConfig& cfg, std::uint32_t) {
  PredictionConfig prediction;
  prediction.prediction_horizon_s = cfg.prediction_horizon_s;
  prediction.uncertainty_sigmas = cfg.uncertainty_sigmas;
  prediction.max_uncertainty_m = cfg.max_uncertainty_m;
  prediction.min_object_size_m = cfg.min_object_size_m;
  prediction.max_object_size_m = cfg.max_object_size_m;
  prediction.max_speed_mps = cfg.max_speed_mps;
  PredictionConfig previous;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    previous = prediction_;
  }
  std::string why = prediction.validate();
  if (!why.empty()) {
    config_errors_.set("prediction", why + "; keeping the previous prediction settings (horizon " +
                                         toText(previous.prediction_horizon_s) + " s)");
    prediction = previous;
  } else {
    config_errors_.clear("prediction");
  }
  // The server stores and publishes what this callback leaves in cfg: the values in use.
  cfg.prediction_horizon_s = prediction.prediction_horizon_s;
  cfg.uncertainty_sigmas = prediction.uncertainty_sigmas;
  cfg.max_uncertainty_m = prediction.max_uncertainty_m;
  cfg.min_object_size_m = prediction.min_object_size_m;
  cfg.max_object_size_m = prediction.max_object_size_m;
  cfg.max_speed_mps = prediction.max_speed_mps;
  TrackInboxConfig inbox = inbox_.config();
  const double previous_timeout = inbox.track_timeout_s;
  inbox.track_timeout_s = cfg.track_timeout_s;
  inbox.include_tentative = cfg.include_tentative;
  inbox.include_coasting = cfg.include_coasting;
  why = inbox.validate();
  if (!why.empty()) {
    config_errors_.set("track_timeout_s", why + "; keeping " + toText(previous_timeout) + " s");
    inbox.track_timeout_s = previous_timeout;
  } else {
    config_errors_.clear("track_timeout_s");
  }
  cfg.track_timeout_s = inbox.track_timeout_s;
  inbox_.setConfig(inbox);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    prediction_ = prediction;
  }
  const bool was_enabled = enabled_;
  enabled_ = cfg.enabled;
  // Subscribed exactly while enabled.
  if (enabled_) {
    activate();
  } else {
    deactivate();
  }
  if (was_enabled != enabled_) layered_costmap_->requestFullRedraw();
  ROS_INFO("layer '%s': tracks from %s, horizon %.2f s, %.1f sigma, timeout %.2f s, %s",
           name_.c_str(), ros::names::resolve(nh_.getNamespace(), inbox.topic).c_str(),
           prediction.prediction_horizon_s, prediction.uncertainty_sigmas, inbox.track_timeout_s,
           enabled_ ? "enabled" : "disabled");
}

void TrackedObstacleLayer::updateBounds(double, double, double, double* min_x, double* min_y,
                                        double* max_x, double* max_y) {
  const FreshTracks fresh = inbox_.fresh(ros::Time::now());
  std::lock_guard<std::mutex> lock(mutex_);
  current_ = fresh.current;
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
    for (const PlanarTrack& t : fresh.tracks) {
      const CellBounds b = predictedCells(t, fresh.age_s, prediction_, g, &cells_);
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
  inbox_.clear();
  std::lock_guard<std::mutex> lock(mutex_);
  cells_.clear();
}

void TrackedObstacleLayer::activate() {
  inbox_.subscribe(nh_, *tf_, layered_costmap_->globalFrame(), name_);
}

void TrackedObstacleLayer::deactivate() {
  inbox_.unsubscribe();
}

void TrackedObstacleLayer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  inbox_.diagnose(status);
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("tracks drawn (last update)", tracks_drawn_);
  status.add("lethal cells drawn (last update)", cells_.size());
  status.add("prediction_horizon_s", prediction_.prediction_horizon_s);
  addParamWarnings(status, param_warnings_);
  if (config_errors_.report(status)) return;  // ERROR, with the first problem
  if (!enabled_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "disabled");
  } else if (inbox_.arraysReceived() == 0) {
    const std::string last = inbox_.lastRejection();
    status.summary(
        diagnostic_msgs::DiagnosticStatus::WARN,
        last.empty() ? "no track array received yet" : "every track array rejected: " + last);
  } else if (!current_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "tracks older than track_timeout_s: none drawn");
  } else if (!param_warnings_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, param_warnings_.front());
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                   "drawing " + std::to_string(tracks_drawn_) + " predicted tracks");
  }
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::TrackedObstacleLayer, downstream_perception::Layer)
