#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "downstream_perception/core/costmap/inflation.h"
#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/core/grid/costmap.h"
#include "downstream_perception/core/tracking/predicted_footprint.h"

using namespace downstream_perception;  // NOLINT

namespace {

/// The lesson's forklift: at (8.0186, 4.0921) in map, rolling at (-0.6, 0) m/s, a point.
PlanarTrack forklift() {
  PlanarTrack t;
  t.position = {8.0186, 4.0921};
  t.velocity = {-0.6, 0.0};
  return t;
}

PredictionConfig pointPrediction() {
  PredictionConfig c;
  c.prediction_horizon_s = 1.5;
  c.uncertainty_sigmas = 0.0;
  return c;
}

std::set<std::pair<int, int>> cellSet(const GridGeometry& g, const std::vector<std::size_t>& v) {
  std::set<std::pair<int, int>> s;
  for (const std::size_t i : v) s.insert({g.cellOf(i).x, g.cellOf(i).y});
  return s;
}

}  // namespace

TEST(PredictedFootprint, LessonForkliftSweepsColumns142To160OfRow81) {
  const GridGeometry g(400, 200, 0.05, 0.0, 0.0);
  std::vector<std::size_t> cells;
  const CellBounds b = predictedCells(forklift(), 0.0, pointPrediction(), g, &cells);
  std::set<std::pair<int, int>> expected;
  for (int x = 142; x <= 160; ++x) expected.insert({x, 81});
  EXPECT_EQ(cellSet(g, cells), expected);
  EXPECT_EQ(b.min_x, 142);
  EXPECT_EQ(b.max_x, 160);
  EXPECT_EQ(b.min_y, 81);
  EXPECT_EQ(b.max_y, 81);
  // 160 - 142 = 18 columns = 0.90 m, the distance 0.6 m/s covers in 1.5 s.
  EXPECT_NEAR((b.max_x - b.min_x) * g.resolution(), 0.6 * 1.5, 1e-12);
}

TEST(PredictedFootprint, LessonCorridorIsInflatedTo34CellsWide) {
  // Footprint radius 0.30 m + 0.10 m margin = 0.40 m = 8 cells; nav2's decay
  // 252 exp(-3 (d - 0.20)) past the inscribed 0.20 m.
  const GridGeometry g(400, 200, 0.05, 0.0, 0.0);
  std::vector<std::size_t> cells;
  predictedCells(forklift(), 0.0, pointPrediction(), g, &cells);
  Costmap map(g, cost::kFreeSpace);
  for (const std::size_t i : cells)
    map.setCost(g.cellOf(i).x, g.cellOf(i).y, cost::kLethalObstacle);
  InflationConfig c;
  c.inflation_radius = 0.40;
  c.inscribed_radius = 0.20;
  c.cost_scaling_factor = 3.0;
  Inflator inflator(c, g.resolution());
  CellBounds all;
  all.expand(0, 0);
  all.expand(g.sizeX() - 1, g.sizeY() - 1);
  inflator.update(&map, all);
  int first = -1, last = -1;
  for (int x = 0; x < g.sizeX(); ++x) {
    if (map.cost(x, 81) == cost::kFreeSpace) continue;
    if (first < 0) first = x;
    last = x;
  }
  EXPECT_EQ(first, 142 - 8);
  EXPECT_EQ(last, 160 + 8);
  EXPECT_NEAR((last - first) * g.resolution(), 1.70, 1e-9);  // 18 + 2 * 8 = 34 cells
  // The halo decays as the lesson's table: 253 at 4 cells, 186 at 6, 138 at 8.
  EXPECT_EQ(map.cost(160 + 4, 81), 253);
  EXPECT_EQ(map.cost(160 + 6, 81), 186);
  EXPECT_EQ(map.cost(160 + 8, 81), 138);
  EXPECT_EQ(map.cost(150, 81 + 8), 138);
  EXPECT_EQ(map.cost(150, 81 + 9), cost::kFreeSpace);
}

TEST(PredictedFootprint, AnOldTrackIsSweptFromWhereItWasSeen) {
  // Seen 0.5 s ago: the sweep covers the 0.5 s already gone plus the 1.5 s horizon.
  const GridGeometry g(400, 200, 0.05, 0.0, 0.0);
  std::vector<std::size_t> cells;
  const CellBounds b = predictedCells(forklift(), 0.5, pointPrediction(), g, &cells);
  EXPECT_EQ(b.max_x, 160);
  EXPECT_EQ(b.min_x, static_cast<int>(std::floor((8.0186 - 0.6 * 2.0) / 0.05)));  // 136
  EXPECT_EQ(cells.size(), 160u - 136u + 1u);
}

