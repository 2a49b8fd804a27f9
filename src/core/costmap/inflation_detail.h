// Helpers shared by inflation.cpp and inflation_band.cpp (private to the core library).
#pragma once

#include <algorithm>
#include <cstddef>

#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {
namespace inflation_detail {

constexpr int kTileShift = 5;  // 32 x 32 cell tiles mark where lethal cells changed

/// `b` grown by `by` cells on every side, clamped to the grid.
inline CellBounds grow(const CellBounds& b, int by, const GridGeometry& g) {
  CellBounds out;
  out.min_x = std::max(0, b.min_x - by);
  out.min_y = std::max(0, b.min_y - by);
  out.max_x = std::min(g.sizeX() - 1, b.max_x + by);
  out.max_y = std::min(g.sizeY() - 1, b.max_y + by);
  return out;
}

inline std::size_t area(const CellBounds& b) {
  return b.empty() ? 0
                   : static_cast<std::size_t>(b.max_x - b.min_x + 1) *
                         static_cast<std::size_t>(b.max_y - b.min_y + 1);
}

}  // namespace inflation_detail
}  // namespace downstream_perception
