#include "downstream_perception/ros/costmap/costmap_ros.h"

#include <geometry_msgs/PolygonStamped.h>

#include <chrono>
#include <cmath>
#include <sstream>

#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/timing_diagnostics.h"
#include "downstream_perception/ros/costmap/costmap_plugin_list.h"
#include "downstream_perception/ros/costmap/footprint_params.h"
#include "downstream_perception/ros/costmap/stvl_keys.h"

namespace downstream_perception {

CostmapRos::CostmapRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    // Named after this costmap, not the process: several nodelets share one manager.
    : nh_(nh), pnh_(pnh), diagnostics_(nh, pnh, pnh.getNamespace()) {
  ParamReader params(pnh_, "costmap");
  config_ = readCostmapConfig(params, &config_errors_);
  tf_buffer_ = std::make_shared<tf2_ros::Buffer>(ros::Duration(30.0));
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_);
  plugin_loader_ = std::make_unique<pluginlib::ClassLoader<Layer>>("downstream_perception",
                                                                   "downstream_perception::Layer");
  layered_costmap_ =
      std::make_unique<LayeredCostmap>(config_.global_frame, config_.track_unknown_space);
  layered_costmap_->setRollingWindow(config_.rolling_window);
  layered_costmap_->resizeMap(GridGeometry(config_.sizeXCells(), config_.sizeYCells(),
                                           config_.resolution, config_.origin_x, config_.origin_y));
  footprint_publisher_ = pnh_.advertise<geometry_msgs::PolygonStamped>("footprint", 1, true);
  applyFootprint();

  diagnostics_.setHardwareID("costmap " + config_.global_frame);
  diagnostics_.add("costmap", this, &CostmapRos::diagnoseCostmap);
  loadPlugins();
  auditKeys(params);

  publisher_ = std::make_unique<CostmapPublisher>(pnh_, "costmap", config_.global_frame,
                                                  config_.always_send_full_costmap);
  publisher_->setNewSubscriberSource([this](nav_msgs::OccupancyGrid* msg) {
    // Every new subscriber, whatever publish_frequency (costmap_2d answers each one this way).
    std::lock_guard<std::recursive_mutex> lock(layered_costmap_->mutex());
    CostmapPublisher::toMessage(layered_costmap_->costmap(), config_.global_frame, ros::Time::now(),
                                msg);
  });
  clear_service_ = pnh_.advertiseService("clear", &CostmapRos::clearService, this);
  update_timer_ = nh_.createTimer(ros::Duration(1.0 / config_.update_frequency),
                                  &CostmapRos::updateTimerCallback, this);
  if (config_.update_on_data) {
    data_trigger_.start(config_.update_on_data_max_rate_hz, [this] { onDataArrived(); });
  }
  // In both modes: how long integrated data waits to be published (diagnostics); the trigger
  // is a no-op unless started.
  layered_costmap_->setDataHandler([this](const ros::Time& stamp) {
    {
      std::lock_guard<std::mutex> lock(data_stamp_mutex_);
      if (oldest_unpublished_stamp_.isZero() || stamp < oldest_unpublished_stamp_) {
        oldest_unpublished_stamp_ = stamp;
      }
    }
    data_trigger_.notify();
  });
  // On the steady clock: a ROS-clock timer is what a jump of the ROS clock may hold up.
  clock_watch_ =
      nh_.createSteadyTimer(ros::WallDuration(kClockWatchPeriodS), &CostmapRos::watchClock, this);
  // Last: its first callback applies the YAML values again (a no-op) and from then on every
  // live change goes through reconfigure().
  reconfigure_.start(pnh_, this, &CostmapRos::reconfigure);
  const std::string on_data =
      config_.update_on_data
          ? " and on new data (at most " + toText(config_.update_on_data_max_rate_hz) + " Hz)"
          : "";
  ROS_INFO(
      "costmap: %d x %d cells at %.3f m in '%s', origin (%.2f, %.2f)%s, %zu layer(s), "
      "update %.1f Hz%s, publish %.1f Hz",
      config_.sizeXCells(), config_.sizeYCells(), config_.resolution, config_.global_frame.c_str(),
      config_.origin_x, config_.origin_y, config_.rolling_window ? " rolling with the robot" : "",
      layered_costmap_->plugins().size(), config_.update_frequency, on_data.c_str(),
      config_.publish_frequency);
}

