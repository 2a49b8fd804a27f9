// Count / mean / max / last of a stream of samples, for diagnostics.
#pragma once

#include <algorithm>
#include <cstddef>

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

}  // namespace downstream_perception
