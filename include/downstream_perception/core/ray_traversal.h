// Grid ray traversal.
//
// Two walkers:
//  * bresenhamLine: the classic integer Bresenham between two cell indices (8-connected; one cell
//    per step of the major axis). Kept because it is the textbook answer key (the lesson's
//    (2,2)->(7,5) example) and is what costmap_2d uses.
//  * traverseRay: Amanatides-Woo traversal of a continuous segment. It visits every cell whose
//    interior the segment crosses, exactly once, in order, ending in the cell that contains the
//    end point. This is what the obstacle layer clears with: Bresenham between cell centres skips
//    cells a diagonal beam really crosses (and visits some it does not), which leaves uncleared
//    specks in free space. Where the segment passes exactly through a cell corner, the walker steps
//    in x first (the two side cells are touched only at a point, so either choice is exact).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

#include "downstream_perception/core/grid_geometry.h"

namespace downstream_perception {

/// Visits (x, y) for every cell of the Bresenham line from (x0, y0) to (x1, y1), both included.
template <class Visitor>
void bresenham(int x0, int y0, int x1, int y1, Visitor&& visit) {
  const int dx = std::abs(x1 - x0);
  const int dy = std::abs(y1 - y0);
  const int sx = x0 < x1 ? 1 : -1;
  const int sy = y0 < y1 ? 1 : -1;
  int err = dx - dy;
  int x = x0;
  int y = y0;
  while (true) {
    visit(x, y);
    if (x == x1 && y == y1) return;
    const int e2 = 2 * err;
    if (e2 > -dy) {
      err -= dy;
      x += sx;
    }
    if (e2 < dx) {
      err += dx;
      y += sy;
    }
  }
}

std::vector<CellIndex> bresenhamLine(int x0, int y0, int x1, int y1);

/// Clips the world segment (x0,y0)-(x1,y1) to the grid's extent (Liang-Barsky). Returns false if
/// it misses the grid. *start_clipped / *end_clipped tell whether an end was moved.
bool clipSegmentToGrid(const GridGeometry& grid, double* x0, double* y0, double* x1, double* y1,
                       bool* start_clipped = nullptr, bool* end_clipped = nullptr);

/// Amanatides-Woo walk over the cells of the world segment (x0,y0)-(x1,y1), which must lie inside
/// the grid (clip it first). Calls visit(cx, cy) for each cell in order; the last cell (the one
/// containing (x1, y1)) is visited only if include_end is true.
///
/// Implementation: integer DDA on fixed-point coordinates (2^-20 cell). "Next vertical edge comes
/// first" (t_max_x <= t_max_y) is decided by the sign of one integer error term, so each step is a
/// compare, a select and an add: a short dependency chain and no unpredictable branch.
template <class Visitor>
void traverseRay(const GridGeometry& grid, double x0, double y0, double x1, double y1,
                 bool include_end, Visitor&& visit) {
  constexpr int kShift = 20;
  constexpr std::int64_t kOne = std::int64_t{1} << kShift;
  const double scale = static_cast<double>(kOne) / grid.resolution();
  const std::int64_t fx0 = std::llround((x0 - grid.originX()) * scale);
  const std::int64_t fy0 = std::llround((y0 - grid.originY()) * scale);
  const std::int64_t fx1 = std::llround((x1 - grid.originX()) * scale);
  const std::int64_t fy1 = std::llround((y1 - grid.originY()) * scale);
  // Arithmetic shift = floor division for the (in-grid, non-negative) coordinates.
  int cx = static_cast<int>(fx0 >> kShift);
  int cy = static_cast<int>(fy0 >> kShift);
  const int ex = static_cast<int>(fx1 >> kShift);
  const int ey = static_cast<int>(fy1 >> kShift);
  const std::int64_t adx = fx1 >= fx0 ? fx1 - fx0 : fx0 - fx1;
  const std::int64_t ady = fy1 >= fy0 ? fy1 - fy0 : fy0 - fy1;
  const int sx = fx1 > fx0 ? 1 : -1;
  const int sy = fy1 > fy0 ? 1 : -1;
  // Distances (fixed point) from the start to the first vertical / horizontal edge crossed.
  const std::int64_t first_x = sx > 0 ? (std::int64_t{cx} + 1) * kOne - fx0 : fx0 - std::int64_t{cx} * kOne;
  const std::int64_t first_y = sy > 0 ? (std::int64_t{cy} + 1) * kOne - fy0 : fy0 - std::int64_t{cy} * kOne;
  // t_max_x <= t_max_y  <=>  first_x / adx <= first_y / ady  <=>  err <= 0.
  std::int64_t err = first_x * ady - first_y * adx;
  const std::int64_t err_step_x = kOne * ady;
  const std::int64_t err_step_y = kOne * adx;
  // The number of steps per axis is fixed by the end cell, so the walk always ends there.
  int steps_x = cx > ex ? cx - ex : ex - cx;
  int steps_y = cy > ey ? cy - ey : ey - cy;
  while (steps_x + steps_y > 0) {
    visit(cx, cy);
    const bool step_x = steps_y == 0 || (steps_x != 0 && err <= 0);
    cx += step_x ? sx : 0;
    cy += step_x ? 0 : sy;
    err += step_x ? err_step_x : -err_step_y;
    steps_x -= step_x ? 1 : 0;
    steps_y -= step_x ? 0 : 1;
  }
  if (include_end) visit(cx, cy);
}

/// Convenience form returning the visited cells (for tests and Python).
std::vector<CellIndex> rayCells(const GridGeometry& grid, double x0, double y0, double x1,
                                double y1, bool include_end = true);

}  // namespace downstream_perception
