#include "downstream_perception/layers/voxel_obstacle_layer.h"

#include <sensor_msgs/point_cloud2_iterator.h>
#include <sensor_msgs/point_cloud_conversion.h>
#include <pluginlib/class_list_macros.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "downstream_perception/core/costmap/footprint.h"
#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/core/voxel/depth_rays.h"
#include "downstream_perception/core/voxel/scan_rays.h"
#include "downstream_perception/ros/common/message_checks.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/common/timing_diagnostics.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

namespace {
// The occupied-voxel cloud is published at most this often (it walks every block).
constexpr double kVoxelCloudPeriodS = 0.5;
}  // namespace

VoxelObstacleLayer::~VoxelObstacleLayer() {
  // Stop the callbacks before the map they write into goes away.
  sources_.clear();
}

void VoxelObstacleLayer::onInitialize() {
  config_errors_.setPrefix("layer '" + name_ + "'");
  ParamReader reader(nh_, "layer '" + name_ + "'");
  track_unknown_space_ = layered_costmap_->isTrackingUnknown();
  reader.get("enabled", &enabled_);
  reader.get("track_unknown_space", &track_unknown_space_);
  reader.get("combination_method", &combination_method_);
  if (combination_method_ != 0 && combination_method_ != 1) {
    config_errors_.add("combination_method must be 0 (overwrite) or 1 (maximum), got " +
                       std::to_string(combination_method_) + "; using 1");
    combination_method_ = 1;
  }
  // costmap_2d VoxelLayer's keys, with its defaults (VoxelMapConfig documents each).
  VoxelMapConfig c;
  reader.get("origin_z", &c.origin_z_m);
  reader.get("z_resolution", &c.z_resolution_m);
  reader.get("z_voxels", &c.z_voxels);
  reader.get("mark_threshold", &c.mark_threshold);
  reader.get("unknown_threshold", &c.unknown_threshold);
  reader.get("publish_voxel_map", &publish_voxel_map_);
  reader.get("min_obstacle_height", &c.min_obstacle_height_m);
  reader.get("max_obstacle_height", &c.max_obstacle_height_m);
  // Ours: the sensor model, decay and the memory bound.
  reader.get("p_hit", &c.log_odds.p_hit);
  reader.get("p_miss", &c.log_odds.p_miss);
  reader.get("log_odds_min", &c.log_odds.clamp_min);
  reader.get("log_odds_max", &c.log_odds.clamp_max);
  reader.get("occupied_log_odds", &c.log_odds.occupied_threshold);
  reader.get("free_log_odds", &c.log_odds.free_threshold);
  reader.get("decay_time_s", &c.decay_time_s);
  reader.get("max_memory_mib", &c.max_memory_mib);
  c.resolution_m = layered_costmap_->costmap().geometry().resolution();
  const std::string why = c.validate();
  if (!why.empty()) {
    config_errors_.add("voxel map invalid (" + why + "); using the defaults");
    const double resolution = c.resolution_m;
    c = VoxelMapConfig();
    c.resolution_m = resolution;
  }
  config_ = c;
  // costmap_2d's layer-level keys read elsewhere: obstacle_range / raytrace_range are found from
  // each source upward (searchParam, readSource); transform_tolerance is validated only (the
  // MessageFilter waits for each message's own transform, as in costmap_2d in practice).
  reader.known({"obstacle_range", "raytrace_range"});
  double transform_tolerance = 0.2;
  reader.get("transform_tolerance", &transform_tolerance);
  if (!std::isfinite(transform_tolerance) || transform_tolerance < 0.0) {
    config_errors_.add("transform_tolerance must be finite and >= 0 s, got " +
                       std::to_string(transform_tolerance));
  }
  std::string names;
  reader.get("observation_sources", &names);
  // costmap_2d's key and default: the robot stands in its footprint, so nothing else is there.
  reader.get("footprint_clearing_enabled", &footprint_clearing_enabled_);
  {
    std::istringstream stream(names);
    std::string name;
    while (stream >> name) {
      reader.known({name});
      readSource(name);
    }
  }
  reader.warnUnknown();
  param_warnings_ = reader.warnings();
  if (publish_voxel_map_) voxel_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("voxel_cloud", 1);
  matchSize();
  if (enabled_) activate();
  ROS_INFO(
      "layer '%s': 3-D voxels %.3f m x %.3f m, %d layers from %.2f m, band [%.2f, %.2f] m, "
      "mark_threshold %d, unknown_threshold %d, decay %.1f s, memory <= %.1f MiB, %zu source(s)",
      name_.c_str(), config_.resolution_m, config_.z_resolution_m, config_.z_voxels,
      config_.origin_z_m, config_.min_obstacle_height_m, config_.max_obstacle_height_m,
      config_.mark_threshold, config_.unknown_threshold, config_.decay_time_s,
      config_.max_memory_mib, sources_.size());
}

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
  reader.unsupported("observation_persistence", "each observation is integrated once");
  reader.unsupported("expected_update_rate", "not checked by this layer");
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
    reader.unsupported("inf_is_valid", "depth images: +Inf is a no-return ray (REP 118)");
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
    s->cloud_sub.unsubscribe();
    s->legacy_cloud_sub.unsubscribe();
    s->depth_sub.unsubscribe();
    s->scan_sub.unsubscribe();
    s->info_sub.shutdown();
  }
}

