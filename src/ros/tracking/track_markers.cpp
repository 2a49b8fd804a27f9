#include "downstream_perception/ros/tracking/track_markers.h"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace downstream_perception {

namespace {

constexpr const char* kNamespaces[] = {"track_box", "track_id", "track_velocity",
                                       "track_covariance"};

std::int32_t markerId(std::uint64_t track_id) {
  return static_cast<std::int32_t>(track_id % 2147483647ULL);  // stable per track
}

void colour(visualization_msgs::Marker* m, std::uint8_t state) {
  // Confirmed: green; coasting: orange; tentative: grey.
  m->color.a = state == TrackedObject::TENTATIVE ? 0.4f : 0.8f;
  m->color.r =
      state == TrackedObject::CONFIRMED ? 0.1f : (state == TrackedObject::COASTING ? 1.0f : 0.6f);
  m->color.g =
      state == TrackedObject::CONFIRMED ? 0.8f : (state == TrackedObject::COASTING ? 0.6f : 0.6f);
  m->color.b =
      state == TrackedObject::CONFIRMED ? 0.2f : (state == TrackedObject::COASTING ? 0.1f : 0.6f);
}

}  // namespace

visualization_msgs::MarkerArray TrackMarkers::build(const TrackedObjectArray& tracks) {
  visualization_msgs::MarkerArray out;
  std::set<std::uint64_t> now;
  for (const TrackedObject& t : tracks.tracks) {
    now.insert(t.id);
    visualization_msgs::Marker base;
    base.header = tracks.header;
    base.id = markerId(t.id);
    base.action = visualization_msgs::Marker::ADD;
    base.pose.position = t.position;
    base.pose.orientation.w = 1.0;
    colour(&base, t.state);

    visualization_msgs::Marker box = base;
    box.ns = kNamespaces[0];
    box.type = visualization_msgs::Marker::CUBE;
    box.scale.x = std::max(0.1f, t.size_x);
    box.scale.y = std::max(0.1f, t.size_y);
    box.scale.z = 0.1;
    out.markers.push_back(box);

    visualization_msgs::Marker text = base;
    text.ns = kNamespaces[1];
    text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    text.text = std::to_string(t.id) + (t.label.empty() ? "" : " " + t.label);
    text.pose.position.z += 0.5;
    text.scale.z = 0.3;
    text.color.a = 1.0f;
    out.markers.push_back(text);

    visualization_msgs::Marker arrow = base;
    arrow.ns = kNamespaces[2];
    arrow.type = visualization_msgs::Marker::ARROW;
    geometry_msgs::Point tip = t.position;
    tip.x += t.velocity.x;  // 1 s ahead
    tip.y += t.velocity.y;
    arrow.pose = geometry_msgs::Pose();
    arrow.pose.orientation.w = 1.0;
    arrow.points = {t.position, tip};
    arrow.scale.x = 0.05;
    arrow.scale.y = 0.1;
    arrow.scale.z = 0.1;
    out.markers.push_back(arrow);

    // 2-sigma ellipse of the position covariance: a flat cylinder scaled along the eigenvectors.
    Eigen::Matrix2d cov;
    cov << t.position_covariance[0], t.position_covariance[1], t.position_covariance[2],
        t.position_covariance[3];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    visualization_msgs::Marker ellipse = base;
    ellipse.ns = kNamespaces[3];
    ellipse.type = visualization_msgs::Marker::CYLINDER;
    const Eigen::Vector2d values = eig.eigenvalues().cwiseMax(1e-6);
    ellipse.scale.x = 4.0 * std::sqrt(values(1));  // diameter = 2 x 2 sigma
    ellipse.scale.y = 4.0 * std::sqrt(values(0));
    ellipse.scale.z = 0.02;
    const Eigen::Vector2d major = eig.eigenvectors().col(1);
    const double yaw = std::atan2(major.y(), major.x());
    ellipse.pose.orientation.z = std::sin(yaw / 2.0);
    ellipse.pose.orientation.w = std::cos(yaw / 2.0);
    ellipse.color.a = 0.3f;
    out.markers.push_back(ellipse);
  }
  for (const std::uint64_t gone : shown_) {
    if (now.count(gone)) continue;
    for (const char* ns : kNamespaces) {
      visualization_msgs::Marker del;
      del.header = tracks.header;
      del.ns = ns;
      del.id = markerId(gone);
      del.action = visualization_msgs::Marker::DELETE;
      out.markers.push_back(del);
    }
  }
  shown_.swap(now);
  return out;
}

}  // namespace downstream_perception
