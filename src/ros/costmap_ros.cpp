#include "downstream_perception/costmap_ros.h"

#include <geometry_msgs/PolygonStamped.h>

#include "downstream_perception/footprint_params.h"

#include <tf2/utils.h>

#include <chrono>
#include <sstream>

namespace downstream_perception {

namespace {
template <class T>
std::string str(const T& v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

CostmapRos::CostmapRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    // Named after this costmap, not the process: several nodelets share one manager.
    : nh_(nh), pnh_(pnh), diagnostics_(nh, pnh, pnh.getNamespace()) {
  readConfig();
  tf_buffer_ = std::make_shared<tf2_ros::Buffer>(ros::Duration(30.0));
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_);
  plugin_loader_ = std::make_unique<pluginlib::ClassLoader<Layer>>("downstream_perception",
                                                                   "downstream_perception::Layer");
  layered_costmap_ =
      std::make_unique<LayeredCostmap>(config_.global_frame, config_.track_unknown_space);

  const int size_x = static_cast<int>(std::lround(config_.width / config_.resolution));
  const int size_y = static_cast<int>(std::lround(config_.height / config_.resolution));
  layered_costmap_->resizeMap(
      GridGeometry(size_x, size_y, config_.resolution, config_.origin_x, config_.origin_y));

  layered_costmap_->setFootprint(readFootprint(pnh_, &config_errors_));

  diagnostics_.setHardwareID("costmap " + config_.global_frame);
  diagnostics_.add("costmap", this, &CostmapRos::diagnoseCostmap);
  loadPlugins();

  publisher_ = std::make_unique<CostmapPublisher>(pnh_, "costmap", config_.global_frame);
  publishFootprint();
  update_timer_ = nh_.createTimer(ros::Duration(1.0 / config_.update_frequency),
                                  &CostmapRos::updateTimerCallback, this);
  ROS_INFO(
      "costmap: %d x %d cells at %.3f m in '%s', origin (%.2f, %.2f), %zu layer(s), "
      "update %.1f Hz, publish %.1f Hz",
      size_x, size_y, config_.resolution, config_.global_frame.c_str(), config_.origin_x,
      config_.origin_y, layered_costmap_->plugins().size(), config_.update_frequency,
      config_.publish_frequency);
}

CostmapRos::~CostmapRos() {
  update_timer_.stop();
  // Layers hold subscriptions that call back into them: drop them before the loader goes.
  layered_costmap_.reset();
}

void CostmapRos::publishFootprint() {
  // Latched, in the robot frame: rviz draws it wherever the robot is.
  footprint_publisher_ = pnh_.advertise<geometry_msgs::PolygonStamped>("footprint", 1, true);
  geometry_msgs::PolygonStamped msg;
  msg.header.frame_id = config_.robot_base_frame;
  msg.header.stamp = ros::Time::now();
  for (const FootprintPoint& p : layered_costmap_->footprint()) {
    geometry_msgs::Point32 q;
    q.x = static_cast<float>(p.x);
    q.y = static_cast<float>(p.y);
    msg.polygon.points.push_back(q);
  }
  footprint_publisher_.publish(msg);
}

void CostmapRos::readConfig() {
  const CostmapRosConfig defaults;
  pnh_.param("global_frame", config_.global_frame, defaults.global_frame);
  pnh_.param("robot_base_frame", config_.robot_base_frame, defaults.robot_base_frame);
  pnh_.param("update_frequency", config_.update_frequency, defaults.update_frequency);
  pnh_.param("publish_frequency", config_.publish_frequency, defaults.publish_frequency);
  pnh_.param("width", config_.width, defaults.width);
  pnh_.param("height", config_.height, defaults.height);
  pnh_.param("resolution", config_.resolution, defaults.resolution);
  pnh_.param("origin_x", config_.origin_x, defaults.origin_x);
  pnh_.param("origin_y", config_.origin_y, defaults.origin_y);
  pnh_.param("transform_tolerance", config_.transform_tolerance, defaults.transform_tolerance);
  pnh_.param("track_unknown_space", config_.track_unknown_space, defaults.track_unknown_space);

  // Absurd values: say which parameter and what we use instead, keep running.
  const auto reject = [this](const std::string& name, const std::string& value,
                             const std::string& fallback) {
    const std::string msg = "parameter ~" + name + " = " + value + " is invalid; using " + fallback;
    ROS_ERROR("costmap: %s", msg.c_str());
    config_errors_.push_back(msg);
  };
  if (!std::isfinite(config_.update_frequency) || config_.update_frequency <= 0.0 ||
      config_.update_frequency > 1000.0) {
    reject("update_frequency", str(config_.update_frequency), str(defaults.update_frequency));
    config_.update_frequency = defaults.update_frequency;
  }
  if (!std::isfinite(config_.publish_frequency) || config_.publish_frequency < 0.0) {
    reject("publish_frequency", str(config_.publish_frequency), str(defaults.publish_frequency));
    config_.publish_frequency = defaults.publish_frequency;
  }
  if (!std::isfinite(config_.transform_tolerance) || config_.transform_tolerance <= 0.0) {
    reject("transform_tolerance", str(config_.transform_tolerance),
           str(defaults.transform_tolerance));
    config_.transform_tolerance = defaults.transform_tolerance;
  }
  const auto cells = [](double metres, double res) {
    return static_cast<int>(std::lround(std::min(metres / res, 1e9)));
  };
  const std::string why =
      (std::isfinite(config_.width) && std::isfinite(config_.height) && config_.resolution > 0.0)
          ? GridGeometry::validate(cells(config_.width, config_.resolution),
                                   cells(config_.height, config_.resolution), config_.resolution,
                                   config_.origin_x, config_.origin_y)
          : std::string("width/height/resolution must be finite and positive");
  if (!why.empty()) {
    reject("width/height/resolution/origin",
           str(config_.width) + " x " + str(config_.height) + " m at " + str(config_.resolution) +
               " m (" + why + ")",
           "the defaults");
    config_.width = defaults.width;
    config_.height = defaults.height;
    config_.resolution = defaults.resolution;
    config_.origin_x = defaults.origin_x;
    config_.origin_y = defaults.origin_y;
  }
}

void CostmapRos::loadPlugins() {
  XmlRpc::XmlRpcValue plugins;
  if (!pnh_.getParam("plugins", plugins)) {
    ROS_WARN("costmap: no ~plugins parameter; the costmap will stay at its default value");
    return;
  }
  if (plugins.getType() != XmlRpc::XmlRpcValue::TypeArray) {
    const std::string msg = "~plugins must be a list of {name, type}";
    ROS_ERROR("costmap: %s", msg.c_str());
    config_errors_.push_back(msg);
    return;
  }
  for (int k = 0; k < plugins.size(); ++k) {
    XmlRpc::XmlRpcValue& entry = plugins[k];
    if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct || !entry.hasMember("name") ||
        !entry.hasMember("type") || entry["name"].getType() != XmlRpc::XmlRpcValue::TypeString ||
        entry["type"].getType() != XmlRpc::XmlRpcValue::TypeString) {
      const std::string msg = "~plugins[" + std::to_string(k) + "] needs string 'name' and 'type'";
      ROS_ERROR("costmap: %s", msg.c_str());
      config_errors_.push_back(msg);
      continue;
    }
    const std::string name = static_cast<std::string>(entry["name"]);
    const std::string type = static_cast<std::string>(entry["type"]);
    try {
      std::shared_ptr<Layer> layer = plugin_loader_->createSharedInstance(type);
      layered_costmap_->addPlugin(layer);
      layer->initialize(layered_costmap_.get(), name, tf_buffer_.get(), pnh_);
      layer->matchSize();
      diagnostics_.add("layer " + name, [layer](diagnostic_updater::DiagnosticStatusWrapper& s) {
        layer->diagnose(s);
      });
      ROS_INFO("costmap: loaded layer '%s' (%s)", name.c_str(), type.c_str());
    } catch (const pluginlib::PluginlibException& e) {
      const std::string msg =
          "cannot load layer '" + name + "' of type '" + type + "': " + e.what();
      ROS_ERROR("costmap: %s", msg.c_str());
      config_errors_.push_back(msg);
    }
  }
}

bool CostmapRos::robotPose(double* x, double* y, double* yaw) {
  try {
    const auto t =
        tf_buffer_->lookupTransform(config_.global_frame, config_.robot_base_frame, ros::Time(0));
    // A chain of static transforms comes back with stamp 0: it is valid at every time.
    const double age = t.header.stamp.isZero() ? 0.0 : (ros::Time::now() - t.header.stamp).toSec();
    if (age > config_.transform_tolerance) {
      last_pose_error_ = "robot pose is " + str(age) + " s old (transform_tolerance " +
                         str(config_.transform_tolerance) + " s)";
      return false;
    }
    *x = t.transform.translation.x;
    *y = t.transform.translation.y;
    *yaw = tf2::getYaw(t.transform.rotation);
    return true;
  } catch (const tf2::TransformException& e) {
    last_pose_error_ = e.what();
    return false;
  }
}

void CostmapRos::updateTimerCallback(const ros::TimerEvent& event) {
  std::unique_lock<std::mutex> busy(update_mutex_, std::try_to_lock);
  if (!busy.owns_lock()) {
    ++updates_skipped_busy_;
    return;
  }
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
  if (!robotPose(&x, &y, &yaw)) {
    ++robot_pose_failures_;
    ROS_WARN_THROTTLE(5.0, "costmap: no robot pose %s <- %s: %s (updating without it)",
                      config_.global_frame.c_str(), config_.robot_base_frame.c_str(),
                      last_pose_error_.c_str());
  }
  const auto t0 = std::chrono::steady_clock::now();
  layered_costmap_->updateMap(x, y, yaw);
  const auto t1 = std::chrono::steady_clock::now();
  update_time_ms_.add(std::chrono::duration<double, std::milli>(t1 - t0).count());
  if (!last_update_.isZero()) update_period_s_.add((event.current_real - last_update_).toSec());
  last_update_ = event.current_real;
  ++updates_;

  const ros::Time now = ros::Time::now();
  if (config_.publish_frequency > 0.0 &&
      (last_publish_.isZero() ||
       (now - last_publish_).toSec() >= 1.0 / config_.publish_frequency)) {
    std::lock_guard<std::recursive_mutex> lock(layered_costmap_->mutex());
    publisher_->publish(layered_costmap_->costmap(), now);
    last_publish_ = now;
  }
  diagnostics_.update();
}

void CostmapRos::diagnoseCostmap(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const double achieved_hz = update_period_s_.mean() > 0.0 ? 1.0 / update_period_s_.mean() : 0.0;
  if (!config_errors_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, config_errors_.front());
  } else if (!layered_costmap_->isCurrent()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "a layer is not current");
  } else if (updates_ > 10 && achieved_hz < 0.8 * config_.update_frequency) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "update loop missed its rate");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "updating");
  }
  const GridGeometry& g = layered_costmap_->costmap().geometry();
  status.add("size (cells)", str(g.sizeX()) + " x " + str(g.sizeY()));
  status.add("resolution (m)", g.resolution());
  status.add("updates", updates_);
  status.add("update rate requested (Hz)", config_.update_frequency);
  status.add("update rate achieved (Hz)", achieved_hz);
  status.add("update time last (ms)", update_time_ms_.last);
  status.add("update time mean (ms)", update_time_ms_.mean());
  status.add("update time max (ms)", update_time_ms_.max);
  status.add("updates skipped (previous still running)", updates_skipped_busy_);
  status.add("robot pose failures", robot_pose_failures_);
  if (!last_pose_error_.empty()) status.add("last robot pose error", last_pose_error_);
  status.add("config errors", config_errors_.size());
  status.add("footprint inscribed radius (m)", layered_costmap_->inscribedRadius());
  status.add("footprint circumscribed radius (m)", layered_costmap_->circumscribedRadius());
}

}  // namespace downstream_perception
