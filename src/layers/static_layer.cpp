#include "downstream_perception/layers/static_layer.h"

#include <tf2_ros/buffer.h>
#include <pluginlib/class_list_macros.hpp>

#include <algorithm>
#include <cmath>

#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

namespace {

CellBounds wholeGrid(const GridGeometry& g) {
  CellBounds all;
  all.expand(0, 0);
  all.expand(g.sizeX() - 1, g.sizeY() - 1);
  return all;
}

/// Grows the world box by the cells of `g` in `cells`, mapped by `global_from_map`.
void expandTransformed(const GridGeometry& g, const CellBounds& cells,
                       const Affine2D& global_from_map, double* min_x, double* min_y, double* max_x,
                       double* max_y) {
  const double x0 = g.originX() + cells.min_x * g.resolution();
  const double y0 = g.originY() + cells.min_y * g.resolution();
  const double x1 = g.originX() + (cells.max_x + 1) * g.resolution();
  const double y1 = g.originY() + (cells.max_y + 1) * g.resolution();
  const double xs[] = {x0, x1, x0, x1};
  const double ys[] = {y0, y0, y1, y1};
  for (int k = 0; k < 4; ++k) {
    double wx = 0.0, wy = 0.0;
    applyAffine(global_from_map, xs[k], ys[k], &wx, &wy);
    if (!std::isfinite(wx) || !std::isfinite(wy)) continue;
    *min_x = std::min(*min_x, wx);
    *min_y = std::min(*min_y, wy);
    *max_x = std::max(*max_x, wx);
    *max_y = std::max(*max_y, wy);
  }
}

}  // namespace

StaticLayer::~StaticLayer() {
  wait_timer_.stop();
  map_sub_.shutdown();
  update_sub_.shutdown();
  reconfigure_.stop();
}

void StaticLayer::readParameters() {
  ParamReader reader(nh_, "layer '" + name_ + "'");
  // costmap_2d's keys, defaults and meaning (static_layer.cpp reads them from the layer's
  // namespace, not upward).
  reader.get("map_topic", &map_topic_);
  reader.get("first_map_only", &first_map_only_);
  reader.get("subscribe_to_updates", &subscribe_to_updates_);
  reader.get("track_unknown_space", &config_.track_unknown_space);
  reader.get("use_maximum", &config_.use_maximum);
  reader.get("lethal_cost_threshold", &config_.lethal_cost_threshold);
  reader.get("unknown_cost_value", &config_.unknown_cost_value);
  reader.get("trinary_costmap", &config_.trinary_costmap);
  // Ours: the memory bound (one byte per cell here, one in the master).
  int max_cells = static_cast<int>(std::min<std::size_t>(config_.max_cells, 0x7fffffff));
  if (reader.get("max_cells", &max_cells)) {
    if (max_cells <= 0) {
      ROS_ERROR("layer '%s': parameter max_cells = %d must be > 0; using %zu", name_.c_str(),
                max_cells, config_.max_cells);
      param_warnings_.push_back("max_cells = " + std::to_string(max_cells) + " must be > 0");
    } else {
      config_.max_cells = static_cast<std::size_t>(max_cells);
    }
  }
  if (config_.lethal_cost_threshold != clampedLethalThreshold(config_.lethal_cost_threshold)) {
    ROS_WARN("layer '%s': lethal_cost_threshold %d clamped to %d (as costmap_2d does)",
             name_.c_str(), config_.lethal_cost_threshold,
             clampedLethalThreshold(config_.lethal_cost_threshold));
  }
  // The dynamic_reconfigure server reads (and writes back) "enabled".
  reader.known({"enabled"});
  reader.warnUnknown();
  for (const auto& w : reader.warnings()) param_warnings_.push_back(w);
}

