// The data-driven update trigger of the costmap host (update_on_data): one update per burst of
// notifications, never more often than the rate limit, nothing after stop(). Waits for expected
// events are generous (they bound a hang, not a speed); no timing is asserted.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "downstream_perception/ros/costmap/data_update_trigger.h"

namespace downstream_perception {
namespace {

using std::chrono::milliseconds;

/// Counts update calls and lets a test wait for a count.
class UpdateCounter {
 public:
  void operator()() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++count_;
    changed_.notify_all();
  }
  bool waitFor(int count, milliseconds timeout = milliseconds(5000)) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return count_ >= count; });
  }
  int count() {
    std::lock_guard<std::mutex> lock(mutex_);
    return count_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int count_ = 0;
};

TEST(DataUpdateTrigger, OneNotificationRunsExactlyOneUpdate) {
  UpdateCounter counter;
  DataUpdateTrigger trigger;
  trigger.start(100.0, [&] { counter(); });
  trigger.notify();
  ASSERT_TRUE(counter.waitFor(1));
  std::this_thread::sleep_for(milliseconds(200));
  EXPECT_EQ(counter.count(), 1);  // no update without new data
  EXPECT_EQ(trigger.notifications(), 1u);
  EXPECT_EQ(trigger.updates(), 1u);
}

TEST(DataUpdateTrigger, ABurstRunsAtOnceThenNotificationsJoinOneLaterUpdate) {
  UpdateCounter counter;
  DataUpdateTrigger trigger;
  trigger.start(0.1, [&] { counter(); });  // one token per 10 s, kBurst = 3 at start
  for (int k = 1; k <= 3; ++k) {
    trigger.notify();
    ASSERT_TRUE(counter.waitFor(k));  // each of the first three runs at once
  }
  for (int k = 0; k < 5; ++k) trigger.notify();
  std::this_thread::sleep_for(milliseconds(300));
  EXPECT_EQ(counter.count(), 3);  // the bucket is empty: the five wait, merged, for a token
  EXPECT_EQ(trigger.notifications(), 8u);
  trigger.stop();  // returns at once: the pending update is dropped, not awaited
  EXPECT_EQ(counter.count(), 3);
}

TEST(DataUpdateTrigger, ANotificationDuringAnUpdateSchedulesAnother) {
  std::mutex gate;
  gate.lock();  // the first update blocks until the test has notified again
  std::atomic<int> calls{0};
  UpdateCounter counter;
  DataUpdateTrigger trigger;
  trigger.start(1000.0, [&] {
    if (calls++ == 0) {
      std::lock_guard<std::mutex> wait(gate);
    }
    counter();
  });
  trigger.notify();
  while (calls.load() == 0) std::this_thread::sleep_for(milliseconds(1));
  trigger.notify();  // arrives while the first update runs
  gate.unlock();
  EXPECT_TRUE(counter.waitFor(2));
  trigger.stop();
  EXPECT_EQ(counter.count(), 2);
}

TEST(DataUpdateTrigger, NotifyIsANoOpUnlessStarted) {
  UpdateCounter counter;
  DataUpdateTrigger trigger;
  trigger.notify();
  EXPECT_EQ(trigger.notifications(), 0u);
  trigger.start(100.0, [&] { counter(); });
  trigger.stop();
  trigger.notify();
  std::this_thread::sleep_for(milliseconds(100));
  EXPECT_EQ(counter.count(), 0);
  EXPECT_EQ(trigger.notifications(), 0u);
}

}  // namespace
}  // namespace downstream_perception
