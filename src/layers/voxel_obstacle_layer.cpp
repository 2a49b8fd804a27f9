// downstream_perception/VoxelObstacleLayer: the layer's parameters, its map over the costmap's
// window (resize, rolling shifts, reset), footprint clearing, the column projection into the
// master and diagnostics. Sources: voxel_obstacle_sources.cpp; messages:
// voxel_obstacle_messages.cpp.
#include "downstream_perception/layers/voxel_obstacle_layer.h"

#include <sensor_msgs/point_cloud2_iterator.h>
#include <pluginlib/class_list_macros.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "downstream_perception/core/costmap/footprint.h"
#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/common/timing_diagnostics.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"
#include "downstream_perception/ros/costmap/stvl_keys.h"

namespace downstream_perception {

namespace {
// The occupied-voxel cloud is published at most this often (it walks every block).
constexpr double kVoxelCloudPeriodS = 0.5;
}  // namespace

VoxelObstacleLayer::~VoxelObstacleLayer() {
  // Stop the callbacks before the map they write into goes away.
  reconfigure_.stop();
  sources_.clear();
}

void VoxelObstacleLayer::reconfigure(VoxelObstacleLayerConfig& cfg, std::uint32_t) {
  // A rejected value is written back into `cfg` (the server then shows the value in use); its
  // error stays in diagnostics until a valid value is set.
  VoxelMapConfig in_use;
  int combination_in_use = 1;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    in_use = config_;
    combination_in_use = combination_method_;
  }
  VoxelMapConfig want = in_use;
  want.origin_z_m = cfg.origin_z;
  want.z_resolution_m = cfg.z_resolution;
  want.z_voxels = cfg.z_voxels;
  want.unknown_threshold = cfg.unknown_threshold;
  want.mark_threshold = cfg.mark_threshold;
  want.min_obstacle_height_m = cfg.min_obstacle_height;
  want.max_obstacle_height_m = cfg.max_obstacle_height;
  want.decay_time_s = cfg.decay_time_s;
  const bool changed =
      want.origin_z_m != in_use.origin_z_m || want.z_resolution_m != in_use.z_resolution_m ||
      want.z_voxels != in_use.z_voxels || want.unknown_threshold != in_use.unknown_threshold ||
      want.mark_threshold != in_use.mark_threshold ||
      want.min_obstacle_height_m != in_use.min_obstacle_height_m ||
      want.max_obstacle_height_m != in_use.max_obstacle_height_m ||
      want.decay_time_s != in_use.decay_time_s;
  bool rebuild = false;
  if (changed) {
    const std::string why = want.validate();
    if (why.empty()) {
      config_errors_.clear("voxel map");
      rebuild = true;
    } else {
      config_errors_.set("voxel map", "voxel map invalid (" + why + "); keeping the previous one");
      cfg.origin_z = in_use.origin_z_m;
      cfg.z_resolution = in_use.z_resolution_m;
      cfg.z_voxels = in_use.z_voxels;
      cfg.unknown_threshold = in_use.unknown_threshold;
      cfg.mark_threshold = in_use.mark_threshold;
      cfg.min_obstacle_height = in_use.min_obstacle_height_m;
      cfg.max_obstacle_height = in_use.max_obstacle_height_m;
      cfg.decay_time_s = in_use.decay_time_s;
      want = in_use;
    }
  }
  if (cfg.combination_method != combination_in_use) {
    if (cfg.combination_method == 0 || cfg.combination_method == 1) {
      config_errors_.clear("combination_method");
    } else {
      config_errors_.set("combination_method",
                         "combination_method must be 0 (overwrite) or 1 (maximum), got " +
                             std::to_string(cfg.combination_method) + "; keeping " +
                             std::to_string(combination_in_use));
      cfg.combination_method = combination_in_use;
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    config_ = want;
    combination_method_ = cfg.combination_method;
    footprint_clearing_enabled_ = cfg.footprint_clearing_enabled;
    redraw_all_ = true;
  }
  // costmap_2d's VoxelLayer resets its grid on a change too (matchSize).
  if (rebuild) matchSize();
  const bool was_enabled = enabled_;
  enabled_ = cfg.enabled;
  if (enabled_) {
    activate();
  } else {
    deactivate();
  }
  if (was_enabled != enabled_ || rebuild) layered_costmap_->requestFullRedraw();
}

void VoxelObstacleLayer::onInitialize() {
  config_errors_.setPrefix("layer '" + name_ + "'");
  ParamReader reader(nh_, "layer '" + name_ + "'");
  track_unknown_space_ = layered_costmap_->isTrackingUnknown();
  reader.get("enabled", &enabled_);
  reader.get("track_unknown_space", &track_unknown_space_);
  // The dynamic_reconfigure keys (cfg/VoxelObstacleLayer.cfg) are type-checked here (the server
  // drops a wrong-typed value without a word) and applied by reconfigure(), called by the server
  // at start-up with the YAML's values and on every change.
  reader.get("combination_method", &combination_method_);
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
    config_errors_.set("voxel map", "voxel map invalid (" + why + "); using the defaults");
    const double resolution = c.resolution_m;
    c = VoxelMapConfig();
    c.resolution_m = resolution;
  }
  config_ = c;
  combination_method_ = 1;  // applied by reconfigure()
  // costmap_2d's layer-level keys read elsewhere: obstacle_range / raytrace_range are found from
  // each source upward (searchParam, readSource); transform_tolerance is validated only (the
  // MessageFilter waits for each message's own transform, as in costmap_2d in practice).
  reader.known({"obstacle_range", "raytrace_range"});
  // STVL's keys belong to this layer only where the costmap host adopted them (the layer's type
  // was STVL's, stvl_keys.h); in any other configuration they are unknown keys like any other.
  stvl_configuration_ = false;
  reader.get("stvl_configuration", &stvl_configuration_);
  if (stvl_configuration_) reader.known(stvlLayerKeys());
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
  // The layer's own warnings first; the sources' (readSource) follow. (An assignment here used
  // to drop the sources' warnings, among them their unknown keys, from the diagnostics.)
  const std::vector<std::string> layer_warnings = reader.warnings();
  param_warnings_.insert(param_warnings_.begin(), layer_warnings.begin(), layer_warnings.end());
  if (publish_voxel_map_) voxel_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("voxel_cloud", 1);
  matchSize();
  const bool enabled = enabled_;
  enabled_ = false;  // reconfigure() subscribes when it sees the layer enabled
  reconfigure_.start(nh_, this, &VoxelObstacleLayer::reconfigure);
  if (enabled && !enabled_) ROS_INFO("layer '%s': disabled by dynamic_reconfigure", name_.c_str());
  ROS_INFO(
      "layer '%s': 3-D voxels %.3f m x %.3f m, %d layers from %.2f m, band [%.2f, %.2f] m, "
      "mark_threshold %d, unknown_threshold %d, decay %.1f s, memory <= %.1f MiB, %zu source(s)",
      name_.c_str(), config_.resolution_m, config_.z_resolution_m, config_.z_voxels,
      config_.origin_z_m, config_.min_obstacle_height_m, config_.max_obstacle_height_m,
      config_.mark_threshold, config_.unknown_threshold, config_.decay_time_s,
      config_.max_memory_mib, sources_.size());
}
void VoxelObstacleLayer::matchSize() {
  const GridGeometry& g = layered_costmap_->costmap().geometry();
  std::lock_guard<std::mutex> lock(mutex_);
  if (g.sizeX() <= 0 || g.sizeY() <= 0) {
    // Not sized yet (costmap_2d initialises its layers before it sizes the master): no map and
    // no error until the master has cells.
    map_.reset();
    config_errors_.clear("window");
    return;
  }
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
    std::lock_guard<std::mutex> lock(mutex_);
    s->waiting_for_camera.clear();  // stamped before the jump
  }
}

std::string VoxelObstacleLayer::notCurrentReason() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return not_current_why_;
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
  not_current_why_ = staleSources();
  current_ = not_current_why_.empty();
  if (!current_) {
    ROS_WARN_THROTTLE(5.0, "layer '%s': %s", name_.c_str(), not_current_why_.c_str());
  }
  if (!map_ || !enabled_) return;
  const ros::Time now = ros::Time::now();
  // Every update cycle, as costmap_2d's VoxelLayer publishes its grid (rate-limited here).
  if (publish_voxel_map_) publishVoxels(now);
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
  // Only the update's bounds (a global costmap's window can hold millions of columns).
  map_->project(now.toSec(), CellBounds{min_i, min_j, max_i - 1, max_j - 1}, &projection_);
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
  status.add("lethal columns (last update's window)", lethal_columns_);
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
    if (s->depth) {
      status.add(p + "depth images waiting for their first CameraInfo",
                 s->waiting_for_camera.size());
    }
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
  } else if (!not_current_why_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "not current: " + not_current_why_);
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
