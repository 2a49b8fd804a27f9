// Translation of log-odds states into costmap costs (the obstacle layer's updateCosts).
#pragma once

#include <cstdint>

#include "downstream_perception/core/costmap.h"
#include "downstream_perception/core/log_odds_grid.h"

namespace downstream_perception {

/// For every cell of `window` (inclusive, clamped to both grids, which must share a geometry):
/// occupied -> LETHAL_OBSTACLE, free -> FREE_SPACE, unknown -> `unknown_cost` if `write_unknown`,
/// else the master cell is left as it is (costmap_2d's updateWithOverwrite never writes
/// NO_INFORMATION over what earlier layers put there). Returns the number of cells written.
std::size_t writeStateCosts(const LogOddsGrid& grid, const CellBounds& window, bool write_unknown,
                            std::uint8_t unknown_cost, Costmap* master);

}  // namespace downstream_perception
