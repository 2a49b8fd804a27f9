#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "downstream_perception/core/costmap/log_odds_grid.h"

using namespace downstream_perception;  // NOLINT

namespace {
LogOddsGrid oneCell(const LogOddsConfig& config = {}) {
  return LogOddsGrid(GridGeometry(1, 1, 0.05, 0.0, 0.0), config);
}
// Half a quantum per rounded increment: the documented bound.
constexpr double kHalfQ = LogOddsGrid::kQuantum / 2.0;
}  // namespace

TEST(LogOdds, IncrementsFromProbabilities) {
  EXPECT_NEAR(LogOddsGrid::logOddsOf(0.7), 0.847, 5e-4);
  EXPECT_NEAR(LogOddsGrid::logOddsOf(0.4), -0.405, 5e-4);
  const LogOddsGrid g = oneCell();
  EXPECT_NEAR(LogOddsGrid::dequantize(g.hitUnits()), std::log(0.7 / 0.3), kHalfQ);
  EXPECT_NEAR(LogOddsGrid::dequantize(g.missUnits()), std::log(0.4 / 0.6), kHalfQ);
}

TEST(LogOdds, ThreeHitsGive0927) {
  LogOddsGrid g = oneCell();
  EXPECT_DOUBLE_EQ(g.probability(0), 0.5);
  g.addHit(0);
  EXPECT_NEAR(g.probability(0), 0.700, 5e-4);
  g.addHit(0);
  EXPECT_NEAR(g.probability(0), 0.845, 5e-4);
  g.addHit(0);
  EXPECT_NEAR(g.logOdds(0), 2.542, 2e-3);
  EXPECT_NEAR(g.probability(0), 0.927, 5e-4);
  EXPECT_EQ(g.state(0), CellState::kOccupied);  // 2.54 > +2
}

TEST(LogOdds, FiveHitsThenTwoMissesGive0969) {
  LogOddsGrid g = oneCell();
  for (int i = 0; i < 5; ++i) g.addHit(0);
  EXPECT_NEAR(g.logOdds(0), 4.237, 3e-3);
  EXPECT_NEAR(g.probability(0), 0.986, 5e-4);
  g.addMiss(0);
  g.addMiss(0);
  EXPECT_NEAR(g.logOdds(0), 3.426, 4e-3);
  EXPECT_NEAR(g.probability(0), 0.969, 5e-4);
}

TEST(LogOdds, HitPlusMissIsNotAWash) {
  LogOddsGrid g = oneCell();
  g.addHit(0);
  g.addMiss(0);
  EXPECT_NEAR(g.logOdds(0), 0.442, 1e-3);
  EXPECT_NEAR(g.probability(0), 0.609, 5e-4);
  EXPECT_EQ(g.state(0), CellState::kUnknown);
}

TEST(LogOdds, DecodeThresholds) {
  LogOddsGrid g = oneCell();
  g.setLogOdds(0, 2.4);
  EXPECT_NEAR(g.probability(0), 0.917, 5e-4);
  EXPECT_EQ(g.state(0), CellState::kOccupied);
  g.setLogOdds(0, -2.4);
  EXPECT_NEAR(g.probability(0), 0.083, 5e-4);
  EXPECT_EQ(g.state(0), CellState::kFree);
  g.setLogOdds(0, 0.0);
  EXPECT_EQ(g.state(0), CellState::kUnknown);
  g.setLogOdds(0, 2.0);  // exactly at the threshold is not yet occupied (l > +2)
  EXPECT_EQ(g.state(0), CellState::kUnknown);
}

TEST(LogOdds, ClampCapsStubbornness) {
  LogOddsGrid g = oneCell();
  for (int i = 0; i < 500; ++i) g.addHit(0);
  EXPECT_DOUBLE_EQ(g.logOdds(0), 8.0);  // not 400
  EXPECT_NEAR(g.probability(0), 0.99966, 1e-5);
  for (int i = 0; i < 500; ++i) g.addMiss(0);
  EXPECT_DOUBLE_EQ(g.logOdds(0), -8.0);
  EXPECT_DOUBLE_EQ(g.maxAbsLogOdds(), 8.0);
}

TEST(LogOdds, LessonErosionCountsForClamp8And2) {
  // The bench's hit increment is 0.9445 and its fractional clearing pass L_FREE * 0.35 = -0.1713.
  // A wall pinned at the clamp falls below the p = 0.6 "occupied" line after 45 passes with
  // clamp 8 (it absorbs 44) and after 10 with clamp 2 (it absorbs about 9).
  for (const auto& [clamp, absorbed] : {std::pair<double, int>{8.0, 44}, {2.0, 9}}) {
    LogOddsConfig config;
    config.clamp_min = -clamp;
    config.clamp_max = clamp;
    config.occupied_threshold = LogOddsGrid::logOddsOf(0.6);
    config.free_threshold = -config.occupied_threshold;
    LogOddsGrid g = oneCell(config);
    const int hit = LogOddsGrid::quantize(0.9445);
    const int pass = LogOddsGrid::quantize(-0.1713);
    int hits_to_clamp = 0;
    while (g.units(0) < g.clampMaxUnits()) {
      g.addUnits(0, hit);
      ++hits_to_clamp;
    }
    EXPECT_EQ(hits_to_clamp, clamp == 8.0 ? 9 : 3);  // 8 / 0.9445 = 8.47; 2 / 0.9445 = 2.12
    int passes = 0;
    while (g.state(0) == CellState::kOccupied) {
      g.addUnits(0, pass);
      ++passes;
    }
    EXPECT_EQ(passes - 1, absorbed) << "clamp " << clamp;
  }
}