void StaticLayer::onInitialize() {
  readParameters();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    map_ = StaticMap(config_);
  }
  current_ = false;  // until the first map (costmap_2d blocks here instead)
  resolved_topic_ = topic_nh_.resolveName(map_topic_);
  subscribe();
  reconfigure_.start(nh_, this, &StaticLayer::reconfigure);
  wait_timer_ =
      topic_nh_.createWallTimer(ros::WallDuration(kWaitWarnFirstS), &StaticLayer::waitWarn, this);
  const std::string updates = subscribe_to_updates_ ? " and " + resolved_topic_ + "_updates" : "";
  ROS_INFO(
      "layer '%s': static map from %s%s (track_unknown_space %s, use_maximum %s, "
      "lethal_cost_threshold %d, unknown_cost_value %d, trinary_costmap %s, max_cells %zu)",
      name_.c_str(), resolved_topic_.c_str(), updates.c_str(),
      config_.track_unknown_space ? "true" : "false", config_.use_maximum ? "true" : "false",
      clampedLethalThreshold(config_.lethal_cost_threshold), config_.unknown_cost_value,
      config_.trinary_costmap ? "true" : "false", config_.max_cells);
}

void StaticLayer::subscribe() {
  subscribed_at_ = ros::WallTime::now();
  // The host node's namespace, as costmap_2d's global NodeHandle: "map" is /map in move_base.
  map_sub_ = topic_nh_.subscribe(map_topic_, 1, &StaticLayer::onMap, this);
  if (subscribe_to_updates_) {
    update_sub_ = topic_nh_.subscribe(map_topic_ + "_updates", 10, &StaticLayer::onUpdate, this);
  }
}

void StaticLayer::reconfigure(StaticLayerConfig& cfg, std::uint32_t) {
  if (cfg.enabled != enabled_) {
    enabled_ = cfg.enabled;
    layered_costmap_->requestFullRedraw();  // the map appears or vanishes everywhere
  }
}

void StaticLayer::waitWarn(const ros::WallTimerEvent&) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (map_.hasMap()) {
    wait_timer_.stop();
    return;
  }
  const std::string refused = maps_refused_ > 0 ? ", " + std::to_string(maps_refused_) +
                                                      " map(s) refused, last: " + last_refusal_
                                                : "";
  ROS_WARN("layer '%s': no map on %s after %.0f s (%u publisher(s)%s)", name_.c_str(),
           resolved_topic_.c_str(), (ros::WallTime::now() - subscribed_at_).toSec(),
           map_sub_.getNumPublishers(), refused.c_str());
  wait_timer_.setPeriod(ros::WallDuration(kWaitWarnRepeatS));
}

std::string StaticLayer::mapFrameOf(const std::string& frame_id) const {
  std::string frame = frame_id;
  if (!frame.empty() && frame[0] == '/') frame.erase(0, 1);  // tf2 drops it too
  return frame.empty() ? layered_costmap_->globalFrame() : frame;
}

void StaticLayer::refuse(const std::string& what, const std::string& why) {
  last_refusal_ = what + ": " + why;
  ROS_ERROR("layer '%s': %s refused (%s)%s", name_.c_str(), what.c_str(), why.c_str(),
            map_.hasMap() ? "; keeping the previous map" : "");
}

void StaticLayer::onMap(const nav_msgs::OccupancyGridConstPtr& msg) {
  const auto& i = msg->info;
  StaticMapInfo info;
  info.width = i.width, info.height = i.height, info.resolution = i.resolution;
  info.origin_x = i.origin.position.x, info.origin_y = i.origin.position.y;
  info.origin_z = i.origin.position.z;
  info.qx = i.origin.orientation.x, info.qy = i.origin.orientation.y;
  info.qz = i.origin.orientation.z, info.qw = i.origin.orientation.w;
  info.data_size = msg->data.size();
  const std::string frame = mapFrameOf(msg->header.frame_id);
  const std::string& global_frame = layered_costmap_->globalFrame();
  const bool rolling = layered_costmap_->isRolling();
  GridGeometry geometry;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++maps_received_;
    std::string why;
    if (!rolling && frame != global_frame) {
      // The master would take the map's size and origin, which are coordinates in the map's
      // frame; drawing them in another frame needs a rolling window (transformed per update).
      why = "map in frame '" + frame + "' but the costmap's global_frame is '" + global_frame +
            "': set global_frame: " + frame + " (or rolling_window: true to transform it)";
    } else {
      why = map_.setMap(info, msg->data.data());
    }
    if (!why.empty()) {
      ++maps_refused_;
      last_map_refused_ = true;
      refuse("map", why);
      return;
    }
    last_map_refused_ = false;
    map_frame_ = frame;
    pending_.expand(map_.lastChange());
    geometry = map_.costs().geometry();
  }
  ROS_INFO("layer '%s': map %d x %d cells at %.3f m, origin (%.3f, %.3f) in '%s'", name_.c_str(),
           geometry.sizeX(), geometry.sizeY(), geometry.resolution(), geometry.originX(),
           geometry.originY(), frame.c_str());
  // As costmap_2d: a non-rolling costmap takes the map's size, resolution and origin, and keeps
  // them (size locked). Not under mutex_: the resize calls every layer's matchSize().
  if (!rolling) layered_costmap_->lockSizeTo(geometry);
  if (first_map_only_) {
    ROS_INFO("layer '%s': first_map_only: no more maps from %s", name_.c_str(),
             resolved_topic_.c_str());
    map_sub_.shutdown();
  }
}

