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

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

#include "downstream_perception/core/grid_geometry.h"

namespace downstream_perception {

/// Visits (x, y) for every cell of the Bresenham line from (x0, y0) to (x1, y1), both included.
/// Any ints: the deltas and the error term are 64-bit (x1 - x0 of two extreme ints does not fit
/// in an int), and x, y only move toward x1, y1, so they never leave the ints' range.
template <class Visitor>
void bresenham(int x0, int y0, int x1, int y1, Visitor&& visit) {
  const std::int64_t dx = std::abs(std::int64_t{x1} - x0);
  const std::int64_t dy = std::abs(std::int64_t{y1} - y0);
  const int sx = x0 < x1 ? 1 : -1;
  const int sy = y0 < y1 ? 1 : -1;
  std::int64_t err = dx - dy;
  int x = x0;
  int y = y0;
  while (true) {
    visit(x, y);
    if (x == x1 && y == y1) return;
    const std::int64_t e2 = 2 * err;
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

/// The cells of bresenham() as a vector. Throws std::invalid_argument for a line of more than
/// GridGeometry::kMaxCellsPerAxis cells (longer than any grid's axis: a typo, and gigabytes).
std::vector<CellIndex> bresenhamLine(int x0, int y0, int x1, int y1);

/// Clips the world segment (x0,y0)-(x1,y1) to the grid's extent (Liang-Barsky). Returns false if
/// it misses the grid or is not finite. *start_clipped / *end_clipped tell whether an end was
/// moved. A moved end is put exactly on the grid edge it was moved to and its other coordinate
/// clamped into the grid's box, so no input (an end 1e18 m away, where the clip's rounding is
/// ~100 m) can put it outside; along the edge it then lies where the rounding put it, which for
/// such an input is as good as any point.
bool clipSegmentToGrid(const GridGeometry& grid, double* x0, double* y0, double* x1, double* y1,
                       bool* start_clipped = nullptr, bool* end_clipped = nullptr);

/// The state of an Amanatides-Woo walk over the cells of a world segment, in integer fixed point
/// (2^-20 cell). Which edge the segment crosses next (t_max_x <= t_max_y) is the sign of one
/// integer error term. Each step is a plain if/else: the x/y pattern of a straight line is
/// periodic, so the branch predictor follows it and the loop-carried chain is one add. (Measured
/// on this project's 2-core VM: a branch-free mask/select step is 2.3x slower, because every step
/// then waits for the compare-select-add chain.)
///
/// Why no per-axis guards are needed: with exact integer arithmetic the walk crosses edges in the
/// true order of their crossing parameters t, and the first stepsLeft() crossings are exactly the
/// ones with t <= 1, i.e. steps_x vertical and steps_y horizontal edges (an end point lying on an
/// edge is entered at t = 1 when moving up, never crossed when moving down). A corner inside the
/// segment may go either way (the two side cells are touched at a single point, so either is
/// exact); a corner at t = 1 must step along the axis that moves up (see tie_to_y).
struct RayWalk {
  static constexpr int kShift = 20;
  static constexpr std::int64_t kOne = std::int64_t{1} << kShift;

  int cx = 0;  ///< start cell
  int cy = 0;
  int sx = 1;  ///< step direction per axis (+-1)
  int sy = 1;
  int steps_x = 0;  ///< x steps from the start cell to the end cell
  int steps_y = 0;
  std::int64_t err = 0;         ///< <= 0: the next edge crossed is vertical (step in x)
  std::int64_t err_step_x = 0;  ///< added to err on an x step
  std::int64_t err_step_y = 0;  ///< subtracted from err on a y step

  /// The segment (x0,y0)-(x1,y1) should lie inside the grid (clip it first). Whatever it is, the
  /// fixed-point ends are clamped into the grid (NaN to 0), so the walk never leaves the grid:
  /// rounding can still put a clipped end a hair outside when the origin is huge (at 1e17 m a
  /// double's step is 16 m, more than the grid's eps margin). Inside the grid the clamp changes
  /// nothing. The grid's per-axis limit (2^22 cells) bounds the coordinates by 2^42 and every
  /// product below by 2^62, so the int64 arithmetic cannot overflow.
  RayWalk(const GridGeometry& grid, double x0, double y0, double x1, double y1) {
    const double scale = static_cast<double>(kOne) / grid.resolution();
    // Round to nearest; the clamped coordinates are non-negative, so truncating v + 0.5 is the
    // rounding (and avoids a libm call per coordinate). Clamped as doubles: casting an
    // out-of-range double to int64 is undefined.
    const auto fixed = [scale](double v, int cells) {
      const double hi = static_cast<double>(std::max<std::int64_t>(0, cells * kOne - 1));
      return static_cast<std::int64_t>(std::max(0.0, std::min(v * scale + 0.5, hi)));
    };
    const std::int64_t fx0 = fixed(x0 - grid.originX(), grid.sizeX());
    const std::int64_t fy0 = fixed(y0 - grid.originY(), grid.sizeY());
    const std::int64_t fx1 = fixed(x1 - grid.originX(), grid.sizeX());
    const std::int64_t fy1 = fixed(y1 - grid.originY(), grid.sizeY());
    // Arithmetic shift = floor division for the (clamped, non-negative) coordinates.
    cx = static_cast<int>(fx0 >> kShift);
    cy = static_cast<int>(fy0 >> kShift);
    const int ex = static_cast<int>(fx1 >> kShift);
    const int ey = static_cast<int>(fy1 >> kShift);
    const std::int64_t adx = fx1 >= fx0 ? fx1 - fx0 : fx0 - fx1;
    const std::int64_t ady = fy1 >= fy0 ? fy1 - fy0 : fy0 - fy1;
    sx = fx1 > fx0 ? 1 : -1;
    sy = fy1 > fy0 ? 1 : -1;
    // Distances (fixed point) from the start to the first vertical / horizontal edge crossed.
    const std::int64_t first_x =
        sx > 0 ? (std::int64_t{cx} + 1) * kOne - fx0 : fx0 - std::int64_t{cx} * kOne;
    const std::int64_t first_y =
        sy > 0 ? (std::int64_t{cy} + 1) * kOne - fy0 : fy0 - std::int64_t{cy} * kOne;
    // t_max_x <= t_max_y  <=>  first_x / adx <= first_y / ady  <=>  err <= 0. A segment with no
    // x extent never crosses a vertical edge (err stays positive; err_step_y is 0 then).
    // Ties (err == 0, a corner) step x, except when x moves down and y up: a corner at t = 1 then
    // lies on the end cell's lower x edge, which must not be crossed, so the tie goes to y
    // (err is an integer, so +1 moves only the ties).
    const std::int64_t tie_to_y = (sx < 0 && sy > 0) ? 1 : 0;
    err = adx == 0 ? std::int64_t{1} : first_x * ady - first_y * adx + tie_to_y;
    err_step_x = kOne * ady;
    err_step_y = kOne * adx;
    steps_x = cx > ex ? cx - ex : ex - cx;
    steps_y = cy > ey ? cy - ey : ey - cy;
  }

  int stepsLeft() const { return steps_x + steps_y; }
  int endX() const { return cx + sx * steps_x; }  ///< the cell containing the end point
  int endY() const { return cy + sy * steps_y; }

  /// Walks the cells before the end cell, calling visit(cx, cy); returns the end cell through
  /// *end_x, *end_y.
  template <class Visitor>
  void walk(Visitor&& visit, int* end_x, int* end_y) const {
    int x = cx;
    int y = cy;
    std::int64_t e = err;
    for (int left = stepsLeft(); left > 0; --left) {
      visit(x, y);
      if (e <= 0) {
        x += sx;
        e += err_step_x;
      } else {
        y += sy;
        e -= err_step_y;
      }
    }
    *end_x = x;
    *end_y = y;
  }
};

/// Amanatides-Woo walk over the cells of the world segment (x0,y0)-(x1,y1), which must lie inside
/// the grid (clip it first). Calls visit(cx, cy) for each cell in order; the last cell (the one
/// containing (x1, y1)) is visited only if include_end is true.
template <class Visitor>
void traverseRay(const GridGeometry& grid, double x0, double y0, double x1, double y1,
                 bool include_end, Visitor&& visit) {
  const RayWalk walk(grid, x0, y0, x1, y1);
  int ex = 0;
  int ey = 0;
  walk.walk(visit, &ex, &ey);
  if (include_end) visit(ex, ey);
}

/// Convenience form returning the visited cells (for tests and Python).
std::vector<CellIndex> rayCells(const GridGeometry& grid, double x0, double y0, double x1,
                                double y1, bool include_end = true);

}  // namespace downstream_perception
