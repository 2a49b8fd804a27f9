// A tracked object re-expressed in another frame, shared by the TrackedObstacleLayer (tracks into
// the costmap) and the handoff nodelet (tracks into the planning frame).
#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <tf2/utils.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "downstream_perception/TrackedObject.h"

namespace downstream_perception {

/// The track through `transform` (target <- the track's frame, sampled at the track's stamp):
/// the position by the whole transform; velocity and the 2 x 2 covariances rotated by its yaw
/// (tracks live in the plane: R v, R S R^T).
inline TrackedObject transformTrack(const TrackedObject& in,
                                    const geometry_msgs::TransformStamped& transform) {
  TrackedObject out = in;
  tf2::doTransform(in.position, out.position, transform);
  const Eigen::Matrix2d R =
      Eigen::Rotation2Dd(tf2::getYaw(transform.transform.rotation)).toRotationMatrix();
  const Eigen::Vector2d v = R * Eigen::Vector2d(in.velocity.x, in.velocity.y);
  out.velocity.x = v.x();
  out.velocity.y = v.y();
  for (auto* cov : {&out.position_covariance, &out.velocity_covariance}) {
    Eigen::Map<Eigen::Matrix<double, 2, 2, Eigen::RowMajor>> m(cov->data());
    m = (R * m * R.transpose()).eval();
  }
  return out;
}

}  // namespace downstream_perception
