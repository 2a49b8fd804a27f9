#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <random>
#include <set>

#include "downstream_perception/core/tracking/assignment.h"
#include "downstream_perception/core/tracking/box.h"
#include "downstream_perception/core/tracking/kalman.h"
#include "downstream_perception/core/tracking/tracker.h"

using namespace downstream_perception;  // NOLINT

TEST(Box, LessonIouGoldenNumbers) {
  EXPECT_NEAR(iou({10, 10, 60, 60}, {30, 30, 80, 80}), 900.0 / 4100.0, 1e-12);  // 0.220
  EXPECT_NEAR(iou({10, 10, 60, 60}, {30, 30, 80, 80}), 0.220, 5e-4);
  // The 12-cell boxes: columns 0-3 x rows 0-2 and columns 2-5 x rows 1-3 -> 4 / 20.
  EXPECT_NEAR(iou({0, 0, 4, 3}, {2, 1, 6, 4}), 0.200, 1e-12);
  // Disjoint boxes: the max(0, .) clamp (negative width x negative height must not count).
  EXPECT_EQ(iou({0, 0, 1, 1}, {2, 2, 3, 3}), 0.0);
  EXPECT_EQ(iou({0, 0, 1, 1}, {0, 0, 1, 1}), 1.0);
  EXPECT_EQ(iou({0, 0, 0, 0}, {0, 0, 0, 0}), 0.0);
  EXPECT_FALSE((Box{0, 0, -1, 1}).validate().empty());
  EXPECT_FALSE((Box{0, std::nan(""), 1, 1}).validate().empty());
}

