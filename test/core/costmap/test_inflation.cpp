#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "downstream_perception/core/costmap/inflation.h"

using namespace downstream_perception;  // NOLINT

namespace {

// The oracle: exact Euclidean distance to the nearest lethal cell by brute force, then the
// formula. Independent of the distance transform and the cost table.
std::vector<std::uint8_t> oracle(const Costmap& lethal_map, const InflationConfig& config) {
  const GridGeometry& g = lethal_map.geometry();
  std::vector<std::pair<int, int>> lethal;
  for (int y = 0; y < g.sizeY(); ++y) {
    for (int x = 0; x < g.sizeX(); ++x) {
      if (lethal_map.cost(x, y) == cost::kLethalObstacle) lethal.emplace_back(x, y);
    }
  }
  std::vector<std::uint8_t> out(g.cellCount(), 0);
  for (int y = 0; y < g.sizeY(); ++y) {
    for (int x = 0; x < g.sizeX(); ++x) {
      long best = -1;
      for (const auto& [lx, ly] : lethal) {
        const long d2 = static_cast<long>(lx - x) * (lx - x) + static_cast<long>(ly - y) * (ly - y);
        if (best < 0 || d2 < best) best = d2;
      }
      if (best >= 0) {
        out[g.index(x, y)] =
            inflationCost(std::sqrt(static_cast<double>(best)) * g.resolution(), config);
      }
    }
  }
  return out;
}

Costmap randomLethalMap(const GridGeometry& g, double density, std::mt19937& rng) {
  Costmap map(g, cost::kFreeSpace);
  std::bernoulli_distribution lethal(density);
  for (int y = 0; y < g.sizeY(); ++y) {
    for (int x = 0; x < g.sizeX(); ++x) {
      if (lethal(rng)) map.setCost(x, y, cost::kLethalObstacle);
    }
  }
  return map;
}

CellBounds everything(const GridGeometry& g) {
  CellBounds b;
  b.expand(0, 0);
  b.expand(g.sizeX() - 1, g.sizeY() - 1);
  return b;
}

}  // namespace

TEST(InflationCost, LessonGoldenNumbers) {
  // 252 * exp(-3 (d - 0.20)) at 5 cm cells: 4 cells -> 253 (inscribed), 6 -> 186.7, 8 -> 138.3,
  // and the planner's cell Q 12 cells out -> 75.9. Costs are truncated like costmap_2d's.
  InflationConfig c;
  c.cost_scaling_factor = 3.0;
  c.inscribed_radius = 0.20;
  c.inflation_radius = 0.60;
  EXPECT_EQ(inflationCost(0.0, c), 254);
  EXPECT_EQ(inflationCost(0.05, c), 253);
  EXPECT_EQ(inflationCost(4 * 0.05, c), 253);
  EXPECT_NEAR(252.0 * std::exp(-3.0 * 0.10), 186.7, 0.05);
  EXPECT_EQ(inflationCost(6 * 0.05, c), 186);
  EXPECT_NEAR(252.0 * std::exp(-3.0 * 0.20), 138.3, 0.05);
  EXPECT_EQ(inflationCost(8 * 0.05, c), 138);
  EXPECT_EQ(inflationCost(12 * 0.05, c), 75);  // exactly on the inflation radius: still inside
  EXPECT_EQ(inflationCost(13 * 0.05, c), 0);   // beyond it
}

TEST(InflationCost, TableMatchesFormulaForEverySquaredDistance) {
  InflationConfig c;
  c.inflation_radius = 1.0;
  c.inscribed_radius = 0.3;
  const Inflator inflator(c, 0.05);
  EXPECT_EQ(inflator.radiusCells(), 20);
  for (int d2 = 0; d2 <= 500; ++d2) {
    ASSERT_EQ(inflator.costOfSquaredDistance(d2), inflationCost(std::sqrt(d2) * 0.05, c)) << d2;
  }
}

