#include "downstream_perception/ros/tsdf/tsdf_ros.h"

#include <sensor_msgs/point_cloud2_iterator.h>

#include <malloc.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include "downstream_perception/core/tsdf/esdf_band.h"
#include "downstream_perception/core/tsdf/tsdf_health.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/message_checks.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/common/save_service.h"
#include "downstream_perception/ros/common/tf_failure.h"
#include "downstream_perception/ros/common/timing_diagnostics.h"
#include "downstream_perception/ros/tsdf/tsdf_params.h"
#include "downstream_perception/ros/tsdf/tsdf_slice_messages.h"

namespace downstream_perception {

template <class M>
void TsdfRos::attachTfFilter(FilteredSubscription<M>* filter,
                             void (TsdfRos::*on_ready)(const boost::shared_ptr<const M>&),
                             const std::string& what, int queue) {
  filter->attach(
      nh_, *tf_buffer_, world_frame_, queue, boost::bind(on_ready, this, boost::placeholders::_1),
      [this, what](const boost::shared_ptr<const M>& m,
                   tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        std::ostringstream detail;
        detail << what << " in '" << m->header.frame_id << "' at stamp " << m->header.stamp;
        rejected_.reject(tfFailureReason(reason), detail.str());
      });
}

TsdfRos::TsdfRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), diagnostics_(nh, pnh, pnh.getNamespace()) {
  config_errors_.setPrefix("tsdf");
  world_frame_ = "odom";
  readParam(pnh_, "world_frame", &world_frame_, &config_errors_);
  output_directory_ = readOutputDirectory(pnh_, &config_errors_);
  const TsdfNodeSettings settings = readTsdfNodeSettings(pnh_, &config_errors_);
  health_period_s_ = settings.health_period_s;
  // Images early for their CameraInfo wait as many as wait for tf.
  camera_infos_ = CameraInfoCache(static_cast<std::size_t>(settings.tf_queue_size));
  slice_ = settings.slice;
  slice_distance_max_m_ = settings.slice_distance_max_m;
  slice_window_ = settings.slice_window;
  map_ = std::make_unique<TsdfMap>(loadTsdfConfig(pnh_, &config_errors_));
  if (slice_distance_max_m_ > 0.0 && slice_distance_max_m_ < map_->voxelSize()) {
    // The band's ESDF needs a cap of a voxel at least (its nearest value is half a voxel).
    config_errors_.add("parameter ~slice_distance_max_m = " + toText(slice_distance_max_m_) +
                       " is below one voxel; using one voxel (" + toText(map_->voxelSize()) +
                       " m)");
    slice_distance_max_m_ = map_->voxelSize();
  }
  const OctomapSettings octomap = readOctomapSettings(pnh_, map_->config(), &config_errors_);
  if (settings.esdf_max_distance_m > 0.0) {
    EsdfConfig esdf;
    esdf.max_distance_m = settings.esdf_max_distance_m;
    const std::string why = esdf.validate(map_->voxelSize());
    if (why.empty()) {
      esdf_ = std::make_unique<EsdfRos>(pnh_, esdf, settings.esdf_slice_z_m, map_.get(), &mutex_);
    } else {
      config_errors_.add("parameter ~esdf_max_distance_m: " + why + "; no ESDF");
    }
  }
  if (octomap.enabled()) {  // ~octomap_resolution_m = 0 turns the OctoMap off
    octree_max_memory_bytes_ = octomap.octree.max_memory_bytes;
    octree_ = std::make_unique<OctreeWorker>(OccupancyOctree(octomap.octree),
                                             static_cast<std::size_t>(octomap.queue_size));
  }

  mesh_publisher_ = pnh_.advertise<visualization_msgs::MarkerArray>("mesh", 2);
  slice_publisher_ = pnh_.advertise<nav_msgs::OccupancyGrid>("slice", 1, true);
  if (slice_distance_max_m_ > 0.0) {
    slice_distance_publisher_ = pnh_.advertise<sensor_msgs::PointCloud2>("slice_distance", 1, true);
  }
  save_service_ = pnh_.advertiseService("save_mesh", &TsdfRos::saveMesh, this);
  if (octree_) {
    octomap_publisher_ = pnh_.advertise<sensor_msgs::PointCloud2>("octomap_occupied", 1, true);
    save_octomap_service_ = pnh_.advertiseService("save_octomap", &TsdfRos::saveOctomap, this);
  }
  clear_service_ = pnh_.advertiseService("clear", &TsdfRos::clear, this);
  diagnostics_.setHardwareID("tsdf " + world_frame_);
  diagnostics_.add("tsdf", this, &TsdfRos::diagnose);

  tf_buffer_ = std::make_shared<tf2_ros::Buffer>(ros::Duration(30.0));
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_);
  camera_info_subscriber_ = nh_.subscribe("depth/camera_info", 5, &TsdfRos::onCameraInfo, this);
  // Raw subscribers check each message first (a wrong encoding is reported at once instead of
  // waiting for tf) and pass it to a tf2 MessageFilter, which holds it until the transform to
  // the world frame at its stamp exists.
  attachTfFilter(&depth_filter_, &TsdfRos::onDepth, "depth image", settings.tf_queue_size);
  depth_subscriber_ = nh_.subscribe("depth/image", 5, &TsdfRos::onDepthRaw, this);
  attachTfFilter(&cloud_filter_, &TsdfRos::onCloud, "point cloud", settings.tf_queue_size);
  cloud_subscriber_ = nh_.subscribe("points", 5, &TsdfRos::onCloudRaw, this);
  mesh_timer_ =
      pnh_.createTimer(ros::Duration(1.0 / settings.mesh_rate_hz), &TsdfRos::publishMesh, this);
  // On the steady clock: a jump of the ROS clock must not hold up its own detection.
  clock_watch_ =
      nh_.createSteadyTimer(ros::WallDuration(kClockWatchPeriodS), &TsdfRos::watchClock, this);
  reconfigure_.start(pnh_, this, &TsdfRos::reconfigure);
  const TsdfConfig& c = map_->config();
  ROS_INFO(
      "tsdf: %.3f m voxels, truncation %.3f m, in '%s'; depth on %s, clouds on %s; files saved "
      "into %s",
      c.voxel_size_m, c.truncation(), world_frame_.c_str(),
      ros::names::resolve(nh_.getNamespace(), "depth/image").c_str(),
      ros::names::resolve(nh_.getNamespace(), "points").c_str(),
      output_directory_.directory().c_str());
}

