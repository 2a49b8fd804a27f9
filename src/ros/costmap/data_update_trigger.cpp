#include "downstream_perception/ros/costmap/data_update_trigger.h"

#include <algorithm>
#include <utility>

namespace downstream_perception {

void DataUpdateTrigger::start(double max_rate_hz, std::function<void()> update) {
  stop();
  std::lock_guard<std::mutex> lock(mutex_);
  update_ = std::move(update);
  rate_hz_ = max_rate_hz;
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
  using Clock = std::chrono::steady_clock;
  double tokens = kBurst;
  auto refilled_at = Clock::now();
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return pending_ || !running_; });
    if (!running_) return;
    const auto now = Clock::now();
    tokens = std::min(kBurst,
                      tokens + rate_hz_ * std::chrono::duration<double>(now - refilled_at).count());
    refilled_at = now;
    if (tokens < 1.0) {
      // Rate limit: notifications arriving meanwhile join this update.
      const auto due = now + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>((1.0 - tokens) / rate_hz_));
      if (wake_.wait_until(lock, due, [this] { return !running_; })) return;
      tokens = 1.0;
      refilled_at = Clock::now();
    }
    tokens -= 1.0;
    pending_ = false;
    ++updates_;
    lock.unlock();
    update_();  // without the lock: notify() must never wait for an update
    lock.lock();
  }
}

}  // namespace downstream_perception
