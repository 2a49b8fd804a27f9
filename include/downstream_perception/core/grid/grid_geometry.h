// Placement of a 2-D grid in a world frame: origin (lower-left corner of cell (0, 0)),
// square cells of `resolution` metres, size_x by size_y cells, row-major (index = y * size_x + x),
// the same layout as nav_msgs/OccupancyGrid.
//
// Which cell a world point lies in is counted on a fixed lattice: from the origin the grid was
// built with (its "lattice anchor") in whole cells, minus the whole cells the origin has moved
// since (rolling-window shifts). The origin itself moves by adding dx * resolution, which rounds:
// counted from the moved origin, a point lying exactly on a cell edge (a simulated wall face, a
// point cloud on a lattice) would fall on one side of the edge after one shift and on the other
// after the next, and be marked in both cells. Counted on the lattice, the same world point is in
// the same world cell whatever the window did.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

namespace downstream_perception {

struct CellIndex {
  int x = 0;
  int y = 0;
  bool operator==(const CellIndex& o) const { return x == o.x && y == o.y; }
  bool operator!=(const CellIndex& o) const { return !(*this == o); }
};

/// Inclusive cell window [min_x, max_x] x [min_y, max_y]; empty when min > max.
struct CellBounds {
  int min_x = std::numeric_limits<int>::max();
  int min_y = std::numeric_limits<int>::max();
  int max_x = std::numeric_limits<int>::min();
  int max_y = std::numeric_limits<int>::min();

  bool empty() const { return min_x > max_x || min_y > max_y; }
  void expand(int x, int y) {
    if (x < min_x) min_x = x;
    if (x > max_x) max_x = x;
    if (y < min_y) min_y = y;
    if (y > max_y) max_y = y;
  }
  void expand(const CellBounds& o) {
    if (o.empty()) return;
    expand(o.min_x, o.min_y);
    expand(o.max_x, o.max_y);
  }
};

class GridGeometry {
 public:
  /// Largest grid we accept (2^28 cells = 16384^2): beyond it a typo in a parameter would
  /// silently allocate gigabytes.
  static constexpr std::size_t kMaxCells = std::size_t{1} << 28;
  /// Per-axis limit: keeps the ray walker's 64-bit fixed-point error term from overflowing.
  static constexpr int kMaxCellsPerAxis = 1 << 22;
  /// Largest cell (m): beyond it cell centres and extents leave the double range.
  static constexpr double kMaxResolutionM = 1000.0;

  GridGeometry() = default;
  /// Throws std::invalid_argument with a message naming the bad value.
  GridGeometry(int size_x, int size_y, double resolution_m, double origin_x_m, double origin_y_m);

  /// Empty string if the values make a valid grid, else the reason.
  static std::string validate(int size_x, int size_y, double resolution_m, double origin_x_m,
                              double origin_y_m);

  int sizeX() const { return size_x_; }
  int sizeY() const { return size_y_; }
  double resolution() const { return resolution_; }
  double originX() const { return origin_x_; }
  double originY() const { return origin_y_; }
  double sizeXMetres() const { return size_x_ * resolution_; }
  double sizeYMetres() const { return size_y_ * resolution_; }
  std::size_t cellCount() const { return static_cast<std::size_t>(size_x_) * size_y_; }

  bool inBounds(int cx, int cy) const { return cx >= 0 && cy >= 0 && cx < size_x_ && cy < size_y_; }
  std::size_t index(int cx, int cy) const {
    return static_cast<std::size_t>(cy) * static_cast<std::size_t>(size_x_) + cx;
  }
  CellIndex cellOf(std::size_t index) const {
    return {static_cast<int>(index % size_x_), static_cast<int>(index / size_x_)};
  }

  /// Cell containing a world point, by floor (an endpoint exactly on a cell edge belongs to the
  /// cell above it; negative offsets floor toward -inf), counted on the lattice (see the file
  /// comment). No bounds check.
  CellIndex worldToCellUnbounded(double wx, double wy) const {
    return {static_cast<int>(cellCoordinate(latticeUnitsX(wx), lattice_shift_x_)),
            static_cast<int>(cellCoordinate(latticeUnitsY(wy), lattice_shift_y_))};
  }
  /// Same as worldToCellUnbounded; returns false (and leaves *cell set) when outside the grid
  /// or when the point is not finite.
  bool worldToCell(double wx, double wy, CellIndex* cell) const;
  /// World coordinates of a cell's centre.
  void cellCentre(int cx, int cy, double* wx, double* wy) const {
    *wx = origin_x_ + (cx + 0.5) * resolution_;
    *wy = origin_y_ + (cy + 0.5) * resolution_;
  }
  /// Cell window covering a world box, clamped to the grid; empty if it misses the grid.
  CellBounds worldBoxToCells(double min_x, double min_y, double max_x, double max_y) const;
  /// Grows the world box (m) to cover `cells` (the inverse of worldBoxToCells). The far corner
  /// stays half a cell inside the last cell: its edge belongs to the next cell.
  void expandWorldBox(const CellBounds& cells, double* min_x, double* min_y, double* max_x,
                      double* max_y) const;

  /// The grid after a rolling-window shift: same size, origin moved by (dx, dy) whole cells (in
  /// double: no integer overflow), the same lattice. Throws std::invalid_argument if the new
  /// origin is not finite.
  GridGeometry shiftedBy(int dx, int dy) const;

  /// A world coordinate in cells from the lattice anchor: the one expression every cell lookup
  /// floors (the ray walker's too, so that its end cell is the cell a hit marks).
  double latticeUnitsX(double wx) const { return (wx - lattice_x_) / resolution_; }
  double latticeUnitsY(double wy) const { return (wy - lattice_y_) / resolution_; }
  /// The lattice anchor (m): the origin the grid was built with; shifts keep it.
  double latticeAnchorX() const { return lattice_x_; }
  double latticeAnchorY() const { return lattice_y_; }
  /// Whole cells the origin moved since the anchor: cell index = floor(lattice units) - shift.
  std::int64_t latticeShiftX() const { return lattice_shift_x_; }
  std::int64_t latticeShiftY() const { return lattice_shift_y_; }

  /// Placement only (size, resolution, origin). The lattice anchor is not compared: two grids at
  /// the same origin differ in it by rounding at most.
  bool operator==(const GridGeometry& o) const {
    return size_x_ == o.size_x_ && size_y_ == o.size_y_ && resolution_ == o.resolution_ &&
           origin_x_ == o.origin_x_ && origin_y_ == o.origin_y_;
  }
  bool operator!=(const GridGeometry& o) const { return !(*this == o); }

 private:
  /// floor(units) - shift as a double (exact below 2^53; out-of-range values stay out of range).
  static double cellCoordinate(double units, std::int64_t shift) {
    return std::floor(units) - static_cast<double>(shift);
  }

  int size_x_ = 0;
  int size_y_ = 0;
  double resolution_ = 0.05;
  double origin_x_ = 0.0;
  double origin_y_ = 0.0;
  double lattice_x_ = 0.0;  ///< the origin the grid was built with
  double lattice_y_ = 0.0;
  std::int64_t lattice_shift_x_ = 0;  ///< whole cells the origin moved since
  std::int64_t lattice_shift_y_ = 0;
};

}  // namespace downstream_perception
