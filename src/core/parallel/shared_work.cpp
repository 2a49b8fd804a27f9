#include "downstream_perception/core/parallel/shared_work.h"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

namespace downstream_perception {

namespace {

// One runShared call: the counter both threads claim from, and how many calls have returned.
// Shared-owned: the helper may reach a batch after its caller has returned (every index claimed
// by then, so it only finds the counter exhausted; `task` is never called after that). It holds
// no mutex or condition variable on purpose: whichever thread drops the last reference destroys
// it, and a condition variable destroyed there could still be being signalled by the other
// thread (ThreadSanitizer reported exactly that, 2026-12-07). The completion signal lives in the
// process-long HelperThread instead.
struct Batch {
  std::atomic<int> next{0};
  std::atomic<int> done{0};
  int count = 0;
  const std::function<void(int)>* task = nullptr;
};

// The process's helper thread: takes batches in the order posted, and owns the signal that tells
// waiting callers a batch is finished.
class HelperThread {
 public:
  HelperThread() : thread_([this] { run(); }) {}
  ~HelperThread() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  HelperThread(const HelperThread&) = delete;
  HelperThread& operator=(const HelperThread&) = delete;

  // Posts the batch, works on it on the calling thread too, and returns when every call returned.
  void runAndWait(const std::shared_ptr<Batch>& batch) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(batch);
    }
    wake_.notify_one();
    claimAndRun(*batch);
    std::unique_lock<std::mutex> lock(finished_mutex_);
    finished_.wait(lock, [&] { return batch->done.load() == batch->count; });
  }

 private:
  void run() {
    for (;;) {
      std::shared_ptr<Batch> batch;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
        if (stop_) return;
        batch = std::move(queue_.front());
        queue_.pop_front();
      }
      claimAndRun(*batch);
    }
  }

  void claimAndRun(Batch& batch) {
    for (;;) {
      const int i = batch.next.fetch_add(1);
      if (i >= batch.count) return;
      (*batch.task)(i);
      if (batch.done.fetch_add(1) + 1 == batch.count) {
        // Under the lock, so a caller between its predicate check and its wait cannot miss it.
        // notify_all: callers on other threads may be waiting for their own batches.
        const std::lock_guard<std::mutex> lock(finished_mutex_);
        finished_.notify_all();
      }
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Batch>> queue_;
  bool stop_ = false;
  std::mutex finished_mutex_;
  std::condition_variable finished_;
  std::thread thread_;  // last: starts once the members above exist
};

HelperThread& helperThread() {
  static HelperThread helper;
  return helper;
}

}  // namespace

void runShared(int count, const std::function<void(int)>& task) {
  static const bool two_cores = std::thread::hardware_concurrency() >= 2;
  if (count <= 1 || !two_cores) {
    for (int i = 0; i < count; ++i) task(i);
    return;
  }
  auto batch = std::make_shared<Batch>();
  batch->count = count;
  batch->task = &task;
  helperThread().runAndWait(batch);
}

}  // namespace downstream_perception