CostmapRos::~CostmapRos() {
  // First: layers notify from their subscriber threads until they are destroyed.
  layered_costmap_->setDataHandler(nullptr);
  data_trigger_.stop();
  reconfigure_.stop();
  update_timer_.stop();
  clock_watch_.stop();
  // Layers hold subscriptions that call back into them: drop them before the loader goes.
  layered_costmap_.reset();
}

void CostmapRos::setErrors(const ConfigErrorLog& errors, const std::vector<std::string>& keys) {
  std::lock_guard<std::mutex> lock(errors_mutex_);
  for (const auto& key : keys) config_errors_.clearWithPrefix(key);
  config_errors_.merge(errors);
}

void CostmapRos::applyFootprint() {
  std::vector<std::string> errors;
  layered_costmap_->setFootprint(readFootprint(pnh_, &errors));
  ConfigErrorLog by_key;
  for (std::size_t k = 0; k < errors.size(); ++k) by_key.keep("footprint " + toText(k), errors[k]);
  setErrors(by_key, {"footprint "});
  // Latched, in the robot frame, stamp 0: the shape holds at every time, so rviz draws it
  // wherever the robot is now (a start-up stamp would predate the robot's first tf). Sent again
  // with every costmap publish: a viewer whose tf was not ready for the first one catches up.
  footprint_msg_ = geometry_msgs::PolygonStamped();
  footprint_msg_.header.frame_id = config_.robot_base_frame;
  for (const FootprintPoint& p : layered_costmap_->footprint()) {
    geometry_msgs::Point32 q;
    q.x = static_cast<float>(p.x);
    q.y = static_cast<float>(p.y);
    footprint_msg_.polygon.points.push_back(q);
  }
  footprint_publisher_.publish(footprint_msg_);
}

void CostmapRos::reconfigure(CostmapConfig& cfg, std::uint32_t) {
  if (!reconfigure_started_) {
    // The first call carries the parameter server's values, already read (and reported if
    // invalid) by readCostmapConfig(): nothing to apply.
    reconfigure_started_ = true;
    return;
  }
  CostmapRosConfig next = config_;
  next.update_frequency = cfg.update_frequency;
  next.publish_frequency = cfg.publish_frequency;
  next.transform_tolerance = cfg.transform_tolerance;
  next.width = cfg.width;
  next.height = cfg.height;
  next.resolution = cfg.resolution;
  if (!config_.rolling_window) {
    next.origin_x = cfg.origin_x;
    next.origin_y = cfg.origin_y;
  }
  next.always_send_full_costmap = cfg.always_send_full_costmap;
  ConfigErrorLog errors;
  validateCostmapConfig(&next, config_, &errors);
  setErrors(errors, {"update_frequency", "publish_frequency", "transform_tolerance",
                     "width/height/resolution/origin"});
  // A rejected value is reverted in the server too: the server applies what this callback
  // leaves in cfg, so rqt_reconfigure shows the value in use, not the refused one.
  cfg.update_frequency = next.update_frequency;
  cfg.publish_frequency = next.publish_frequency;
  cfg.transform_tolerance = next.transform_tolerance;
  cfg.width = next.width;
  cfg.height = next.height;
  cfg.resolution = next.resolution;
  cfg.origin_x = next.origin_x;
  cfg.origin_y = next.origin_y;

  std::lock_guard<std::mutex> busy(update_mutex_);  // no update while the map changes
  const bool resize = next.sizeXCells() != config_.sizeXCells() ||
                      next.sizeYCells() != config_.sizeYCells() ||
                      next.resolution != config_.resolution || next.origin_x != config_.origin_x ||
                      next.origin_y != config_.origin_y;
  if (resize && layered_costmap_->sizeLocked()) {
    // A static map fixed the geometry (costmap_2d's size_locked): the map's size wins.
    ROS_WARN(
        "costmap: width / height / resolution / origin not applied: the static map sets the "
        "costmap's size");
  } else if (resize) {
    std::lock_guard<std::recursive_mutex> lock(layered_costmap_->mutex());
    // A rolling window keeps its current (robot-centred) origin; the next update re-centres.
    const GridGeometry& g = layered_costmap_->costmap().geometry();
    const double ox = next.rolling_window ? g.originX() : next.origin_x;
    const double oy = next.rolling_window ? g.originY() : next.origin_y;
    layered_costmap_->resizeMap(
        GridGeometry(next.sizeXCells(), next.sizeYCells(), next.resolution, ox, oy));
    ROS_INFO("costmap: resized to %d x %d cells at %.3f m", next.sizeXCells(), next.sizeYCells(),
             next.resolution);
  }
  if (next.update_frequency != config_.update_frequency) {
    update_timer_.setPeriod(ros::Duration(1.0 / next.update_frequency));
  }
  if (publisher_) publisher_->setAlwaysSendFull(next.always_send_full_costmap);
  config_ = next;
  // The footprint's limits (readFootprint's): a refused value is reverted in the server.
  ConfigErrorLog footprint_errors("costmap");  // set() logs each
  if (!std::isfinite(cfg.robot_radius) || cfg.robot_radius < 0.0 || cfg.robot_radius > 100.0) {
    footprint_errors.set("robot_radius", "parameter ~robot_radius = " + toText(cfg.robot_radius) +
                                             " is invalid (0..100 m); keeping the previous value");
    pnh_.param("robot_radius", cfg.robot_radius, 0.46);
  }
  if (!std::isfinite(cfg.footprint_padding) || cfg.footprint_padding < 0.0 ||
      cfg.footprint_padding > 10.0) {
    footprint_errors.set("footprint_padding",
                         "parameter ~footprint_padding = " + toText(cfg.footprint_padding) +
                             " is invalid (0..10 m); keeping the previous value");
    pnh_.param("footprint_padding", cfg.footprint_padding, 0.01);
  }
  setErrors(footprint_errors, {"robot_radius", "footprint_padding"});
  // The footprint parameters are read back from the parameter server, so set them first.
  double radius = 0.0;
  double padding = 0.0;
  pnh_.param("robot_radius", radius, cfg.robot_radius);
  pnh_.param("footprint_padding", padding, cfg.footprint_padding);
  if (radius != cfg.robot_radius || padding != cfg.footprint_padding) {
    pnh_.setParam("robot_radius", cfg.robot_radius);
    pnh_.setParam("footprint_padding", cfg.footprint_padding);
    std::lock_guard<std::recursive_mutex> lock(layered_costmap_->mutex());
    applyFootprint();
    layered_costmap_->requestFullRedraw();
  }
}

