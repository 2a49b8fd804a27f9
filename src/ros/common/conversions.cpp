#include "downstream_perception/ros/common/conversions.h"

#include <tf2/utils.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

#include <cstdint>

namespace downstream_perception {

Eigen::Matrix3d rotationOf(const geometry_msgs::Quaternion& q) {
  return Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
}

Eigen::Isometry3d toEigen(const geometry_msgs::Transform& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotationOf(t.rotation);
  T.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  return T;
}

geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  geometry_msgs::Transform t;
  t.translation.x = T.translation().x();
  t.translation.y = T.translation().y();
  t.translation.z = T.translation().z();
  t.rotation.x = q.x();
  t.rotation.y = q.y();
  t.rotation.z = q.z();
  t.rotation.w = q.w();
  return t;
}

double yawOf(const geometry_msgs::Quaternion& q) {
  return tf2::getYaw(q);
}

Eigen::Matrix2d yawRotation(double yaw_rad) {
  return Eigen::Rotation2Dd(yaw_rad).toRotationMatrix();
}

void rotateCovariance(const Eigen::Matrix2d& R, boost::array<double, 4>* covariance) {
  Eigen::Map<Eigen::Matrix<double, 2, 2, Eigen::RowMajor>> m(covariance->data());
  m = (R * m * R.transpose()).eval();
}

TrackedObject transformTrack(const TrackedObject& in,
                             const geometry_msgs::TransformStamped& transform) {
  TrackedObject out = in;
  tf2::doTransform(in.position, out.position, transform);
  const Eigen::Matrix2d R = yawRotation(yawOf(transform.transform.rotation));
  const Eigen::Vector2d v = R * Eigen::Vector2d(in.velocity.x, in.velocity.y);
  out.velocity.x = v.x();
  out.velocity.y = v.y();
  rotateCovariance(R, &out.position_covariance);
  rotateCovariance(R, &out.velocity_covariance);
  return out;
}

nav_msgs::MapMetaData mapMetaData(const GridGeometry& grid, double z_m,
                                  const ros::Time& load_time) {
  nav_msgs::MapMetaData info;
  info.map_load_time = load_time;
  info.resolution = static_cast<float>(grid.resolution());
  info.width = static_cast<std::uint32_t>(grid.sizeX());
  info.height = static_cast<std::uint32_t>(grid.sizeY());
  info.origin.position.x = grid.originX();
  info.origin.position.y = grid.originY();
  info.origin.position.z = z_m;
  info.origin.orientation.w = 1.0;
  return info;
}

}  // namespace downstream_perception