TEST(BoundedSquaredDistances, ExactAgainstBruteForceInsideTheCap) {
  std::mt19937 rng(4);
  const GridGeometry g(47, 31, 1.0, 0.0, 0.0);
  for (const double density : {0.002, 0.02, 0.2}) {
    const Costmap map = randomLethalMap(g, density, rng);
    std::vector<std::uint8_t> lethal(g.cellCount());
    for (std::size_t i = 0; i < g.cellCount(); ++i)
      lethal[i] = map.cells()[i] == cost::kLethalObstacle;
    std::vector<std::int32_t> d2;
    const int cap = 9;
    boundedSquaredDistances(lethal.data(), g.sizeX(), everything(g), everything(g), cap, &d2);
    for (int y = 0; y < g.sizeY(); ++y) {
      for (int x = 0; x < g.sizeX(); ++x) {
        long best = kFarSquared;
        for (int ly = 0; ly < g.sizeY(); ++ly) {
          for (int lx = 0; lx < g.sizeX(); ++lx) {
            if (lethal[g.index(lx, ly)])
              best = std::min<long>(best, (lx - x) * (lx - x) + (ly - y) * (ly - y));
          }
        }
        const long got = d2[g.index(x, y)];
        if (best <= static_cast<long>(cap) * cap) {
          ASSERT_EQ(got, best) << x << "," << y;
        } else {
          ASSERT_GE(got, best) << x << "," << y;  // beyond the cap: never closer than the truth
        }
      }
    }
  }
}

TEST(Inflator, FullUpdateMatchesTheExactOracleOnRandomMaps) {
  std::mt19937 rng(7);
  const GridGeometry g(64, 48, 0.05, -1.0, 2.0);
  for (const double radius : {0.0, 0.05, 0.33, 0.55, 1.0, 5.0}) {
    for (const double density : {0.001, 0.01, 0.05}) {
      InflationConfig c;
      c.inflation_radius = radius;
      c.cost_scaling_factor = 3.0;
      c.inscribed_radius = std::min(radius, 0.17);
      Costmap map = randomLethalMap(g, density, rng);
      const auto expected = oracle(map, c);
      Inflator inflator(c, g.resolution());
      inflator.update(&map, everything(g));
      for (std::size_t i = 0; i < g.cellCount(); ++i) {
        ASSERT_EQ(inflator.costs()[i], expected[i]) << "radius " << radius << " cell " << i;
        ASSERT_EQ(map.cells()[i], expected[i]) << "master, radius " << radius << " cell " << i;
      }
    }
  }
}

TEST(Inflator, BandRestrictedFullUpdateMatchesTheOracleOnOneAndTwoThreads) {
  // Maps larger than a strip, with lethal cells in a few clusters (walls, a pillar, lone cells
  // near the borders): the full update recomputes only the band around them, split over two
  // threads, and must still equal the brute-force oracle everywhere.
  std::mt19937 rng(11);
  for (const auto& [sx, sy] : {std::pair<int, int>{300, 230}, {97, 410}, {33, 33}}) {
    const GridGeometry g(sx, sy, 0.05, 0.3, -2.0);
    for (const double radius : {0.05, 0.55, 1.6}) {
      Costmap map(g, cost::kFreeSpace);
      std::uniform_int_distribution<int> ux(0, sx - 1);
      std::uniform_int_distribution<int> uy(0, sy - 1);
      for (int k = 0; k < 4; ++k) {  // short walls
        const int x0 = ux(rng);
        const int y0 = uy(rng);
        for (int i = 0; i < 25; ++i) {
          const int x = k % 2 == 0 ? std::min(sx - 1, x0 + i) : x0;
          const int y = k % 2 == 0 ? y0 : std::min(sy - 1, y0 + i);
          map.setCost(x, y, cost::kLethalObstacle);
        }
      }
      map.setCost(0, sy - 1, cost::kLethalObstacle);
      map.setCost(sx - 1, 0, cost::kLethalObstacle);
      InflationConfig c;
      c.inflation_radius = radius;
      c.cost_scaling_factor = 2.0;
      c.inscribed_radius = 0.1;
      const auto expected = oracle(map, c);
      for (const int threads : {1, 2}) {
        Costmap master = map;
        Inflator inflator(c, g.resolution());
        inflator.setThreads(threads);
        const InflationStats stats = inflator.update(&master, everything(g));
        for (std::size_t i = 0; i < g.cellCount(); ++i) {
          ASSERT_EQ(inflator.costs()[i], expected[i])
              << sx << "x" << sy << " radius " << radius << " threads " << threads << " cell " << i;
        }
        if (sx == 300 && radius < 1.0) {
          // Sparse lethal cells on a large map: the band is a fraction of the map.
          EXPECT_LT(stats.cells_recomputed, g.cellCount() * 3 / 4) << radius;
          EXPECT_GE(stats.regions, 2u);
        }
      }
    }
  }
}

