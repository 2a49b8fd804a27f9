#include "downstream_perception/layers/observation/point_cloud_source.h"

#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/message_checks.h"

#include <sensor_msgs/point_cloud_conversion.h>
#include <Eigen/Geometry>

namespace downstream_perception {

PointCloudSource::PointCloudSource(std::string name, const ObservationSourceConfig& config,
                                   ros::NodeHandle nh, tf2_ros::Buffer& tf,
                                   std::string global_frame, Callback on_observation, bool legacy)
    : ObservationSource(std::move(name), config, nh, tf, std::move(global_frame),
                        std::move(on_observation)),
      legacy_(legacy) {}

void PointCloudSource::subscribe() {
  if (subscription_.subscribed() || legacy_subscription_.subscribed()) return;  // idempotent
  if (legacy_) {
    legacy_subscription_.subscribe(
        nh_, config_.topic, tf_, global_frame_, config_.tf_queue_size,
        [this](const sensor_msgs::PointCloudConstPtr& msg) { onLegacyCloud(msg); },
        [this](const sensor_msgs::PointCloudConstPtr& msg,
               tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          onTfFailure(msg->header.frame_id, msg->header.stamp, reason);
        });
  } else {
    subscription_.subscribe(
        nh_, config_.topic, tf_, global_frame_, config_.tf_queue_size,
        [this](const sensor_msgs::PointCloud2ConstPtr& msg) { onCloud(*msg); },
        [this](const sensor_msgs::PointCloud2ConstPtr& msg,
               tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          onTfFailure(msg->header.frame_id, msg->header.stamp, reason);
        });
  }
  markSubscribed();
}

void PointCloudSource::onLegacyCloud(const sensor_msgs::PointCloudConstPtr& msg) {
  // costmap_2d converts too; the converted cloud then meets the same checks as a PointCloud2
  // (its channels become FLOAT32 fields after x, y, z).
  sensor_msgs::PointCloud2 cloud;
  if (!sensor_msgs::convertPointCloudToPointCloud2(*msg, cloud)) {
    countReceived();
    reject("bad message: PointCloud conversion failed",
           "sensor_msgs::convertPointCloudToPointCloud2 refused it (a channel's value count "
           "differs from the point count?)");
    return;
  }
  onCloud(cloud);
}

void PointCloudSource::onCloud(const sensor_msgs::PointCloud2& msg) {
  countReceived();
  if (msg.header.stamp.isZero()) {
    reject("bad message: zero stamp", "a cloud must carry its measurement time");
    return;
  }
  std::size_t x_offset = 0;
  const std::string why = checkCloudLayout(msg, &x_offset);
  if (!why.empty()) {
    reject("bad message: cloud layout", why);
    return;
  }
  geometry_msgs::TransformStamped t;
  if (!lookup(frameOf(msg.header.frame_id), msg.header.stamp, &t)) return;
  const Eigen::Isometry3d grid_from_sensor = toEigen(t.transform);

  Observation obs;
  obs.stamp = msg.header.stamp;
  CloudBeamsConfig band = heightBand();
  band.merge_grid = mergeGrid();
  // An empty cloud may still claim 2^32 - 1 rows of nothing: no loop over them.
  const std::uint32_t rows = msg.width == 0 ? 0 : msg.height;
  for (std::uint32_t row = 0; row < rows; ++row) {
    beamsFromCloud(integrator_, band,
                   msg.data.data() + static_cast<std::size_t>(row) * msg.row_step + x_offset,
                   msg.width, msg.point_step, grid_from_sensor, &obs.beams, &obs.decisions);
  }
  on_observation_(*this, obs);
}

}  // namespace downstream_perception
