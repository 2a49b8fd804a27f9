#include "downstream_perception/layers/log_odds_obstacle_layer.h"

#include <pluginlib/class_list_macros.hpp>

#include <chrono>
#include <sstream>

#include "downstream_perception/core/log_odds_costs.h"
#include "downstream_perception/layered_costmap.h"

namespace downstream_perception {

LogOddsObstacleLayer::~LogOddsObstacleLayer() {
  // Stop the callbacks before the grid they write into goes away.
  sources_.clear();
}

void LogOddsObstacleLayer::onInitialize() {
  nh_.param("enabled", enabled_, true);
  const LogOddsConfig defaults;
  nh_.param("p_hit", grid_config_.p_hit, defaults.p_hit);
  nh_.param("p_miss", grid_config_.p_miss, defaults.p_miss);
  nh_.param("log_odds_min", grid_config_.clamp_min, defaults.clamp_min);
  nh_.param("log_odds_max", grid_config_.clamp_max, defaults.clamp_max);
  nh_.param("occupied_log_odds", grid_config_.occupied_threshold, defaults.occupied_threshold);
  nh_.param("free_log_odds", grid_config_.free_threshold, defaults.free_threshold);
  nh_.param("track_unknown_space", track_unknown_space_, layered_costmap_->isTrackingUnknown());
  const std::string why = grid_config_.validate();
  if (!why.empty()) {
    const std::string msg = "sensor model invalid (" + why + "); using the defaults";
    ROS_ERROR("layer '%s': %s", name_.c_str(), msg.c_str());
    config_errors_.push_back(msg);
    grid_config_ = defaults;
  }
  grid_ = LogOddsGrid(layered_costmap_->costmap().geometry(), grid_config_);
  readSources();
  if (enabled_) activate();
}

void LogOddsObstacleLayer::readSources() {
  std::string names;
  nh_.param("observation_sources", names, std::string());
  std::istringstream stream(names);
  std::string name;
  while (stream >> name) {
    ros::NodeHandle snh(nh_, name);
    LaserScanSourceConfig config;
    std::string data_type;
    snh.param("data_type", data_type, std::string("LaserScan"));
    if (data_type != "LaserScan") {
      const std::string msg = "source '" + name + "': data_type '" + data_type +
                              "' is not supported yet (only LaserScan); source ignored";
      ROS_ERROR("layer '%s': %s", name_.c_str(), msg.c_str());
      config_errors_.push_back(msg);
      continue;
    }
    snh.param("topic", config.topic, name);
    snh.param("sensor_frame", config.sensor_frame, std::string());
    snh.param("expected_update_rate", config.expected_update_rate, 0.0);
    snh.param("tf_queue_size", config.tf_queue_size, 20);
    ScanIntegratorConfig& ic = config.integrator;
    const ScanIntegratorConfig d;
    snh.param("marking", ic.marking, d.marking);
    snh.param("clearing", ic.clearing, d.clearing);
    snh.param("obstacle_min_range", ic.obstacle_min_range, d.obstacle_min_range);
    snh.param("obstacle_max_range", ic.obstacle_max_range, d.obstacle_max_range);
    snh.param("raytrace_min_range", ic.raytrace_min_range, d.raytrace_min_range);
    snh.param("raytrace_max_range", ic.raytrace_max_range, d.raytrace_max_range);
    snh.param("inf_is_valid", ic.inf_is_valid, d.inf_is_valid);
    snh.param("range_max_is_no_return", ic.range_max_is_no_return, d.range_max_is_no_return);
    std::string why = ic.validate();
    if (config.tf_queue_size < 1 || config.tf_queue_size > 10000) {
      why = "tf_queue_size must be in [1, 10000], got " + std::to_string(config.tf_queue_size);
    }
    if (!why.empty()) {
      const std::string msg = "source '" + name + "': " + why + "; source ignored";
      ROS_ERROR("layer '%s': %s", name_.c_str(), msg.c_str());
      config_errors_.push_back(msg);
      continue;
    }
    sources_.push_back(std::make_unique<LaserScanSource>(
        name, config, nh_, *tf_, layered_costmap_->globalFrame(),
        [this](LaserScanSource& source, const AcceptedScan& scan) {
          integrateScan(source, scan);
        }));
    ROS_INFO("layer '%s': source '%s' on %s (mark <= %.2f m, clear <= %.2f m, inf_is_valid %s)",
             name_.c_str(), name.c_str(),
             ros::names::resolve(nh_.getNamespace(), config.topic).c_str(), ic.obstacle_max_range,
             ic.raytrace_max_range, ic.inf_is_valid ? "true" : "false");
  }
  if (sources_.empty()) {
    ROS_WARN("layer '%s': no usable observation_sources; the layer will stay empty", name_.c_str());
  }
}

void LogOddsObstacleLayer::integrateScan(LaserScanSource& source, const AcceptedScan& scan) {
  const auto t0 = std::chrono::steady_clock::now();
  IntegrationStats stats;
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    stats = source.integrator().integrate(grid_, scan.view, scan.sensor_pose);
    // Only cells whose state changed alter this layer's output: that is the window the master
    // must refresh (a sensor sweeping an unchanged room costs no re-inflation downstream).
    dirty_.expand(stats.changed);
  }
  const auto t1 = std::chrono::steady_clock::now();
  const double age = (ros::Time::now() - scan.msg->header.stamp).toSec();
  source.recordIntegration(stats, std::chrono::duration<double, std::milli>(t1 - t0).count(), age);
}