TEST(Inflator, FullUpdateOfAMapWithoutLethalCellsRecomputesNothing) {
  const GridGeometry g(200, 150, 0.05, 0.0, 0.0);
  Costmap map(g, cost::kFreeSpace);
  InflationConfig c;
  c.inflation_radius = 0.55;
  Inflator inflator(c, g.resolution());
  const InflationStats stats = inflator.update(&map, everything(g));
  EXPECT_EQ(stats.cells_recomputed, 0u);
  EXPECT_EQ(stats.regions, 0u);
  for (const std::uint8_t v : inflator.costs()) ASSERT_EQ(v, 0);
}

TEST(Inflator, LethalCellsOnTheBorderAndRadiusZero) {
  const GridGeometry g(20, 10, 0.1, 0.0, 0.0);
  Costmap map(g, cost::kFreeSpace);
  map.setCost(0, 0, cost::kLethalObstacle);
  map.setCost(19, 9, cost::kLethalObstacle);
  map.setCost(10, 0, cost::kLethalObstacle);
  InflationConfig c;
  c.inflation_radius = 0.3;
  c.inscribed_radius = 0.1;
  Inflator inflator(c, g.resolution());
  Costmap inflated = map;
  inflator.update(&inflated, everything(g));
  const auto expected = oracle(map, c);
  for (std::size_t i = 0; i < g.cellCount(); ++i) ASSERT_EQ(inflated.cells()[i], expected[i]);
  EXPECT_EQ(inflated.cost(1, 0), 253);
  EXPECT_EQ(inflated.cost(18, 9), 253);
  // Radius 0 (costmap_2d hangs there, navigation#556): only the lethal cells carry cost.
  c.inflation_radius = 0.0;
  c.inscribed_radius = 0.0;
  Inflator zero(c, g.resolution());
  Costmap plain = map;
  zero.update(&plain, everything(g));
  EXPECT_EQ(plain.cells(), map.cells());
}

TEST(Inflator, UnknownCellsFollowCostmap2dMergeRule) {
  const GridGeometry g(20, 1, 0.05, 0.0, 0.0);
  Costmap map(g, cost::kNoInformation);
  map.setCost(0, 0, cost::kLethalObstacle);
  InflationConfig c;
  c.inflation_radius = 0.5;
  c.inscribed_radius = 0.1;
  c.cost_scaling_factor = 3.0;
  Inflator inflator(c, g.resolution());
  Costmap m1 = map;
  inflator.update(&m1, everything(g));
  EXPECT_EQ(m1.cost(2, 0), 253);                   // inscribed cost overwrites unknown
  EXPECT_EQ(m1.cost(3, 0), cost::kNoInformation);  // lower costs do not
  c.inflate_unknown = true;
  Inflator unknown(c, g.resolution());
  Costmap m2 = map;
  unknown.update(&m2, everything(g));
  EXPECT_EQ(m2.cost(3, 0), inflationCost(0.15, c));
  EXPECT_EQ(m2.cost(15, 0), cost::kNoInformation);  // beyond the radius (cost 0) stays unknown
}

// The incremental path must give exactly what a full recomputation gives, after any sequence of
// bounded changes (the LayeredCostmap resets the window, the obstacle layer writes, inflation
// merges over the window grown by the radius).
TEST(Inflator, IncrementalUpdatesEqualFullRecomputation) {
  std::mt19937 rng(13);
  const GridGeometry g(150, 90, 0.05, 0.0, 0.0);
  for (const double radius : {0.0, 0.2, 0.55, 2.0}) {
    InflationConfig c;
    c.inflation_radius = radius;
    c.inscribed_radius = 0.1;
    Costmap truth = randomLethalMap(g, 0.01, rng);
    Costmap master = truth;
    Inflator inflator(c, g.resolution());
    inflator.update(&master, everything(g));
    std::uniform_int_distribution<int> ux(0, g.sizeX() - 1), uy(0, g.sizeY() - 1);
    std::uniform_int_distribution<int> extent(0, 12);
    for (int step = 0; step < 60; ++step) {
      // Lethal cells change inside a few random boxes.
      CellBounds changed;
      for (int k = 0; k < 1 + step % 4; ++k) {
        const int x0 = ux(rng), y0 = uy(rng), w = extent(rng), h = extent(rng);
        for (int y = y0; y <= std::min(g.sizeY() - 1, y0 + h); ++y) {
          for (int x = x0; x <= std::min(g.sizeX() - 1, x0 + w); ++x) {
            truth.setCost(x, y, rng() % 7 == 0 ? cost::kLethalObstacle : cost::kFreeSpace);
            changed.expand(x, y);
          }
        }
      }
      CellBounds window = changed;
      window.min_x -= inflator.radiusCells();
      window.min_y -= inflator.radiusCells();
      window.max_x += inflator.radiusCells();
      window.max_y += inflator.radiusCells();
      window = master.clamp(window);
      for (int y = window.min_y; y <= window.max_y; ++y) {
        for (int x = window.min_x; x <= window.max_x; ++x) master.setCost(x, y, truth.cost(x, y));
      }
      inflator.update(&master, window);
    }
    Costmap fresh = truth;
    Inflator full(c, g.resolution());
    full.update(&fresh, everything(g));
    ASSERT_EQ(inflator.costs(), full.costs()) << "radius " << radius;
    ASSERT_EQ(master.cells(), fresh.cells()) << "radius " << radius;
  }
}

