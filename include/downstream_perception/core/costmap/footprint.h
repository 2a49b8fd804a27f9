// Robot footprint: a polygon in the base frame (REP-103: x forward, y left, metres).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "downstream_perception/core/grid/grid_geometry.h"
#include "downstream_perception/core/grid/se2.h"

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
/// footprint_padding: x and y grow by padding with the vertex's sign; a coordinate that is
/// exactly 0 stays 0, as costmap_2d's sign0 keeps it).
Footprint padFootprint(const Footprint& polygon, double padding_m);
/// costmap_2d's footprint string, "[[x, y], [x, y], ...]", parsed with its strictness: brackets
/// must nest to depth 2 and balance, numbers only at depth 2, >= 3 points of exactly 2 numbers.
/// Empty *error on success, else the reason (and an empty footprint).
Footprint parseFootprintString(const std::string& text, std::string* error);
/// Shortest distance from the origin to the polygon's edges (costmap_2d's inscribed radius).
double inscribedRadius(const Footprint& polygon);
/// Largest distance from the origin to a vertex (circumscribed radius).
double circumscribedRadius(const Footprint& polygon);

/// The polygon placed at `pose` (world <- base) in world coordinates.
Footprint transformFootprint(const Footprint& polygon, const Pose2D& pose);
/// Indices of the grid cells whose centre lies inside the polygon (given in world coordinates;
/// even-odd rule, so concave polygons work), clipped to the grid, row by row. Appends to *cells
/// and returns the window they span (empty if none).
CellBounds polygonCells(const Footprint& world_polygon, const GridGeometry& geometry,
                        std::vector<std::size_t>* cells);

}  // namespace downstream_perception