TEST(PredictedFootprint, BoxGrowsByKSigmaOfThePredictedPosition) {
  const GridGeometry g(200, 200, 0.05, 0.0, 0.0);
  PlanarTrack t;
  t.position = {5.0, 5.0};
  t.size_x = 1.0;
  t.size_y = 0.5;
  t.position_covariance = Eigen::Matrix2d::Identity() * 0.01;  // sigma 0.1 m
  PredictionConfig c;
  c.uncertainty_sigmas = 2.0;  // grow 0.2 m
  EXPECT_NEAR(uncertaintyRadius(t, 1.5, c), 0.2, 1e-12);
  std::vector<std::size_t> cells;
  predictedCells(t, 0.0, c, g, &cells);
  const auto s = cellSet(g, cells);
  // Cell 113's centre (5.675) is 0.175 m beyond the box's x edge (5.5): inside; 114 (5.725) not.
  EXPECT_TRUE(s.count({113, 100}));
  EXPECT_FALSE(s.count({114, 100}));
  // Along y the edge is at 5.25: cell 108 (5.425, 0.175 out) in, 109 (5.475) out.
  EXPECT_TRUE(s.count({100, 108}));
  EXPECT_FALSE(s.count({100, 109}));
  // Corners are rounded: (5.675, 5.425) is sqrt(2) * 0.175 = 0.247 m from the corner: out.
  EXPECT_FALSE(s.count({113, 108}));
  // Velocity uncertainty grows with time: sqrt(0.01 + 2^2 * 0.01) * 2 = 0.447 m.
  t.velocity_covariance = Eigen::Matrix2d::Identity() * 0.01;
  EXPECT_NEAR(uncertaintyRadius(t, 2.0, c), 2.0 * std::sqrt(0.05), 1e-12);
  // An absurd covariance is capped.
  t.position_covariance = Eigen::Matrix2d::Identity() * 1e6;
  EXPECT_DOUBLE_EQ(uncertaintyRadius(t, 0.0, c), c.max_uncertainty_m);
}

TEST(PredictedFootprint, SweptPolygonIsTheHullOfBothEnds) {
  PlanarTrack t;
  t.size_x = 2.0;
  t.size_y = 1.0;
  t.velocity = {1.0, 0.0};
  PredictionConfig c;
  // Along the box's axis: a 4-vertex rectangle from x = -1 to 3 (2 s at 1 m/s).
  Footprint p = sweptPolygon(t, 2.0, c);
  ASSERT_EQ(p.size(), 4u);
  double min_x = 1e9, max_x = -1e9;
  for (const auto& v : p) min_x = std::min(min_x, v.x), max_x = std::max(max_x, v.x);
  EXPECT_DOUBLE_EQ(min_x, -1.0);
  EXPECT_DOUBLE_EQ(max_x, 3.0);
  // Diagonal motion: a hexagon.
  t.velocity = {1.0, 1.0};
  EXPECT_EQ(sweptPolygon(t, 2.0, c).size(), 6u);
  // Rotated 90 degrees: the 2 m side now lies along y.
  t.velocity = {0.0, 0.0};
  t.box_yaw = M_PI / 2;
  p = sweptPolygon(t, 0.0, c);
  double max_y = -1e9;
  for (const auto& v : p) max_y = std::max(max_y, v.y);
  EXPECT_NEAR(max_y, 1.0, 1e-12);
}

TEST(PredictedFootprint, StationaryPointTakesItsOwnCell) {
  const GridGeometry g(100, 100, 0.05, 0.0, 0.0);
  PlanarTrack t;
  t.position = {1.01, 2.02};
  std::vector<std::size_t> cells;
  predictedCells(t, 0.0, pointPrediction(), g, &cells);
  ASSERT_EQ(cells.size(), 1u);
  EXPECT_EQ(g.cellOf(cells[0]).x, 20);
  EXPECT_EQ(g.cellOf(cells[0]).y, 40);
}