TEST(Inflator, RejectsAbsurdConfigs) {
  InflationConfig c;
  c.inflation_radius = std::nan("");
  EXPECT_THROW(Inflator(c, 0.05), std::invalid_argument);
  c.inflation_radius = -1.0;
  EXPECT_THROW(Inflator(c, 0.05), std::invalid_argument);
  c = InflationConfig{};
  c.cost_scaling_factor = -2.0;
  EXPECT_THROW(Inflator(c, 0.05), std::invalid_argument);
  EXPECT_THROW(Inflator(InflationConfig{}, 0.0), std::invalid_argument);
  EXPECT_TRUE(InflationConfig{}.validate().empty());
}

// Issue 17 item 8: 0.55 m at 2e-5 m (27,500 cells) took 28 s per update; at 5e-324 m the cost
// table could not be allocated ("cannot create std::vector larger than max_size()").
TEST(Inflator, RefusesRadiiOfTooManyCells) {
  InflationConfig c;  // 0.55 m
  for (const double res : {2e-5, 5e-324, 1e-200}) {
    const std::string why = c.validate(res);
    EXPECT_NE(why.find("cells"), std::string::npos) << res << ": " << why;
    EXPECT_THROW(Inflator(c, res), std::invalid_argument) << res;
  }
  for (const double res : {0.0, -0.05, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EXPECT_NE(c.validate(res).find("resolution"), std::string::npos) << res;
    EXPECT_THROW(Inflator(c, res), std::invalid_argument) << res;
  }
  // The bound itself is accepted, one cell more is not.
  c.inflation_radius = InflationConfig::kMaxRadiusCells * 0.05;
  EXPECT_EQ(c.validate(0.05), "");
  Inflator at_limit(c, 0.05);
  EXPECT_EQ(at_limit.radiusCells(), InflationConfig::kMaxRadiusCells);
  c.inflation_radius = (InflationConfig::kMaxRadiusCells + 1) * 0.01;
  EXPECT_FALSE(c.validate(0.01).empty());
  // A radius of 0 fits any resolution; a refused setConfig keeps the old config.
  c.inflation_radius = 0.0;
  EXPECT_EQ(c.validate(5e-324), "");
  Inflator kept(InflationConfig{}, 0.05);
  EXPECT_THROW(kept.setConfig(InflationConfig{}, 2e-5), std::invalid_argument);
  EXPECT_EQ(kept.radiusCells(), 11);
}

TEST(Inflator, RollingWindowShiftsEqualFullRecomputation) {
  // A robot-centred window moving over a fixed random world: after each whole-cell shift (and
  // the lethal cells that came into view), the shifted cache must equal a fresh inflation of the
  // same window. Shifts cover +-x, +-y, diagonal, larger than a tile and larger than the radius.
  std::mt19937 rng(29);
  const GridGeometry world_g(400, 300, 0.05, -10.0, -7.5);
  const Costmap world = randomLethalMap(world_g, 0.004, rng);
  for (const double radius : {0.0, 0.3, 1.0}) {
    InflationConfig c;
    c.inflation_radius = radius;
    c.inscribed_radius = 0.1;
    const auto window_from_world = [&](const GridGeometry& g) {
      Costmap m(g, cost::kNoInformation);
      for (int y = 0; y < g.sizeY(); ++y) {
        for (int x = 0; x < g.sizeX(); ++x) {
          double wx = 0.0, wy = 0.0;
          g.cellCentre(x, y, &wx, &wy);
          CellIndex w;
          if (world_g.worldToCell(wx, wy, &w)) m.setCost(x, y, world.cost(w.x, w.y));
        }
      }
      return m;
    };
    GridGeometry g(120, 80, 0.05, -3.0, -2.0);
    Costmap master = window_from_world(g);
    Inflator inflator(c, g.resolution());
    inflator.update(&master, everything(g));
    const int moves[][2] = {{1, 0}, {0, -1}, {3, 2}, {-5, 7}, {40, 0}, {0, -33}, {-70, -9}, {2, 0}};
    int k = 0;
    for (const auto& move : moves) {
      master.shift(move[0], move[1]);
      inflator.shift(move[0], move[1]);
      if (++k % 3 == 0) {  // two shifts between updates: pending bands must move too
        master.shift(-1, 1);
        inflator.shift(-1, 1);
      }
      g = master.geometry();
      // What the layers would redraw: the whole window (the LayeredCostmap redraws all on a
      // shift); the Inflator must still only recompute near the edges.
      master = window_from_world(g);
      const InflationStats stats = inflator.update(&master, everything(g));
      EXPECT_LT(stats.cells_recomputed, g.cellCount() + 1);
      Costmap fresh = window_from_world(g);
      Inflator full(c, g.resolution());
      full.update(&fresh, everything(g));
      ASSERT_EQ(inflator.costs(), full.costs())
          << "radius " << radius << " after move " << move[0] << "," << move[1];
      ASSERT_EQ(master.cells(), fresh.cells()) << "radius " << radius;
    }
  }
}

TEST(Inflator, SmallShiftRecomputesOnlyTheEdges) {
  std::mt19937 rng(31);
  const GridGeometry g(400, 400, 0.05, 0.0, 0.0);
  Costmap master = randomLethalMap(g, 0.002, rng);
  InflationConfig c;
  c.inflation_radius = 0.3;
  Inflator inflator(c, g.resolution());
  inflator.update(&master, everything(g));
  master.shift(1, 0);
  inflator.shift(1, 0);
  const InflationStats stats = inflator.update(&master, everything(master.geometry()));
  // The exposed column and the band of radius + 1 columns at the other edge: 8 of 400 columns.
  EXPECT_EQ(stats.cells_recomputed, 8u * 400u);
}

// Issue 17 item 8: std::abs(INT_MIN) in Inflator::shift is undefined (UBSan); any shift of at
// least the grid's size must simply recompute everything.
TEST(Inflator, ExtremeShiftsEqualFullRecomputation) {
  std::mt19937 rng(37);
  const GridGeometry g(60, 50, 0.05, 0.0, 0.0);
  InflationConfig c;
  c.inflation_radius = 0.3;
  for (const int d : {std::numeric_limits<int>::min(), std::numeric_limits<int>::max(), -60, 50}) {
    Costmap master = randomLethalMap(g, 0.01, rng);
    Inflator inflator(c, g.resolution());
    inflator.update(&master, everything(g));
    master.shift(d, 1);
    inflator.shift(d, 1);
    const GridGeometry moved = master.geometry();
    Costmap fresh = randomLethalMap(moved, 0.01, rng);
    master = fresh;
    inflator.update(&master, everything(moved));
    Inflator full(c, moved.resolution());
    full.update(&fresh, everything(moved));
    ASSERT_EQ(inflator.costs(), full.costs()) << "shift " << d;
    ASSERT_EQ(master.cells(), fresh.cells()) << "shift " << d;
  }
}

TEST(InflationRadius, ACellExactlyOnTheRadiusCountsAtAFloat32Resolution) {
  // A map_server map's resolution is float32: 0.1 arrives as 0.100000001490116, so 1.0 m is
  // 9.99999985 cells. The cell 10 cells from the wall is on the radius and gets a cost, as in
  // costmap_2d (252 * exp(-3 * (1.0 - 0.087)) = 16).
  const double resolution = static_cast<double>(0.1f);
  InflationConfig config;
  config.inflation_radius = 1.0;
  config.cost_scaling_factor = 3.0;
  config.inscribed_radius = 0.087;
  const GridGeometry g(41, 41, resolution, 0.0, 0.0);
  Costmap map(g, cost::kFreeSpace);
  map.setCost(20, 20, cost::kLethalObstacle);
  Inflator inflator(config, resolution);
  EXPECT_EQ(inflator.radiusCells(), 10);
  inflator.update(&map, everything(g));
  EXPECT_EQ(map.cost(30, 20), 16);
  EXPECT_EQ(map.cost(20, 10), 16);
  EXPECT_EQ(map.cost(31, 20), 0);
}
