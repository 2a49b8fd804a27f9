// Translation of log-odds states into costmap costs (the obstacle layer's updateCosts).
#pragma once

#include <cstdint>
#include <string>

#include "downstream_perception/core/costmap/log_odds_grid.h"
#include "downstream_perception/core/grid/costmap.h"

namespace downstream_perception {

/// How a layer's costs meet what earlier layers wrote (costmap_2d's combination_method codes).
enum class CombinationMethod : int {
  kOverwrite = 0,  ///< the layer's known cells replace the master's (updateWithOverwrite)
  kMaximum = 1,    ///< max(master, layer), NO_INFORMATION in the master always replaced
};
/// Empty if `code` is a valid combination_method, else the reason.
std::string validateCombinationMethod(int code);

/// For every cell of `window` (inclusive, clamped to both grids, which must share a geometry):
/// occupied -> LETHAL_OBSTACLE, free -> FREE_SPACE, unknown -> `unknown_cost` if `write_unknown`,
/// else the master cell is left as it is (costmap_2d's updateWithOverwrite never writes
/// NO_INFORMATION over what earlier layers put there). With kMaximum a cell only rises (or
/// replaces NO_INFORMATION). Returns the number of cells visited.
std::size_t writeStateCosts(const LogOddsGrid& grid, const CellBounds& window, bool write_unknown,
                            std::uint8_t unknown_cost, Costmap* master,
                            CombinationMethod method = CombinationMethod::kOverwrite);

}  // namespace downstream_perception
