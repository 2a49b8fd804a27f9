// downstream_perception/VoxelObstacleLayer: a 3-D voxel obstacle layer with costmap_2d
// VoxelLayer's keys and meaning. PointCloud2, depth-image and LaserScan sources, each transformed
// at its own stamp (tf2 MessageFilter), mark and clear a sparse 3-D log-odds voxel map
// (core/voxel) over the costmap's window with exact 3-D ray traversal (or, per depth source,
// frustum clearing): a ray that passes under a table top does not erase it. Each column within
// the robot's height band is projected into the master with costmap_2d's rule (more than
// mark_threshold occupied voxels: lethal; at most unknown_threshold unknown voxels: known, so
// free). The occupied voxels can be published as a PointCloud2.
#pragma once

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud.h>
#include <sensor_msgs/PointCloud2.h>

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/VoxelObstacleLayerConfig.h"
#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/voxel/scan_rays.h"
#include "downstream_perception/core/voxel/voxel_map.h"
#include "downstream_perception/ros/common/camera_info_cache.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/filtered_subscription.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/costmap/layer.h"

namespace downstream_perception {

class VoxelObstacleLayer : public Layer {
 public:
  ~VoxelObstacleLayer() override;
  void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x, double* min_y,
                    double* max_x, double* max_y) override;
  void updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) override;
  void matchSize() override;
  void shiftOrigin(int dx, int dy) override;
  void reset() override;
  void activate() override;
  void deactivate() override;
  void onClockJump() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;
  std::string notCurrentReason() const override;

 protected:
  void onInitialize() override;

 private:
  /// One observation source (<layer ns>/<name>).
  struct Source {
    std::string name;
    std::string topic;
    std::string camera_info_topic;  ///< depth sources
    std::string sensor_frame;       ///< overrides the message's frame_id when set
    bool depth = false;             ///< DepthImage
    bool scan = false;              ///< LaserScan
    bool legacy_cloud = false;      ///< sensor_msgs/PointCloud (none of these: PointCloud2)
    /// costmap_2d's source band in the global frame, m (its defaults 0 and 2; DepthImage: none):
    /// points outside it neither mark nor clear.
    double min_z_m = 0.0;
    double max_z_m = 2.0;
    ScanRayOptions scan_options;  ///< LaserScan: +Inf and range_max readings
    /// LaserScan: each beam's end at its own time (time_increment), as costmap_2d projects.
    bool per_beam_time_correction = true;
    double tf_tolerance_s = 0.0;  ///< how long past the stamp the tf filter waits (the sweep)
    bool zero_is_no_return = false;
    bool frustum = false;  ///< clearing_mode frustum (depth sources)
    int stride = 1;
    int tf_queue_size = 20;
    VoxelRayConfig rays;
    FilteredSubscription<sensor_msgs::PointCloud2> cloud_sub;
    FilteredSubscription<sensor_msgs::PointCloud> legacy_cloud_sub;
    FilteredSubscription<sensor_msgs::Image> depth_sub;
    FilteredSubscription<sensor_msgs::LaserScan> scan_sub;
    ros::Subscriber info_sub;
    // Guarded by the layer's mutex_.
    std::optional<PinholeCamera> camera;
    /// Depth images that came before the first CameraInfo (at most tf_queue_size).
    WaitingImages waiting_for_camera;
    std::size_t received = 0;
    std::size_t integrated = 0;
    std::size_t rejected = 0;
    std::size_t outside_band = 0;  ///< points dropped by the source's height band
    std::size_t deskew_skipped = 0;
    double expected_update_rate_s = 0.0;  ///< costmap_2d's key: 0 = not checked
    ros::WallTime subscribed_since;       ///< zero while not subscribed
    ros::WallTime last_integrated;  ///< scans integrated with one pose (no tf at the last beam)
    std::string last_rejection;
    VoxelIntegrationStats last;
    TimingStats integrate_ms;
  };

  void readSource(const std::string& name);
  void onCloud(Source* s, const sensor_msgs::PointCloud2ConstPtr& msg);
  void onLegacyCloud(Source* s, const sensor_msgs::PointCloudConstPtr& msg);
  void onCloudMessage(Source* s, const sensor_msgs::PointCloud2& msg);
  void onDepth(Source* s, const sensor_msgs::ImageConstPtr& msg);
  /// A depth image with the camera it is read with (checked against the image's size).
  void integrateDepth(Source* s, const sensor_msgs::ImageConstPtr& msg,
                      const PinholeCamera& camera);
  void onScan(Source* s, const sensor_msgs::LaserScanConstPtr& msg);
  void onCameraInfo(Source* s, const sensor_msgs::CameraInfoConstPtr& msg);
  void reject(Source* s, const std::string& why);
  /// sensor -> global at the stamp; false (and a rejection) when tf cannot give it.
  bool lookup(Source* s, const std::string& frame, const ros::Time& stamp, Eigen::Isometry3d* pose);
  /// The same without a rejection: false if tf cannot give a finite transform.
  bool lookupQuiet(const std::string& frame, const ros::Time& stamp, Eigen::Isometry3d* pose);
  /// global <- frame at `stamp` through tf; false with the reason in *why (if given) when tf
  /// has none or it is not finite.
  bool transformAt(const std::string& frame, const ros::Time& stamp, Eigen::Isometry3d* pose,
                   std::string* why);
  /// Drops the hits outside the source's height band, then integrates (hits is modified).
  void integrate(Source* s, const Eigen::Vector3d& origin, std::vector<float>& hits,
                 const std::vector<float>& no_returns, const ros::Time& stamp);
  void clearFootprint(double robot_x, double robot_y, double robot_yaw, const ros::Time& now);
  void integrateFrustum(Source* s, const std::vector<float>& metres, const PinholeCamera& camera,
                        const Eigen::Isometry3d& pose, const ros::Time& stamp);
  /// Runs one integration under the lock and books its result (timing, counts, dirty window).
  void runIntegration(Source* s, const ros::Time& stamp,
                      const std::function<VoxelIntegrationStats()>& work);
  void publishVoxels(const ros::Time& stamp);

  /// dynamic_reconfigure (cfg/VoxelObstacleLayer.cfg): costmap_2d VoxelPlugin's keys.
  void reconfigure(VoxelObstacleLayerConfig& cfg, std::uint32_t level);
  /// "" while every source with an expected_update_rate delivers in time, else why not.
  std::string staleSources() const;

  mutable std::mutex mutex_;
  std::string not_current_why_;
  VoxelMapConfig config_;
  std::unique_ptr<VoxelMap> map_;
  std::vector<std::unique_ptr<Source>> sources_;
  bool track_unknown_space_ = true;
  int combination_method_ = 1;  ///< 0 overwrite, 1 maximum (costmap_2d's default)
  bool publish_voxel_map_ = false;
  bool stvl_configuration_ = false;         ///< STVL's keys were adopted by the host (stvl_keys.h)
  bool footprint_clearing_enabled_ = true;  ///< costmap_2d's default
  std::vector<std::size_t> footprint_cells_;
  std::vector<std::pair<int, int>> footprint_columns_;
  std::size_t footprint_voxels_cleared_ = 0;
  bool redraw_all_ = true;  ///< the whole window changed (resize, shift, decay, reset)
  CellBounds dirty_;        ///< window-relative columns changed since the last update
  double prune_period_s_ = 1.0;
  ros::Time last_prune_;
  ros::Publisher voxel_pub_;
  ros::WallTime last_voxel_cloud_;
  std::vector<std::uint8_t> projection_;
  std::size_t lethal_columns_ = 0;
  std::size_t dropped_updates_ = 0;
  ConfigErrorLog config_errors_;
  std::vector<std::string> param_warnings_;
  ReconfigureHost<VoxelObstacleLayerConfig> reconfigure_;  ///< last member: stopped first
};

}  // namespace downstream_perception
