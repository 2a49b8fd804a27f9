// Invalid, out-of-range and low-score input, configurations and stamps the tracker refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "downstream_perception/core/tracking/tracker.h"
#include "tracker_test_helpers.h"

using namespace downstream_perception;  // NOLINT
using downstream_perception::test::at;

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
  c.initial_velocity_std = 1e200;  // finite, but its variance is not
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

TEST(Tracker, OneStampIsOneFrameARepeatedStampIsRefused) {
  // Issue 21 defect 4: a repeated stamp was taken as a frame with dt = 0, so a lost track never
  // aged (200 calls at one stamp kept it alive). It is refused like an older stamp, and the
  // refused call changes nothing.
  TrackerConfig c;
  c.min_hits = 1;
  c.max_age_s = 0.2;
  Tracker tracker(c);
  tracker.step(0.0, {at(0.0, 0.0, 1)});
  tracker.step(0.1, {});
  for (int i = 0; i < 200; ++i) {
    EXPECT_THROW(tracker.step(0.1, {at(5.0, 5.0, 2)}), std::invalid_argument);
  }
  ASSERT_EQ(tracker.tracks().size(), 1u);
  EXPECT_EQ(tracker.tracks().front().id, 1u);
  EXPECT_EQ(tracker.tracks().front().state, TrackState::kCoasting);
  tracker.step(0.3, {});  // 0.3 s since its last update, beyond max_age_s
  EXPECT_TRUE(tracker.tracks().empty());
}
