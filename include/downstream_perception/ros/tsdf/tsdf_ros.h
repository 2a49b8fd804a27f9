// ROS host of the TSDF: depth images (+ CameraInfo) and/or point clouds in, each fused at its own
// stamp in a fixed world frame (a tf2 MessageFilter holds a message until its transform exists);
// the mesh out as per-block rviz markers and a height-band slice (OccupancyGrid, for the
// TsdfLayer and rviz) at ~mesh_rate_hz; services to save the mesh and clear
// the map; diagnostics; the settings that keep the voxel lattice live through
// dynamic_reconfigure. The nodelet and the node are thin shells around it.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include <Eigen/Geometry>

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/SaveMap.h"
#include "downstream_perception/TsdfNodeletConfig.h"
#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/core/tsdf/esdf_band.h"
#include "downstream_perception/core/tsdf/marching_cubes.h"
#include "downstream_perception/core/tsdf/octree_worker.h"
#include "downstream_perception/core/tsdf/tsdf_health.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "downstream_perception/ros/common/camera_info_cache.h"
#include "downstream_perception/ros/common/clock_jump.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/filtered_subscription.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/common/rejection_counter.h"
#include "downstream_perception/ros/common/save_service.h"
#include "downstream_perception/ros/tsdf/esdf_ros.h"
#include "downstream_perception/ros/tsdf/tsdf_mesh_markers.h"

namespace downstream_perception {

class TsdfRos {
 public:
  TsdfRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~TsdfRos();