void VoxelObstacleLayer::reject(Source* s, const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++s->rejected;
  s->last_rejection = why;
  ROS_WARN_THROTTLE(5.0, "layer '%s', source '%s': message refused: %s", name_.c_str(),
                    s->name.c_str(), why.c_str());
}

bool VoxelObstacleLayer::lookup(Source* s, const std::string& frame, const ros::Time& stamp,
                                Eigen::Isometry3d* pose) {
  try {
    const auto t = tf_->lookupTransform(layered_costmap_->globalFrame(), frame, stamp);
    const auto& q = t.transform.rotation;
    const auto& v = t.transform.translation;
    *pose = Eigen::Isometry3d::Identity();
    pose->linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
    pose->translation() = Eigen::Vector3d(v.x, v.y, v.z);
    if (!pose->matrix().allFinite()) {  // a zero or NaN quaternion normalises to NaN
      reject(s, "transform from '" + frame + "' is not finite");
      return false;
    }
    return true;
  } catch (const tf2::TransformException& e) {
    reject(s, std::string("tf: ") + e.what());
    return false;
  }
}

bool VoxelObstacleLayer::lookupQuiet(const std::string& frame, const ros::Time& stamp,
                                     Eigen::Isometry3d* pose) {
  try {
    const auto t = tf_->lookupTransform(layered_costmap_->globalFrame(), frame, stamp);
    const auto& q = t.transform.rotation;
    const auto& v = t.transform.translation;
    pose->linear() = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
    pose->translation() = Eigen::Vector3d(v.x, v.y, v.z);
    return pose->matrix().allFinite();
  } catch (const tf2::TransformException&) {
    return false;
  }
}

void VoxelObstacleLayer::onCameraInfo(Source* s, const sensor_msgs::CameraInfoConstPtr& msg) {
  PinholeCamera cam;
  cam.fx = msg->K[0];
  cam.fy = msg->K[4];
  cam.cx = msg->K[2];
  cam.cy = msg->K[5];
  cam.width = static_cast<int>(std::min<std::uint32_t>(msg->width, 1u << 30));
  cam.height = static_cast<int>(std::min<std::uint32_t>(msg->height, 1u << 30));
  const std::string why = cam.validate();
  if (!why.empty()) {
    reject(s, "camera_info: " + why);
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  s->camera = cam;
}

void VoxelObstacleLayer::onDepth(Source* s, const sensor_msgs::ImageConstPtr& msg) {
  std::optional<PinholeCamera> cam;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++s->received;
    cam = s->camera;
  }
  if (!cam) {
    reject(s, "no camera_info yet on " + s->camera_info_topic);
    return;
  }
  if (static_cast<int>(msg->width) != cam->width || static_cast<int>(msg->height) != cam->height) {
    reject(s, "image " + std::to_string(msg->width) + " x " + std::to_string(msg->height) +
                  " does not match camera_info's " + std::to_string(cam->width) + " x " +
                  std::to_string(cam->height));
    return;
  }
  std::vector<float> metres;
  std::string why;
  if (!depthImageToMetres(*msg, &metres, &why, s->zero_is_no_return)) {
    reject(s, why);
    return;
  }
  Eigen::Isometry3d pose;
  if (!lookup(s, s->sensor_frame.empty() ? msg->header.frame_id : s->sensor_frame,
              msg->header.stamp, &pose)) {
    return;
  }
  if (s->frustum) {
    integrateFrustum(s, metres, *cam, pose, msg->header.stamp);
    return;
  }
  DepthRays rays;
  depthToRays(metres.data(), *cam, pose, s->zero_is_no_return, s->stride, &rays);
  integrate(s, pose.translation(), rays.hits, rays.no_returns, msg->header.stamp);
}

