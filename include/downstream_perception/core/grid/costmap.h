// A grid of 8-bit costs (costmap_2d's values: 0 free .. 252 inflated, 253 inscribed,
// 254 lethal, 255 unknown). The master grid of a LayeredCostmap is one of these.
#pragma once

#include <cstdint>
#include <vector>

#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {

class Costmap {
 public:
  Costmap() = default;
  Costmap(const GridGeometry& geometry, std::uint8_t default_value);

  const GridGeometry& geometry() const { return geometry_; }
  std::uint8_t defaultValue() const { return default_value_; }
  void setDefaultValue(std::uint8_t value) { default_value_ = value; }

  /// New geometry, every cell set to the default value.
  void resize(const GridGeometry& geometry);
  /// Every cell to the default value.
  void reset();
  /// Cells of the inclusive window to the default value (clamped to the grid).
  void resetWindow(const CellBounds& window);
  /// Moves the origin by whole cells (rolling window): content that stays in view keeps its world
  /// position, newly exposed cells get the default value. Any dx, dy; throws
  /// std::invalid_argument (and changes nothing) if the new origin would not be finite.
  void shift(int dx, int dy);

  std::uint8_t cost(int x, int y) const { return cells_[geometry_.index(x, y)]; }
  void setCost(int x, int y, std::uint8_t c) { cells_[geometry_.index(x, y)] = c; }
  std::uint8_t* data() { return cells_.data(); }
  const std::uint8_t* data() const { return cells_.data(); }
  const std::vector<std::uint8_t>& cells() const { return cells_; }

  /// Clamps a window to the grid; empty result if it misses.
  CellBounds clamp(const CellBounds& window) const;

 private:
  GridGeometry geometry_;
  std::uint8_t default_value_ = cost::kFreeSpace;
  std::vector<std::uint8_t> cells_;
};

}  // namespace downstream_perception
