// Robot footprint: a polygon in the base frame (REP-103: x forward, y left, metres).
#pragma once

#include <string>
#include <vector>

namespace downstream_perception {

struct FootprintPoint {
  double x = 0.0;
  double y = 0.0;
};

using Footprint = std::vector<FootprintPoint>;

/// Empty if the polygon is usable (>= 3 finite vertices), else the reason.
std::string validateFootprint(const Footprint& polygon);
/// A regular 16-gon of the given radius (costmap_2d's robot_radius footprint).
Footprint circularFootprint(double radius_m);
/// Moves every vertex `padding_m` farther from the origin along each axis (costmap_2d's
/// footprint_padding: x and y grow by padding with the vertex's sign).
Footprint padFootprint(const Footprint& polygon, double padding_m);
/// Shortest distance from the origin to the polygon's edges (costmap_2d's inscribed radius).
double inscribedRadius(const Footprint& polygon);
/// Largest distance from the origin to a vertex (circumscribed radius).
double circumscribedRadius(const Footprint& polygon);

}  // namespace downstream_perception
