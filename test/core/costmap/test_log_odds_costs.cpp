#include <gtest/gtest.h>

#include <random>

#include "downstream_perception/core/costmap/log_odds_costs.h"

using namespace downstream_perception;  // NOLINT

TEST(WriteStateCosts, TranslatesStatesByThresholdsInsideTheWindowOnly) {
  const GridGeometry g(6, 4, 0.1, 0.0, 0.0);
  LogOddsGrid grid(g);
  grid.setLogOdds(g.index(1, 1), 2.5);   // occupied (> 2)
  grid.setLogOdds(g.index(2, 1), 2.0);   // exactly at the threshold: unknown
  grid.setLogOdds(g.index(3, 1), -2.5);  // free (< -2)
  grid.setLogOdds(g.index(4, 1), -1.0);  // unknown
  Costmap master(g, 77);
  CellBounds window;
  window.expand(1, 1);
  window.expand(4, 2);
  EXPECT_EQ(writeStateCosts(grid, window, false, cost::kNoInformation, &master), 8u);
  EXPECT_EQ(master.cost(1, 1), cost::kLethalObstacle);
  EXPECT_EQ(master.cost(2, 1), 77);  // unknown leaves the master as it was
  EXPECT_EQ(master.cost(3, 1), cost::kFreeSpace);
  EXPECT_EQ(master.cost(4, 1), 77);
  EXPECT_EQ(master.cost(0, 1), 77);  // outside the window
  writeStateCosts(grid, window, true, cost::kNoInformation, &master);
  EXPECT_EQ(master.cost(2, 1), cost::kNoInformation);
  EXPECT_EQ(master.cost(1, 2), cost::kNoInformation);
  EXPECT_EQ(master.cost(5, 1), 77);
}

TEST(WriteStateCosts, MatchesPerCellStateOnRandomGridsAndClampsTheWindow) {
  const GridGeometry g(37, 23, 0.05, -1.0, -1.0);
  LogOddsGrid grid(g);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> l(-9.0, 9.0);
  for (std::size_t i = 0; i < g.cellCount(); ++i) grid.setLogOdds(i, l(rng));
  Costmap master(g, 100);
  CellBounds window;
  window.expand(-5, -5);
  window.expand(100, 100);  // clamped to the grid
  EXPECT_EQ(writeStateCosts(grid, window, true, cost::kFreeSpace, &master), g.cellCount());
  for (int y = 0; y < g.sizeY(); ++y) {
    for (int x = 0; x < g.sizeX(); ++x) {
      const CellState s = grid.state(g.index(x, y));
      const std::uint8_t expected =
          s == CellState::kOccupied ? cost::kLethalObstacle : cost::kFreeSpace;
      ASSERT_EQ(master.cost(x, y), expected) << x << "," << y;
    }
  }
  Costmap other(GridGeometry(5, 5, 0.05, 0.0, 0.0), 0);
  EXPECT_THROW(writeStateCosts(grid, window, true, 0, &other), std::invalid_argument);
}

TEST(LogOddsCosts, MaximumCombinationOnlyRaisesCosts) {
  const GridGeometry geometry(4, 1, 0.05, 0.0, 0.0);
  LogOddsGrid grid(geometry);
  grid.setLogOdds(0, 8.0);   // occupied
  grid.setLogOdds(1, -8.0);  // free
  grid.setLogOdds(2, -8.0);  // free
  // cell 3 unknown
  Costmap master(geometry, cost::kNoInformation);
  master.setCost(0, 0, 100);
  master.setCost(1, 0, 100);
  // master cell 2 is NO_INFORMATION, cell 3 holds 50
  master.setCost(3, 0, 50);
  CellBounds all;
  all.expand(0, 0);
  all.expand(3, 0);
  writeStateCosts(grid, all, false, cost::kFreeSpace, &master, CombinationMethod::kMaximum);
  EXPECT_EQ(master.cost(0, 0), cost::kLethalObstacle);  // 254 > 100
  EXPECT_EQ(master.cost(1, 0), 100);                    // free does not lower an earlier cost
  EXPECT_EQ(master.cost(2, 0), cost::kFreeSpace);       // NO_INFORMATION is always replaced
  EXPECT_EQ(master.cost(3, 0), 50);                     // unknown writes nothing
  // Overwrite on the same input lowers cell 1.
  master.setCost(1, 0, 100);
  writeStateCosts(grid, all, false, cost::kFreeSpace, &master, CombinationMethod::kOverwrite);
  EXPECT_EQ(master.cost(1, 0), cost::kFreeSpace);
  EXPECT_TRUE(validateCombinationMethod(0).empty());
  EXPECT_TRUE(validateCombinationMethod(1).empty());
  EXPECT_FALSE(validateCombinationMethod(99).empty());
}