TsdfRos::~TsdfRos() {
  clock_watch_.stop();
  reconfigure_.stop();
  mesh_timer_.stop();
  depth_subscriber_.shutdown();
  cloud_subscriber_.shutdown();
  depth_filter_.unsubscribe();
  cloud_filter_.unsubscribe();
}

void TsdfRos::watchClock(const ros::SteadyTimerEvent&) {
  if (clock_jump_.check(ros::Time::now(), "tsdf") == 0.0) return;
  // A looped bag or a restarted simulator: the messages waiting for tf wait for old-timeline
  // stamps, tf restarts as in the other components (clock_jump.h), and the health check and
  // the diagnostics updater would wait until the clock passed their old-timeline times. The
  // map itself does not age.
  depth_filter_.clearWaiting();
  cloud_filter_.clearWaiting();
  restartTf(*tf_buffer_, tf_listener_, nh_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    camera_infos_.clearWaiting();
    last_health_ = ros::Time();  // the health check's period restarts on the new timeline
  }
  diagnostics_.force_update();  // the updater, too, waits for its next (old-timeline) time
}

void TsdfRos::reconfigure(TsdfNodeletConfig& cfg, std::uint32_t) {
  if (!reconfigure_started_) {
    // The first call carries the parameter server's values, already read (and reported if
    // invalid) by the constructor: nothing to apply.
    reconfigure_started_ = true;
    return;
  }
  TsdfConfig next;
  TsdfSliceConfig slice;
  SliceWindow window;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    next = map_->config();
    slice = slice_;
    window = slice_window_;
  }
  next.max_weight = cfg.max_weight;
  next.behind_surface_dropoff = cfg.behind_surface_dropoff;
  next.behind_surface_dropoff_start_voxels = cfg.behind_surface_dropoff_start_voxels;
  next.confirm_depth_voxels = cfg.confirm_depth_voxels;
  next.confirm_depth_max_m = cfg.confirm_depth_max_m;
  next.unconfirmed_update_weight = cfg.unconfirmed_update_weight;
  next.far_free_guess_weight = cfg.far_free_guess_weight;
  next.incidence_window_radius_px = cfg.incidence_window_radius_px;
  next.edge_guard_rad = cfg.edge_guard_rad;
  next.edge_guard_near_side_only = cfg.edge_guard_near_side_only;
  next.edge_guard_grazing_voxels = cfg.edge_guard_grazing_voxels;
  next.edge_guard_rim_scale = cfg.edge_guard_rim_scale;
  next.grazing_reach_voxels = cfg.grazing_reach_voxels;
  next.grazing_reach_max_voxels = cfg.grazing_reach_max_voxels;
  next.interpolate_depth = cfg.interpolate_depth;
  next.carve_free_space = cfg.carve_free_space;
  next.no_return_carve_min_valid_fraction = cfg.no_return_carve_min_valid_fraction;
  next.min_depth_m = cfg.min_depth_m;
  next.max_depth_m = cfg.max_depth_m;
  next.min_weight = cfg.min_weight;
  next.mesh_extrapolate_voxels = cfg.mesh_extrapolate_voxels;
  next.max_block_distance_m = cfg.max_block_distance_m;
  std::string why = setNamedTsdfSettings(cfg.weighting, cfg.edge_guard_rule, cfg.max_blocks, &next);
  TsdfSliceConfig next_slice = slice;
  next_slice.min_z_m = cfg.slice_min_z_m;
  next_slice.max_z_m = cfg.slice_max_z_m;
  const std::string slice_why = next_slice.validate();
  SliceWindow next_window = window;
  next_window.side_m = cfg.slice_window_m;
  // An int in dynamic_reconfigure: negative values are refused by validate() as 0 is.
  next_window.max_cells = static_cast<std::size_t>(std::max(0, cfg.slice_max_cells));
  const std::string window_why = next_window.validate();
  TsdfConfig now;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (why.empty()) why = map_->setConfig(next);
    if (slice_why.empty()) {
      slice_changed_ = slice_changed_ || next_slice.min_z_m != slice_.min_z_m ||
                       next_slice.max_z_m != slice_.max_z_m;
      slice_ = next_slice;
    }
    if (window_why.empty()) {
      slice_changed_ = slice_changed_ || next_window.side_m != slice_window_.side_m ||
                       next_window.max_cells != slice_window_.max_cells;
      slice_window_.side_m = next_window.side_m;
      slice_window_.max_cells = next_window.max_cells;
    }
    now = map_->config();
    slice = slice_;
    window = slice_window_;
  }
  if (!why.empty())
    config_errors_.add("live TSDF parameters refused (" + why + "); keeping the previous");
  if (octree_) octree_->setMaxDistance(now.max_block_distance_m);  // valid: the map took it
  if (why.empty() && !now.inertSettings().empty())
    ROS_WARN("tsdf: %s", now.inertSettings().c_str());
  if (!slice_why.empty()) {
    config_errors_.add("live slice band refused (" + slice_why + "); keeping [" +
                       toText(slice.min_z_m) + ", " + toText(slice.max_z_m) + "] m");
  }
  if (!window_why.empty()) {
    config_errors_.add("live slice window refused (" + window_why + "); keeping " +
                       toText(window.side_m) + " m, " + std::to_string(window.max_cells) +
                       " cells");
  }
  ROS_INFO(
      "tsdf: live settings: max weight %.1f, depth [%.2f, %.2f] m, slice [%.2f, %.2f] m, window "
      "%.2f m (0: whole map), at most %zu cells",
      now.max_weight, now.min_depth_m, now.max_depth_m, slice.min_z_m, slice.max_z_m, window.side_m,
      window.max_cells);
}