void StaticLayer::onUpdate(const map_msgs::OccupancyGridUpdateConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++updates_received_;
  std::string why;
  const std::string frame = msg->header.frame_id;
  if (!frame.empty() && map_.hasMap() && mapFrameOf(frame) != map_frame_) {
    why = "update in frame '" + frame + "', map in '" + map_frame_ + "'";
  } else {
    why = map_.applyUpdate(msg->x, msg->y, msg->width, msg->height, msg->data.data(),
                           msg->data.size());
  }
  if (!why.empty()) {
    ++updates_refused_;
    refuse("update", why);
    return;
  }
  pending_.expand(map_.lastChange());
}

bool StaticLayer::lookUpTransform() {
  const std::string& global_frame = layered_costmap_->globalFrame();
  Affine2D t;
  if (map_frame_ != global_frame) {
    if (tf_ == nullptr) return false;
    try {
      // costmap_2d's lookup: map frame <- global frame, latest, applied to points at z = 0.
      const auto s = tf_->lookupTransform(map_frame_, global_frame, ros::Time(0));
      const Eigen::Matrix3d r = rotationOf(s.transform.rotation);
      t.xx = r(0, 0), t.xy = r(0, 1), t.yx = r(1, 0), t.yy = r(1, 1);
      t.tx = s.transform.translation.x, t.ty = s.transform.translation.y;
    } catch (const tf2::TransformException& e) {
      ++tf_failures_;
      last_tf_error_ = e.what();
      ROS_ERROR_THROTTLE(5.0, "layer '%s': no transform %s <- %s: %s", name_.c_str(),
                         map_frame_.c_str(), global_frame.c_str(), e.what());
      have_transform_ = false;
      return false;
    }
  }
  const bool changed = !have_transform_ || t.xx != map_from_global_.xx ||
                       t.xy != map_from_global_.xy || t.yx != map_from_global_.yx ||
                       t.yy != map_from_global_.yy || t.tx != map_from_global_.tx ||
                       t.ty != map_from_global_.ty;
  map_from_global_ = t;
  have_transform_ = true;
  last_tf_error_.clear();
  return changed;
}

void StaticLayer::updateBounds(double, double, double, double* min_x, double* min_y, double* max_x,
                               double* max_y) {
  std::lock_guard<std::mutex> lock(mutex_);
  current_ = map_.hasMap();
  if (!map_.hasMap() || !enabled_) return;
  const GridGeometry& g = map_.costs().geometry();
  if (!layered_costmap_->isRolling()) {
    // Same frame (checked on arrival): the whole map after a map, the window after an update.
    const CellBounds cells = redraw_all_ ? wholeGrid(g) : pending_;
    if (!cells.empty()) g.expandWorldBox(cells, min_x, min_y, max_x, max_y);
  } else {
    const bool moved = lookUpTransform();
    if (!have_transform_) return;  // pending_ is kept for when the transform is back
    const Affine2D global_from_map = invert(map_from_global_);
    if (redraw_all_ || moved) {
      expandTransformed(g, wholeGrid(g), global_from_map, min_x, min_y, max_x, max_y);
    } else if (!pending_.empty()) {
      expandTransformed(g, pending_, global_from_map, min_x, min_y, max_x, max_y);
    }
  }
  pending_ = CellBounds{};
  redraw_all_ = false;
}

