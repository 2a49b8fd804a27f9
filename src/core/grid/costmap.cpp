#include "downstream_perception/core/grid/costmap.h"

#include "downstream_perception/core/grid/grid_shift.h"

#include <algorithm>

namespace downstream_perception {

Costmap::Costmap(const GridGeometry& geometry, std::uint8_t default_value)
    : default_value_(default_value) {
  resize(geometry);
}

void Costmap::resize(const GridGeometry& geometry) {
  geometry_ = geometry;
  cells_.assign(geometry.cellCount(), default_value_);
}

void Costmap::reset() {
  std::fill(cells_.begin(), cells_.end(), default_value_);
}

CellBounds Costmap::clamp(const CellBounds& window) const {
  CellBounds b;
  if (window.empty() || geometry_.cellCount() == 0) return b;
  b.min_x = std::max(window.min_x, 0);
  b.min_y = std::max(window.min_y, 0);
  b.max_x = std::min(window.max_x, geometry_.sizeX() - 1);
  b.max_y = std::min(window.max_y, geometry_.sizeY() - 1);
  return b.empty() ? CellBounds{} : b;
}

void Costmap::resetWindow(const CellBounds& window) {
  const CellBounds b = clamp(window);
  if (b.empty()) return;
  for (int y = b.min_y; y <= b.max_y; ++y) {
    std::uint8_t* row = cells_.data() + geometry_.index(b.min_x, y);
    std::fill(row, row + (b.max_x - b.min_x + 1), default_value_);
  }
}

void Costmap::shift(int dx, int dy) {
  // The new geometry first: if its origin is not finite it throws and nothing has moved.
  const GridGeometry shifted = shiftedGeometry(geometry_, dx, dy);
  shiftGridData(&cells_, geometry_.sizeX(), geometry_.sizeY(), dx, dy, default_value_);
  geometry_ = shifted;
}

}  // namespace downstream_perception
