// WalkChooser (walk_chooser.h): kAuto's timed choice between the exact clearing walks. Fed with
// made-up times, it must explore each walk, settle on the fastest, keep retrying the others at
// doubling intervals (so their cost stays small), follow a change of scene, ride out a spike and
// undo a lucky trial; contexts are kept apart.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "downstream_perception/core/costmap/walk_chooser.h"

using namespace downstream_perception;  // NOLINT

namespace {

using Walk = WalkChooser::Walk;
using Costs = std::array<double, WalkChooser::kWalks>;
// Most tests use the four one-thread walks (their costs: per ray, blocks, reverse query, first
// visit); the shared walks have a test of their own.
constexpr std::uint32_t kOne = WalkChooser::kOneThreadWalks;

// Runs n scans in `context` where walk k costs costs[k] ns per cell; returns the walks run.
std::vector<Walk> run(WalkChooser* chooser, std::uint32_t context, Walk prior, const Costs& costs,
                      int n, std::uint32_t available = kOne) {
  std::vector<Walk> walks;
  for (int i = 0; i < n; ++i) {
    const Walk w = chooser->choose(context, prior, available);
    chooser->report(costs[w]);
    walks.push_back(w);
  }
  return walks;
}

int count(const std::vector<Walk>& walks, Walk w, std::size_t from = 0) {
  int n = 0;
  for (std::size_t i = from; i < walks.size(); ++i) n += walks[i] == w;
  return n;
}

}  // namespace

TEST(WalkChooser, ExploresThePriorFirstThenEachWalkTwice) {
  WalkChooser chooser;
  const std::vector<Walk> walks =
      run(&chooser, 1, WalkChooser::kReverseQuery, {1.0, 2.0, 3.0, 4.0}, 8);
  const std::vector<Walk> expected = {WalkChooser::kReverseQuery, WalkChooser::kReverseQuery,
                                      WalkChooser::kPerRay,       WalkChooser::kPerRay,
                                      WalkChooser::kBlocks,       WalkChooser::kBlocks,
                                      WalkChooser::kFirstVisit,   WalkChooser::kFirstVisit};
  EXPECT_EQ(walks, expected);
  EXPECT_DOUBLE_EQ(chooser.figure(1, WalkChooser::kBlocks), 2.0);
  EXPECT_DOUBLE_EQ(chooser.figure(1, WalkChooser::kPerRay), 1.0);
  EXPECT_LT(chooser.figure(2, WalkChooser::kPerRay), 0.0);  // another context: never measured
}

TEST(WalkChooser, SettlesOnTheFastestAndRetriesTheOthersAtDoublingIntervals) {
  WalkChooser chooser;
  const std::vector<Walk> walks =
      run(&chooser, 7, WalkChooser::kPerRay, {1.0, 2.0, 0.5, 1.5}, 2000);
  // After the 8 exploring scans: retries after 16, 32, 64, 128, 256, 256, ... scans per walk.
  const int slower = count(walks, WalkChooser::kPerRay, 8) + count(walks, WalkChooser::kBlocks, 8) +
                     count(walks, WalkChooser::kFirstVisit, 8);
  EXPECT_GE(slower, 3 * 8);   // each slower walk is still tried now and then ...
  EXPECT_LE(slower, 3 * 14);  // ... but rarely: about 1 scan in 65 here
  EXPECT_LE(count(walks, WalkChooser::kBlocks, 1000), 5);  // past the doubling: one in 256
  EXPECT_EQ(chooser.runs()[WalkChooser::kReverseQuery],
            static_cast<std::uint64_t>(count(walks, WalkChooser::kReverseQuery)));
}

TEST(WalkChooser, FollowsAChangeOfScene) {
  WalkChooser chooser;
  run(&chooser, 3, WalkChooser::kReverseQuery, {1.0, 2.0, 0.5, 1.5}, 3000);
  // The scene changes: the per-ray walk is now the fastest. Its next retry is at most 256 scans
  // away; from then on it runs.
  const std::vector<Walk> walks =
      run(&chooser, 3, WalkChooser::kReverseQuery, {0.3, 2.0, 0.5, 1.5}, 600);
  EXPECT_GE(count(walks, WalkChooser::kPerRay, 300), 290);
}

TEST(WalkChooser, OneSlowScanOfTheFastestWalkDoesNotDethroneIt) {
  WalkChooser chooser;
  run(&chooser, 4, WalkChooser::kPerRay, {1.0, 2.0, 0.5, 1.5}, 100);
  // One preempted scan of the running walk, 100x its time: capped at 3x, averaged in.
  const Walk w = chooser.choose(4, WalkChooser::kPerRay, kOne);
  ASSERT_EQ(w, WalkChooser::kReverseQuery);
  chooser.report(50.0);
  EXPECT_LT(chooser.figure(4, WalkChooser::kReverseQuery), 1.0);
  EXPECT_EQ(chooser.choose(4, WalkChooser::kPerRay, kOne), WalkChooser::kReverseQuery);
  chooser.report(0.5);
}

