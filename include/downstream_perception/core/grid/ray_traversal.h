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
//    diagonally: the two side cells are touched at a single point, their interiors are not
//    crossed, so neither is visited (visiting one of them, as an x-first tie-break did, clears a
//    cell on one side of the beam only and depends on the beam's direction).
//    The start and end cells are the cells GridGeometry::worldToCell gives for the two points
//    (floor on the grid's lattice: a point exactly on an edge is in the cell above it), so the
//    walk ends in exactly the cell a hit at its end point marks.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

#include "downstream_perception/core/grid/grid_geometry.h"

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
/// edge is entered at t = 1 when moving up, never crossed when moving down). A corner (a tie,
/// err == tie) is crossed diagonally, both edges in one step, when two or more crossings are left:
/// inside the segment both edges are crossed at that t, and at t = 1 that is the case only when
/// both axes move up (then the end cell is the diagonal one). With one crossing left the corner is
/// at t = 1 and only the axis that moves up crosses its edge; tie = 1 makes the tie fall on that
/// axis when it is y. A diagonal step is one visit for two crossings: stepsLeft() counts
/// crossings, the walk may visit fewer cells.
struct RayWalk {
  static constexpr int kShift = 20;
  static constexpr std::int64_t kOne = std::int64_t{1} << kShift;

  int cx = 0;  ///< start cell
  int cy = 0;
  int sx = 1;  ///< step direction per axis (+-1)
  int sy = 1;
  int steps_x = 0;  ///< x steps from the start cell to the end cell
  int steps_y = 0;
  std::int64_t err = 0;         ///< <= tie: the next edge crossed is vertical (step in x)
  std::int64_t err_step_x = 0;  ///< added to err on an x step
  std::int64_t err_step_y = 0;  ///< subtracted from err on a y step
  std::int64_t tie = 0;         ///< err == tie: the next crossing is a corner (both edges)
  bool corners = false;         ///< whether err can ever equal tie (else no corner is crossed)

  /// The segment (x0,y0)-(x1,y1) should lie inside the grid (clip it first). Whatever it is, the
  /// fixed-point ends are clamped into the grid (NaN to 0), so the walk never leaves the grid:
  /// rounding can still put a clipped end a hair outside when the origin is huge (at 1e17 m a
  /// double's step is 16 m, more than the grid's eps margin). Inside the grid the clamp changes
  /// nothing. The grid's per-axis limit (2^22 cells) bounds the coordinates by 2^42 and every
  /// product below by 2^62, so the int64 arithmetic cannot overflow.
  RayWalk(const GridGeometry& grid, double x0, double y0, double x1, double y1) {
    const double scale = static_cast<double>(kOne) / grid.resolution();
    const std::int64_t fx0 = fixedX(grid, x0, scale);
    const std::int64_t fy0 = fixedY(grid, y0, scale);
    const std::int64_t fx1 = fixedX(grid, x1, scale);
    const std::int64_t fy1 = fixedY(grid, y1, scale);
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
    // t_max_x <= t_max_y  <=>  first_x / adx <= first_y / ady  <=>  err <= tie. A segment with no
    // x extent never crosses a vertical edge (err stays at 2, above any tie; err_step_y is 0).
    // Ties (a corner) are err == tie: tie is 0, except when x moves down and y up: a corner at
    // t = 1 then lies on the end cell's lower x edge, which must not be crossed, so the tie goes
    // to y (err is an integer, so +1 moves only the ties).
    tie = (sx < 0 && sy > 0) ? 1 : 0;
    // A segment with no y extent never crosses a horizontal edge: err stays at -1, below any tie
    // (first_y may be 0 there, which would make a false tie).
    err = adx == 0   ? std::int64_t{2}
          : ady == 0 ? std::int64_t{-1}
                     : first_x * ady - first_y * adx + tie;
    err_step_x = kOne * ady;
    err_step_y = kOne * adx;
    // err moves in multiples of kOne, so it can only ever equal tie if it starts congruent to it
    // modulo kOne: true for segments between lattice-exact points (tests, simulated walls), all
    // but never for measured rays. The others walk the loop without the corner test.
    corners = adx != 0 && ady != 0 && ((err - tie) & (kOne - 1)) == 0;
    steps_x = cx > ex ? cx - ex : ex - cx;
    steps_y = cy > ey ? cy - ey : ey - cy;
  }

  /// A world coordinate in fixed point relative to the grid, clamped into the grid (NaN to 0).
  /// Its cell is exactly the cell GridGeometry::worldToCell gives; only the fraction is rounded
  /// (to 2^-20 cell, never across an edge). Fast path: (x - origin) * scale rounded, as precise
  /// as the exact form to far below 2^-20 cell, so its cell is right whenever the point is more
  /// than 2^-19 cell from an edge; nearer (points on edges: lattice-exact geometry) the exact form
  /// is taken (a division, off the common path).
  static std::int64_t fixedX(const GridGeometry& g, double x, double scale) {
    return fixedAxis(x - g.originX(), scale, g.sizeX(),
                     [&g, x] { return fixed(g.latticeUnitsX(x), g.latticeShiftX(), g.sizeX()); });
  }
  static std::int64_t fixedY(const GridGeometry& g, double y, double scale) {
    return fixedAxis(y - g.originY(), scale, g.sizeY(),
                     [&g, y] { return fixed(g.latticeUnitsY(y), g.latticeShiftY(), g.sizeY()); });
  }
  template <class Exact>
  static std::int64_t fixedAxis(double offset, double scale, int cells, Exact&& exact) {
    // Clamped as doubles: casting an out-of-range double to int64 is undefined. Non-negative
    // after the clamp, so truncating v + 0.5 rounds (no libm call).
    const double hi = static_cast<double>(std::max<std::int64_t>(0, cells * kOne - 1));
    const auto f = static_cast<std::int64_t>(std::max(0.0, std::min(offset * scale + 0.5, hi)));
    const std::int64_t sub = f & (kOne - 1);
    if (__builtin_expect(sub < 2 || sub > kOne - 2, 0)) return exact();
    return f;
  }

  /// The exact form: a lattice coordinate u (GridGeometry::latticeUnitsX/Y) in fixed point
  /// relative to the grid, clamped into [0, cells) (NaN to 0); its cell is floor(u) - shift,
  /// exactly as GridGeometry::worldToCell floors.
  static std::int64_t fixed(double u, std::int64_t shift, int cells) {
    const double lo = static_cast<double>(shift);
    const double c = std::max(lo, std::min(u, lo + static_cast<double>(cells)));  // NaN to lo
    auto whole = static_cast<std::int64_t>(c);  // |c| < 2^63: c lies in [lo, lo + cells]
    whole -= static_cast<double>(whole) > c ? 1 : 0;
    const double fraction = c - static_cast<double>(whole);  // exact, in [0, 1)
    const auto sub = std::min(static_cast<std::int64_t>(fraction * kOne + 0.5), kOne - 1);
    return std::min((whole - shift) * kOne + sub, std::int64_t{cells} * kOne - 1);
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
      if (corners && e == tie &&
          left >= 2) {  // a corner: both edges in one step (see the struct comment)
        x += sx;
        y += sy;
        e += err_step_x - err_step_y;
        --left;
      } else if (e <= 0) {
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
