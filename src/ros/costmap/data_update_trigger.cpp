#include "downstream_perception/ros/costmap/data_update_trigger.h"

#include <utility>

namespace downstream_perception {

void DataUpdateTrigger::start(double max_rate_hz, std::function<void()> update) {
  stop();
  std::lock_guard<std::mutex> lock(mutex_);
  update_ = std::move(update);
  min_period_ = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / max_rate_hz));
  running_ = true;
  pending_ = false;
  thread_ = std::thread(&DataUpdateTrigger::run, this);
}

void DataUpdateTrigger::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!running_) return;
    running_ = false;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void DataUpdateTrigger::notify() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!running_) return;
    ++notifications_;
    pending_ = true;
  }
  wake_.notify_one();
}

std::size_t DataUpdateTrigger::notifications() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return notifications_;
}

std::size_t DataUpdateTrigger::updates() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return updates_;
}

void DataUpdateTrigger::run() {
  // The first update may run at once.
  auto next_allowed = std::chrono::steady_clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return pending_ || !running_; });
    if (!running_) return;
    // Rate limit: notifications arriving meanwhile join this update.
    if (wake_.wait_until(lock, next_allowed, [this] { return !running_; })) return;
    pending_ = false;
    next_allowed = std::chrono::steady_clock::now() + min_period_;
    ++updates_;
    lock.unlock();
    update_();  // without the lock: notify() must never wait for an update
    lock.lock();
  }
}

}  // namespace downstream_perception