 private:
  void onCameraInfo(const sensor_msgs::CameraInfoConstPtr& msg);
  void onDepthRaw(const sensor_msgs::ImageConstPtr& msg);  ///< checks, then waits for tf
  /// A checked image whose frame has a CameraInfo: checked against it, then waits for tf.
  void acceptDepth(const sensor_msgs::ImageConstPtr& msg);
  void onDepth(const sensor_msgs::ImageConstPtr& msg);  ///< tf available: integrates
  void onCloudRaw(const sensor_msgs::PointCloud2ConstPtr& msg);
  void onCloud(const sensor_msgs::PointCloud2ConstPtr& msg);
  /// The pinhole model for an image from the latest CameraInfo of its frame, or why not.
  bool cameraFor(const sensor_msgs::Image& image, PinholeCamera* camera, std::string* why);
  /// A MessageFilter into world_frame_ calling on_ready, and rejected_ counts the reason of a drop.
  template <class M>
  void attachTfFilter(FilteredSubscription<M>* filter,
                      void (TsdfRos::*on_ready)(const boost::shared_ptr<const M>&),
                      const std::string& what, int queue);
  bool lookup(const std_msgs::Header& header, Eigen::Isometry3d* T_world_sensor, std::string* why);
  void publishMesh(const ros::TimerEvent& event);
  /// On the steady clock: after a jump of the ROS clock back, drops the messages waiting for
  /// old-timeline transforms and restarts tf (clock_jump.h).
  void watchClock(const ros::SteadyTimerEvent& event);
  /// Under mutex_: the slice and, while someone listens, its clearance (the band's ESDF), over
  /// sliceGridLocked(); leaves both null and counts slices_refused_ when no grid can be made.
  void sliceLocked(const std_msgs::Header& header, nav_msgs::OccupancyGridPtr* slice,
                   sensor_msgs::PointCloud2Ptr* distance);
  /// Under mutex_: the slice's grid, the window of slice_window_ around the sensor's latest
  /// position (the blocks' middle before any frame) cut to the blocks; counts slices_capped_.
  GridGeometry sliceGridLocked();
  /// Under mutex_: the position the next slice is centred on (frames integrated from `T`).
  void setSensorLocked(const Eigen::Isometry3d& T_world_sensor);
  /// malloc_trim every kTrimPeriodS (on the mesh timer): freed memory goes back to the OS.
  void returnFreeMemory();
  static constexpr int kTrimPeriodS = 5;
  std::chrono::steady_clock::time_point last_trim_{};
  /// Centres of the OctoMap's occupied leaves as a PointCloud2 (x, y, z) for rviz.
  sensor_msgs::PointCloud2Ptr occupiedCloud(const std_msgs::Header& header);
  bool saveOctomap(SaveMap::Request& request, SaveMap::Response& response);
  bool saveMesh(SaveMap::Request& request, SaveMap::Response& response);
  bool clear(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// Under mutex_: the slice's window, cap, cuts, cells and bytes, and its clearance's.
  void addSliceSizeLocked(diagnostic_updater::DiagnosticStatusWrapper& status) const;
  void reconfigure(TsdfNodeletConfig& config, std::uint32_t level);
  void account(const TsdfIntegrationStats& stats, double elapsed_ms);

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  std::string world_frame_;
  std::mutex mutex_;  ///< guards the map, the mesher and the counters
  std::unique_ptr<TsdfMap> map_;
  std::unique_ptr<EsdfRos> esdf_;  ///< null with ~esdf_max_distance_m = 0; uses map_, mutex_
  DepthIntegrator integrator_;     ///< keeps the per-pixel buffers between frames
  TsdfMesher mesher_;
  TsdfMeshMarkers markers_;
  CameraInfoCache camera_infos_{0};  ///< latest per frame id; images early for theirs wait

  std::shared_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::Subscriber camera_info_subscriber_;
  ros::Subscriber depth_subscriber_;
  FilteredSubscription<sensor_msgs::Image> depth_filter_;
  ros::Subscriber cloud_subscriber_;
  FilteredSubscription<sensor_msgs::PointCloud2> cloud_filter_;
  ros::Publisher mesh_publisher_;
  ros::Publisher slice_publisher_;
  ros::Publisher slice_distance_publisher_;  ///< not advertised when slice_distance_max_m is 0
  ros::Publisher octomap_publisher_;
  ros::ServiceServer save_octomap_service_;
  /// Inserts into the OctoMap on its own thread; null when ~octomap_resolution_m is 0.
  std::unique_ptr<OctreeWorker> octree_;
  std::atomic<std::size_t> octree_occupied_{0};  ///< set by the publishing timer
  std::size_t octree_max_memory_bytes_ = 0;      ///< ~octomap_max_memory_mb
  TsdfSliceConfig slice_;
  bool slice_changed_ = false;         ///< the band moved: re-slice at the next mesh tick
  double slice_distance_max_m_ = 2.0;  ///< clearance cap of ~slice_distance (m); 0: off
  TsdfSliceStats slice_stats_;
  SliceWindow slice_window_;  ///< side (~slice_window_m) and cap (~slice_max_cells); centre below
  Eigen::Vector2d sensor_xy_ = Eigen::Vector2d::Zero();  ///< latest integrated frame's (world)
  bool sensor_known_ = false;
  // What the last slice held and cost, for diagnostics.
  std::size_t slice_cells_ = 0;
  EsdfBandStats slice_distance_stats_;
  double slice_ms_ = 0.0;  ///< the slice and its clearance, last tick
  ros::ServiceServer save_service_;
  OutputDirectory output_directory_{
      defaultOutputDirectory()};  ///< ~output_dir: services write here
  ros::ServiceServer clear_service_;
  ros::Timer mesh_timer_;
  ClockJumpDetector clock_jump_;
  ros::SteadyTimer clock_watch_;
  diagnostic_updater::Updater diagnostics_;

  // Diagnostics.
  std::size_t frames_integrated_ = 0;
  RejectionCounter rejected_{"tsdf: frame rejected"};
  TsdfIntegrationStats last_;
  std::size_t pixels_invalid_ = 0;
  std::size_t blocks_refused_ = 0;
  std::size_t slices_refused_ = 0;  ///< mesh ticks whose map extent fits no slice grid
  std::size_t slices_capped_ = 0;   ///< slices cut to ~slice_max_cells around the sensor
  /// The clearance computes at most this many columns per ~slice_max_cells (window and padding):
  /// 8 M columns, 72 MB of working memory, at the default cap.
  static constexpr std::size_t kClearanceColumnsPerSliceCell = 2;
  std::size_t clearance_padding_cuts_ = 0;  ///< clearances whose padding was narrowed to fit
  std::size_t blocks_evicted_ = 0;
  std::size_t pixels_no_return_ignored_ = 0;  ///< +Inf pixels carving refused to use (total)
  TimingStats integrate_ms_;
  RunningStats mesh_ms_;
  std::size_t mesh_triangles_ = 0;
  double health_period_s_ = 10.0;
  ros::Time last_health_;
  TsdfHealth health_;
  ConfigErrorLog config_errors_;

  ReconfigureHost<TsdfNodeletConfig> reconfigure_;
  bool reconfigure_started_ = false;
};

}  // namespace downstream_perception