TEST(Box, LessonNmsKeepsAandC) {
  // Forklift A (0.95) + duplicate B (0.90), person C (0.75) + duplicate D (0.70), 100 x 100.
  const std::vector<Box> boxes = {
      {0, 0, 100, 100}, {20, 0, 120, 100}, {60, 0, 160, 100}, {80, 0, 180, 100}};
  const std::vector<double> scores = {0.95, 0.90, 0.75, 0.70};
  EXPECT_NEAR(iou(boxes[0], boxes[1]), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(iou(boxes[0], boxes[2]), 0.25, 1e-12);
  EXPECT_NEAR(iou(boxes[0], boxes[3]), 1.0 / 9.0, 1e-12);
  EXPECT_EQ(nms(boxes, scores, 0.5), (std::vector<std::size_t>{0, 2}));
  // Very low threshold: even the two objects collapse (IoU(A, C) = 0.25); very high: all stay.
  EXPECT_EQ(nms(boxes, scores, 0.2), (std::vector<std::size_t>{0, 3}));
  EXPECT_EQ(nms(boxes, scores, 0.9).size(), 4u);
  // Class-aware: B is another class, so A cannot suppress it.
  const std::vector<int> classes = {1, 2, 1, 1};
  EXPECT_EQ(nms(boxes, scores, 0.5, &classes), (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_THROW(nms(boxes, {0.5}, 0.5), std::invalid_argument);
}

TEST(Box, LessonLPalletMask) {
  // 4 x 4 floor; the L-pallet is the bottom row and the left column: 7 cells. Its bounding box
  // claims all 16: mask IoU(box, L) = 7/16 and 9 cells of free floor are reclaimed by the mask.
  std::vector<std::uint8_t> pallet(16, 0), box(16, 1);
  for (int x = 0; x < 4; ++x) pallet[x] = 1;                                // row y = 0
  for (int y = 1; y < 4; ++y) pallet[static_cast<std::size_t>(y) * 4] = 1;  // column x = 0
  EXPECT_EQ(std::accumulate(pallet.begin(), pallet.end(), 0), 7);
  EXPECT_NEAR(maskIou(box.data(), pallet.data(), 16), 7.0 / 16.0, 1e-12);
  EXPECT_EQ(16 - std::accumulate(pallet.begin(), pallet.end(), 0), 9);
  std::vector<std::uint8_t> empty(16, 0);
  EXPECT_EQ(maskIou(empty.data(), empty.data(), 16), 0.0);
}

TEST(Gate, LessonMahalanobisGoldenNumbers) {
  EXPECT_NEAR(chiSquareQuantile(2, 0.99), 9.21, 5e-3);
  EXPECT_NEAR(chiSquareQuantile(1, 0.95), 3.841, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(4, 0.95), 9.488, 1e-3);
  EXPECT_THROW(chiSquareQuantile(0, 0.9), std::invalid_argument);
  EXPECT_THROW(chiSquareQuantile(2, 1.0), std::invalid_argument);
  // Track predicts (5, 5) with P = I (and R = 0): d1 (5.5, 5.2) -> 0.29 pass, d2 (9, 9) -> 32.
  ConstantVelocityKalman<2> f(Eigen::Vector2d(5, 5), Eigen::Matrix2d::Identity(), 1.0);
  const Eigen::Matrix2d R = Eigen::Matrix2d::Zero();
  EXPECT_NEAR(f.mahalanobis2(Eigen::Vector2d(5.5, 5.2), R), 0.29, 1e-12);
  EXPECT_NEAR(f.mahalanobis2(Eigen::Vector2d(9, 9), R), 32.0, 1e-12);
  // The sigma = 4 / 1 ellipse: 3.5 along the long axis -> 0.77 pass, across -> 12.25 reject.
  ConstantVelocityKalman<2> e(Eigen::Vector2d(0, 0), Eigen::Vector2d(16, 1).asDiagonal(), 1.0);
  EXPECT_NEAR(e.mahalanobis2(Eigen::Vector2d(3.5, 0), R), 0.765625, 1e-12);
  EXPECT_NEAR(e.mahalanobis2(Eigen::Vector2d(0, 3.5), R), 12.25, 1e-12);
  // Rotated 30 deg: the forgiveness rotates with the ellipse.
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  Eigen::Matrix2d rot;
  rot << c, -s, s, c;
  const Eigen::Matrix2d P = rot * Eigen::Vector2d(16, 1).asDiagonal() * rot.transpose();
  ConstantVelocityKalman<2> r(Eigen::Vector2d(0, 0), P, 1.0);
  EXPECT_NEAR(r.mahalanobis2(Eigen::Vector2d(3.5 * c, 3.5 * s), R), 0.765625, 1e-9);
}

TEST(Kalman, ConstantVelocityPredictUpdateAndCoastingGrowth) {
  ConstantVelocityKalman<2> f(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity() * 0.01, 1.0);
  const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * 0.01;
  // An object moving at (1, 0.5) m/s observed at 10 Hz: the velocity converges.
  for (int k = 1; k <= 50; ++k) {
    f.predict(0.1, 0.1);
    f.update(Eigen::Vector2d(0.1 * k, 0.05 * k), R);
  }
  EXPECT_NEAR(f.velocity().x(), 1.0, 0.02);
  EXPECT_NEAR(f.velocity().y(), 0.5, 0.02);
  // Coasting: the position covariance grows monotonically (the gate widens).
  double last = f.positionCov().trace();
  for (int k = 0; k < 10; ++k) {
    f.predict(0.1, 0.1);
    EXPECT_GT(f.positionCov().trace(), last);
    last = f.positionCov().trace();
  }
  EXPECT_NEAR(f.position().x(), 6.0, 0.05);  // 5 m + 1 s of coasting at 1 m/s
  // Symmetric, positive definite after many Joseph-form updates.
  EXPECT_LT((f.covariance() - f.covariance().transpose()).norm(), 1e-12);
  EXPECT_GT(f.covariance().ldlt().vectorD().minCoeff(), 0.0);
}

TEST(Assignment, MatchesBruteForceOnSmallGatedMatrices) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::bernoulli_distribution forbid(0.3);
  for (int trial = 0; trial < 300; ++trial) {
    const int rows = 1 + static_cast<int>(rng() % 5);
    const int cols = 1 + static_cast<int>(rng() % 5);
    Eigen::MatrixXd c(rows, cols);
    for (int r = 0; r < rows; ++r) {
      for (int k = 0; k < cols; ++k) c(r, k) = forbid(rng) ? kForbidden : u(rng);
    }
    // Brute force: every injective partial map, best (most pairs, then least cost).
    int best_pairs = -1;
    double best_cost = 0.0;
    std::vector<int> assign(rows, -1);
    std::vector<char> used(cols, 0);
    std::function<void(int, int, double)> search = [&](int r, int pairs, double total) {
      if (r == rows) {
        if (pairs > best_pairs || (pairs == best_pairs && total < best_cost - 1e-9)) {
          best_pairs = pairs;
          best_cost = total;
        }
        return;
      }
      search(r + 1, pairs, total);
      for (int k = 0; k < cols; ++k) {
        if (used[k] || !std::isfinite(c(r, k))) continue;
        used[k] = 1;
        search(r + 1, pairs + 1, total + c(r, k));
        used[k] = 0;
      }
    };
    search(0, 0, 0.0);
    const std::vector<int> got = solveAssignment(c);
    int pairs = 0;
    double total = 0.0;
    std::vector<char> seen(cols, 0);
    for (int r = 0; r < rows; ++r) {
      if (got[r] < 0) continue;
      ASSERT_TRUE(std::isfinite(c(r, got[r]))) << "a forbidden pair was assigned";
      ASSERT_FALSE(seen[got[r]]) << "a column used twice";
      seen[got[r]] = 1;
      ++pairs;
      total += c(r, got[r]);
    }
    ASSERT_EQ(pairs, best_pairs) << "trial " << trial;
    ASSERT_NEAR(total, best_cost, 1e-9) << "trial " << trial;
  }
  EXPECT_TRUE(solveAssignment(Eigen::MatrixXd(0, 3)).empty());
}

namespace {
Detection at(double x, double y, int truth, double score = 0.9) {
  Detection d;
  d.x = x;
  d.y = y;
  d.score = score;
  d.truth_id = truth;
  d.class_id = 0;
  return d;
}
}  // namespace

TEST(Tracker, ConfirmsAfterMinHitsAndEstimatesVelocity) {
  TrackerConfig c;
  c.min_hits = 3;
  Tracker tracker(c);
  for (int k = 0; k < 30; ++k) {
    const double t = 0.1 * k;
    tracker.step(t, {at(1.0 + 0.8 * t, -0.4 * t, 7)});
    ASSERT_EQ(tracker.tracks().size(), 1u);
    EXPECT_EQ(tracker.tracks()[0].state,
              k + 1 >= 3 ? TrackState::kConfirmed : TrackState::kTentative);
  }
  const Track& track = tracker.tracks()[0];
  EXPECT_EQ(track.id, 1u);
  EXPECT_NEAR(track.velocity.x(), 0.8, 0.05);
  EXPECT_NEAR(track.velocity.y(), -0.4, 0.05);
  EXPECT_EQ(track.hits, 30);
}

TEST(Tracker, CoastsThroughAnOcclusionAndKeepsItsIdThenDies) {
  TrackerConfig c;
  c.max_age_s = 1.5;
  Tracker tracker(c);
  double t = 0.0;
  std::size_t switches = 0;
  for (int k = 0; k < 20; ++k, t += 0.1) switches += tracker.step(t, {at(t, 0.0, 1)}).id_switches;
  const std::uint64_t id = tracker.tracks()[0].id;
  // 1 s unseen (10 frames): coasting, covariance growing, position predicted.
  for (int k = 0; k < 10; ++k, t += 0.1) {
    tracker.step(t, {});
    ASSERT_EQ(tracker.tracks().size(), 1u);
    EXPECT_EQ(tracker.tracks()[0].state, TrackState::kCoasting);
  }
  EXPECT_NEAR(tracker.tracks()[0].position.x(), t - 0.1, 0.1);
  // Seen again 1 m further: inside the widened gate, same id.
  switches += tracker.step(t, {at(t, 0.0, 1)}).id_switches;
  EXPECT_EQ(tracker.tracks()[0].id, id);
  EXPECT_EQ(tracker.tracks()[0].state, TrackState::kConfirmed);
  EXPECT_EQ(switches, 0u);
  // Gone for good: deleted after max_age_s; a new object gets a new id (ids never reused).
  for (int k = 0; k < 17; ++k) tracker.step(t += 0.1, {});
  EXPECT_TRUE(tracker.tracks().empty());
  tracker.step(t += 0.1, {at(t, 0.0, 2)});
  EXPECT_GT(tracker.tracks()[0].id, id);
}

TEST(Tracker, CrossingObjectsKeepTheirIds) {
  // Two paths cross at the origin in an X; object 2 passes the crossing 0.4 s after object 1
  // (0.57 m behind), with 5 cm detection noise: the predictions keep them apart.
  Tracker tracker;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::size_t switches = 0;
  for (int k = 0; k <= 60; ++k) {
    const double t = 0.1 * k;
    const double s1 = -3.0 + t;  // 1 m/s along each axis
    const double s2 = -3.4 + t;
    switches += tracker
                    .step(t, {at(s1 + noise(rng), s1 + noise(rng), 1),
                              at(s2 + noise(rng), -s2 + noise(rng), 2)})
                    .id_switches;
  }
  EXPECT_EQ(switches, 0u);
  EXPECT_EQ(tracker.tracks().size(), 2u);
}

TEST(Tracker, SecondPassContinuesTracksWithLowScoresButNeverStartsThem) {
  TrackerConfig c;
  c.min_hits = 1;
  Tracker tracker(c);
  tracker.step(0.0, {at(0, 0, 1, 0.9)});
  // Low-score detection of the same object: continues the track.
  TrackerStats s = tracker.step(0.1, {at(0.05, 0, 1, 0.3)});
  EXPECT_EQ(s.matched_second_pass, 1u);
  EXPECT_EQ(tracker.tracks()[0].state, TrackState::kConfirmed);
  // A low-score detection far away starts nothing; one below low_score is ignored.
  s = tracker.step(0.2, {at(0.1, 0, 1, 0.9), at(5, 5, 2, 0.3), at(9, 9, 3, 0.05)});
  EXPECT_EQ(tracker.tracks().size(), 1u);
  EXPECT_EQ(s.detections_ignored_low_score, 1u);
  // Without the second pass the low-score detection is ignored.
  c.second_pass = false;
  Tracker plain(c);
  plain.step(0.0, {at(0, 0, 1, 0.9)});
  s = plain.step(0.1, {at(0.05, 0, 1, 0.3)});
  EXPECT_EQ(s.matched_second_pass, 0u);
  EXPECT_EQ(plain.tracks()[0].state, TrackState::kCoasting);
}

TEST(Tracker, ImageModeAssociatesByIou) {
  TrackerConfig c;
  c.mode = TrackerConfig::Mode::kImage;
  c.min_hits = 2;
  Tracker tracker(c);
  for (int k = 0; k < 10; ++k) {
    Detection a, b;
    a.box = {100.0 + 5 * k, 100, 150.0 + 5 * k, 200};
    b.box = {400.0 - 5 * k, 120, 450.0 - 5 * k, 220};
    a.truth_id = 1;
    b.truth_id = 2;
    EXPECT_EQ(tracker.step(0.1 * k, {a, b}).id_switches, 0u);
  }
  ASSERT_EQ(tracker.tracks().size(), 2u);
  EXPECT_NEAR(tracker.tracks()[0].velocity.x(), 50.0, 3.0);  // 5 px per 0.1 s
  EXPECT_NEAR(tracker.tracks()[1].velocity.x(), -50.0, 3.0);
  EXPECT_NEAR(tracker.tracks()[0].size_y, 100.0, 1.0);
}

TEST(Tracker, BadInputIsCountedNotFatal) {
  Tracker tracker;
  Detection nan_det = at(std::nan(""), 0, 1);
  Detection bad_cov = at(0, 0, 1);
  bad_cov.cov_xx = -1.0;
  const TrackerStats s = tracker.step(0.0, {nan_det, bad_cov, at(1, 1, 2)});
  EXPECT_EQ(s.detections_rejected_invalid, 2u);
  EXPECT_EQ(tracker.tracks().size(), 1u);
  EXPECT_THROW(tracker.step(-1.0, {}), std::invalid_argument);  // time went backwards
  TrackerConfig c;
  c.gate_confidence = 1.5;
  EXPECT_THROW(Tracker{c}, std::invalid_argument);
  c = TrackerConfig{};
  c.low_score = 0.8;
  c.high_score = 0.5;
  EXPECT_FALSE(c.validate().empty());
}

// An object walks along x at 1 m/s, is unseen for frames 10-19 and comes back `offset_m` to
// the side (it turned while occluded). Returns the ids confirmed over 4 s and the counts.
struct ReappearResult {
  std::set<std::uint64_t> confirmed_ids;
  std::size_t reidentified = 0;
  std::size_t duplicates = 0;
  std::set<std::uint64_t> ids_at_end;
};
ReappearResult reappear(double offset_m, const TrackerConfig& config) {
  Tracker tracker(config);
  ReappearResult r;
  for (int k = 0; k < 40; ++k) {
    const double t = 0.1 * k;
    std::vector<Detection> dets;
    if (k < 10) dets.push_back(at(t, 0.0, 1));
    if (k >= 20) dets.push_back(at(t, offset_m, 1));
    const TrackerStats s = tracker.step(t, dets);
    r.reidentified += s.reidentified;
    r.duplicates += s.duplicates_removed;
    for (const Track& track : tracker.tracks()) {
      if (track.state != TrackState::kTentative) r.confirmed_ids.insert(track.id);
    }
  }
  for (const Track& track : tracker.tracks()) r.ids_at_end.insert(track.id);
  return r;
}

TEST(Tracker, ReidentifiesAnObjectThatCameBackOutsideTheGate) {
  // 3 m to the side is outside the 99.9 % gate of the coasting track but inside the re-id gate:
  // the newcomer is confirmed under the old id, so only one id is ever reported.
  const ReappearResult near = reappear(3.0, TrackerConfig{});
  EXPECT_EQ(near.reidentified, 1u);
  EXPECT_EQ(near.confirmed_ids, (std::set<std::uint64_t>{1}));
  EXPECT_EQ(near.ids_at_end, (std::set<std::uint64_t>{1}));
  // 5 m away is another object as far as the filter can tell: a new id.
  const ReappearResult far = reappear(5.0, TrackerConfig{});
  EXPECT_EQ(far.reidentified, 0u);
  EXPECT_EQ(far.confirmed_ids.size(), 2u);
  // Without re-identification (tiny gate) the duplicate rule still removes the coasting track
  // once the newcomer sits inside its (here wide) duplicate gate: no ghost next to the object.
  TrackerConfig no_reid;
  no_reid.reid_confidence = 0.5;
  no_reid.duplicate_confidence = 0.99999;
  const ReappearResult dup = reappear(3.0, no_reid);
  EXPECT_EQ(dup.reidentified, 0u);
  EXPECT_EQ(dup.duplicates, 1u);
  EXPECT_EQ(dup.ids_at_end, (std::set<std::uint64_t>{2}));
}

TEST(Tracker, NeighboursAndOccludedObjectsAreNotDuplicates) {
  // Two objects walk side by side 0.6 m apart; each is missed every other frame. Their tracks
  // must both survive (real neighbours are not duplicates).
  Tracker tracker;
  std::size_t duplicates = 0;
  for (int k = 0; k < 40; ++k) {
    const double t = 0.1 * k;
    std::vector<Detection> dets;
    if (k % 2 == 0 || k < 4) dets.push_back(at(t, 0.0, 1));
    if (k % 2 == 1 || k < 4) dets.push_back(at(t, 0.6, 2));
    duplicates += tracker.step(t, dets).duplicates_removed;
  }
  EXPECT_EQ(duplicates, 0u);
  EXPECT_EQ(tracker.tracks().size(), 2u);
  // Two objects converge and one disappears behind the other: its track coasts next to the
  // visible one (it may come out again) and dies only after max_age_s.
  TrackerConfig config;
  config.max_age_s = 1.0;
  Tracker behind(config);
  std::size_t coasting_frames = 0;
  for (int k = 0; k < 30; ++k) {
    const double t = 0.1 * k;
    const double gap = std::max(0.0, 1.0 - 0.1 * k);  // meet at k = 10
    std::vector<Detection> dets = {at(t, 0.5 + gap / 2, 1)};
    if (gap > 0.0) dets.push_back(at(t, 0.5 - gap / 2, 2));
    duplicates += behind.step(t, dets).duplicates_removed;
    for (const Track& track : behind.tracks()) {
      coasting_frames += track.state == TrackState::kCoasting;
    }
  }
  EXPECT_EQ(duplicates, 0u);
  EXPECT_GE(coasting_frames, 9u);  // about max_age_s at 10 Hz
  EXPECT_LE(coasting_frames, 11u);
  EXPECT_EQ(behind.tracks().size(), 1u);
}

TEST(Assignment, SparseEntriesEqualTheDenseMatrix) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (int trial = 0; trial < 200; ++trial) {
    const int rows = 1 + static_cast<int>(rng() % 30);
    const int cols = 1 + static_cast<int>(rng() % 30);
    Eigen::MatrixXd dense = Eigen::MatrixXd::Constant(rows, cols, kForbidden);
    std::vector<CostEntry> entries;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (rng() % 5 != 0) continue;  // ~20 % allowed: several groups
        dense(r, c) = u(rng);
        entries.push_back({r, c, dense(r, c)});
      }
    }
    const std::vector<int> a = solveAssignment(dense);
    const std::vector<int> b = solveAssignment(rows, cols, entries);
    double cost_a = 0.0, cost_b = 0.0;
    int pairs_a = 0, pairs_b = 0;
    for (int r = 0; r < rows; ++r) {
      if (a[r] >= 0) cost_a += dense(r, a[r]), ++pairs_a;
      if (b[r] >= 0) cost_b += dense(r, b[r]), ++pairs_b;
    }
    ASSERT_EQ(pairs_a, pairs_b) << trial;
    ASSERT_NEAR(cost_a, cost_b, 1e-9) << trial;
  }
}

