// Re-identification after an occlusion and duplicate removal (metric mode).
#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

#include "downstream_perception/core/tracking/tracker.h"
#include "tracker_test_helpers.h"

using namespace downstream_perception;  // NOLINT
using downstream_perception::test::at;

namespace {

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

}  // namespace

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

TEST(Tracker, ACoastingTrackIsNeverADuplicateOfItself) {
  // Issue 21 defect 2: a coasting track updated at this very stamp passed every duplicate test
  // against itself and was removed (duplicates_removed == 1, track 1 gone).
  TrackerConfig c;
  c.min_hits = 1;
  Tracker tracker(c);
  tracker.step(1.0, {at(0.0, 0.0, 1)});
  TrackerStats s;
  try {
    s = tracker.step(1.0, {at(5.0, 5.0, 2)});
  } catch (const std::invalid_argument&) {
    // A repeated stamp may be refused (one stamp, one frame): then nothing may change.
  }
  EXPECT_EQ(s.duplicates_removed, 0u);
  ASSERT_FALSE(tracker.tracks().empty());
  EXPECT_EQ(tracker.tracks().front().id, 1u);
}