// The row loop works on int16 raw values and selects (so that it vectorises): every combination of
// write_unknown and combination method against a per-cell statement of the rule, on a random
// master (free, lethal, unknown, anything) and log-odds up to the int16 extremes, in windows whose
// rows are longer than a vector and end in a partial one.
TEST(WriteStateCosts, EveryVariantMatchesThePerCellRule) {
  const GridGeometry g(67, 19, 0.05, 0.0, 0.0);
  LogOddsConfig wide;
  wide.clamp_min = -LogOddsGrid::kMaxLogOdds;
  wide.clamp_max = LogOddsGrid::kMaxLogOdds;
  LogOddsGrid grid(g, wide);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> l(-LogOddsGrid::kMaxLogOdds, LogOddsGrid::kMaxLogOdds);
  std::uniform_int_distribution<int> pick(0, 9);
  for (std::size_t i = 0; i < g.cellCount(); ++i) {
    const int k = pick(rng);  // some cells exactly on a threshold or at the extremes
    grid.setLogOdds(i, k == 0   ? wide.occupied_threshold
                       : k == 1 ? wide.free_threshold
                       : k == 2 ? LogOddsGrid::kMaxLogOdds
                       : k == 3 ? -LogOddsGrid::kMaxLogOdds
                                : l(rng));
  }
  Costmap start(g, 0);
  std::uniform_int_distribution<int> any(0, 255);
  for (int y = 0; y < g.sizeY(); ++y) {
    for (int x = 0; x < g.sizeX(); ++x) {
      const int k = pick(rng);
      start.setCost(x, y,
                    k < 2   ? cost::kNoInformation
                    : k < 4 ? cost::kFreeSpace
                    : k < 5 ? cost::kLethalObstacle
                            : static_cast<std::uint8_t>(any(rng)));
    }
  }
  CellBounds window;
  window.expand(3, 2);
  window.expand(61, 17);
  for (const bool write_unknown : {false, true}) {
    for (const CombinationMethod method :
         {CombinationMethod::kOverwrite, CombinationMethod::kMaximum}) {
      Costmap master = start;
      writeStateCosts(grid, window, write_unknown, 77, &master, method);
      for (int y = 0; y < g.sizeY(); ++y) {
        for (int x = 0; x < g.sizeX(); ++x) {
          const std::uint8_t old = start.cost(x, y);
          std::uint8_t expected = old;
          const CellState s = grid.state(g.index(x, y));
          const bool inside = x >= 3 && x <= 61 && y >= 2 && y <= 17;
          if (inside && (s != CellState::kUnknown || write_unknown)) {
            const std::uint8_t layer = s == CellState::kOccupied ? cost::kLethalObstacle
                                       : s == CellState::kFree   ? cost::kFreeSpace
                                                                 : std::uint8_t{77};
            expected = method == CombinationMethod::kOverwrite        ? layer
                       : (old == cost::kNoInformation || layer > old) ? layer
                                                                      : old;
          }
          ASSERT_EQ(master.cost(x, y), expected) << x << "," << y << " unknown " << write_unknown
                                                 << " method " << static_cast<int>(method);
        }
      }
    }
  }
}
