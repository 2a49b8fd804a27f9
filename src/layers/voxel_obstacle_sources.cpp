// VoxelObstacleLayer's observation sources: their parameters (costmap_2d's source keys and
// ours), their subscriptions through tf2 MessageFilters, and the update-rate check.
#include "downstream_perception/layers/voxel_obstacle_layer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"
#include "downstream_perception/ros/costmap/stvl_keys.h"

namespace downstream_perception {

void VoxelObstacleLayer::readSource(const std::string& name) {
  ros::NodeHandle snh(nh_, name);
  ParamReader reader(snh, "layer '" + name_ + "', source '" + name + "'");
  auto s = std::make_unique<Source>();
  s->name = name;
  s->topic = name;
  // costmap_2d's default data_type (sensor_msgs/PointCloud, converted as costmap_2d converts).
  std::string data_type = "PointCloud";
  reader.get("topic", &s->topic);
  reader.get("data_type", &data_type);
  reader.get("sensor_frame", &s->sensor_frame);
  reader.get("marking", &s->rays.marking);
  reader.get("clearing", &s->rays.clearing);
  // costmap_2d's ranges, found like costmap_2d does (searchParam from the source up).
  const auto search = [&snh](const char* key, double* value) {
    std::string found;
    if (snh.searchParam(key, found)) snh.getParam(found, *value);
  };
  search("obstacle_range", &s->rays.obstacle_max_range_m);
  search("raytrace_range", &s->rays.raytrace_max_range_m);
  s->rays.no_return_range_m = s->rays.raytrace_max_range_m;
  reader.known({"obstacle_range", "raytrace_range"});
  if (stvl_configuration_) reader.known(stvlSourceKeys());  // adopted by the host (stvl_keys.h)
  reader.get("no_return_range", &s->rays.no_return_range_m);
  reader.get("camera_info_topic", &s->camera_info_topic);
  reader.get("zero_is_no_return", &s->zero_is_no_return);
  reader.get("one_ray_per_end_voxel", &s->rays.one_ray_per_end_voxel);
  std::string clearing_mode = "ray";
  reader.get("clearing_mode", &clearing_mode);
  reader.get("stride", &s->stride);
  reader.get("tf_queue_size", &s->tf_queue_size);
  if (data_type == "DepthImage") {
    reader.unsupported("min_obstacle_height",
                       "depth images mark every pixel; the layer's min/max_obstacle_height decide "
                       "which voxels reach the costmap");
    reader.unsupported("max_obstacle_height", "see min_obstacle_height");
  } else {
    // costmap_2d's source band (its defaults 0 and 2 m): points outside it neither mark nor clear.
    reader.get("min_obstacle_height", &s->min_z_m);
    reader.get("max_obstacle_height", &s->max_z_m);
  }
  // costmap_2d's default 0 (the latest observation only) is what this layer does: only a
  // longer persistence is a difference.
  double persistence_s = 0.0;
  if (reader.get("observation_persistence", &persistence_s) && persistence_s != 0.0) {
    reader.unsupported("observation_persistence",
                       "each observation is integrated once (as with 0, costmap_2d's default)");
  }
  // costmap_2d's rule: the layer (and the costmap) is not current while a source has delivered
  // nothing for longer than this since its last observation or since subscribing.
  reader.get("expected_update_rate", &s->expected_update_rate_s);
  if (data_type == "LaserScan") {
    // costmap_2d's inf_is_valid keeps its meaning (+Inf: a return at range_max); ours,
    // inf_is_no_return (REP-117), wins when both are set, with a WARN.
    reader.get("inf_is_valid", &s->scan_options.inf_is_valid);
    reader.get("inf_is_no_return", &s->scan_options.inf_is_no_return);
    reader.get("range_max_is_no_return", &s->scan_options.range_max_is_no_return);
    reader.get("per_beam_time_correction", &s->per_beam_time_correction);
    if (s->scan_options.inf_is_valid && s->scan_options.inf_is_no_return) {
      const std::string msg =
          "source '" + name +
          "': inf_is_valid (costmap_2d: +Inf is a return at range_max) and inf_is_no_return "
          "(ours: +Inf clears to no_return_range, never marks) are both set; using "
          "inf_is_no_return";
      ROS_WARN("layer '%s': %s", name_.c_str(), msg.c_str());
      param_warnings_.push_back(msg);
    }
  } else {
    // costmap_2d reads inf_is_valid for LaserScan sources only; true elsewhere is a difference.
    bool inf_is_valid = false;
    if (reader.get("inf_is_valid", &inf_is_valid) && inf_is_valid) {
      reader.unsupported("inf_is_valid",
                         data_type == "DepthImage"
                             ? "depth images: +Inf is a no-return ray (REP 118)"
                             : "clouds have no ranges to substitute (costmap_2d ignores it "
                               "there too)");
    }
  }
  reader.warnUnknown();
  for (const auto& w : reader.warnings()) param_warnings_.push_back("source '" + name + "': " + w);
  std::string why = s->rays.validate();
  if (data_type != "PointCloud" && data_type != "PointCloud2" && data_type != "DepthImage" &&
      data_type != "LaserScan") {
    why = "data_type '" + data_type +
          "' is not supported (PointCloud, PointCloud2, DepthImage or LaserScan)";
  } else if (!(s->min_z_m <= s->max_z_m) || std::isnan(s->min_z_m) || std::isnan(s->max_z_m)) {
    why = "min_obstacle_height " + std::to_string(s->min_z_m) +
          " m must be <= max_obstacle_height " + std::to_string(s->max_z_m) + " m";
  } else if (clearing_mode != "ray" && clearing_mode != "frustum") {
    why = "clearing_mode '" + clearing_mode + "' is not supported (ray or frustum)";
  } else if (clearing_mode == "frustum" && data_type != "DepthImage") {
    why =
        "clearing_mode 'frustum' needs a DepthImage source (a cloud has no image to project "
        "into)";
  } else if (!std::isfinite(s->expected_update_rate_s) || s->expected_update_rate_s < 0.0) {
    why = "expected_update_rate must be finite and >= 0 s, got " +
          std::to_string(s->expected_update_rate_s);
  } else if (s->stride < 1 || s->stride > 64) {
    why = "stride must be in [1, 64] pixels, got " + std::to_string(s->stride);
  } else if (s->tf_queue_size < 1 || s->tf_queue_size > 10000) {
    why = "tf_queue_size must be in [1, 10000], got " + std::to_string(s->tf_queue_size);
  }
  if (!why.empty()) {
    config_errors_.add("source '" + name + "': " + why + "; source ignored");
    return;
  }
  s->depth = data_type == "DepthImage";
  s->waiting_for_camera = WaitingImages(static_cast<std::size_t>(s->tf_queue_size));
  s->frustum = clearing_mode == "frustum";
  s->scan = data_type == "LaserScan";
  s->legacy_cloud = data_type == "PointCloud";
  if (s->depth) {
    s->min_z_m = -std::numeric_limits<double>::infinity();
    s->max_z_m = std::numeric_limits<double>::infinity();
  }
  if (s->depth && s->camera_info_topic.empty()) {
    // image_transport's convention: the camera_info next to the image.
    const std::size_t slash = s->topic.rfind('/');
    s->camera_info_topic =
        slash == std::string::npos ? "camera_info" : s->topic.substr(0, slash + 1) + "camera_info";
  }
  ROS_INFO("layer '%s': %s source '%s' on %s (%s, %s, mark <= %.2f m, clear <= %.2f m)",
           name_.c_str(), data_type.c_str(), name.c_str(),
           ros::names::resolve(topic_nh_.getNamespace(), s->topic).c_str(),
           s->rays.marking ? "marking" : "not marking",
           s->rays.clearing ? "clearing" : "not clearing", s->rays.obstacle_max_range_m,
           s->rays.raytrace_max_range_m);
  sources_.push_back(std::move(s));
}

void VoxelObstacleLayer::activate() {
  const std::string& frame = layered_costmap_->globalFrame();
  for (auto& sp : sources_) {
    Source* s = sp.get();
    {
      // Subscribing is idempotent; the update-rate clock starts at the first subscription.
      std::lock_guard<std::mutex> lock(mutex_);
      if (s->subscribed_since.isZero()) s->subscribed_since = ros::WallTime::now();
    }
    const auto on_failure =
        [this, s, &frame](const auto& msg, tf2_ros::filter_failure_reasons::FilterFailureReason) {
          reject(s, "no transform " + frame + " <- " + msg->header.frame_id + " at the stamp");
        };
    if (s->depth) {
      if (!s->info_sub) {
        s->info_sub = topic_nh_.subscribe<sensor_msgs::CameraInfo>(
            s->camera_info_topic, 1,
            [this, s](const sensor_msgs::CameraInfoConstPtr& m) { onCameraInfo(s, m); });
      }
      s->depth_sub.subscribe(
          topic_nh_, s->topic, *tf_, frame, s->tf_queue_size,
          [this, s](const sensor_msgs::ImageConstPtr& m) { onDepth(s, m); },
          [on_failure](const sensor_msgs::ImageConstPtr& m,
                       tf2_ros::filter_failure_reasons::FilterFailureReason r) {
            on_failure(m, r);
          });
    } else if (s->scan) {
      s->scan_sub.subscribe(
          topic_nh_, s->topic, *tf_, frame, s->tf_queue_size,
          [this, s](const sensor_msgs::LaserScanConstPtr& m) { onScan(s, m); },
          [on_failure](const sensor_msgs::LaserScanConstPtr& m,
                       tf2_ros::filter_failure_reasons::FilterFailureReason r) {
            on_failure(m, r);
          });
    } else if (s->legacy_cloud) {
      s->legacy_cloud_sub.subscribe(
          topic_nh_, s->topic, *tf_, frame, s->tf_queue_size,
          [this, s](const sensor_msgs::PointCloudConstPtr& m) { onLegacyCloud(s, m); },
          [on_failure](const sensor_msgs::PointCloudConstPtr& m,
                       tf2_ros::filter_failure_reasons::FilterFailureReason r) {
            on_failure(m, r);
          });
    } else {
      s->cloud_sub.subscribe(
          topic_nh_, s->topic, *tf_, frame, s->tf_queue_size,
          [this, s](const sensor_msgs::PointCloud2ConstPtr& m) { onCloud(s, m); },
          [on_failure](const sensor_msgs::PointCloud2ConstPtr& m,
                       tf2_ros::filter_failure_reasons::FilterFailureReason r) {
            on_failure(m, r);
          });
    }
  }
}

void VoxelObstacleLayer::deactivate() {
  for (auto& s : sources_) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      s->subscribed_since = ros::WallTime();
      s->waiting_for_camera.clear();
    }
    s->cloud_sub.unsubscribe();
    s->legacy_cloud_sub.unsubscribe();
    s->depth_sub.unsubscribe();
    s->scan_sub.unsubscribe();
    s->info_sub.shutdown();
  }
}

std::string VoxelObstacleLayer::staleSources() const {
  // costmap_2d's ObservationBuffer::isCurrent: the time since the last observation (or since
  // subscribing, before the first one) is at most expected_update_rate. Caller holds mutex_.
  std::ostringstream why;
  why.precision(2);
  const ros::WallTime now = ros::WallTime::now();
  for (const auto& s : sources_) {
    if (s->expected_update_rate_s <= 0.0 || s->subscribed_since.isZero()) continue;
    const double silent_s = (now - std::max(s->subscribed_since, s->last_integrated)).toSec();
    if (silent_s <= s->expected_update_rate_s) continue;
    why << (why.tellp() > 0 ? "; " : "") << std::fixed << "source '" << s->name << "' (" << s->topic
        << "): " << (s->integrated == 0 ? "no observation integrated yet, " : "no observation for ")
        << silent_s << " s, expected_update_rate " << s->expected_update_rate_s << " s";
  }
  return why.str();
}

}  // namespace downstream_perception