TEST(PredictedFootprint, PathLeavingTheGridIsClipped) {
  const GridGeometry g(100, 100, 0.05, 0.0, 0.0);  // 5 m x 5 m
  PlanarTrack t;
  t.position = {4.5, 2.5};
  t.velocity = {2.0, 0.0};  // leaves the grid at x = 5
  std::vector<std::size_t> cells;
  const CellBounds b = predictedCells(t, 0.0, pointPrediction(), g, &cells);
  EXPECT_EQ(b.min_x, 90);
  EXPECT_EQ(b.max_x, 99);
  EXPECT_EQ(cells.size(), 10u);
  // Entirely outside: nothing.
  t.position = {-10.0, -10.0};
  cells.clear();
  EXPECT_TRUE(predictedCells(t, 0.0, pointPrediction(), g, &cells).empty());
  EXPECT_TRUE(cells.empty());
}

TEST(PredictedFootprint, BadTracksAndConfigsAreRefused) {
  const GridGeometry g(100, 100, 0.05, 0.0, 0.0);
  std::vector<std::size_t> cells;
  PlanarTrack t;
  t.position = {2.0, 2.0};
  t.position.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(t.validate().empty());
  EXPECT_TRUE(predictedCells(t, 0.0, PredictionConfig(), g, &cells).empty());
  t.position = {2.0, 2.0};
  t.velocity = {0.0, std::numeric_limits<double>::infinity()};
  EXPECT_FALSE(t.validate().empty());
  t.velocity = {50.0, 0.0};  // faster than max_speed_mps: a bad estimate, not swept
  EXPECT_TRUE(t.validate().empty());
  EXPECT_TRUE(predictedCells(t, 0.0, PredictionConfig(), g, &cells).empty());
  t.velocity = {0.0, 0.0};
  t.position_covariance << 1.0, 0.5, 0.0, 1.0;
  EXPECT_NE(t.validate().find("symmetric"), std::string::npos);
  t.position_covariance.setZero();
  EXPECT_TRUE(predictedCells(t, -1.0, PredictionConfig(), g, &cells).empty());  // negative age
  EXPECT_TRUE(cells.empty());

  PredictionConfig c;
  EXPECT_TRUE(c.validate().empty());
  c.prediction_horizon_s = -1.0;
  EXPECT_NE(c.validate().find("prediction_horizon_s"), std::string::npos);
  c = PredictionConfig();
  c.uncertainty_sigmas = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(c.validate().find("uncertainty_sigmas"), std::string::npos);
  c = PredictionConfig();
  c.min_object_size_m = 2.0;
  c.max_object_size_m = 1.0;
  EXPECT_NE(c.validate().find("min_object_size_m"), std::string::npos);
}

TEST(PredictedFootprint, RecentCellsCoverTheGrownBoxFromLookbackToNow) {
  const GridGeometry g(200, 100, 0.05, 0.0, 0.0);
  PlanarTrack t;
  t.position = {5.0, 2.0};
  t.velocity = {1.0, 0.0};
  t.size_x = 1.0;
  t.size_y = 0.6;
  std::vector<std::size_t> cells;
  // 0.1 s back and 0.1 s on at 1 m/s, grown 0.1 m: x in [4.3, 5.7], y in [1.6, 2.4].
  const CellBounds b = recentCells(t, 0.1, 0.1, 0.1, 5.0, g, &cells);
  EXPECT_EQ(b.min_x, 86);              // centre 4.325
  EXPECT_EQ(b.max_x, 113);             // centre 5.675
  EXPECT_EQ(b.min_y, 32);              // centre 1.625
  EXPECT_EQ(b.max_y, 47);              // centre 2.375
  EXPECT_EQ(cells.size(), 28u * 16u);  // a full rectangle: the sweep of an axis-aligned box
  // Nothing ahead of where the object is now: clearing must not reach where it is going.
  for (const std::size_t i : cells) EXPECT_LE(g.cellOf(i).x, 113);
}