void VoxelObstacleLayer::onScan(Source* s, const sensor_msgs::LaserScanConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++s->received;
  }
  // The shared message check (sizes and offsets in 64 bits, the sweep's duration, intensities).
  const std::string why = checkScan(*msg);
  if (!why.empty()) {
    reject(s, "laser scan: " + why);
    return;
  }
  const LaserScanView view{msg->ranges.data(),   msg->ranges.size(), msg->angle_min,
                           msg->angle_increment, msg->range_min,     msg->range_max};
  const std::string& frame = s->sensor_frame.empty() ? msg->header.frame_id : s->sensor_frame;
  Eigen::Isometry3d pose;
  if (!lookup(s, frame, msg->header.stamp, &pose)) return;
  // REP 117: the header stamp is the first beam's time, beam k is k * time_increment later. Each
  // beam's end is placed at its own time, as costmap_2d's laser_geometry projection does; the
  // rays start from the sensor at the header stamp, as there.
  Eigen::Isometry3d last = pose;
  const double sweep_s = msg->time_increment * static_cast<double>(msg->ranges.size() - 1);
  if (s->per_beam_time_correction && sweep_s != 0.0 && msg->ranges.size() > 1) {
    if (sweep_s > s->tf_tolerance_s) {
      s->tf_tolerance_s = sweep_s;  // from now on wait for tf at the last beam too
      s->scan_sub.setTolerance(ros::Duration(sweep_s));
    }
    if (!lookupQuiet(frame, msg->header.stamp + ros::Duration(sweep_s), &last)) {
      last = pose;
      std::lock_guard<std::mutex> lock(mutex_);
      ++s->deskew_skipped;
    }
  }
  DepthRays rays;
  scanToRays(view, pose, last, s->scan_options, &rays);
  integrate(s, pose.translation(), rays.hits, rays.no_returns, msg->header.stamp);
}

void VoxelObstacleLayer::onLegacyCloud(Source* s, const sensor_msgs::PointCloudConstPtr& msg) {
  // costmap_2d converts too; the converted cloud then meets the same checks as a PointCloud2.
  sensor_msgs::PointCloud2 cloud;
  if (!sensor_msgs::convertPointCloudToPointCloud2(*msg, cloud)) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++s->received;
    }
    reject(s,
           "PointCloud conversion failed (a channel's value count differs from the point "
           "count?)");
    return;
  }
  onCloudMessage(s, cloud);
}

void VoxelObstacleLayer::onCloud(Source* s, const sensor_msgs::PointCloud2ConstPtr& msg) {
  onCloudMessage(s, *msg);
}

void VoxelObstacleLayer::onCloudMessage(Source* s, const sensor_msgs::PointCloud2& cloud) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++s->received;
  }
  const sensor_msgs::PointCloud2* msg = &cloud;
  std::size_t x_offset = 0;
  const std::string why = checkCloudLayout(*msg, &x_offset);
  if (!why.empty()) {
    reject(s, why);
    return;
  }
  Eigen::Isometry3d pose;
  if (!lookup(s, s->sensor_frame.empty() ? msg->header.frame_id : s->sensor_frame,
              msg->header.stamp, &pose)) {
    return;
  }
  const Eigen::Matrix3f r = pose.linear().cast<float>();
  const Eigen::Vector3f t = pose.translation().cast<float>();
  std::vector<float> hits;
  hits.reserve(static_cast<std::size_t>(msg->width) * msg->height * 3);
  forEachCloudPoint(*msg, x_offset, [&](float x, float y, float z) {
    const Eigen::Vector3f p = r * Eigen::Vector3f(x, y, z) + t;
    hits.insert(hits.end(), {p.x(), p.y(), p.z()});
  });
  integrate(s, pose.translation(), hits, {}, msg->header.stamp);
}

void VoxelObstacleLayer::integrate(Source* s, const Eigen::Vector3d& origin,
                                   std::vector<float>& hits, const std::vector<float>& no_returns,
                                   const ros::Time& stamp) {
  const std::size_t outside = dropOutsideHeightBand(&hits, s->min_z_m, s->max_z_m);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s->outside_band += outside;
  }
  runIntegration(s, stamp, [&] {
    return map_->integrate(origin, hits.data(), hits.size() / 3, no_returns.data(),
                           no_returns.size() / 3, stamp.toSec(), s->rays);
  });
}

void VoxelObstacleLayer::integrateFrustum(Source* s, const std::vector<float>& metres,
                                          const PinholeCamera& camera,
                                          const Eigen::Isometry3d& pose, const ros::Time& stamp) {
  runIntegration(s, stamp, [&] {
    return map_->integrateDepthFrustum(metres.data(), camera, pose, s->zero_is_no_return, s->stride,
                                       stamp.toSec(), s->rays);
  });
}

