#include "downstream_perception/layers/inflation_layer.h"

#include <pluginlib/class_list_macros.hpp>

#include <chrono>
#include <cmath>
#include <limits>

#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

void InflationLayer::onInitialize() {
  ParamReader params(nh_, "layer '" + name_ + "'");
  params.reconfigureKeys<InflationLayerConfig>();
  params.warnUnknown();
  param_warnings_ = params.warnings();
  // The server reads the YAML values (or the .cfg defaults, equal to InflationConfig's) and calls
  // reconfigure() at once: one code path for start-up and live changes.
  reconfigure_.start(nh_, this, &InflationLayer::reconfigure);
}

void InflationLayer::reconfigure(InflationLayerConfig& cfg, std::uint32_t) {
  config_errors_.setPrefix("layer '" + name_ + "'");
  InflationConfig candidate;
  bool changed = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    candidate = config_;
    candidate.inflation_radius = cfg.inflation_radius;
    candidate.cost_scaling_factor = cfg.cost_scaling_factor;
    candidate.inflate_unknown = cfg.inflate_unknown;
    changed = !inflator_ || candidate.inflation_radius != config_.inflation_radius ||
              candidate.cost_scaling_factor != config_.cost_scaling_factor ||
              candidate.inflate_unknown != config_.inflate_unknown;
  }
  // Unchanged values are not validated again: a kept error stays until a request fixes it.
  if (changed && !applyConfig(candidate, "parameters")) {
    // The server stores and publishes what the callback leaves in `cfg`: the values in use, so
    // a later change of another key does not send the rejected ones again.
    std::lock_guard<std::mutex> lock(mutex_);
    cfg.inflation_radius = config_.inflation_radius;
    cfg.cost_scaling_factor = config_.cost_scaling_factor;
    cfg.inflate_unknown = config_.inflate_unknown;
  }
  if (cfg.enabled != enabled_) {
    enabled_ = cfg.enabled;
    layered_costmap_->requestFullRedraw();  // its costs appear or vanish everywhere
  }
}

bool InflationLayer::applyConfig(InflationConfig candidate, const std::string& error_key) {
  std::lock_guard<std::mutex> lock(mutex_);
  candidate.inscribed_radius = layered_costmap_->inscribedRadius();
  const double map_resolution = layered_costmap_->costmap().geometry().resolution();
  const double resolution = map_resolution > 0.0 ? map_resolution : 0.05;
  const std::string why = candidate.validate(resolution);
  const bool accepted = why.empty();
  if (accepted) {
    config_errors_.clear(error_key);
  } else {
    std::string msg = "parameters invalid (" + why + "); keeping inflation_radius " +
                      std::to_string(config_.inflation_radius) + " m, cost_scaling_factor " +
                      std::to_string(config_.cost_scaling_factor) + " 1/m";
    candidate = config_;
    candidate.inscribed_radius = layered_costmap_->inscribedRadius();
    if (!candidate.validate(resolution).empty()) {
      // The kept radius does not fit this resolution either (the costmap became finer): the
      // largest radius that does, rather than no inflation at all.
      candidate.inflation_radius = InflationConfig::kMaxRadiusCells * resolution;
      msg += " capped to " + std::to_string(candidate.inflation_radius) + " m (" +
             std::to_string(InflationConfig::kMaxRadiusCells) + " cells)";
    }
    config_errors_.set(error_key, msg);
  }
  // Allowed (costmap_2d accepts it) but the robot would touch walls the planner thinks clear.
  // Once per pair of radii: the config is applied again on every resize and footprint update.
  std::string small_radius;
  if (candidate.inflation_radius < candidate.inscribed_radius) {
    small_radius = "inflation_radius " + toText(candidate.inflation_radius) +
                   " m is smaller than the footprint's inscribed radius " +
                   toText(candidate.inscribed_radius) + " m";
  }
  if (!small_radius.empty() && small_radius != small_radius_note_) {
    ROS_WARN("layer '%s': %s", name_.c_str(), small_radius.c_str());
  }
  small_radius_note_ = small_radius;
  config_ = candidate;
  inflator_ = std::make_unique<Inflator>(config_, resolution);
  need_full_window_ = true;
  noteRadiusDifference(resolution);
  ROS_INFO(
      "layer '%s': inflation radius %.3f m (%d cells), cost_scaling_factor %.2f 1/m, "
      "inscribed radius %.3f m",
      name_.c_str(), config_.inflation_radius, inflator_->radiusCells(),
      config_.cost_scaling_factor, config_.inscribed_radius);
  return accepted;
}