void CostmapRos::loadPlugins() {
  std::vector<std::string> errors;
  const std::vector<LayerSpec> layers = readLayerList(pnh_, &errors, &param_warnings_);
  for (const LayerSpec& spec : layers) {
    std::string note;
    const std::string type = ourLayerType(spec.type, &note);
    if (!note.empty()) ROS_INFO("costmap: layer '%s': %s", spec.name.c_str(), note.c_str());
    if (spec.type == kStvlType) {
      ros::NodeHandle layer_nh(pnh_, spec.name);
      const std::vector<std::string> notes =
          adoptStvlKeys(layer_nh, config_.resolution, "costmap: layer '" + spec.name + "'");
      for (const auto& n : notes) param_warnings_.push_back("layer '" + spec.name + "': " + n);
    }
    try {
      std::shared_ptr<Layer> layer = plugin_loader_->createSharedInstance(type);
      layered_costmap_->addPlugin(layer);
      layer->initialize(layered_costmap_.get(), spec.name, tf_buffer_.get(), pnh_, nh_);
      layer->matchSize();
      diagnostics_.add(
          "layer " + spec.name,
          [layer](diagnostic_updater::DiagnosticStatusWrapper& s) { layer->diagnose(s); });
      layer_types_.push_back(spec.type);
      ROS_INFO("costmap: loaded layer '%s' (%s)", spec.name.c_str(), type.c_str());
    } catch (const pluginlib::PluginlibException& e) {
      errors.push_back("cannot load layer '" + spec.name + "' of type '" + spec.type + "'" +
                       (type != spec.type ? " (as " + type + ")" : std::string()) + ": " +
                       e.what());
      ROS_ERROR("costmap: %s", errors.back().c_str());
    }
  }
  ConfigErrorLog by_key;
  for (std::size_t k = 0; k < errors.size(); ++k) by_key.keep("plugins " + toText(k), errors[k]);
  setErrors(by_key, {});
}