// Issue 17 item 8: an image box with a 1e308 coordinate made the track covariance infinite;
// negative metric sizes and positions of 1e30 m were accepted silently.
TEST(Tracker, OutOfRangeAndNegativeDetectionsAreCountedAndRefused) {
  TrackerConfig image;
  image.mode = TrackerConfig::Mode::kImage;
  Tracker boxes(image);
  Detection huge;
  huge.box = {0.0, 0.0, 1e308, 1e308};
  Detection far;
  far.box = {1e300, 1e300, 1e300 + 1e290, 1e300 + 1e290};
  Detection edge;  // at the bound: accepted
  edge.box = {TrackerConfig::kMaxBoxCoordinatePx - 100.0, 0.0, TrackerConfig::kMaxBoxCoordinatePx,
              50.0};
  Detection inverted;
  inverted.box = {10.0, 10.0, 5.0, 20.0};
  for (int k = 0; k < 5; ++k) {
    const TrackerStats s = boxes.step(0.1 * k, {huge, far, edge, inverted});
    EXPECT_EQ(s.detections_rejected_out_of_range, 2u);
    EXPECT_EQ(s.detections_rejected_invalid, 1u);
  }
  ASSERT_EQ(boxes.tracks().size(), 1u);  // the box at the bound only
  for (const Track& t : boxes.tracks()) {
    EXPECT_TRUE(t.position_cov.allFinite());
    EXPECT_TRUE(t.velocity_cov.allFinite());
    EXPECT_TRUE(t.position.allFinite());
  }

  Tracker metric;
  Detection negative = at(1.0, 1.0, 1);
  negative.size_x = -0.5;
  Detection far_away = at(1e30, 0.0, 2);
  Detection huge_cov = at(3.0, 3.0, 3);
  huge_cov.cov_xx = huge_cov.cov_yy = 1e300;
  Detection big_size = at(4.0, 4.0, 4);
  big_size.size_y = 1e30;
  Detection utm = at(5e6, 9.9e6, 5);  // a UTM-sized frame is fine
  const TrackerStats s = metric.step(0.0, {negative, far_away, huge_cov, big_size, utm});
  EXPECT_EQ(s.detections_rejected_invalid, 1u);
  EXPECT_EQ(s.detections_rejected_out_of_range, 3u);
  ASSERT_EQ(metric.tracks().size(), 1u);
  EXPECT_DOUBLE_EQ(metric.tracks()[0].position.y(), 9.9e6);
  TrackerStats total;
  total.accumulate(s);
  total.accumulate(s);
  EXPECT_EQ(total.detections_rejected_out_of_range, 6u);
}

