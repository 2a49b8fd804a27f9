#include "downstream_perception/core/ray_traversal.h"

#include <algorithm>

namespace downstream_perception {

std::vector<CellIndex> bresenhamLine(int x0, int y0, int x1, int y1) {
  std::vector<CellIndex> cells;
  cells.reserve(static_cast<std::size_t>(std::max(std::abs(x1 - x0), std::abs(y1 - y0))) + 1);
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
      t0 = std::max(t0, t);
    } else {
      if (t < t0) return false;
      t1 = std::min(t1, t);
    }
  }
  const double sx = *x0;
  const double sy = *y0;
  if (t0 > 0.0) {
    *x0 = sx + t0 * dx;
    *y0 = sy + t0 * dy;
    if (start_clipped != nullptr) *start_clipped = true;
  }
  if (t1 < 1.0) {
    *x1 = sx + t1 * dx;
    *y1 = sy + t1 * dy;
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
