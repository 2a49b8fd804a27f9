#include "downstream_perception/layers/tsdf_layer.h"

#include <pluginlib/class_list_macros.hpp>

#include <algorithm>
#include <cmath>

#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/message_checks.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

void TsdfLayer::onInitialize() {
  ParamReader params(nh_, "layer '" + name_ + "'");
  topic_ = params.param<std::string>("topic", "/tsdf/slice");
  max_age_s_ = params.param("max_age_s", 0.0);
  enabled_ = params.param("enabled", true);
  params.warnUnknown();
  param_warnings_ = params.warnings();
  if (!(std::isfinite(max_age_s_) && max_age_s_ >= 0.0)) {
    config_errors_.setPrefix("layer '" + name_ + "'");
    config_errors_.add("parameter max_age_s = " + toText(max_age_s_) +
                       " must be >= 0 s (0 = any age); using 0");
    max_age_s_ = 0.0;
  }
  global_frame_ = layered_costmap_->globalFrame();
  subscriber_ = nh_.subscribe(topic_, 1, &TsdfLayer::onSlice, this);
  current_ = max_age_s_ == 0.0;
  ROS_INFO("layer '%s': TSDF slice from %s", name_.c_str(),
           ros::names::resolve(nh_.getNamespace(), topic_).c_str());
}

void TsdfLayer::onSlice(const nav_msgs::OccupancyGridConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto& info = msg->info;
  const double yaw_z = info.origin.orientation.z, yaw_w = info.origin.orientation.w;
  std::string why;
  if (msg->header.frame_id != global_frame_) {
    why = "slice in '" + msg->header.frame_id + "', costmap in '" + global_frame_ +
          "' (run the TSDF with world_frame = the costmap's global_frame)";
  } else {
    why = checkOccupancyGrid(*msg);  // 64-bit width x height against the data
  }
  if (why.empty() && (std::abs(yaw_z) > 1e-6 || std::abs(std::abs(yaw_w) - 1.0) > 1e-6)) {
    why = "rotated grids are not supported";
  }
  if (!why.empty()) {
    ++slices_rejected_;
    last_rejection_ = why;
    ROS_WARN_THROTTLE(5.0, "layer '%s': slice rejected: %s", name_.c_str(), why.c_str());
    return;
  }
  slice_ = msg;
  slice_changed_ = true;
  ++slices_received_;
  layered_costmap_->notifyDataArrived(msg->header.stamp);
}

void TsdfLayer::updateBounds(double, double, double, double* min_x, double* min_y, double* max_x,
                             double* max_y) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (max_age_s_ > 0.0) {
    current_ = slice_ && (ros::Time::now() - slice_->header.stamp).toSec() <= max_age_s_;
  }
  if (!slice_changed_ || !enabled_) return;
  // Redraw where the old slice was and where the new one is (cells may have become free).
  const auto grow = [&](double x0, double y0, double x1, double y1) {
    if (x0 > x1) return;
    *min_x = std::min(*min_x, x0);
    *min_y = std::min(*min_y, y0);
    *max_x = std::max(*max_x, x1);
    *max_y = std::max(*max_y, y1);
  };
  grow(drawn_min_x_, drawn_min_y_, drawn_max_x_, drawn_max_y_);
  const auto& info = slice_->info;
  drawn_min_x_ = info.origin.position.x;
  drawn_min_y_ = info.origin.position.y;
  drawn_max_x_ = drawn_min_x_ + info.width * info.resolution;
  drawn_max_y_ = drawn_min_y_ + info.height * info.resolution;
  grow(drawn_min_x_, drawn_min_y_, drawn_max_x_, drawn_max_y_);
  slice_changed_ = false;
}

void TsdfLayer::updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!slice_ || !enabled_) return;
  const GridGeometry& g = master.geometry();
  const auto& info = slice_->info;
  const double inv = 1.0 / info.resolution;
  const int w = static_cast<int>(info.width), h = static_cast<int>(info.height);
  lethal_written_ = 0;
  // Each master cell takes the slice cell under its centre; free and unknown slice cells leave
  // the master as the other layers drew it.
  for (int j = std::max(0, min_j); j < std::min(max_j, g.sizeY()); ++j) {
    const double wy = g.originY() + (j + 0.5) * g.resolution();
    const int sy = static_cast<int>(std::floor((wy - info.origin.position.y) * inv));
    if (sy < 0 || sy >= h) continue;
    for (int i = std::max(0, min_i); i < std::min(max_i, g.sizeX()); ++i) {
      const double wx = g.originX() + (i + 0.5) * g.resolution();
      const int sx = static_cast<int>(std::floor((wx - info.origin.position.x) * inv));
      if (sx < 0 || sx >= w) continue;
      if (slice_->data[static_cast<std::size_t>(sy) * w + sx] == 100) {
        master.setCost(i, j, cost::kLethalObstacle);  // an obstacle outranks any other cost
        ++lethal_written_;
      }
    }
  }
}

void TsdfLayer::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  slice_changed_ = slice_ != nullptr;
}

void TsdfLayer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("topic", topic_);
  status.add("slices received", slices_received_);
  status.add("slices rejected", slices_rejected_);
  if (!last_rejection_.empty()) status.add("last rejection", last_rejection_);
  status.add("lethal cells written (last update)", lethal_written_);
  const std::vector<std::string> config_errors = config_errors_.all();
  addConfigErrors(status, config_errors);
  if (!config_errors.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, config_errors.front());
  } else if (!slice_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no TSDF slice received yet");
  } else if (!current_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "TSDF slice older than max_age_s");
  } else if (!param_warnings_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, param_warnings_.front());
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "drawing the TSDF slice");
  }
  addParamWarnings(status, param_warnings_);
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::TsdfLayer, downstream_perception::Layer)
