#include "downstream_perception/core/costmap/log_odds_costs.h"

#include <algorithm>
#include <stdexcept>

#include "downstream_perception/core/parallel/avx2_clones.h"

namespace downstream_perception {

std::string validateCombinationMethod(int code) {
  if (code == static_cast<int>(CombinationMethod::kOverwrite) ||
      code == static_cast<int>(CombinationMethod::kMaximum)) {
    return {};
  }
  return "combination_method must be 0 (overwrite) or 1 (maximum), got " + std::to_string(code);
}

namespace {

// One row; `Combine` decides the new master value from (old, layer cost). The state test works on
// raw values: between scans every flag bit is clear, so raw = 2 * units. The loop is
// compare/select only and vectorises.
template <bool kWriteUnknown, class Combine>
void writeRow(const std::int16_t* in, std::uint8_t* dst, int width, std::int16_t occupied_raw,
              std::int16_t free_raw, std::uint8_t unknown_cost, Combine combine) {
  // Compares on int16 (raw values are 2 * units, |units| <= 16383: they fit), so that every
  // instantiation vectorises.
  for (int x = 0; x < width; ++x) {
    const std::int16_t v = in[x];
    const std::uint8_t old = dst[x];
    const std::uint8_t layer =
        v > occupied_raw ? cost::kLethalObstacle
                         : (v < free_raw ? cost::kFreeSpace : (kWriteUnknown ? unknown_cost : old));
    dst[x] = (kWriteUnknown || v > occupied_raw || v < free_raw) ? combine(old, layer) : old;
  }
}

}  // namespace

// The rows vectorise twice as wide with AVX2 (avx2_clones.h; a map's window is up to millions of
// cells per update). Integer compares and selects only: both copies write the same bytes.
DP_AVX2_CLONES
std::size_t writeStateCosts(const LogOddsGrid& grid, const CellBounds& window, bool write_unknown,
                            std::uint8_t unknown_cost, Costmap* master, CombinationMethod method) {
  if (master == nullptr || !(grid.geometry() == master->geometry())) {
    throw std::invalid_argument(
        "writeStateCosts: the master grid's geometry differs from the layer's");
  }
  const CellBounds w = master->clamp(window);
  if (w.empty()) return 0;
  const GridGeometry& g = grid.geometry();
  const std::int16_t* raw = grid.rawCells();
  std::uint8_t* out = master->data();
  const auto occupied_raw = static_cast<std::int16_t>(2 * grid.occupiedUnits());
  const auto free_raw = static_cast<std::int16_t>(2 * grid.freeUnits());
  const int width = w.max_x - w.min_x + 1;
  const auto overwrite = [](std::uint8_t, std::uint8_t layer) { return layer; };
  const auto maximum = [](std::uint8_t old, std::uint8_t layer) {
    const std::uint8_t larger = std::max(old, layer);
    return old == cost::kNoInformation ? layer : larger;  // two selects: vectorises
  };
  for (int y = w.min_y; y <= w.max_y; ++y) {
    const std::size_t row = g.index(w.min_x, y);
    const std::int16_t* in = raw + row;
    std::uint8_t* dst = out + row;
    if (method == CombinationMethod::kMaximum) {
      if (write_unknown) {
        writeRow<true>(in, dst, width, occupied_raw, free_raw, unknown_cost, maximum);
      } else {
        writeRow<false>(in, dst, width, occupied_raw, free_raw, unknown_cost, maximum);
      }
    } else if (write_unknown) {
      writeRow<true>(in, dst, width, occupied_raw, free_raw, unknown_cost, overwrite);
    } else {
      writeRow<false>(in, dst, width, occupied_raw, free_raw, unknown_cost, overwrite);
    }
  }
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(w.max_y - w.min_y + 1);
}

}  // namespace downstream_perception
