// Count / mean / max / last of a stream of samples, and percentiles of its recent part, for
// diagnostics.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <deque>
#include <vector>

namespace downstream_perception {

struct RunningStats {
  std::size_t count = 0;
  double sum = 0.0;
  double max = 0.0;
  double last = 0.0;

  void add(double v) {
    max = count == 0 ? v : std::max(max, v);
    ++count;
    sum += v;
    last = v;
  }
  double mean() const { return count == 0 ? 0.0 : sum / static_cast<double>(count); }
};

/// Percentiles of the last `capacity` samples (non-finite ones are skipped).
class SampleWindow {
 public:
  explicit SampleWindow(std::size_t capacity = 200) : capacity_(capacity) {}
  void add(double value) {
    if (!std::isfinite(value)) return;
    samples_.push_back(value);
    ++total_;
    while (samples_.size() > capacity_) samples_.pop_front();
  }
  /// The q-quantile (q in [0, 1], nearest rank) of the samples held; 0 if none.
  double percentile(double q) const {
    if (samples_.empty()) return 0.0;
    std::vector<double> sorted(samples_.begin(), samples_.end());
    const auto rank = static_cast<std::size_t>(
        std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(sorted.size())));
    const std::size_t k = rank == 0 ? 0 : rank - 1;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
    return sorted[k];
  }
  std::size_t size() const { return samples_.size(); }
  std::size_t total() const { return total_; }
  void clear() { samples_.clear(); }

 private:
  std::size_t capacity_;
  std::size_t total_ = 0;
  std::deque<double> samples_;
};

}  // namespace downstream_perception
