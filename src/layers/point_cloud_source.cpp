#include "downstream_perception/layers/point_cloud_source.h"

#include <Eigen/Geometry>

#include <sstream>

namespace downstream_perception {

PointCloudSource::PointCloudSource(std::string name, const ObservationSourceConfig& config,
                                   ros::NodeHandle nh, tf2_ros::Buffer& tf,
                                   std::string global_frame, Callback on_observation)
    : ObservationSource(std::move(name), config, nh, tf, std::move(global_frame),
                        std::move(on_observation)) {}

void PointCloudSource::subscribe() {
  subscription_.subscribe(
      nh_, config_.topic, tf_, global_frame_, config_.tf_queue_size,
      [this](const sensor_msgs::PointCloud2ConstPtr& msg) { onCloud(msg); },
      [this](const sensor_msgs::PointCloud2ConstPtr& msg,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        onTfFailure(msg->header.frame_id, msg->header.stamp, reason);
      });
}

std::string PointCloudSource::checkLayout(const sensor_msgs::PointCloud2& msg,
                                          std::size_t* x_offset) {
  const auto field = [&msg](const char* name) -> const sensor_msgs::PointField* {
    for (const auto& f : msg.fields) {
      if (f.name == name) return &f;
    }
    return nullptr;
  };
  const sensor_msgs::PointField* x = field("x");
  const sensor_msgs::PointField* y = field("y");
  const sensor_msgs::PointField* z = field("z");
  std::ostringstream why;
  if (x == nullptr || y == nullptr || z == nullptr) {
    why << "no x, y and z fields";
  } else if (x->datatype != sensor_msgs::PointField::FLOAT32 ||
             y->datatype != sensor_msgs::PointField::FLOAT32 ||
             z->datatype != sensor_msgs::PointField::FLOAT32 || y->offset != x->offset + 4 ||
             z->offset != x->offset + 8) {
    why << "x, y, z must be consecutive FLOAT32 fields";
  } else if (msg.is_bigendian) {
    why << "big-endian clouds are not supported";
  } else if (msg.point_step < x->offset + 12) {
    why << "point_step " << msg.point_step << " is smaller than the x, y, z fields";
  } else if (static_cast<std::uint64_t>(msg.width) * msg.point_step > msg.row_step) {
    why << "row_step " << msg.row_step << " < width * point_step";
  } else if (static_cast<std::uint64_t>(msg.row_step) * msg.height != msg.data.size()) {
    why << "data holds " << msg.data.size()
        << " bytes, row_step * height = " << static_cast<std::uint64_t>(msg.row_step) * msg.height;
  } else {
    *x_offset = x->offset;
  }
  return why.str();
}

void PointCloudSource::onCloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
  countReceived();
  if (msg->header.stamp.isZero()) {
    reject("bad message: zero stamp", "a cloud must carry its measurement time");
    return;
  }
  std::size_t x_offset = 0;
  const std::string why = checkLayout(*msg, &x_offset);
  if (!why.empty()) {
    reject("bad message: cloud layout", why);
    return;
  }
  geometry_msgs::TransformStamped t;
  if (!lookup(frameOf(msg->header.frame_id), msg->header.stamp, &t)) return;
  const auto& q = t.transform.rotation;
  const auto& p = t.transform.translation;
  Eigen::Isometry3d grid_from_sensor = Eigen::Isometry3d::Identity();
  grid_from_sensor.linear() =
      Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
  grid_from_sensor.translation() = Eigen::Vector3d(p.x, p.y, p.z);

  Observation obs;
  obs.stamp = msg->header.stamp;
  for (std::uint32_t row = 0; row < msg->height; ++row) {
    beamsFromCloud(integrator_, config_.cloud,
                   msg->data.data() + static_cast<std::size_t>(row) * msg->row_step + x_offset,
                   msg->width, msg->point_step, grid_from_sensor, &obs.beams, &obs.decisions);
  }
  on_observation_(*this, obs);
}

}  // namespace downstream_perception