void CostmapRos::auditKeys(ParamReader& params) {
  params.reconfigureKeys<CostmapConfig>();  // robot_radius, footprint_padding, ... type-checked
  params.known({"plugins", "static_map", "map_type", "footprint"});
  params.unsupported("footprint_topic",
                     "the footprint is read from ~footprint / robot_radius (also on "
                     "dynamic_reconfigure) and published on ~footprint; no footprint subscriber");
  params.unsupported("published_footprint_topic", "the footprint is published on ~footprint");
  for (const auto& layer : layered_costmap_->plugins()) params.known({layer->name()});
  for (const std::string& type : layer_types_) {
    params.known(keysCopiedIntoLayer(type));
    // costmap_2d's obstacle layers search these from each source upward (host level included).
    params.known({"obstacle_range", "raytrace_range"});
  }
  params.warnUnknown();
  param_warnings_.insert(param_warnings_.end(), params.warnings().begin(), params.warnings().end());
}

bool CostmapRos::clearService(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  std::lock_guard<std::recursive_mutex> lock(layered_costmap_->mutex());
  layered_costmap_->resetLayers();
  ++clears_;
  ROS_INFO("costmap: cleared every layer (~clear)");
  return true;
}

bool CostmapRos::robotPose(double* x, double* y, double* yaw) {
  try {
    const auto t =
        tf_buffer_->lookupTransform(config_.global_frame, config_.robot_base_frame, ros::Time(0));
    // A chain of static transforms comes back with stamp 0: it is valid at every time.
    const double age = t.header.stamp.isZero() ? 0.0 : (ros::Time::now() - t.header.stamp).toSec();
    if (age > config_.transform_tolerance) {
      last_pose_error_ = "robot pose is " + toText(age) + " s old (transform_tolerance " +
                         toText(config_.transform_tolerance) + " s)";
      return false;
    }
    *x = t.transform.translation.x;
    *y = t.transform.translation.y;
    *yaw = yawOf(t.transform.rotation);
    return true;
  } catch (const tf2::TransformException& e) {
    last_pose_error_ = e.what();
    return false;
  }
}

void CostmapRos::watchClock(const ros::SteadyTimerEvent&) {
  if (clock_jump_.check(ros::Time::now(), "costmap") == 0.0) return;
  {
    std::lock_guard<std::mutex> busy(update_mutex_);
    restartTf(*tf_buffer_, tf_listener_, nh_);
    layered_costmap_->onClockJump();
    last_publish_ = ros::Time();  // else nothing is published until the clock passes it again
    std::lock_guard<std::mutex> stamps(data_stamp_mutex_);
    oldest_unpublished_stamp_ = ros::Time();  // of the old timeline
  }
  diagnostics_.force_update();  // the updater, too, waits for its next (old-timeline) time
}

void CostmapRos::updateTimerCallback(const ros::TimerEvent& event) {
  std::unique_lock<std::mutex> busy(update_mutex_, std::try_to_lock);
  if (!busy.owns_lock()) {
    ++updates_skipped_busy_;
    return;
  }
  if (!last_update_.isZero()) update_period_s_.add((event.current_real - last_update_).toSec());
  last_update_ = event.current_real;
  updateAndPublish(false);
  diagnostics_.update();
}

void CostmapRos::onDataArrived() {
  // The trigger's thread; waits for a timer update that is running (it may hold new data).
  std::lock_guard<std::mutex> busy(update_mutex_);
  ++data_updates_;
  updateAndPublish(true);
}

void CostmapRos::updateAndPublish(bool on_data) {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
  const bool have_pose = robotPose(&x, &y, &yaw);
  if (!have_pose) {
    ++robot_pose_failures_;
    ROS_WARN_THROTTLE(5.0,
                      "costmap: no robot pose %s <- %s: %s (updating without it: no footprint "
                      "clearing, no rolling)",
                      config_.global_frame.c_str(), config_.robot_base_frame.c_str(),
                      last_pose_error_.c_str());
  }
  const auto t0 = std::chrono::steady_clock::now();
  unpublished_.expand(layered_costmap_->updateMap(x, y, yaw, have_pose));
  const auto t1 = std::chrono::steady_clock::now();
  update_time_ms_.add(std::chrono::duration<double, std::milli>(t1 - t0).count());
  ++updates_;

  // publish_frequency 0 means "never publish" (costmap_2d), in either mode. New data is
  // published at once when it changed the master (its rate is the trigger's limit); the timer
  // publishes at publish_frequency, as costmap_2d does.
  if (config_.publish_frequency <= 0.0) return;
  const ros::Time now = ros::Time::now();
  const bool due = on_data ? !unpublished_.empty() || last_publish_.isZero()
                           : last_publish_.isZero() ||
                                 (now - last_publish_).toSec() >= 1.0 / config_.publish_frequency;
  if (!due) return;
  std::lock_guard<std::recursive_mutex> lock(layered_costmap_->mutex());
  publisher_->publish(layered_costmap_->costmap(), now, unpublished_);
  unpublished_ = CellBounds{};
  last_publish_ = now;
  footprint_publisher_.publish(footprint_msg_);
  std::lock_guard<std::mutex> stamps(data_stamp_mutex_);
  if (!oldest_unpublished_stamp_.isZero()) {
    // The oldest data in this message: stamp -> handed to the publisher, in ms.
    const double ms = 1e3 * (ros::Time::now() - oldest_unpublished_stamp_).toSec();
    data_to_publish_ms_.add(ms);
    data_to_publish_max_ms_ = std::max(data_to_publish_max_ms_, ms);
    oldest_unpublished_stamp_ = ros::Time();
  }
}

