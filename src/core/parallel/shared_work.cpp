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
// by then, so it only finds the counter exhausted; `task` is never called after that).
struct Batch {
  std::atomic<int> next{0};
  std::atomic<int> done{0};
  int count = 0;
  const std::function<void(int)>* task = nullptr;
  std::mutex mutex;
  std::condition_variable finished;
};

void claimAndRun(Batch& batch) {
  for (;;) {
    const int i = batch.next.fetch_add(1);
    if (i >= batch.count) return;
    (*batch.task)(i);
    if (batch.done.fetch_add(1) + 1 == batch.count) {
      const std::lock_guard<std::mutex> lock(batch.mutex);
      batch.finished.notify_all();
    }
  }
}

// The process's helper thread: takes batches in the order posted.
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

  void post(std::shared_ptr<Batch> batch) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      queue_.push_back(std::move(batch));
    }
    wake_.notify_one();
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

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Batch>> queue_;
  bool stop_ = false;
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
  helperThread().post(batch);
  claimAndRun(*batch);
  std::unique_lock<std::mutex> lock(batch->mutex);
  batch->finished.wait(lock, [&] { return batch->done.load() == count; });
}

}  // namespace downstream_perception
