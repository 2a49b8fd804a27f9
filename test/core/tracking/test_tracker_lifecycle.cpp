// Track life: confirmation, coasting, death, crossing objects, the second pass, image mode.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "downstream_perception/core/tracking/box.h"
#include "downstream_perception/core/tracking/tracker.h"
#include "tracker_test_helpers.h"

using namespace downstream_perception;  // NOLINT
using downstream_perception::test::at;

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

TEST(Tracker, ImageModeFindsADetectionAtTheFarEdgeOfAWideBox) {
  // Image association prunes pairs by centre distance in x (at most half the summed widths):
  // a narrow box at the right edge of a 400 px wide track overlaps it although the centres are
  // 190 px apart, and must still be associated; a narrow track in between changes nothing.
  TrackerConfig c = TrackerConfig::defaultsFor(TrackerConfig::Mode::kImage);
  c.min_iou = 0.01;
  c.min_hits = 1;
  Tracker tracker(c);
  Detection wide, narrow, edge;
  wide.box = {0.0, 0.0, 400.0, 100.0};
  narrow.box = {150.0, 200.0, 170.0, 300.0};
  edge.box = {380.0, 0.0, 400.0, 100.0};  // IoU with the wide box: 2000 / 40000 = 0.05
  tracker.step(0.0, {wide, narrow});
  ASSERT_EQ(tracker.tracks().size(), 2u);
  const std::uint64_t wide_id = tracker.lastAssignment()[0];
  const TrackerStats s = tracker.step(0.04, {edge});
  EXPECT_EQ(s.births, 0u);
  EXPECT_EQ(tracker.lastAssignment()[0], wide_id);
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

TEST(Tracker, AMaxAgeOfKFramesKeepsATrackForKMisses) {
  // Issue 21 defect 3: at 25 fps, max_age_s 0.04 and 0.12 dropped a track after 1 and 3 misses
  // but 0.08 kept it after 2: the age and the limit differed in the last bit. Also at a ROS
  // epoch, where a stamp is only exact to about 2e-7 s.
  for (const double epoch : {0.0, 1.7e9}) {
    for (int k = 1; k <= 8; ++k) {
      TrackerConfig c;
      c.min_hits = 1;
      c.max_age_s = k / 25.0;
      Tracker tracker(c);
      tracker.step(epoch, {at(0.0, 0.0, 1)});
      int misses_survived = 0;
      for (int i = 1; i <= k + 1 && !tracker.tracks().empty(); ++i) {
        tracker.step(epoch + i / 25.0, {});
        misses_survived += tracker.tracks().empty() ? 0 : 1;
      }
      EXPECT_EQ(misses_survived, k) << "max_age_s " << c.max_age_s << " at epoch " << epoch;
    }
  }
}