bool TsdfRos::lookup(const std_msgs::Header& header, Eigen::Isometry3d* T, std::string* why) {
  try {
    *T =
        toEigen(tf_buffer_->lookupTransform(world_frame_, header.frame_id, header.stamp).transform);
    return true;
  } catch (const tf2::TransformException& e) {
    *why = e.what();
    return false;
  }
}

void TsdfRos::onCameraInfo(const sensor_msgs::CameraInfoConstPtr& msg) {
  std::vector<sensor_msgs::ImageConstPtr> waited;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    waited = camera_infos_.update(*msg);
  }
  for (const auto& image : waited) acceptDepth(image);
}

void TsdfRos::account(const TsdfIntegrationStats& stats, double elapsed_ms) {
  if (stats.refused != nullptr) {  // counted as rejected, like the node's own checks
    rejected_.count(std::string("integrator: ") + stats.refused);
    ROS_WARN_THROTTLE(2.0, "tsdf: frame rejected: %s", stats.refused);
    return;
  }
  ++frames_integrated_;
  last_ = stats;
  pixels_invalid_ += stats.pixels_invalid;
  blocks_refused_ += stats.blocks_refused;
  blocks_evicted_ += stats.blocks_evicted;
  pixels_no_return_ignored_ += stats.pixels_no_return_ignored;
  integrate_ms_.add(elapsed_ms);
}

