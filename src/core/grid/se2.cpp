#include "downstream_perception/core/grid/se2.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <cmath>

namespace downstream_perception {

double normalizeAngle(double angle_rad) {
  // (a + pi) mod 2pi - pi, with a floored modulo so negative inputs wrap the same way.
  const double two_pi = 2.0 * M_PI;
  double a = std::fmod(angle_rad + M_PI, two_pi);
  if (a < 0.0) a += two_pi;
  return a - M_PI;
}

double shortestAngularDistance(double from_rad, double to_rad) {
  return normalizeAngle(to_rad - from_rad);
}

Pose2D compose(const Pose2D& a, const Pose2D& b) {
  const double c = std::cos(a.yaw);
  const double s = std::sin(a.yaw);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, normalizeAngle(a.yaw + b.yaw)};
}

Pose2D inverse(const Pose2D& a) {
  const double c = std::cos(a.yaw);
  const double s = std::sin(a.yaw);
  return {-(c * a.x + s * a.y), s * a.x - c * a.y, normalizeAngle(-a.yaw)};
}

Point2 apply(const Pose2D& a, const Point2& p) {
  const double c = std::cos(a.yaw);
  const double s = std::sin(a.yaw);
  return {a.x + c * p.x - s * p.y, a.y + s * p.x + c * p.y};
}

Pose2D interpolate(const Pose2D& a, double t_a, const Pose2D& b, double t_b, double t) {
  if (t_b == t_a) return a;
  const double alpha = (t - t_a) / (t_b - t_a);
  const Pose2D p{a.x + alpha * (b.x - a.x), a.y + alpha * (b.y - a.y),
                 normalizeAngle(a.yaw + alpha * shortestAngularDistance(a.yaw, b.yaw))};
  // Finite poses and stamps can still overflow (a sub-normal interval, an extrapolation 1e300
  // intervals out): a refusal, not an infinite pose.
  if (std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(b.x) && std::isfinite(b.y) &&
      !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.yaw))) {
    throw std::invalid_argument("interpolate: the pose at t overflows (t = " + std::to_string(t) +
                                " s between " + std::to_string(t_a) + " and " +
                                std::to_string(t_b) + " s)");
  }
  return p;
}

}  // namespace downstream_perception
