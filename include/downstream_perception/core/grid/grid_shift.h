// Whole-cell origin shift of row-major grid data (rolling window), shared by every grid type.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {

/// Moves the content of a size_x by size_y row-major grid so that old cell (dx, dy) becomes
/// cell (0, 0): what stays in view keeps its world position, cells that come into view get
/// `fill`, cells that leave are dropped. Any dx, dy (a shift of 2^31 - 1 drops everything): the
/// overlap is computed in 64 bits, where size + shift cannot overflow.
template <class T>
void shiftGridData(std::vector<T>* cells, int size_x, int size_y, int dx, int dy, T fill) {
  if (dx == 0 && dy == 0) return;
  std::vector<T> shifted(cells->size(), fill);
  // Overlap of the old grid [dx, dx + size_x) x [dy, dy + size_y) with the new one; when it is
  // not empty, |dx| < size_x and |dy| < size_y, so the ints below hold every value.
  const std::int64_t x_lo = std::max<std::int64_t>(0, dx);
  const std::int64_t x_hi = std::min<std::int64_t>(size_x, std::int64_t{size_x} + dx);
  const std::int64_t y_lo = std::max<std::int64_t>(0, dy);
  const std::int64_t y_hi = std::min<std::int64_t>(size_y, std::int64_t{size_y} + dy);
  const auto index = [size_x](std::int64_t x, std::int64_t y) {
    return static_cast<std::ptrdiff_t>(y * size_x + x);
  };
  if (x_lo < x_hi) {
    for (std::int64_t y = y_lo; y < y_hi; ++y) {
      const auto src = cells->begin() + index(x_lo, y);
      std::copy(src, src + (x_hi - x_lo), shifted.begin() + index(x_lo - dx, y - dy));
    }
  }
  cells->swap(shifted);
}

/// The geometry after such a shift (GridGeometry::shiftedBy: the origin moves by (dx, dy) cells,
/// the lattice cells are counted on stays). Throws std::invalid_argument if the new origin is
/// not finite.
inline GridGeometry shiftedGeometry(const GridGeometry& g, int dx, int dy) {
  return g.shiftedBy(dx, dy);
}

}  // namespace downstream_perception
