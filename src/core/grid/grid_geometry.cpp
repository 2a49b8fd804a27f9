#include "downstream_perception/core/grid/grid_geometry.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace downstream_perception {

std::string GridGeometry::validate(int size_x, int size_y, double resolution_m, double origin_x_m,
                                   double origin_y_m) {
  std::ostringstream why;
  if (!(resolution_m > 0.0 && resolution_m <= kMaxResolutionM)) {
    why << "resolution must be in (0, " << kMaxResolutionM << "] m, got " << resolution_m;
  } else if (size_x <= 0 || size_y <= 0) {
    why << "grid size must be positive, got " << size_x << " x " << size_y << " cells";
  } else if (size_x > kMaxCellsPerAxis || size_y > kMaxCellsPerAxis) {
    why << "grid of " << size_x << " x " << size_y << " cells exceeds the per-axis limit of "
        << kMaxCellsPerAxis << " cells";
  } else if (static_cast<std::size_t>(size_x) * static_cast<std::size_t>(size_y) > kMaxCells) {
    why << "grid of " << size_x << " x " << size_y << " cells exceeds the limit of " << kMaxCells
        << " cells (check width/height/resolution)";
  } else if (!std::isfinite(origin_x_m) || !std::isfinite(origin_y_m)) {
    why << "origin must be finite, got (" << origin_x_m << ", " << origin_y_m << ")";
  }
  return why.str();
}

GridGeometry::GridGeometry(int size_x, int size_y, double resolution_m, double origin_x_m,
                           double origin_y_m)
    : size_x_(size_x),
      size_y_(size_y),
      resolution_(resolution_m),
      origin_x_(origin_x_m),
      origin_y_(origin_y_m),
      lattice_x_(origin_x_m),
      lattice_y_(origin_y_m) {
  const std::string why = validate(size_x, size_y, resolution_m, origin_x_m, origin_y_m);
  if (!why.empty()) throw std::invalid_argument(why);
}

GridGeometry GridGeometry::shiftedBy(int dx, int dy) const {
  // The origin moves as costmap_2d moves it (origin + cells * resolution), so a host's origin and
  // ours stay equal; cells are still counted on the unchanged lattice.
  GridGeometry g(size_x_, size_y_, resolution_, origin_x_ + dx * resolution_,
                 origin_y_ + dy * resolution_);
  g.lattice_x_ = lattice_x_;
  g.lattice_y_ = lattice_y_;
  g.lattice_shift_x_ = lattice_shift_x_ + dx;
  g.lattice_shift_y_ = lattice_shift_y_ + dy;
  return g;
}

bool GridGeometry::worldToCell(double wx, double wy, CellIndex* cell) const {
  if (!std::isfinite(wx) || !std::isfinite(wy)) return false;
  const double gx = cellCoordinate(latticeUnitsX(wx), lattice_shift_x_);
  const double gy = cellCoordinate(latticeUnitsY(wy), lattice_shift_y_);
  // Compare as doubles first: casting a huge value to int is undefined.
  if (gx < 0.0 || gy < 0.0 || gx >= size_x_ || gy >= size_y_) {
    cell->x = static_cast<int>(std::clamp(gx, -1.0, static_cast<double>(size_x_)));
    cell->y = static_cast<int>(std::clamp(gy, -1.0, static_cast<double>(size_y_)));
    return false;
  }
  cell->x = static_cast<int>(gx);
  cell->y = static_cast<int>(gy);
  return true;
}

void GridGeometry::expandWorldBox(const CellBounds& cells, double* min_x, double* min_y,
                                  double* max_x, double* max_y) const {
  if (cells.empty()) return;
  *min_x = std::min(*min_x, origin_x_ + cells.min_x * resolution_);
  *min_y = std::min(*min_y, origin_y_ + cells.min_y * resolution_);
  *max_x = std::max(*max_x, origin_x_ + (cells.max_x + 0.5) * resolution_);
  *max_y = std::max(*max_y, origin_y_ + (cells.max_y + 0.5) * resolution_);
}

CellBounds GridGeometry::worldBoxToCells(double min_x, double min_y, double max_x,
                                         double max_y) const {
  CellBounds b;
  if (!(min_x <= max_x) || !(min_y <= max_y)) return b;
  const double lo_x = cellCoordinate(latticeUnitsX(min_x), lattice_shift_x_);
  const double lo_y = cellCoordinate(latticeUnitsY(min_y), lattice_shift_y_);
  const double hi_x = cellCoordinate(latticeUnitsX(max_x), lattice_shift_x_);
  const double hi_y = cellCoordinate(latticeUnitsY(max_y), lattice_shift_y_);
  if (hi_x < 0.0 || hi_y < 0.0 || lo_x >= size_x_ || lo_y >= size_y_) return b;
  b.min_x = static_cast<int>(std::max(lo_x, 0.0));
  b.min_y = static_cast<int>(std::max(lo_y, 0.0));
  b.max_x = static_cast<int>(std::min(hi_x, size_x_ - 1.0));
  b.max_y = static_cast<int>(std::min(hi_y, size_y_ - 1.0));
  return b;
}

}  // namespace downstream_perception
