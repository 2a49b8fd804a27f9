#include "downstream_perception/core/grid/ray_traversal.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace downstream_perception {

std::vector<CellIndex> bresenhamLine(int x0, int y0, int x1, int y1) {
  const std::int64_t length =
      std::max(std::abs(std::int64_t{x1} - x0), std::abs(std::int64_t{y1} - y0)) + 1;
  if (length > GridGeometry::kMaxCellsPerAxis) {
    throw std::invalid_argument(
        "bresenham line (" + std::to_string(x0) + ", " + std::to_string(y0) + ") -> (" +
        std::to_string(x1) + ", " + std::to_string(y1) + ") has " + std::to_string(length) +
        " cells, more than the " + std::to_string(GridGeometry::kMaxCellsPerAxis) +
        " of the longest grid axis");
  }
  std::vector<CellIndex> cells;
  cells.reserve(static_cast<std::size_t>(length));
  bresenham(x0, y0, x1, y1, [&cells](int x, int y) { cells.push_back({x, y}); });
  return cells;
}

bool clipSegmentToGrid(const GridGeometry& grid, double* x0, double* y0, double* x1, double* y1,
                       bool* start_clipped, bool* end_clipped) {
  if (start_clipped != nullptr) *start_clipped = false;
  if (end_clipped != nullptr) *end_clipped = false;
  if (!std::isfinite(*x0) || !std::isfinite(*y0) || !std::isfinite(*x1) || !std::isfinite(*y1)) {
    return false;
  }
  // Keep the clipped points strictly inside the last cell: the upper grid edge belongs to the
  // cell beyond it, and flooring a point exactly on it would step out of the grid.
  const double eps = grid.resolution() * 1e-6;
  const double xmin = grid.originX() + eps;
  const double ymin = grid.originY() + eps;
  const double xmax = grid.originX() + grid.sizeXMetres() - eps;
  const double ymax = grid.originY() + grid.sizeYMetres() - eps;
  const double dx = *x1 - *x0;
  const double dy = *y1 - *y0;
  double t0 = 0.0;
  double t1 = 1.0;
  int edge0 = -1;  // the edge (index into p, q) the start was moved to, -1 if it was not moved
  int edge1 = -1;
  // Liang-Barsky: for each edge, p * t <= q.
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {*x0 - xmin, xmax - *x0, *y0 - ymin, ymax - *y0};
  for (int k = 0; k < 4; ++k) {
    if (p[k] == 0.0) {
      if (q[k] < 0.0) return false;
      continue;
    }
    const double t = q[k] / p[k];
    if (p[k] < 0.0) {
      if (t > t1) return false;
      if (t > t0) {
        t0 = t;
        edge0 = k;
      }
    } else {
      if (t < t0) return false;
      if (t < t1) {
        t1 = t;
        edge1 = k;
      }
    }
  }
  // A moved end is put exactly on the edge it was moved to, and its other coordinate clamped
  // into the box: sx + t * dx cancels catastrophically when the far end is far away (at 1e12 m
  // its rounding already exceeds eps; at 1e18 m it is ~100 m, and t0 == t1 for a segment from
  // -1e18 to 1e18), and the point must not leave the grid whatever the input. For every sensor
  // within about 1e6 m of a 1 cm grid this moves the point by rounding only (far less than eps),
  // so no cell changes. An end that was not moved passed every edge test, so it is inside up
  // to rounding (which RayWalk's clamp absorbs).
  const double edge_value[4] = {xmin, xmax, ymin, ymax};
  const auto place = [&](double t, int edge, double* x, double* y) {
    *x = std::min(std::max(*x + t * dx, xmin), xmax);
    *y = std::min(std::max(*y + t * dy, ymin), ymax);
    (edge < 2 ? *x : *y) = edge_value[edge];
  };
  const double sx = *x0;
  const double sy = *y0;
  if (edge0 >= 0) {
    place(t0, edge0, x0, y0);
    if (start_clipped != nullptr) *start_clipped = true;
  }
  if (edge1 >= 0) {
    *x1 = sx;
    *y1 = sy;
    place(t1, edge1, x1, y1);
    if (end_clipped != nullptr) *end_clipped = true;
  }
  return true;
}

std::vector<CellIndex> rayCells(const GridGeometry& grid, double x0, double y0, double x1,
                                double y1, bool include_end) {
  std::vector<CellIndex> cells;
  bool end_clipped = false;
  if (!clipSegmentToGrid(grid, &x0, &y0, &x1, &y1, nullptr, &end_clipped)) return cells;
  traverseRay(grid, x0, y0, x1, y1, include_end || end_clipped, [&cells](int x, int y) {
    cells.push_back({x, y});
  });
  return cells;
}

}  // namespace downstream_perception
