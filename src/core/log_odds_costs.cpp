#include "downstream_perception/core/log_odds_costs.h"

#include <algorithm>
#include <stdexcept>

namespace downstream_perception {

std::size_t writeStateCosts(const LogOddsGrid& grid, const CellBounds& window, bool write_unknown,
                            std::uint8_t unknown_cost, Costmap* master) {
  if (master == nullptr || !(grid.geometry() == master->geometry())) {
    throw std::invalid_argument(
        "writeStateCosts: the master grid's geometry differs from the layer's");
  }
  const CellBounds w = master->clamp(window);
  if (w.empty()) return 0;
  const GridGeometry& g = grid.geometry();
  const std::int16_t* raw = grid.rawCells();
  std::uint8_t* out = master->data();
  // Between scans every flag bit is clear, so raw = 2 * units and the thresholds compare on raw
  // values directly; the row loop is compare/select only and vectorises.
  const int occupied_raw = 2 * grid.occupiedUnits();
  const int free_raw = 2 * grid.freeUnits();
  const int width = w.max_x - w.min_x + 1;
  for (int y = w.min_y; y <= w.max_y; ++y) {
    const std::size_t row = g.index(w.min_x, y);
    const std::int16_t* in = raw + row;
    std::uint8_t* dst = out + row;
    if (write_unknown) {
      for (int x = 0; x < width; ++x) {
        const int v = in[x];
        dst[x] = v > occupied_raw ? cost::kLethalObstacle
                                  : (v < free_raw ? cost::kFreeSpace : unknown_cost);
      }
    } else {
      for (int x = 0; x < width; ++x) {
        const int v = in[x];
        dst[x] =
            v > occupied_raw ? cost::kLethalObstacle : (v < free_raw ? cost::kFreeSpace : dst[x]);
      }
    }
  }
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(w.max_y - w.min_y + 1);
}

}  // namespace downstream_perception