bool TsdfRos::cameraFor(const sensor_msgs::Image& image, PinholeCamera* camera, std::string* why) {
  std::lock_guard<std::mutex> lock(mutex_);
  const sensor_msgs::CameraInfo* info = camera_infos_.find(image.header.frame_id);
  if (info == nullptr) {
    *why = "no CameraInfo yet for frame '" + image.header.frame_id + "'";
    return false;
  }
  if (info->width != image.width || info->height != image.height) {
    *why = "image " + std::to_string(image.width) + "x" + std::to_string(image.height) +
           " but CameraInfo " + std::to_string(info->width) + "x" + std::to_string(info->height);
    return false;
  }
  const auto& K = info->K;
  *camera = PinholeCamera{
      K[0], K[4], K[2], K[5], static_cast<int>(image.width), static_cast<int>(image.height)};
  *why = camera->validate();
  return why->empty();
}

void TsdfRos::onDepthRaw(const sensor_msgs::ImageConstPtr& msg) {
  if (msg->header.stamp.isZero()) {
    rejected_.reject("bad message: zero stamp", "depth images must carry their measurement time");
    return;
  }
  std::string why;
  if (!checkDepthImage(*msg, &why)) {  // converted once, after tf, in onDepth()
    rejected_.reject("bad depth image", why);
    return;
  }
  sensor_msgs::ImageConstPtr dropped;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (camera_infos_.find(msg->header.frame_id) == nullptr) {
      dropped = camera_infos_.wait(msg);  // until its frame's first CameraInfo
      if (dropped == nullptr) return;
    }
  }
  if (dropped != nullptr) {
    rejected_.reject("camera_info missing or inconsistent",
                     "no CameraInfo for frame '" + dropped->header.frame_id + "' while " +
                         std::to_string(camera_infos_.maxWaiting()) + " images waited for one");
    return;
  }
  acceptDepth(msg);
}

