// runShared: every index exactly once, whoever runs it, and nothing after it returns.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include "downstream_perception/core/parallel/shared_work.h"

using downstream_perception::runShared;

TEST(SharedWork, RunsEveryIndexExactlyOnce) {
  for (int count : {0, 1, 2, 3, 4, 7, 64}) {
    for (int round = 0; round < 50; ++round) {
      std::vector<std::atomic<int>> calls(static_cast<std::size_t>(count));
      for (auto& c : calls) c = 0;
      runShared(count, [&](int i) {
        // A little work, so that the helper sometimes gets some of it.
        volatile double x = 0.0;
        for (int k = 0; k < 2000; ++k) x = x + k;
        calls[static_cast<std::size_t>(i)]++;
      });
      for (int i = 0; i < count; ++i) ASSERT_EQ(calls[static_cast<std::size_t>(i)].load(), 1);
    }
  }
}

TEST(SharedWork, ReturnsOnlyWhenEveryCallHasReturned) {
  std::atomic<int> running{0};
  std::atomic<int> finished{0};
  for (int round = 0; round < 20; ++round) {
    runShared(4, [&](int) {
      ++running;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      ++finished;
      --running;
    });
    EXPECT_EQ(running.load(), 0);
    EXPECT_EQ(finished.load(), 4 * (round + 1));
  }
}

TEST(SharedWork, CallersOnSeveralThreadsShareTheOneHelper) {
  // Two callers at once (two layers in one nodelet manager): each batch still runs completely.
  std::atomic<long> sum{0};
  auto caller = [&] {
    for (int round = 0; round < 100; ++round) runShared(5, [&](int i) { sum += i + 1; });
  };
  std::thread a(caller);
  std::thread b(caller);
  a.join();
  b.join();
  EXPECT_EQ(sum.load(), 2 * 100 * 15);
}