void LogOddsObstacleLayer::updateBounds(double, double, double, double* min_x, double* min_y,
                                        double* max_x, double* max_y) {
  bool current = true;
  for (const auto& source : sources_) current = current && source->isCurrent();
  current_ = current;
  std::lock_guard<std::mutex> lock(grid_mutex_);
  grid_.geometry().expandWorldBox(dirty_, min_x, min_y, max_x, max_y);
  dirty_ = CellBounds{};
}

void LogOddsObstacleLayer::updateCosts(Costmap& master, int min_i, int min_j, int max_i,
                                       int max_j) {
  std::lock_guard<std::mutex> lock(grid_mutex_);
  if (grid_.geometry() != master.geometry()) return;  // matchSize() pending
  CellBounds window;
  window.expand(min_i, min_j);
  window.expand(max_i - 1, max_j - 1);
  // Unknown cells write nothing when tracking unknown space: costmap_2d's updateWithOverwrite
  // never writes NO_INFORMATION over what the master holds.
  writeStateCosts(grid_, window, !track_unknown_space_, cost::kFreeSpace, &master);
}

void LogOddsObstacleLayer::matchSize() {
  std::lock_guard<std::mutex> lock(grid_mutex_);
  const GridGeometry& g = layered_costmap_->costmap().geometry();
  if (grid_.geometry() != g) grid_.resize(g);
  dirty_ = CellBounds{};
  dirty_.expand(0, 0);
  dirty_.expand(g.sizeX() - 1, g.sizeY() - 1);
}

void LogOddsObstacleLayer::reset() {
  std::lock_guard<std::mutex> lock(grid_mutex_);
  grid_.reset();
  const GridGeometry& g = grid_.geometry();
  dirty_ = CellBounds{};
  dirty_.expand(0, 0);
  dirty_.expand(g.sizeX() - 1, g.sizeY() - 1);
}

void LogOddsObstacleLayer::activate() {
  for (auto& source : sources_) source->subscribe();
}

void LogOddsObstacleLayer::deactivate() {
  for (auto& source : sources_) source->unsubscribe();
}

void LogOddsObstacleLayer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::size_t n_free = 0;
  std::size_t n_occ = 0;
  std::size_t n_unknown = 0;
  double max_abs = 0.0;
  {
    std::lock_guard<std::mutex> lock(grid_mutex_);
    grid_.countStates(&n_free, &n_occ, &n_unknown);
    max_abs = grid_.maxAbsLogOdds();
  }
  std::size_t rejected_total = 0;
  bool all_current = true;
  bool any_integrated = sources_.empty();
  for (auto& source : sources_) {
    const bool current = source->isCurrent();
    all_current = all_current && current;
    std::lock_guard<std::mutex> lock(source->mutex());
    const auto& h = source->health();
    const std::string p = source->name() + ": ";
    any_integrated = any_integrated || h.integrated > 0;
    status.add(p + "scans received", h.received);
    status.add(p + "scans integrated", h.integrated);
    std::size_t rejected = 0;
    for (const auto& [reason, count] : h.rejected) {
      status.add(p + "rejected (" + reason + ")", count);
      rejected += count;
    }
    rejected_total += rejected;
    status.add(p + "scans rejected", rejected);
    status.add(p + "transform age at integration mean (s)", h.transform_age_s.mean());
    status.add(p + "transform age at integration max (s)", h.transform_age_s.max);
    status.add(p + "integration time mean (ms)", h.integrate_ms.mean());
    status.add(p + "integration time max (ms)", h.integrate_ms.max);
    status.add(p + "last scan cells cleared", h.last.cells_cleared);
    status.add(p + "last scan cells marked", h.last.cells_marked);
    status.add(p + "clear:mark ratio (last scan)", h.last.clearMarkRatio());
    status.add(p + "clear:mark ratio (all scans)", h.total.clearMarkRatio());
    status.add(p + "beams invalid (total)", h.total.beams_invalid);
    status.add(p + "beams no return (total)", h.total.beams_no_return);
    status.add(p + "current", current);
  }
  status.add("cells occupied", n_occ);
  status.add("cells free", n_free);
  status.add("cells unknown", n_unknown);
  status.add("max |log-odds|", max_abs);
  status.add("log-odds clamp", grid_config_.clamp_max);
  status.add("memory (bytes)", grid_.memoryBytes());
  status.add("config errors", config_errors_.size());
  if (!config_errors_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, config_errors_.front());
  } else if (!all_current) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "a source is not current");
  } else if (!any_integrated) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no scan integrated yet");
  } else if (rejected_total > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::to_string(rejected_total) + " scan(s) rejected (see counts)");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "integrating");
  }
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::LogOddsObstacleLayer, downstream_perception::Layer)
