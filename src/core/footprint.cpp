#include "downstream_perception/core/footprint.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace downstream_perception {

namespace {

double distanceToSegment(double px, double py, const FootprintPoint& a, const FootprintPoint& b) {
  const double dx = b.x - a.x;
  const double dy = b.y - a.y;
  const double len2 = dx * dx + dy * dy;
  double t = len2 > 0.0 ? ((px - a.x) * dx + (py - a.y) * dy) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(px - (a.x + t * dx), py - (a.y + t * dy));
}

}  // namespace

std::string validateFootprint(const Footprint& polygon) {
  std::ostringstream why;
  if (polygon.size() < 3) {
    why << "footprint needs at least 3 points, got " << polygon.size();
    return why.str();
  }
  for (const FootprintPoint& p : polygon) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || std::abs(p.x) > 100.0 ||
        std::abs(p.y) > 100.0) {
      why << "footprint point (" << p.x << ", " << p.y << ") is not finite or beyond 100 m";
      return why.str();
    }
  }
  return {};
}

Footprint circularFootprint(double radius_m) {
  Footprint polygon;
  constexpr int kSides = 16;
  for (int i = 0; i < kSides; ++i) {
    const double a = 2.0 * M_PI * i / kSides;
    polygon.push_back({radius_m * std::cos(a), radius_m * std::sin(a)});
  }
  return polygon;
}

Footprint padFootprint(const Footprint& polygon, double padding_m) {
  Footprint out = polygon;
  for (FootprintPoint& p : out) {
    p.x += (p.x >= 0.0 ? 1.0 : -1.0) * padding_m;
    p.y += (p.y >= 0.0 ? 1.0 : -1.0) * padding_m;
  }
  return out;
}

double inscribedRadius(const Footprint& polygon) {
  if (polygon.empty()) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    best =
        std::min(best, distanceToSegment(0.0, 0.0, polygon[i], polygon[(i + 1) % polygon.size()]));
  }
  return best;
}

double circumscribedRadius(const Footprint& polygon) {
  double best = 0.0;
  for (const FootprintPoint& p : polygon) best = std::max(best, std::hypot(p.x, p.y));
  return best;
}

}  // namespace downstream_perception
