// Issue 21 defect 6: each mode has its own defaults; a config whose mode is set by hand keeps
// every other field (a YAML key keeps its meaning).
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/core/tracking/tracker.h"

using namespace downstream_perception;  // NOLINT

namespace {

Detection boxAt(double x_min) {
  Detection d;
  d.box = {x_min, 100.0, x_min + 40.0, 200.0};
  d.score = 0.9;
  return d;
}

// States of the only track after `frames` frames of one box moving 2 px per frame at 25 fps.
TrackState stateAfter(const TrackerConfig& config, int frames) {
  Tracker tracker(config);
  for (int k = 0; k < frames; ++k) tracker.step(k / 25.0, {boxAt(100.0 + 2.0 * k)});
  EXPECT_EQ(tracker.tracks().size(), 1u);
  return tracker.tracks().front().state;
}

}  // namespace

TEST(TrackerModeDefaults, MetricDefaultsAreTheMemberInitialisers) {
  const TrackerConfig plain;
  const TrackerConfig metric = TrackerConfig::defaultsFor(TrackerConfig::Mode::kMetric);
  EXPECT_EQ(metric.mode, TrackerConfig::Mode::kMetric);
  EXPECT_EQ(metric.min_hits, plain.min_hits);
  EXPECT_EQ(metric.max_age_s, plain.max_age_s);
  EXPECT_EQ(metric.accel_psd, plain.accel_psd);
  EXPECT_EQ(metric.measurement_std, plain.measurement_std);
  EXPECT_TRUE(TrackerConfig::modeSpecificDefaults(TrackerConfig::Mode::kMetric).empty());
}

TEST(TrackerModeDefaults, ImageModeListsExactlyTheFieldsItChanges) {
  const TrackerConfig image = TrackerConfig::defaultsFor(TrackerConfig::Mode::kImage);
  EXPECT_EQ(image.mode, TrackerConfig::Mode::kImage);
  EXPECT_TRUE(image.validate().empty());
  const auto differing = TrackerConfig::modeSpecificDefaults(TrackerConfig::Mode::kImage);
  ASSERT_FALSE(differing.empty());
  // Applying the listed values to a metric config gives the image defaults field by field.
  TrackerConfig rebuilt;
  rebuilt.mode = TrackerConfig::Mode::kImage;
  for (const auto& [name, value] : differing) {
    if (name == "min_hits") {
      rebuilt.min_hits = static_cast<int>(value);
    } else if (name == "confirm_at_start") {
      rebuilt.confirm_at_start = value != 0.0;
    } else if (name == "maximize_matches") {
      rebuilt.maximize_matches = value != 0.0;
    } else if (name == "max_age_s") {
      rebuilt.max_age_s = value;
    } else if (name == "accel_psd") {
      rebuilt.accel_psd = value;
    } else if (name == "measurement_std") {
      rebuilt.measurement_std = value;
    } else if (name == "initial_velocity_std") {
      rebuilt.initial_velocity_std = value;
    } else if (name == "min_iou") {
      rebuilt.min_iou = value;
    } else {
      ADD_FAILURE() << "unexpected image default " << name;
    }
  }
  EXPECT_EQ(rebuilt.min_hits, image.min_hits);
  EXPECT_EQ(rebuilt.confirm_at_start, image.confirm_at_start);
  EXPECT_EQ(rebuilt.maximize_matches, image.maximize_matches);
  EXPECT_EQ(rebuilt.max_age_s, image.max_age_s);
  EXPECT_EQ(rebuilt.accel_psd, image.accel_psd);
  EXPECT_EQ(rebuilt.measurement_std, image.measurement_std);
  EXPECT_EQ(rebuilt.initial_velocity_std, image.initial_velocity_std);
  EXPECT_EQ(rebuilt.min_iou, image.min_iou);
}

TEST(TrackerModeDefaults, ImageDefaultsConfirmAfterMinHitsWhileAHandSetModeKeepsTheOldOnes) {
  // Without start-up confirmation (image default on: a first-frame track is confirmed at once,
  // test_tracker_start_confirmation.cpp) the count of updates decides.
  TrackerConfig image = TrackerConfig::defaultsFor(TrackerConfig::Mode::kImage);
  ASSERT_LT(image.min_hits, TrackerConfig{}.min_hits);
  EXPECT_EQ(stateAfter(image, 1), TrackState::kConfirmed);
  image.confirm_at_start = false;
  EXPECT_EQ(stateAfter(image, image.min_hits - 1), TrackState::kTentative);
  EXPECT_EQ(stateAfter(image, image.min_hits), TrackState::kConfirmed);
  // Setting only the mode on a default config (what existing code does) keeps min_hits 3.
  TrackerConfig old;
  old.mode = TrackerConfig::Mode::kImage;
  EXPECT_EQ(stateAfter(old, image.min_hits), TrackState::kTentative);
  EXPECT_EQ(stateAfter(old, old.min_hits), TrackState::kConfirmed);
}
