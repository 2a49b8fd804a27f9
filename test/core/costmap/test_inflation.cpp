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

// Copies `truth` into `master` over the changed cells grown by the inflation radius (clamped to
// the map), as a layer's update window does, and updates the inflation there.
void applyChange(const Costmap& truth, const CellBounds& changed, Costmap* master,
                 Inflator* inflator) {
  CellBounds window = changed;
  window.min_x -= inflator->radiusCells();
  window.min_y -= inflator->radiusCells();
  window.max_x += inflator->radiusCells();
  window.max_y += inflator->radiusCells();
  window = master->clamp(window);
  for (int y = window.min_y; y <= window.max_y; ++y) {
    for (int x = window.min_x; x <= window.max_x; ++x) master->setCost(x, y, truth.cost(x, y));
  }
  inflator->update(master, window);
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

// costmap_2d's inscribed test is hypot(dx, dy) * resolution <= inscribed in plain doubles; the
// cases worked by hand in double arithmetic.
TEST(InflationCost, InscribedTieAgainstCostmap2dIsFoundWhereTheDoublesRoundUp) {
  InflationConfig c;
  c.inflation_radius = 0.55;
  c.inscribed_radius = 0.3;
  // 6 * 0.05 = 0.30000000000000004 > 0.3: costmap_2d's cell 6 is outside, ours inside.
  EXPECT_GT(6 * 0.05, 0.3);
  EXPECT_EQ(inflationCost(6 * 0.05, c), 253);
  EXPECT_DOUBLE_EQ(inscribedTieCells(c, 0.05), 6.0);
  // 3 * 0.1 = 0.30000000000000004 too.
  EXPECT_DOUBLE_EQ(inscribedTieCells(c, 0.1), 3.0);
  // 5 * 0.05 rounds to exactly 0.25: both call it inscribed, no difference.
  c.inscribed_radius = 0.25;
  EXPECT_EQ(5 * 0.05, 0.25);
  EXPECT_EQ(inscribedTieCells(c, 0.05), 0.0);
  // Not a whole number of cells, and beyond the inflation radius: no tie to name.
  c.inscribed_radius = 0.32;
  EXPECT_EQ(inscribedTieCells(c, 0.05), 0.0);
  c.inscribed_radius = 0.3;
  c.inflation_radius = 0.2;
  EXPECT_EQ(inscribedTieCells(c, 0.05), 0.0);
  // 3-4-5: cell (3, 4) is 5 cells out, 5 * 0.1 = 0.5 exactly: no tie; 0.7 = 7 * 0.1 rounds up.
  c.inflation_radius = 1.0;
  c.inscribed_radius = 0.5;
  EXPECT_EQ(inscribedTieCells(c, 0.1), 0.0);
  c.inscribed_radius = 0.7;
  EXPECT_GT(7 * 0.1, 0.7);
  EXPECT_DOUBLE_EQ(inscribedTieCells(c, 0.1), 7.0);
  // Degenerate inputs name nothing.
  EXPECT_EQ(inscribedTieCells(c, 0.0), 0.0);
  c.inscribed_radius = 0.0;
  EXPECT_EQ(inscribedTieCells(c, 0.1), 0.0);
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
        inflator.setMethod(InflationMethod::kTransform);  // the band (kAuto would stamp here)
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
      applyChange(truth, changed, &master, &inflator);
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

// Issue 20: stamping and the transform are two exact ways to the same bytes. Each test forces
// one, then the other (and the automatic choice), on maps built to catch a shortcut: lethal cells
// on and near every edge, filled blocks (interior lethal cells get no stamp), unknown cells,
// radii of 0, 1 cell, a non-whole number of cells and more than the kernel limit, cost scaling
// factors from 0 (flat 252) to one that rounds most of the disc to 0, inscribed radius beyond the
// radius.
namespace {

Costmap edgeAndBlockMap(const GridGeometry& g, std::mt19937* rng, std::uint8_t background) {
  Costmap map(g, background);
  const int sx = g.sizeX();
  const int sy = g.sizeY();
  for (const auto& [x, y] : {std::pair<int, int>{0, 0},
                             {sx - 1, 0},
                             {0, sy - 1},
                             {sx - 1, sy - 1},
                             {sx / 2, 0},
                             {0, sy / 2},
                             {sx - 1, sy / 3},
                             {sx / 3, sy - 1},
                             {1, 1},
                             {sx - 2, sy - 2}}) {
    map.setCost(x, y, cost::kLethalObstacle);
  }
  // A filled block and a wall along the bottom edge.
  for (int y = sy / 3; y < sy / 3 + 7 && y < sy; ++y) {
    for (int x = sx / 4; x < sx / 4 + 9 && x < sx; ++x) map.setCost(x, y, cost::kLethalObstacle);
  }
  for (int x = 3; x < sx - 3; ++x) map.setCost(x, sy - 2, cost::kLethalObstacle);
  std::bernoulli_distribution lone(0.004);
  for (int y = 0; y < sy; ++y) {
    for (int x = 0; x < sx; ++x) {
      if (lone(*rng)) map.setCost(x, y, cost::kLethalObstacle);
    }
  }
  return map;
}

InflationStats inflateWith(InflationMethod method, int threads, const InflationConfig& c,
                           Costmap* map, std::vector<std::uint8_t>* costs) {
  Inflator inflator(c, map->geometry().resolution());
  inflator.setMethod(method);
  inflator.setThreads(threads);
  const InflationStats stats = inflator.update(map, everything(map->geometry()));
  *costs = inflator.costs();
  return stats;
}

}  // namespace

TEST(InflatorMethods, StampAndTransformEqualTheOracleOnEdgesBlocksAndUnknownCells) {
  std::mt19937 rng(41);
  const GridGeometry g(83, 61, 0.05, -0.4, 1.3);
  struct Case {
    double radius, csf, inscribed;
  };
  const Case cases[] = {{0.0, 10.0, 0.0}, {0.05, 10.0, 0.0},  {0.55, 10.0, 0.25},
                        {0.33, 0.0, 0.1}, {0.62, 60.0, 0.05}, {0.4, 3.0, 0.6},
                        {1.3, 2.0, 0.2},  {0.071, 1.0, 0.0}};
  for (const Case& k : cases) {
    for (const std::uint8_t background : {cost::kFreeSpace, cost::kNoInformation}) {
      for (const bool inflate_unknown : {false, true}) {
        InflationConfig c;
        c.inflation_radius = k.radius;
        c.cost_scaling_factor = k.csf;
        c.inscribed_radius = k.inscribed;
        c.inflate_unknown = inflate_unknown;
        const Costmap map = edgeAndBlockMap(g, &rng, background);
        const auto expected = oracle(map, c);
        std::vector<std::uint8_t> reference_master;
        for (const InflationMethod method :
             {InflationMethod::kTransform, InflationMethod::kStamp, InflationMethod::kAuto}) {
          for (const int threads : {1, 2}) {
            Costmap master = map;
            std::vector<std::uint8_t> costs;
            const InflationStats stats = inflateWith(method, threads, c, &master, &costs);
            const std::string what = "radius " + std::to_string(k.radius) + " csf " +
                                     std::to_string(k.csf) + " method " +
                                     std::to_string(static_cast<int>(method)) + " threads " +
                                     std::to_string(threads);
            ASSERT_EQ(costs, expected) << what;
            if (reference_master.empty()) reference_master = master.cells();
            ASSERT_EQ(master.cells(), reference_master) << what;  // same merge, same bytes
            if (method == InflationMethod::kStamp) {
              EXPECT_EQ(stats.regions_stamped, 1u) << what;
            }
            if (method == InflationMethod::kTransform) {
              EXPECT_EQ(stats.regions_stamped, 0u) << what;
            }
          }
        }
      }
    }
  }
}

TEST(InflatorMethods, StampSplitOverTwoThreadsEqualsOneThreadAndTheTransform) {
  // Enough stamp work for the second thread (a 1 m radius over 2 % lethal cells), on a map with
  // an odd number of rows, so the row halves and the stamps that straddle them are exercised.
  std::mt19937 rng(43);
  const GridGeometry g(410, 301, 0.05, 0.0, 0.0);
  const Costmap map = randomLethalMap(g, 0.02, rng);
  InflationConfig c;
  c.inflation_radius = 1.0;
  c.cost_scaling_factor = 3.0;
  c.inscribed_radius = 0.2;
  std::vector<std::uint8_t> transform, one, two;
  Costmap m0 = map, m1 = map, m2 = map;
  inflateWith(InflationMethod::kTransform, 1, c, &m0, &transform);
  inflateWith(InflationMethod::kStamp, 1, c, &m1, &one);
  inflateWith(InflationMethod::kStamp, 2, c, &m2, &two);
  ASSERT_EQ(one, transform);
  ASSERT_EQ(two, transform);
  ASSERT_EQ(m2.cells(), m0.cells());
  // Spot check against the oracle's formula: cell (0, 0)'s nearest lethal cell by brute force.
  long best = -1;
  for (int y = 0; y < 25; ++y) {
    for (int x = 0; x < 25; ++x) {
      if (map.cost(x, y) != cost::kLethalObstacle) continue;
      const long d2 = static_cast<long>(x) * x + static_cast<long>(y) * y;
      if (best < 0 || d2 < best) best = d2;
    }
  }
  const std::uint8_t at_origin =
      best < 0 ? 0 : inflationCost(std::sqrt(static_cast<double>(best)) * 0.05, c);
  EXPECT_EQ(two[0], at_origin);
}

TEST(InflatorMethods, RadiusBeyondTheKernelLimitFallsBackToTheExactTransform) {
  // 300 cells > kMaxStampRadiusCells: no kernel; kStamp must still give exact costs.
  const GridGeometry g(70, 40, 0.05, 0.0, 0.0);
  Costmap map(g, cost::kFreeSpace);
  map.setCost(3, 5, cost::kLethalObstacle);
  map.setCost(69, 39, cost::kLethalObstacle);
  InflationConfig c;
  c.inflation_radius = 15.0;  // 300 cells
  c.cost_scaling_factor = 0.5;
  ASSERT_GT(15.0 / 0.05, Inflator::kMaxStampRadiusCells);
  const auto expected = oracle(map, c);
  for (const InflationMethod method : {InflationMethod::kStamp, InflationMethod::kAuto}) {
    Costmap master = map;
    std::vector<std::uint8_t> costs;
    const InflationStats stats = inflateWith(method, 1, c, &master, &costs);
    ASSERT_EQ(costs, expected);
    EXPECT_EQ(stats.regions_stamped, 0u);
  }
}

TEST(InflatorMethods, AutoStampsSparseMapsAndTransformsDenseOnes) {
  std::mt19937 rng(47);
  const GridGeometry g(300, 200, 0.05, 0.0, 0.0);
  InflationConfig c;
  c.inflation_radius = 1.0;
  std::vector<std::uint8_t> costs;
  Costmap sparse = randomLethalMap(g, 0.001, rng);
  EXPECT_EQ(inflateWith(InflationMethod::kAuto, 1, c, &sparse, &costs).regions_stamped, 1u);
  // Half the cells lethal at random: nearly all of them boundary cells, each a 41-row stamp.
  Costmap dense = randomLethalMap(g, 0.5, rng);
  const auto expected = oracle(dense, c);
  EXPECT_EQ(inflateWith(InflationMethod::kAuto, 1, c, &dense, &costs).regions_stamped, 0u);
  ASSERT_EQ(costs, expected);
}

TEST(InflatorMethods, IncrementalAndRollingUpdatesEqualFullRecomputationWithEitherMethod) {
  std::mt19937 rng(53);
  const GridGeometry g(130, 95, 0.05, 0.0, 0.0);
  for (const InflationMethod method : {InflationMethod::kStamp, InflationMethod::kTransform}) {
    for (const double radius : {0.05, 0.55, 1.2}) {
      InflationConfig c;
      c.inflation_radius = radius;
      c.inscribed_radius = 0.15;
      Costmap truth = edgeAndBlockMap(g, &rng, cost::kFreeSpace);
      Costmap master = truth;
      Inflator inflator(c, g.resolution());
      inflator.setMethod(method);
      inflator.update(&master, everything(g));
      std::uniform_int_distribution<int> ux(0, g.sizeX() - 1), uy(0, g.sizeY() - 1);
      for (int step = 0; step < 30; ++step) {
        CellBounds changed;
        const int x0 = ux(rng), y0 = uy(rng);
        for (int y = y0; y <= std::min(g.sizeY() - 1, y0 + 6); ++y) {
          for (int x = x0; x <= std::min(g.sizeX() - 1, x0 + 9); ++x) {
            truth.setCost(x, y, rng() % 3 == 0 ? cost::kLethalObstacle : cost::kFreeSpace);
            changed.expand(x, y);
          }
        }
        applyChange(truth, changed, &master, &inflator);
      }
      ASSERT_EQ(inflator.costs(), oracle(truth, c))
          << "radius " << radius << " method " << static_cast<int>(method);
      // A shift: the edge bands go through the same method.
      master.shift(3, -2);
      inflator.shift(3, -2);
      Costmap moved(master.geometry(), cost::kFreeSpace);
      for (int y = 0; y < g.sizeY(); ++y) {
        for (int x = 0; x < g.sizeX(); ++x) {
          const int wx = x + 3, wy = y - 2;
          if (wx < g.sizeX() && wy >= 0) moved.setCost(x, y, truth.cost(wx, wy));
        }
      }
      master = moved;
      inflator.update(&master, everything(master.geometry()));
      ASSERT_EQ(inflator.costs(), oracle(moved, c))
          << "after shift, radius " << radius << " method " << static_cast<int>(method);
    }
  }
}
