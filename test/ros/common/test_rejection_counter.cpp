// RejectionCounter: counts by reason, the latest rejection, and the diagnostics keys the
// rostests read ("<prefix>rejected (<reason>)"), from several threads at once.
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include "downstream_perception/ros/common/rejection_counter.h"

namespace downstream_perception {
namespace {

std::string valueOf(const diagnostic_updater::DiagnosticStatusWrapper& status,
                    const std::string& key) {
  for (const auto& kv : status.values) {
    if (kv.key == key) return kv.value;
  }
  return "<missing>";
}

TEST(RejectionCounter, CountsByReasonAndKeepsTheLatest) {
  RejectionCounter counter("test");
  counter.reject("bad message: zero stamp", "no time");
  counter.reject("tf: lookup at stamp failed", "no transform");
  counter.reject("bad message: zero stamp", "again");
  counter.count("older than the tracks already held");
  EXPECT_EQ(counter.total(), 4u);
  EXPECT_EQ(counter.counts().at("bad message: zero stamp"), 2u);
  EXPECT_EQ(counter.counts().at("tf: lookup at stamp failed"), 1u);
  // count() leaves the latest rejection's text alone.
  EXPECT_EQ(counter.last(), "bad message: zero stamp: again");
}

TEST(RejectionCounter, ReportWritesOneKeyPerReasonWithThePrefix) {
  RejectionCounter counter;
  counter.reject("b", "x");
  counter.reject("a", "y");
  counter.reject("b", "z");
  diagnostic_updater::DiagnosticStatusWrapper status;
  EXPECT_EQ(counter.report(status, "scan: "), 3u);
  ASSERT_EQ(status.values.size(), 2u);
  EXPECT_EQ(status.values[0].key, "scan: rejected (a)");  // by reason, as std::map orders them
  EXPECT_EQ(valueOf(status, "scan: rejected (a)"), "1");
  EXPECT_EQ(valueOf(status, "scan: rejected (b)"), "2");
}

TEST(RejectionCounter, NothingRejectedWritesNothing) {
  const RejectionCounter counter;
  diagnostic_updater::DiagnosticStatusWrapper status;
  EXPECT_EQ(counter.report(status), 0u);
  EXPECT_TRUE(status.values.empty());
  EXPECT_EQ(counter.last(), "");
}

TEST(RejectionCounter, CountsFromManyThreads) {
  RejectionCounter counter("threads");
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&counter, t] {
      for (int k = 0; k < 1000; ++k) counter.count(t % 2 == 0 ? "even" : "odd");
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(counter.total(), 4000u);
  EXPECT_EQ(counter.counts().at("even"), 2000u);
  EXPECT_EQ(counter.counts().at("odd"), 2000u);
}

}  // namespace
}  // namespace downstream_perception