void VoxelObstacleLayer::runIntegration(Source* s, const ros::Time& stamp,
                                        const std::function<VoxelIntegrationStats()>& work) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!map_) return;
  const auto t0 = std::chrono::steady_clock::now();
  VoxelIntegrationStats stats;
  try {
    stats = work();
  } catch (const std::invalid_argument& e) {
    ++s->rejected;
    s->last_rejection = e.what();
    return;
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ++s->integrated;
  s->last = stats;
  s->integrate_ms.add(ms);
  dropped_updates_ += stats.dropped_updates;
  dirty_.expand(stats.touched);
  if (!stats.touched.empty()) layered_costmap_->notifyDataArrived(stamp);
}

void VoxelObstacleLayer::matchSize() {
  const GridGeometry& g = layered_costmap_->costmap().geometry();
  std::lock_guard<std::mutex> lock(mutex_);
  config_.resolution_m = g.resolution();
  try {
    auto map = std::make_unique<VoxelMap>(config_, g.latticeAnchorX(), g.latticeAnchorY(),
                                          g.sizeX(), g.sizeY());
    map->setWindow(static_cast<int>(g.latticeShiftX()), static_cast<int>(g.latticeShiftY()),
                   g.sizeX(), g.sizeY());
    map_ = std::move(map);
    config_errors_.clear("window");
  } catch (const std::invalid_argument& e) {
    map_.reset();
    config_errors_.set("window", std::string("no voxel map for this costmap: ") + e.what());
  }
  redraw_all_ = true;
  dirty_ = CellBounds();
}

void VoxelObstacleLayer::shiftOrigin(int dx, int dy) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!map_) return;
  try {
    map_->setWindow(map_->windowX0() + dx, map_->windowY0() + dy, map_->nx(), map_->ny());
  } catch (const std::invalid_argument& e) {
    config_errors_.set("window", std::string("rolling window: ") + e.what());
  }
  redraw_all_ = true;
}

void VoxelObstacleLayer::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (map_) map_->clear();
  redraw_all_ = true;
}

void VoxelObstacleLayer::onClockJump() {
  for (auto& s : sources_) {
    s->cloud_sub.clearWaiting();
    s->legacy_cloud_sub.clearWaiting();
    s->depth_sub.clearWaiting();
    s->scan_sub.clearWaiting();
  }
}

void VoxelObstacleLayer::clearFootprint(double robot_x, double robot_y, double robot_yaw,
                                        const ros::Time& now) {
  // costmap_2d frees the footprint's cells in its 2-D layer; here the band voxels of those
  // columns become free, so the cells stay free until something is seen there again, as there.
  // Caller holds mutex_.
  const GridGeometry& g = layered_costmap_->costmap().geometry();
  const Footprint world =
      transformFootprint(layered_costmap_->footprint(), Pose2D{robot_x, robot_y, robot_yaw});
  footprint_cells_.clear();
  polygonCells(world, g, &footprint_cells_);
  footprint_columns_.clear();
  for (const std::size_t i : footprint_cells_) {
    const CellIndex c = g.cellOf(i);
    footprint_columns_.emplace_back(c.x, c.y);
  }
  const VoxelIntegrationStats stats = map_->clearColumns(footprint_columns_, now.toSec());
  footprint_voxels_cleared_ += stats.cleared;
  dropped_updates_ += stats.dropped_updates;
  dirty_.expand(stats.touched);
}

void VoxelObstacleLayer::updateBounds(double robot_x, double robot_y, double robot_yaw,
                                      double* min_x, double* min_y, double* max_x, double* max_y) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!map_ || !enabled_) return;
  const ros::Time now = ros::Time::now();
  if (footprint_clearing_enabled_ && layered_costmap_->hasRobotPose()) {
    clearFootprint(robot_x, robot_y, robot_yaw, now);
  }
  if (config_.decay_time_s > 0.0) {
    redraw_all_ = true;  // every column may change with time
    if (last_prune_.isZero() || (now - last_prune_).toSec() >= prune_period_s_) {
      map_->prune(now.toSec());
      last_prune_ = now;
    }
  }
  CellBounds box = dirty_;
  if (redraw_all_) box = CellBounds{0, 0, map_->nx() - 1, map_->ny() - 1};
  if (box.empty()) return;
  const double res = config_.resolution_m;
  *min_x = std::min(*min_x, map_->windowOriginX() + box.min_x * res);
  *min_y = std::min(*min_y, map_->windowOriginY() + box.min_y * res);
  *max_x = std::max(*max_x, map_->windowOriginX() + (box.max_x + 1) * res);
  *max_y = std::max(*max_y, map_->windowOriginY() + (box.max_y + 1) * res);
}