TEST(WalkChooser, ALuckyTrialIsUndoneSoon) {
  WalkChooser chooser;
  const Costs costs = {1.0, 2.0, 0.5, 1.5};
  run(&chooser, 5, WalkChooser::kPerRay, costs, 8);
  // The blocks' first retry comes 16 scans after exploring; make that one sample look fast.
  int scans = 0;
  for (;; ++scans) {
    ASSERT_LT(scans, 100);
    const Walk w = chooser.choose(5, WalkChooser::kPerRay, kOne);
    if (w == WalkChooser::kBlocks) {
      chooser.report(0.1);  // lucky
      break;
    }
    chooser.report(costs[w]);
  }
  EXPECT_EQ(chooser.choose(5, WalkChooser::kPerRay, kOne),
            WalkChooser::kBlocks);  // believed, at first
  chooser.report(costs[WalkChooser::kBlocks]);
  // Its real figures come in (each capped at 3x its figure, so a few scans) and the reverse
  // query's old figure is faster again: back to it, the blocks tried again 16 scans later.
  const std::vector<Walk> after = run(&chooser, 5, WalkChooser::kPerRay, costs, 40);
  EXPECT_LE(count(after, WalkChooser::kBlocks), 6);
  EXPECT_GE(count(after, WalkChooser::kReverseQuery, 10), 26);
}

TEST(WalkChooser, KeepsContextsApart) {
  WalkChooser chooser;
  const std::uint32_t sparse = WalkChooser::contextOf(100000, 1000000);
  const std::uint32_t dense = WalkChooser::contextOf(2000000, 1000000);
  ASSERT_NE(sparse, dense);
  EXPECT_EQ(WalkChooser::contextOf(100000, 1000000), WalkChooser::contextOf(120000, 1040000));
  // Two sensors in turn: each kind of scan settles on its own fastest walk.
  std::vector<Walk> sparse_walks;
  std::vector<Walk> dense_walks;
  for (int i = 0; i < 400; ++i) {
    const Walk a = chooser.choose(sparse, WalkChooser::kPerRay, kOne);
    chooser.report(a == WalkChooser::kPerRay ? 1.0 : 3.0);
    sparse_walks.push_back(a);
    const Walk b = chooser.choose(dense, WalkChooser::kReverseQuery, kOne);
    chooser.report(b == WalkChooser::kReverseQuery ? 0.2 : 1.0);
    dense_walks.push_back(b);
  }
  EXPECT_GE(count(sparse_walks, WalkChooser::kPerRay, 200), 195);
  EXPECT_GE(count(dense_walks, WalkChooser::kReverseQuery, 200), 195);
  // More contexts than it keeps: the least recently used is forgotten, the others are not.
  for (std::uint32_t k = 100; k < 100 + WalkChooser::kContexts - 1; ++k) {
    run(&chooser, k, WalkChooser::kPerRay, {1.0, 1.0, 1.0, 1.0}, 1);
  }
  EXPECT_LT(chooser.figure(sparse, WalkChooser::kPerRay), 0.0);
  EXPECT_DOUBLE_EQ(chooser.figure(dense, WalkChooser::kReverseQuery), 0.2);
}

TEST(WalkChooser, ChoosesOnlyAvailableWalksAndTheSharedOnesWhereTheyPay) {
  // A large map: two threads pay for the per-ray walk (0.6 against 1.0), not for the blocks.
  const Costs large = {1.0, 2.0, 1.2, 1.5, 0.6, 2.5, 1.4};
  WalkChooser chooser;
  const std::vector<Walk> walks =
      run(&chooser, 1, WalkChooser::kPerRayShared, large, 300, WalkChooser::kAllWalks);
  EXPECT_GE(count(walks, WalkChooser::kPerRayShared, 100), 185);  // 6 walks retried: ~1 in 43
  for (int k = 0; k < WalkChooser::kWalks; ++k) EXPECT_GE(chooser.runs()[k], 2u) << k;
  // No second thread available (a small scan): never a shared walk, whatever it cost before.
  const std::vector<Walk> small = run(&chooser, 2, WalkChooser::kPerRay, large, 300, kOne);
  for (const Walk w : small) EXPECT_FALSE(WalkChooser::shared(w));
  EXPECT_GE(count(small, WalkChooser::kPerRay, 100), 190);
  // The walks' one-thread forms.
  EXPECT_EQ(WalkChooser::oneThread(WalkChooser::kBlocksShared), WalkChooser::kBlocks);
  EXPECT_EQ(WalkChooser::oneThread(WalkChooser::kFirstVisitShared), WalkChooser::kFirstVisit);
  EXPECT_EQ(WalkChooser::oneThread(WalkChooser::kReverseQuery), WalkChooser::kReverseQuery);
  // The context tells availability apart.
  EXPECT_NE(WalkChooser::contextOf(1000, 1000, kOne), WalkChooser::contextOf(1000, 1000));
}

TEST(WalkChooser, ReportWithoutChoiceOrWithABadFigureIsHarmless) {
  WalkChooser chooser;
  chooser.report(1.0);  // nothing chosen: ignored
  std::uint64_t runs = 0;
  for (const std::uint64_t n : chooser.runs()) runs += n;
  EXPECT_EQ(runs, 0u);
  EXPECT_EQ(chooser.choose(9, WalkChooser::kBlocks, kOne), WalkChooser::kBlocks);
  chooser.report(0.0);  // below the clock's resolution: counts as fast, not as unmeasured
  EXPECT_GT(chooser.figure(9, WalkChooser::kBlocks), 0.0);
  EXPECT_EQ(chooser.choose(9, WalkChooser::kBlocks, kOne), WalkChooser::kBlocks);
  chooser.report(-5.0);
  EXPECT_GT(chooser.figure(9, WalkChooser::kBlocks), 0.0);
}
