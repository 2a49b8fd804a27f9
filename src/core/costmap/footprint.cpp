#include "downstream_perception/core/costmap/footprint.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
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

namespace {
double sign0(double v) {
  return v < 0.0 ? -1.0 : (v > 0.0 ? 1.0 : 0.0);
}
}  // namespace

Footprint padFootprint(const Footprint& polygon, double padding_m) {
  Footprint out = polygon;
  for (FootprintPoint& p : out) {
    p.x += sign0(p.x) * padding_m;
    p.y += sign0(p.y) * padding_m;
  }
  return out;
}

Footprint parseFootprintString(const std::string& text, std::string* error) {
  // One pass over the characters, as costmap_2d's parser reads them: '[' opens (depth <= 2),
  // ']' closes (a depth-2 close ends a point), ',' and blanks separate, anything else must be a
  // number inside a point.
  std::vector<std::vector<double>> points;
  std::vector<double> current;
  int depth = 0;
  std::size_t k = 0;
  const auto fail = [&](const std::string& why) {
    *error = why + " in footprint string '" + text + "'";
    return Footprint{};
  };
  while (k < text.size()) {
    const char c = text[k];
    if (c == '[') {
      if (++depth > 2) return fail("brackets nested deeper than [[x, y], ...]");
      current.clear();
      ++k;
    } else if (c == ']') {
      if (--depth < 0) return fail("more ']' than '['");
      if (depth == 1) points.push_back(current);
      ++k;
    } else if (c == ',' || c == ' ' || c == '\t' || c == '\n' || c == '\r') {
      ++k;
    } else {
      if (depth != 2) {
        return fail(std::string("'") + c + "' outside a point (numbers belong at depth 2)");
      }
      const char* begin = text.c_str() + k;
      char* end = nullptr;
      const double v = std::strtod(begin, &end);
      if (end == begin) return fail(std::string("'") + c + "' is not part of a number");
      current.push_back(v);
      k += static_cast<std::size_t>(end - begin);
    }
  }
  if (depth != 0) return fail("unterminated: more '[' than ']'");
  if (points.size() < 3) {
    return fail("a footprint needs at least 3 points, got " + std::to_string(points.size()));
  }
  Footprint polygon;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].size() != 2) {
      return fail("point " + std::to_string(i + 1) + " has " + std::to_string(points[i].size()) +
                  " numbers, not 2");
    }
    polygon.push_back({points[i][0], points[i][1]});
  }
  error->clear();
  return polygon;
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

namespace downstream_perception {

Footprint transformFootprint(const Footprint& polygon, const Pose2D& pose) {
  Footprint out;
  out.reserve(polygon.size());
  for (const FootprintPoint& p : polygon) {
    const Point2 q = apply(pose, Point2{p.x, p.y});
    out.push_back({q.x, q.y});
  }
  return out;
}

CellBounds polygonCells(const Footprint& world_polygon, const GridGeometry& g,
                        std::vector<std::size_t>* cells) {
  CellBounds window;
  if (world_polygon.size() < 3 || g.cellCount() == 0) return window;
  double min_y = std::numeric_limits<double>::max();
  double max_y = std::numeric_limits<double>::lowest();
  for (const FootprintPoint& p : world_polygon) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) return window;
    min_y = std::min(min_y, p.y);
    max_y = std::max(max_y, p.y);
  }
  const double res = g.resolution();
  // Rows whose centre line can cross the polygon, clipped to the grid.
  const int row_lo = std::max(0, static_cast<int>(std::floor((min_y - g.originY()) / res - 0.5)));
  const int row_hi =
      std::min(g.sizeY() - 1, static_cast<int>(std::ceil((max_y - g.originY()) / res - 0.5)));
  std::vector<double> crossings;
  const std::size_t n = world_polygon.size();
  for (int cy = row_lo; cy <= row_hi; ++cy) {
    const double y = g.originY() + (cy + 0.5) * res;
    crossings.clear();
    for (std::size_t k = 0; k < n; ++k) {
      const FootprintPoint& a = world_polygon[k];
      const FootprintPoint& b = world_polygon[(k + 1) % n];
      // Half-open in y so a vertex on the scan line is counted once.
      if ((a.y <= y) == (b.y <= y)) continue;
      crossings.push_back(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
    }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
      // Cells whose centre x lies in [x0, x1].
      const int c0 =
          std::max(0, static_cast<int>(std::ceil((crossings[k] - g.originX()) / res - 0.5)));
      const int c1 =
          std::min(g.sizeX() - 1,
                   static_cast<int>(std::floor((crossings[k + 1] - g.originX()) / res - 0.5)));
      if (c0 > c1) continue;
      window.expand(c0, cy);
      window.expand(c1, cy);
      for (int cx = c0; cx <= c1; ++cx) cells->push_back(g.index(cx, cy));
    }
  }
  return window;
}

}  // namespace downstream_perception