void CostmapRos::diagnoseCostmap(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const double achieved_hz = update_period_s_.mean() > 0.0 ? 1.0 / update_period_s_.mean() : 0.0;
  std::vector<std::string> errors;
  {
    std::lock_guard<std::mutex> lock(errors_mutex_);
    errors = config_errors_.all();
  }
  std::string stale;
  for (const auto& layer : layered_costmap_->plugins()) {
    if (!layer->isEnabled() || layer->isCurrent()) continue;
    std::string why = layer->notCurrentReason();
    if (why.empty()) why = "layer '" + layer->name() + "' is not current";
    stale += (stale.empty() ? "" : "; ") + why;
  }
  if (!errors.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, errors.front());
  } else if (layered_costmap_->plugins().empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR,
                   "no layers: the costmap stays at its default value (set ~plugins)");
  } else if (!stale.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, stale);
  } else if (!param_warnings_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, param_warnings_.front());
  } else if (updates_ > 10 && achieved_hz < 0.8 * config_.update_frequency) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "update loop missed its rate");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "updating");
  }
  const GridGeometry& g = layered_costmap_->costmap().geometry();
  status.add("size (cells)", toText(g.sizeX()) + " x " + toText(g.sizeY()));
  status.add("resolution (m)", g.resolution());
  status.add("origin (m)", toText(g.originX()) + ", " + toText(g.originY()));
  status.add("rolling window", config_.rolling_window);
  status.add("updates", updates_);
  status.add("update rate requested (Hz)", config_.update_frequency);
  status.add("update rate achieved (Hz)", achieved_hz);
  status.add("update time last (ms)", update_time_ms_.last);
  status.add("update time mean (ms)", update_time_ms_.mean());
  status.add("update time max (ms)", update_time_ms_.max);
  addTimingHistogram(status, "update time", "ms", update_time_ms_.histogram);
  status.add("updates skipped (previous still running)", updates_skipped_busy_);
  status.add("update on data", config_.update_on_data);
  if (data_to_publish_ms_.total() > 0) {
    // Measured from each message's stamp (sensor time) to the costmap message handed to the
    // publisher, for the oldest data in each published message; last 200 publishes.
    status.add("data stamp to publish p50 (ms)", data_to_publish_ms_.percentile(0.5));
    status.add("data stamp to publish p99 (ms)", data_to_publish_ms_.percentile(0.99));
    status.add("data stamp to publish max (ms)", data_to_publish_max_ms_);
  }
  if (config_.update_on_data) {
    status.add("updates on data", data_updates_);
    status.add("data notifications (merged into those updates)", data_trigger_.notifications());
  }
  status.add("robot pose failures", robot_pose_failures_);
  if (!last_pose_error_.empty()) status.add("last robot pose error", last_pose_error_);
  status.add("full grids published", publisher_ ? publisher_->fullGridsPublished() : 0);
  status.add("updates published", publisher_ ? publisher_->updatesPublished() : 0);
  status.add("clears (~clear)", clears_);
  status.add("clock jumps back", clock_jump_.jumps());
  addConfigErrors(status, errors);
  addParamWarnings(status, param_warnings_);
  status.add("footprint inscribed radius (m)", layered_costmap_->inscribedRadius());
  status.add("footprint circumscribed radius (m)", layered_costmap_->circumscribedRadius());
}

}  // namespace downstream_perception