TEST(PredictedFootprint, RecentCellsClampAbsurdSizesAndRefuseBadArguments) {
  const GridGeometry g(200, 200, 0.05, 0.0, 0.0);
  PlanarTrack t;
  t.position = {5.0, 5.0};
  t.size_x = t.size_y = 1000.0;  // a broken size estimate must not blank the map
  std::vector<std::size_t> cells;
  const CellBounds b = recentCells(t, 0.0, 0.0, 0.0, 1.0, g, &cells);
  EXPECT_EQ(b.max_x - b.min_x + 1, 20);  // 1.0 m
  EXPECT_EQ(cells.size(), 400u);
  cells.clear();
  EXPECT_TRUE(recentCells(t, -0.1, 0.0, 0.0, 1.0, g, &cells).empty());
  EXPECT_TRUE(recentCells(t, 0.0, 0.0, std::nan(""), 1.0, g, &cells).empty());
  t.velocity.x() = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(recentCells(t, 0.0, 0.0, 0.0, 1.0, g, &cells).empty());
  EXPECT_TRUE(cells.empty());
}

// Issue 17 item 8: the helpers skipped validate(): a NaN polygon and a negative radius came out,
// and an invalid config (min_object_size_m > max_object_size_m: std::clamp is undefined then)
// was swept.
TEST(PredictedFootprint, HelpersValidateTheirInputs) {
  const GridGeometry g(100, 100, 0.05, 0.0, 0.0);
  PlanarTrack t;
  t.position = {2.0, 2.0};
  t.velocity = {0.5, 0.0};
  t.size_x = 0.4;
  t.size_y = 0.3;
  const PredictionConfig ok;
  EXPECT_EQ(validatePrediction(t, 1.0, ok), "");

  PlanarTrack nan_size = t;
  nan_size.size_x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(validatePrediction(nan_size, 1.0, ok).find("track"), std::string::npos);
  EXPECT_THROW(sweptPolygon(nan_size, 1.0, ok), std::invalid_argument);
  EXPECT_THROW(uncertaintyRadius(nan_size, 1.0, ok), std::invalid_argument);

  PredictionConfig negative_cap;
  negative_cap.max_uncertainty_m = -1.0;
  EXPECT_NE(validatePrediction(t, 1.0, negative_cap).find("max_uncertainty_m"), std::string::npos);
  EXPECT_THROW(uncertaintyRadius(t, 1.0, negative_cap), std::invalid_argument);
  PredictionConfig reversed;
  reversed.min_object_size_m = 2.0;
  reversed.max_object_size_m = 1.0;
  EXPECT_THROW(sweptPolygon(t, 1.0, reversed), std::invalid_argument);
  EXPECT_THROW(sweptPolygon(t, std::numeric_limits<double>::infinity(), ok), std::invalid_argument);

  // predictedCells does not throw (it runs per track on message data): it appends nothing.
  std::vector<std::size_t> cells;
  EXPECT_TRUE(predictedCells(t, 0.0, negative_cap, g, &cells).empty());
  EXPECT_TRUE(predictedCells(t, 0.0, reversed, g, &cells).empty());
  EXPECT_TRUE(cells.empty());
  EXPECT_FALSE(predictedCells(t, 0.0, ok, g, &cells).empty());  // the same track, valid config

  // Valid inputs give finite shapes; recentCellsReason names what recentCells refuses.
  for (const FootprintPoint& p : sweptPolygon(t, 1.0, ok)) {
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y));
  }
  EXPECT_EQ(recentCellsReason(t, 0.1, 0.1, 0.1, 5.0), "");
  EXPECT_NE(recentCellsReason(t, -0.1, 0.1, 0.1, 5.0).find("lookback_s"), std::string::npos);
  EXPECT_NE(recentCellsReason(nan_size, 0.1, 0.1, 0.1, 5.0).find("track"), std::string::npos);
}

TEST(PredictedFootprint, OverflowingUncertaintyIsCappedNotZero) {
  // dt^2 * Σv overflows to inf and inf * 0 (the off-diagonal) is NaN: the growth is beyond any
  // cap, so it is the cap (the eigenvalue formula's NaN used to come out as 0).
  PlanarTrack t;
  t.velocity_covariance << 1e305, 0.0, 0.0, 1e305;
  PredictionConfig c;
  c.max_uncertainty_m = 0.7;
  EXPECT_DOUBLE_EQ(uncertaintyRadius(t, 3600.0, c), 0.7);
  t.velocity_covariance << 1.0, 0.0, 0.0, 1.0;
  EXPECT_DOUBLE_EQ(uncertaintyRadius(t, 0.1, c), 2.0 * 0.1);  // k sqrt(dt^2 * 1), below the cap
  EXPECT_THROW(uncertaintyRadius(t, 1e200, c), std::invalid_argument);  // beyond an hour
}