void VoxelObstacleLayer::updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!map_ || !enabled_) return;
  const ros::Time now = ros::Time::now();
  map_->project(now.toSec(), &projection_);
  redraw_all_ = false;
  dirty_ = CellBounds();
  const GridGeometry& g = master.geometry();
  const int nx = std::min(map_->nx(), g.sizeX());
  const int ny = std::min(map_->ny(), g.sizeY());
  lethal_columns_ = 0;
  for (int j = std::max(0, min_j); j < std::min(max_j, ny); ++j) {
    for (int i = std::max(0, min_i); i < std::min(max_i, nx); ++i) {
      std::uint8_t c = projection_[static_cast<std::size_t>(j) * map_->nx() + i];
      if (c == cost::kNoInformation && !track_unknown_space_) c = cost::kFreeSpace;
      lethal_columns_ += c == cost::kLethalObstacle;
      if (combination_method_ == 0) {
        master.setCost(i, j, c);
      } else if (c != cost::kNoInformation) {
        // costmap_2d's updateWithMax: the larger cost wins, and any known cost replaces unknown.
        const std::uint8_t old = master.cost(i, j);
        if (old == cost::kNoInformation || old < c) master.setCost(i, j, c);
      }
    }
  }
  if (publish_voxel_map_) publishVoxels(now);
}

void VoxelObstacleLayer::publishVoxels(const ros::Time& stamp) {
  const ros::WallTime wall = ros::WallTime::now();
  if (!last_voxel_cloud_.isZero() && (wall - last_voxel_cloud_).toSec() < kVoxelCloudPeriodS) {
    return;
  }
  last_voxel_cloud_ = wall;
  const std::vector<Eigen::Vector3f> centres = map_->occupiedCentres(stamp.toSec());
  sensor_msgs::PointCloud2 cloud;
  cloud.header.stamp = stamp;
  cloud.header.frame_id = layered_costmap_->globalFrame();
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(centres.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x");
  for (const auto& c : centres) {
    x[0] = c.x();
    x[1] = c.y();
    x[2] = c.z();
    ++x;
  }
  voxel_pub_.publish(cloud);
}

void VoxelObstacleLayer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (map_) {
    status.add("voxel blocks", map_->blocks());
    status.add("voxel blocks max (memory bound)", map_->maxBlocks());
    status.add("voxel memory (bytes)", map_->memoryBytes());
    status.add("window (voxels)", std::to_string(map_->nx()) + " x " + std::to_string(map_->ny()) +
                                      " x " + std::to_string(map_->nz()));
    status.add("height band (voxel layers)",
               std::to_string(map_->bandFirst()) + " .. " + std::to_string(map_->bandLast()));
  }
  status.add("updates dropped by the memory bound", dropped_updates_);
  status.add("lethal columns (last update)", lethal_columns_);
  status.add("footprint clearing", footprint_clearing_enabled_);
  status.add("voxels cleared under the footprint", footprint_voxels_cleared_);
  std::string stale;
  for (const auto& s : sources_) {
    const std::string p = "source '" + s->name + "' ";
    status.add(p + "received", s->received);
    status.add(p + "integrated", s->integrated);
    status.add(p + "refused", s->rejected);
    status.add(p + "points outside height band", s->outside_band);
    if (s->scan)
      status.add(p + "per-beam correction skipped (no tf at the last beam)", s->deskew_skipped);
    if (!s->last_rejection.empty()) status.add(p + "last refusal", s->last_rejection);
    status.add(p + "last rays", s->last.rays);
    status.add(p + "last voxels marked", s->last.marked);
    status.add(p + "last voxels cleared", s->last.cleared);
    status.add(p + "last voxel visits", s->last.voxels_walked);
    addTimingHistogram(status, p + "integration time", "ms", s->integrate_ms.histogram);
    if (s->integrated == 0 && stale.empty()) stale = "source '" + s->name + "' integrated nothing";
  }
  const std::vector<std::string> errors = config_errors_.all();
  addConfigErrors(status, errors);
  if (!errors.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, errors.front());
  } else if (sources_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no usable observation_sources");
  } else if (!stale.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, stale);
  } else if (dropped_updates_ > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "voxel updates dropped: max_memory_mib reached");
  } else if (!param_warnings_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, param_warnings_.front());
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "3-D voxel layer running");
  }
  addParamWarnings(status, param_warnings_);
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::VoxelObstacleLayer, downstream_perception::Layer)
