// VoxelObstacleLayer's message handlers: each accepted message (PointCloud, PointCloud2,
// LaserScan, depth image) passes the shared message checks, is transformed at its own stamp and
// integrated into the voxel map under the layer's lock.
#include "downstream_perception/layers/voxel_obstacle_layer.h"

#include <sensor_msgs/point_cloud_conversion.h>

#include <chrono>
#include <functional>

#include "downstream_perception/core/voxel/depth_rays.h"
#include "downstream_perception/core/voxel/scan_rays.h"
#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/message_checks.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

void VoxelObstacleLayer::reject(Source* s, const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++s->rejected;
  s->last_rejection = why;
  ROS_WARN_THROTTLE(5.0, "layer '%s', source '%s': message refused: %s", name_.c_str(),
                    s->name.c_str(), why.c_str());
}

bool VoxelObstacleLayer::lookup(Source* s, const std::string& frame, const ros::Time& stamp,
                                Eigen::Isometry3d* pose) {
  if (stamp.isZero()) {
    // tf reads stamp 0 as "latest": exactly the mistake this layer exists to prevent.
    reject(s, "zero stamp: a message must carry its measurement time");
    return false;
  }
  std::string why;
  if (transformAt(frame, stamp, pose, &why)) return true;
  reject(s, why);
  return false;
}

bool VoxelObstacleLayer::lookupQuiet(const std::string& frame, const ros::Time& stamp,
                                     Eigen::Isometry3d* pose) {
  return transformAt(frame, stamp, pose, nullptr);
}

bool VoxelObstacleLayer::transformAt(const std::string& frame, const ros::Time& stamp,
                                     Eigen::Isometry3d* pose, std::string* why) {
  try {
    *pose = toEigen(tf_->lookupTransform(layered_costmap_->globalFrame(), frame, stamp).transform);
  } catch (const tf2::TransformException& e) {
    if (why) *why = std::string("tf: ") + e.what();
    return false;
  }
  if (pose->matrix().allFinite()) return true;  // a zero or NaN quaternion normalises to NaN
  if (why) *why = "transform from '" + frame + "' is not finite";
  return false;
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
  std::vector<sensor_msgs::ImageConstPtr> waited;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s->camera = cam;
    waited = s->waiting_for_camera.release();
  }
  for (const auto& image : waited) integrateDepth(s, image, cam);
}

void VoxelObstacleLayer::onDepth(Source* s, const sensor_msgs::ImageConstPtr& msg) {
  std::string why;
  const bool well_formed = checkDepthImage(*msg, &why);  // before it may be held
  std::optional<PinholeCamera> cam;
  sensor_msgs::ImageConstPtr pushed_out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++s->received;
    cam = s->camera;
    if (!cam && well_formed) {
      // The image overtook its first CameraInfo (two topics on two connections: nothing orders
      // them at start-up or in a bag replay). It waits, at most tf_queue_size of them.
      pushed_out = s->waiting_for_camera.hold(msg);
    }
  }
  if (!well_formed) {
    reject(s, "depth image: " + why);
  } else if (cam) {
    integrateDepth(s, msg, *cam);
  } else if (pushed_out) {
    reject(s, "no camera_info on " + s->camera_info_topic + " while " +
                  std::to_string(s->tf_queue_size) + " depth images waited for one");
  }
}

void VoxelObstacleLayer::integrateDepth(Source* s, const sensor_msgs::ImageConstPtr& msg,
                                        const PinholeCamera& cam) {
  if (static_cast<int>(msg->width) != cam.width || static_cast<int>(msg->height) != cam.height) {
    reject(s, "image " + std::to_string(msg->width) + " x " + std::to_string(msg->height) +
                  " does not match camera_info's " + std::to_string(cam.width) + " x " +
                  std::to_string(cam.height));
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
    integrateFrustum(s, metres, cam, pose, msg->header.stamp);
    return;
  }
  DepthRays rays;
  depthToRays(metres.data(), cam, pose, s->zero_is_no_return, s->stride, &rays);
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
  s->last_integrated = ros::WallTime::now();
  s->last = stats;
  s->integrate_ms.add(ms);
  dropped_updates_ += stats.dropped_updates;
  dirty_.expand(stats.touched);
  if (!stats.touched.empty()) layered_costmap_->notifyDataArrived(stamp);
}

}  // namespace downstream_perception