void InflationLayer::noteRadiusDifference(double resolution) {
  // costmap_2d inflates every cell within ceil(inflation_radius / resolution) cells; we inflate
  // within the radius itself. They differ only when the radius is not a whole number of cells.
  const double cells = config_.inflation_radius / resolution;
  const double theirs = std::ceil(cells * (1.0 - 1e-6));
  std::string note;
  if (theirs > inflator_->radiusCells()) {
    note = "inflation_radius " + toText(config_.inflation_radius) + " m is " + toText(cells) +
           " cells of " + toText(resolution) +
           " m: costmap_2d inflates to ceil = " + toText(theirs) + " cells (" +
           toText(theirs * resolution) + " m), this layer to the radius itself (" +
           toText(inflator_->radiusCells()) + " whole cells)";
  }
  const double tie_cells = inscribedTieCells(config_, resolution);
  if (tie_cells > 0.0) {
    note += std::string(note.empty() ? "" : "; ") + "cells exactly at the inscribed radius " +
            toText(config_.inscribed_radius) + " m (" + toText(tie_cells) +
            " cells) cost 253 (inscribed) here, where costmap_2d's double comparison puts them "
            "just outside it (251 or 252)";
  }
  if (!note.empty() && note != radius_note_)
    ROS_WARN("layer '%s': %s", name_.c_str(), note.c_str());
  radius_note_ = note;
}

void InflationLayer::updateBounds(double, double, double, double* min_x, double* min_y,
                                  double* max_x, double* max_y) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!inflator_) return;
  if (need_full_window_) {
    const GridGeometry& g = layered_costmap_->costmap().geometry();
    CellBounds all;
    all.expand(0, 0);
    all.expand(g.sizeX() - 1, g.sizeY() - 1);
    g.expandWorldBox(all, min_x, min_y, max_x, max_y);
    need_full_window_ = false;
    return;
  }
  if (*min_x > *max_x) return;  // nothing changed upstream: nothing to re-inflate
  // A lethal cell that appeared or vanished changes costs up to the radius around it.
  const double r = config_.inflation_radius;
  *min_x -= r;
  *min_y -= r;
  *max_x += r;
  *max_y += r;
}

void InflationLayer::updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!inflator_ || min_i >= max_i || min_j >= max_j) return;
  const auto t0 = std::chrono::steady_clock::now();
  CellBounds window;
  window.expand(min_i, min_j);
  window.expand(max_i - 1, max_j - 1);
  last_ = inflator_->update(&master, window);
  update_ms_.add(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  ++updates_;
}

void InflationLayer::matchSize() {
  // The Inflator follows the master's geometry by itself; a new resolution needs a new table.
  if (inflator_) applyConfig(config_, "resolution");
}

void InflationLayer::shiftOrigin(int dx, int dy) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (inflator_) inflator_->shift(dx, dy);
}

void InflationLayer::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!inflator_) return;
  inflator_->reset();
  need_full_window_ = true;
}

void InflationLayer::onFootprintChanged() {
  if (inflator_) applyConfig(config_, "footprint");
}

void InflationLayer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  status.summary(diagnostic_msgs::DiagnosticStatus::OK, "inflating");
  if (!param_warnings_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, param_warnings_.front());
  }
  addParamWarnings(status, param_warnings_);
  if (!radius_note_.empty()) status.add("difference from costmap_2d", radius_note_);
  status.add("inflation radius (m)", config_.inflation_radius);
  status.add("inflation radius (cells)", inflator_ ? inflator_->radiusCells() : 0);
  status.add("cost scaling factor (1/m)", config_.cost_scaling_factor);
  status.add("inscribed radius (m)", config_.inscribed_radius);
  status.add("inflate unknown", config_.inflate_unknown);
  status.add("updates", updates_);
  status.add("update time mean (ms)", update_ms_.mean());
  status.add("update time max (ms)", update_ms_.max);
  status.add("last update: lethal cells changed", last_.lethal_changed);
  status.add("last update: cells re-inflated", last_.cells_recomputed);
  status.add("last update: cells merged", last_.cells_merged);
  config_errors_.report(status);  // ERROR with the first problem, if any
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::InflationLayer, downstream_perception::Layer)
