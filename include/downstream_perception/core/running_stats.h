// Count / mean / max / last of a stream of samples, percentiles of its recent part, and a
// histogram of all of it in bounded memory, for diagnostics.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <deque>
#include <sstream>
#include <string>
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

/// Counts of every sample of a positive quantity (a time in ms, say) in log-spaced bins: four per
/// decade from 1e-3 to 1e5, plus one bin below and one above. Memory is fixed whatever the
/// number of samples, so a nodelet can keep the whole run's distribution (the replay tool plots
/// it) where SampleWindow keeps only the recent samples.
class LogHistogram {
 public:
  static constexpr int kBinsPerDecade = 4;
  static constexpr int kDecades = 8;
  static constexpr double kLowest = 1e-3;  ///< lower edge of the first regular bin
  static constexpr int kBins = kBinsPerDecade * kDecades + 2;  ///< with under- and overflow

  void add(double value) {
    if (std::isnan(value)) return;
    ++counts_[static_cast<std::size_t>(binOf(value))];
    ++total_;
  }
  std::size_t total() const { return total_; }
  std::size_t count(int bin) const { return counts_[static_cast<std::size_t>(bin)]; }
  /// Edges of `bin`: bin 0 is [0, kLowest), the last [1e5, inf).
  static double lowerEdge(int bin) {
    return bin == 0 ? 0.0 : kLowest * std::pow(10.0, static_cast<double>(bin - 1) / kBinsPerDecade);
  }
  static double upperEdge(int bin) {
    return bin == kBins - 1 ? INFINITY
                            : kLowest * std::pow(10.0, static_cast<double>(bin) / kBinsPerDecade);
  }
  /// An upper bound of the q-quantile (nearest rank): the upper edge of the bin holding it; 0 if
  /// empty.
  double percentile(double q) const {
    if (total_ == 0) return 0.0;
    const auto rank = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::ceil(std::clamp(q, 0.0, 1.0) * total_)));
    std::size_t seen = 0;
    for (int b = 0; b < kBins; ++b) {
      seen += count(b);
      if (seen >= rank) return upperEdge(b);
    }
    return upperEdge(kBins - 1);
  }
  /// The non-empty bins as "lower-upper:count" separated by spaces (edges to 3 significant
  /// digits), e.g. "0.562-1:12 1-1.78:230": short enough for a diagnostics value.
  std::string encode() const {
    std::ostringstream out;
    out.precision(3);
    for (int b = 0; b < kBins; ++b) {
      if (count(b) == 0) continue;
      if (out.tellp() > 0) out << ' ';
      out << lowerEdge(b) << '-' << upperEdge(b) << ':' << count(b);
    }
    return out.str();
  }

 private:
  static int binOf(double value) {
    if (!(value >= kLowest)) return 0;  // also negatives
    const int b = 1 + static_cast<int>(std::floor(std::log10(value / kLowest) * kBinsPerDecade));
    return std::min(b, kBins - 1);
  }

  std::array<std::size_t, kBins> counts_{};
  std::size_t total_ = 0;
};

/// RunningStats of a processing time plus the whole run's histogram of it.
struct TimingStats : RunningStats {
  LogHistogram histogram;
  void add(double v) {
    RunningStats::add(v);
    histogram.add(v);
  }
};

}  // namespace downstream_perception