void TsdfRos::acceptDepth(const sensor_msgs::ImageConstPtr& msg) {
  std::string why;
  PinholeCamera camera;
  if (!cameraFor(*msg, &camera, &why)) {
    rejected_.reject("camera_info missing or inconsistent", why);
  } else {
    depth_filter_.add(msg);
  }
}

void TsdfRos::onDepth(const sensor_msgs::ImageConstPtr& msg) {
  std::vector<float> metres;
  std::string why;
  PinholeCamera camera;
  Eigen::Isometry3d T_world_camera;
  // Checked on arrival already; the CameraInfo may have changed while waiting for tf.
  if (!depthImageToMetres(*msg, &metres, &why) || !cameraFor(*msg, &camera, &why)) {
    rejected_.reject("camera_info missing or inconsistent", why);
    return;
  }
  if (!lookup(msg->header, &T_world_camera, &why)) {
    rejected_.reject("tf: lookup at stamp failed", why);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto t0 = std::chrono::steady_clock::now();
    const TsdfIntegrationStats stats =
        integrator_.integrate(map_.get(), metres.data(), camera, T_world_camera);
    if (stats.refused == nullptr) setSensorLocked(T_world_camera);
    account(
        stats,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  // The same observation, as occupancy, inserted on the OctoMap's own thread.
  if (octree_) octree_->submitDepth(std::move(metres), camera, T_world_camera);
  diagnostics_.update();
}

void TsdfRos::onCloudRaw(const sensor_msgs::PointCloud2ConstPtr& msg) {
  if (msg->header.stamp.isZero()) {
    rejected_.reject("bad message: zero stamp", "point clouds must carry their measurement time");
    return;
  }
  const std::string why = checkCloudLayout(*msg);  // the layout every cloud consumer checks
  if (!why.empty()) {
    rejected_.reject("bad point cloud", why);
    return;
  }
  cloud_filter_.add(msg);
}

void TsdfRos::onCloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
  Eigen::Isometry3d T_world_sensor;
  std::string why;
  if (!lookup(msg->header, &T_world_sensor, &why)) {
    rejected_.reject("tf: lookup at stamp failed", why);
    return;
  }
  std::size_t x_offset = 0;
  if (!checkCloudLayout(*msg, &x_offset).empty()) return;  // checked on arrival (onCloudRaw)
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(msg->width) * msg->height);
  forEachCloudPoint(*msg, x_offset, [&](float x, float y, float z) {
    points.push_back(T_world_sensor * Eigen::Vector3d(x, y, z));  // NaN stays NaN: counted
  });
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto t0 = std::chrono::steady_clock::now();
    const TsdfIntegrationStats stats =
        integratePoints(map_.get(), points, T_world_sensor.translation());
    if (stats.refused == nullptr) setSensorLocked(T_world_sensor);
    account(
        stats,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  if (octree_) octree_->submitPoints(std::move(points), T_world_sensor.translation());
  diagnostics_.update();
}

void TsdfRos::publishMesh(const ros::TimerEvent&) {
  visualization_msgs::MarkerArray markers;
  nav_msgs::OccupancyGridPtr slice;
  sensor_msgs::PointCloud2Ptr occupied, esdf_slice, slice_distance;
  std_msgs::Header header;
  header.frame_id = world_frame_;
  header.stamp = ros::Time::now();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto t0 = std::chrono::steady_clock::now();
    mesher_.update(*map_);  // evicted blocks are reported by markers_.changed() too
    mesh_ms_.add(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    markers = markers_.changed(mesher_, header);
    if (!mesher_.lastUpdated().empty() || !markers.markers.empty() || slice_changed_) {
      sliceLocked(header, &slice, &slice_distance);
    }
    if (esdf_) esdf_slice = esdf_->sliceLocked(header);
    mesh_triangles_ = 0;
    for (const auto& kv : mesher_.blocks()) mesh_triangles_ += kv.second.triangleCount();
    // The health check walks the whole map (tens of ms): every health_period_s at most.
    const ros::Time now = ros::Time::now();
    if (health_period_s_ > 0.0 && !mesher_.lastUpdated().empty() &&
        (last_health_.isZero() || (now - last_health_).toSec() >= health_period_s_)) {
      health_ = tsdfHealth(*map_);
      last_health_ = now;
    }
  }
  // Outside mutex_: reading the OctoMap waits for an insertion under way, which must not hold
  // up the TSDF.
  if (octree_ && octree_->takeChanged()) occupied = occupiedCloud(header);
  if (!markers.markers.empty()) mesh_publisher_.publish(markers);
  if (slice) slice_publisher_.publish(slice);
  if (slice_distance) slice_distance_publisher_.publish(slice_distance);
  if (occupied) octomap_publisher_.publish(occupied);
  if (esdf_slice) esdf_->publish(esdf_slice);
  returnFreeMemory();
  diagnostics_.update();
}

void TsdfRos::returnFreeMemory() {
  // Depth frames, cloud points and OctoMap rays are allocated and freed in bursts on several
  // threads; glibc keeps what its per-thread arenas freed, so the process's RSS wanders a few
  // MB above what the maps hold (the soak measured the swing in the arenas alone). Handing the
  // free pages back every few seconds keeps RSS to what the bounded maps use.
  const auto now = std::chrono::steady_clock::now();
  if (now - last_trim_ < std::chrono::seconds(kTrimPeriodS)) return;
  last_trim_ = now;
  malloc_trim(0);
}

sensor_msgs::PointCloud2Ptr TsdfRos::occupiedCloud(const std_msgs::Header& header) {
  const std::vector<Eigen::Vector3d> centres =
      octree_->read([](const OccupancyOctree& tree) { return tree.occupiedCenters(); });
  sensor_msgs::PointCloud2Ptr cloud(new sensor_msgs::PointCloud2);
  cloud->header = header;
  sensor_msgs::PointCloud2Modifier modifier(*cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(centres.size());
  sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z");
  for (const Eigen::Vector3d& c : centres) {
    *x = static_cast<float>(c.x());
    *y = static_cast<float>(c.y());
    *z = static_cast<float>(c.z());
    ++x, ++y, ++z;
  }
  octree_occupied_ = centres.size();
  return cloud;
}

bool TsdfRos::saveOctomap(SaveMap::Request& request, SaveMap::Response& response) {
  return serveSave("tsdf", "save_octomap", output_directory_, ".bt", request, response,
                   [&](std::ostream& out, std::string* what) {
                     return octree_->read([&](const OccupancyOctree& tree) {
                       *what = std::to_string(tree.leafCount()) + " leaves";
                       return tree.writeBinary(out);
                     });
                   });
}

bool TsdfRos::saveMesh(SaveMap::Request& request, SaveMap::Response& response) {
  return serveSave("tsdf", "save_mesh", output_directory_, ".ply", request, response,
                   [&](std::ostream& out, std::string* what) {
                     // A mesher of its own: the published one's lastUpdated() feeds the
                     // markers and must not be consumed here.
                     TsdfMesher mesher;
                     {
                       std::lock_guard<std::mutex> lock(mutex_);
                       mesher.update(*map_);
                     }
                     const TriangleMesh mesh = mesher.combined();
                     mesh.writePly(out);
                     *what = std::to_string(mesh.vertices.size()) + " vertices, " +
                             std::to_string(mesh.triangleCount()) + " triangles";
                     return static_cast<bool>(out);
                   });
}

bool TsdfRos::clear(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  visualization_msgs::MarkerArray markers;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    map_->clear();
    mesher_.clear();
    std_msgs::Header header;
    header.frame_id = world_frame_;
    header.stamp = ros::Time::now();
    markers = markers_.clearAll(header);
  }
  if (octree_) octree_->clear();
  mesh_publisher_.publish(markers);
  ROS_INFO("tsdf: map cleared");
  return true;
}

}  // namespace downstream_perception
