// Issue 21: image mode's association objective. With maximize_matches false (the image default)
// each pass maximises the summed (IoU - min_iou), as ByteTrack's lapjv with a cost limit does,
// instead of the number of pairs: a coasting track overlapping a person no longer takes the
// person's detection so that the person's own track can take a false positive.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "downstream_perception/core/tracking/assignment.h"
#include "downstream_perception/core/tracking/tracker.h"

using namespace downstream_perception;  // NOLINT

namespace {

Detection box(double x_min, double y_min, double score) {
  Detection d;
  d.box = {x_min, y_min, x_min + 50.0, y_min + 150.0};
  d.score = score;
  return d;
}

// Two people side by side (boxes 20 px apart: IoU 0.43), tracked for a second; then the right
// one is hidden for a frame (its track coasts) and a frame holds the left person's box and a
// false positive 60 px below it (IoU 0.43 with the left track, 0.22 with the right one). Returns
// the ids of the tracks that took the person's box and the false positive, and the left track's.
struct Outcome {
  std::uint64_t person = 0;
  std::uint64_t false_positive = 0;
  std::uint64_t left = 0;
  std::uint64_t right = 0;
};

Outcome run(const TrackerConfig& config) {
  Tracker tracker(config);
  const double fps = 25.0;
  int k = 0;
  for (; k < 25; ++k) tracker.step(k / fps, {box(100.0, 100.0, 0.9), box(120.0, 100.0, 0.9)});
  Outcome out;
  for (const Track& t : tracker.tracks()) {
    (t.position.x() < 140.0 ? out.left : out.right) = t.id;
  }
  tracker.step(k++ / fps, {box(100.0, 100.0, 0.9)});  // the right person hidden: it coasts
  tracker.step(k / fps, {box(100.0, 100.0, 0.9), box(100.0, 160.0, 0.6)});
  out.person = tracker.lastAssignment()[0];
  out.false_positive = tracker.lastAssignment()[1];
  return out;
}

}  // namespace

TEST(TrackerAssignmentObjective, APersonsDetectionStaysWithItsTrackNotACoastingNeighbour) {
  const TrackerConfig image = TrackerConfig::defaultsFor(TrackerConfig::Mode::kImage);
  ASSERT_FALSE(image.maximize_matches);
  const Outcome got = run(image);
  ASSERT_NE(got.left, 0u);
  ASSERT_NE(got.right, 0u);
  EXPECT_EQ(got.person, got.left);
  EXPECT_NE(got.false_positive, got.left);
  EXPECT_NE(got.false_positive, got.right);  // IoU 0.22: below min_iou
}

TEST(TrackerAssignmentObjective, MaximizingMatchesHandsThePersonToTheCoastingTrack) {
  // The member default (SORT's gated Hungarian): two pairs (left - false positive, right -
  // person) beat one, so the identities are handed over. This is what the image default avoids.
  TrackerConfig config = TrackerConfig::defaultsFor(TrackerConfig::Mode::kImage);
  config.maximize_matches = true;
  const Outcome got = run(config);
  EXPECT_EQ(got.person, got.right);
  EXPECT_EQ(got.false_positive, got.left);
}

TEST(Assignment, WithACostLimitMatchesBruteForce) {
  // Finite unmatched_pair_cost L: the least sum of (cost - L) over pairs cheaper than L.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::bernoulli_distribution forbid(0.3);
  const double limit = 6.0;
  for (int trial = 0; trial < 300; ++trial) {
    const int rows = 1 + static_cast<int>(rng() % 5);
    const int cols = 1 + static_cast<int>(rng() % 5);
    Eigen::MatrixXd c(rows, cols);
    for (int r = 0; r < rows; ++r) {
      for (int k = 0; k < cols; ++k) c(r, k) = forbid(rng) ? kForbidden : u(rng);
    }
    double best = 0.0;
    std::vector<char> used(cols, 0);
    std::function<void(int, double)> search = [&](int r, double total) {
      if (r == rows) {
        best = std::min(best, total);
        return;
      }
      search(r + 1, total);
      for (int k = 0; k < cols; ++k) {
        if (used[k] || !(c(r, k) < limit)) continue;
        used[k] = 1;
        search(r + 1, total + c(r, k) - limit);
        used[k] = 0;
      }
    };
    search(0, 0.0);
    const std::vector<int> dense = solveAssignment(c, limit);
    std::vector<CostEntry> entries;
    for (int r = 0; r < rows; ++r) {
      for (int k = 0; k < cols; ++k) {
        if (std::isfinite(c(r, k))) entries.push_back({r, k, c(r, k)});
      }
    }
    const std::vector<int> sparse = solveAssignment(rows, cols, entries, limit);
    for (const std::vector<int>* got : {&dense, &sparse}) {
      double total = 0.0;
      std::vector<char> seen(cols, 0);
      for (int r = 0; r < rows; ++r) {
        const int k = (*got)[r];
        if (k < 0) continue;
        ASSERT_LT(c(r, k), limit) << "a pair at or above the limit was assigned";
        ASSERT_FALSE(seen[k]) << "a column used twice";
        seen[k] = 1;
        total += c(r, k) - limit;
      }
      ASSERT_NEAR(total, best, 1e-9) << "trial " << trial;
    }
  }
}

TEST(Assignment, ACostLimitTakesOneGoodPairOverTwoPoorOnes) {
  Eigen::MatrixXd c(2, 2);
  c << 0.15, 0.65, 0.5, kForbidden;
  EXPECT_EQ(solveAssignment(c), (std::vector<int>{1, 0}));        // most pairs first
  EXPECT_EQ(solveAssignment(c, 0.7), (std::vector<int>{0, -1}));  // 0.55 > 0.05 + 0.2
}