TEST(TrackerConfig, RefusesNoiseAndAgesThatOverflowOrNeverEnd) {
  TrackerConfig c;
  EXPECT_EQ(c.validate(), "");
  c.initial_velocity_std = 1.8e308;  // once a non-finite velocity covariance
  EXPECT_NE(c.validate(), "");
  c = TrackerConfig{};
  c.accel_psd = 1e7;
  EXPECT_NE(c.validate(), "");
  c = TrackerConfig{};
  c.max_age_s = 1e300;  // a coasting track would never die
  EXPECT_NE(c.validate(), "");
  c.max_age_s = 3600.0;
  EXPECT_EQ(c.validate(), "");
}

TEST(Tracker, RefusesStampsBeyondRosTime) {
  Tracker tracker(TrackerConfig{});
  EXPECT_THROW(tracker.step(1e300, {}), std::invalid_argument);
  EXPECT_THROW(tracker.step(std::nan(""), {}), std::invalid_argument);
  EXPECT_NO_THROW(tracker.step(1.7e9, {}));
}

TEST(Tracker, ACoastingImageBoxNeverTurnsInsideOut) {
  // Issue 21's example: a box shrinking 4 px a frame at 25 fps, then nothing: its width kept
  // shrinking at constant velocity while it coasted, to -0.44 px at frame 26.
  TrackerConfig c;
  c.mode = TrackerConfig::Mode::kImage;
  c.min_hits = 1;
  Tracker tracker(c);
  for (int i = 0; i <= 3; ++i) {
    Detection d;
    d.box = {100.0, 100.0, 150.0 - 4.0 * i, 250.0};
    d.score = 0.9;
    tracker.step(i / 25.0, {d});
  }
  for (int i = 4; i <= 40; ++i) {
    tracker.step(i / 25.0, {});
    for (const auto& t : tracker.tracks()) {
      EXPECT_GE(t.size_x, 1.0) << "frame " << i;
      EXPECT_GE(t.size_y, 1.0) << "frame " << i;
    }
  }
}