void StaticLayer::updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!map_.hasMap() || !enabled_) return;
  const Costmap& layer = map_.costs();
  if (!layered_costmap_->isRolling()) {
    if (master.geometry() == layer.geometry()) {
      if (config_.use_maximum) {
        copyStaticMax(layer, &master, min_i, min_j, max_i, max_j);
      } else {
        copyStaticOverwrite(layer, &master, min_i, min_j, max_i, max_j);
      }
    } else {
      // The master is being resized to this map (lockSizeTo() runs on the map's thread): draw
      // by position meanwhile; the resize redraws everything.
      copyStaticSampled(layer, Affine2D(), config_.use_maximum, &master, min_i, min_j, max_i,
                        max_j);
    }
    return;
  }
  if (!have_transform_) return;
  copyStaticSampled(layer, map_from_global_, config_.use_maximum, &master, min_i, min_j, max_i,
                    max_j);
}

void StaticLayer::matchSize() {
  std::lock_guard<std::mutex> lock(mutex_);
  redraw_all_ = true;  // the map keeps its own geometry; the new master needs all of it
}

void StaticLayer::reset() {
  // costmap_2d re-runs onInitialize() (which waits for a map unless one is kept); the map is
  // kept here and drawn again, without waiting. The subscriptions stay as they are.
  std::lock_guard<std::mutex> lock(mutex_);
  redraw_all_ = true;
}

void StaticLayer::activate() {
  bool have_map = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    have_map = map_.hasMap();
    redraw_all_ = true;
  }
  if (!map_sub_ && !(first_map_only_ && have_map)) {
    subscribed_at_ = ros::WallTime::now();
    map_sub_ = topic_nh_.subscribe(map_topic_, 1, &StaticLayer::onMap, this);
  }
  if (subscribe_to_updates_ && !update_sub_) {
    update_sub_ = topic_nh_.subscribe(map_topic_ + "_updates", 10, &StaticLayer::onUpdate, this);
  }
}

void StaticLayer::deactivate() {
  map_sub_.shutdown();
  update_sub_.shutdown();
}

void StaticLayer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("map topic", resolved_topic_);
  if (subscribe_to_updates_) status.add("updates topic", resolved_topic_ + "_updates");
  status.add("map received", map_.hasMap() ? "yes" : "no");
  if (map_.hasMap()) {
    const GridGeometry& g = map_.costs().geometry();
    status.add("map size (cells)", toText(g.sizeX()) + " x " + toText(g.sizeY()));
    status.add("map resolution (m)", g.resolution());
    status.add("map origin (m)", "(" + toText(g.originX()) + ", " + toText(g.originY()) + ")");
    status.add("map frame", map_frame_);
  }
  status.add("maps received", maps_received_);
  status.add("maps refused", maps_refused_);
  status.add("updates received", updates_received_);
  status.add("updates refused", updates_refused_);
  if (!last_refusal_.empty()) status.add("last refusal", last_refusal_);
  const StaticCellCounts& c = map_.counts();
  status.add("lethal cells", c.lethal);
  status.add("unknown cells", c.unknown);
  status.add("free cells", c.free);
  status.add("scaled cells", c.other);
  if (layered_costmap_->isRolling()) status.add("transform failures", tf_failures_);
  addParamWarnings(status, param_warnings_);
  using diagnostic_msgs::DiagnosticStatus;
  if (!enabled_) {
    status.summary(DiagnosticStatus::OK, "disabled");
  } else if (!map_.hasMap()) {
    std::string msg = "waiting for map on " + resolved_topic_;
    if (maps_refused_ > 0) msg += " (" + last_refusal_ + ")";
    status.summary(DiagnosticStatus::WARN, msg);
  } else if (!last_tf_error_.empty()) {
    status.summary(DiagnosticStatus::WARN, "no transform for the map: " + last_tf_error_);
  } else if (last_map_refused_) {
    status.summary(DiagnosticStatus::WARN, "drawing the previous map; latest " + last_refusal_);
  } else {
    status.summary(DiagnosticStatus::OK, "drawing the static map");
  }
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::StaticLayer, downstream_perception::Layer)
