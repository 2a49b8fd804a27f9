// Planar rigid transforms (SE(2)): x, y in metres, yaw in radians (REP-103, CCW positive).
// A Pose2D doubles as the transform "parent <- child": apply() maps child coordinates to parent.
#pragma once

namespace downstream_perception {

struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

struct Pose2D {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
};

/// Wraps an angle into [-pi, pi).
double normalizeAngle(double angle_rad);
/// Shortest signed arc from a to b, in [-pi, pi).
double shortestAngularDistance(double from_rad, double to_rad);

/// a ∘ b: if a = parent<-mid and b = mid<-child, the result is parent<-child.
Pose2D compose(const Pose2D& a, const Pose2D& b);
/// Closed-form inverse (R^T, -R^T t): child<-parent.
Pose2D inverse(const Pose2D& a);
/// R p + t.
Point2 apply(const Pose2D& a, const Point2& p);
/// Pose at time t between (a, t_a) and (b, t_b): linear in translation, shortest arc in yaw.
/// Extrapolates linearly outside [t_a, t_b]. If t_a == t_b returns a.
/// Throws std::invalid_argument when finite inputs give a pose that overflows.
Pose2D interpolate(const Pose2D& a, double t_a, const Pose2D& b, double t_b, double t);

}  // namespace downstream_perception