TEST(LogOdds, FixedPointErrorStaysWithinTheDocumentedBound) {
  LogOddsGrid g = oneCell();
  std::mt19937 rng(3);
  std::bernoulli_distribution is_hit(0.55);
  const double hit = std::log(0.7 / 0.3);
  const double miss = std::log(0.4 / 0.6);
  double exact = 0.0;
  for (int n = 1; n <= 5000; ++n) {
    const bool h = is_hit(rng);
    exact = std::clamp(exact + (h ? hit : miss), -8.0, 8.0);
    if (h)
      g.addHit(0);
    else
      g.addMiss(0);
    ASSERT_LE(std::abs(g.logOdds(0) - exact), (n + 1) * kHalfQ) << "after " << n;
  }
  // And a single set/get rounds by at most half a quantum.
  for (double v = -7.9; v < 7.9; v += 0.0123) {
    g.setLogOdds(0, v);
    ASSERT_LE(std::abs(g.logOdds(0) - v), kHalfQ + 1e-12);
  }
}

TEST(LogOdds, TwoBytesPerCellAndFlagDoesNotLeakIntoValue) {
  LogOddsGrid g(GridGeometry(200, 100, 0.05, 0, 0));
  EXPECT_EQ(g.memoryBytes(), 200u * 100u * 2u);
  g.setLogOdds(7, -3.0);
  const int before = g.units(7);
  g.setFlag(7);
  EXPECT_TRUE(g.flagged(7));
  EXPECT_EQ(g.units(7), before);
  g.addMiss(7);
  EXPECT_TRUE(g.flagged(7));
  EXPECT_EQ(g.units(7), before + g.missUnits());
  g.clearFlag(7);
  EXPECT_FALSE(g.flagged(7));
  EXPECT_EQ(g.units(7), before + g.missUnits());
}

TEST(LogOdds, RejectsAbsurdConfigs) {
  LogOddsConfig c;
  c.p_hit = 0.4;
  EXPECT_FALSE(c.validate().empty());
  EXPECT_THROW(oneCell(c), std::invalid_argument);
  c = LogOddsConfig{};
  c.p_miss = std::nan("");
  EXPECT_FALSE(c.validate().empty());
  c = LogOddsConfig{};
  c.clamp_max = 100.0;
  EXPECT_FALSE(c.validate().empty());
  c = LogOddsConfig{};
  c.occupied_threshold = 9.0;  // unreachable with clamp 8
  EXPECT_FALSE(c.validate().empty());
  EXPECT_TRUE(LogOddsConfig{}.validate().empty());
}

TEST(LogOdds, CountsStatesAndShifts) {
  LogOddsGrid g(GridGeometry(4, 3, 1.0, 0, 0));
  g.setLogOdds(g.geometry().index(1, 1), 5.0);
  g.setLogOdds(g.geometry().index(3, 2), -5.0);
  std::size_t f = 0, o = 0, u = 0;
  g.countStates(&f, &o, &u);
  EXPECT_EQ(f, 1u);
  EXPECT_EQ(o, 1u);
  EXPECT_EQ(u, 10u);
  g.shift(1, 1);  // origin moves +1 cell in x and y: old (1,1) -> new (0,0)
  EXPECT_DOUBLE_EQ(g.geometry().originX(), 1.0);
  EXPECT_EQ(g.state(g.geometry().index(0, 0)), CellState::kOccupied);
  EXPECT_EQ(g.state(g.geometry().index(2, 1)), CellState::kFree);
  EXPECT_EQ(g.state(g.geometry().index(3, 2)), CellState::kUnknown);  // newly exposed
}

TEST(LogOdds, DecayFadesTowardUnknownAndReportsStateChanges) {
  const GridGeometry geometry(4, 1, 0.05, 0.0, 0.0);
  LogOddsGrid g(geometry);
  g.setLogOdds(0, 8.0);   // saturated obstacle
  g.setLogOdds(1, -8.0);  // saturated free
  g.setLogOdds(2, 2.5);   // barely occupied
  CellBounds all;
  all.expand(0, 0);
  all.expand(3, 0);
  // tau = 1 s, dt = 0.5 s: factor exp(-0.5) = 0.6065.
  std::size_t changed = 0;
  CellBounds window = g.decay(std::exp(-0.5), all, &changed);
  EXPECT_NEAR(g.logOdds(0), 8.0 * std::exp(-0.5), 2 * LogOddsGrid::kQuantum);
  EXPECT_NEAR(g.logOdds(1), -8.0 * std::exp(-0.5), 2 * LogOddsGrid::kQuantum);
  EXPECT_EQ(g.state(2), CellState::kUnknown);  // 2.5 -> 1.52: below the occupied threshold
  EXPECT_EQ(changed, 1u);
  EXPECT_EQ(window.min_x, 2);
  EXPECT_EQ(window.max_x, 2);
  // A saturated obstacle stops being lethal after tau * ln(8 / 2) = 1.386 s.
  for (int k = 0; k < 2; ++k) g.decay(std::exp(-0.5), all);  // t = 1.5 s
  EXPECT_EQ(g.state(0), CellState::kUnknown);
  // Decay never crosses zero and reaches it exactly.
  for (int k = 0; k < 40; ++k) g.decay(0.5, all);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(g.units(i), 0) << i;
  EXPECT_THROW(g.decay(1.5, all), std::invalid_argument);
  EXPECT_THROW(g.decay(std::nan(""), all), std::invalid_argument);
}
