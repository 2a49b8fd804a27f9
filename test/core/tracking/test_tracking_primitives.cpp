// Boxes, the Mahalanobis gate, the Kalman filter and the assignment solver.
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
