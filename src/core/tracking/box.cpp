#include "downstream_perception/core/tracking/box.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace downstream_perception {

std::string Box::validate() const {
  std::ostringstream why;
  if (!std::isfinite(x_min) || !std::isfinite(y_min) || !std::isfinite(x_max) ||
      !std::isfinite(y_max)) {
    why << "box corners must be finite";
  } else if (x_min > x_max || y_min > y_max) {
    why << "box (" << x_min << ", " << y_min << ")-(" << x_max << ", " << y_max
        << ") has min > max";
  }
  return why.str();
}

double iou(const Box& a, const Box& b) {
  // The max(0, .) on each side: without it two disjoint boxes report a positive overlap.
  const double w = std::max(0.0, std::min(a.x_max, b.x_max) - std::max(a.x_min, b.x_min));
  const double h = std::max(0.0, std::min(a.y_max, b.y_max) - std::max(a.y_min, b.y_min));
  const double inter = w * h;
  const double uni = a.area() + b.area() - inter;
  return uni > 0.0 ? inter / uni : 0.0;
}

std::vector<std::size_t> nms(const std::vector<Box>& boxes, const std::vector<double>& scores,
                             double iou_threshold, const std::vector<int>* class_ids) {
  if (scores.size() != boxes.size() || (class_ids && class_ids->size() != boxes.size())) {
    throw std::invalid_argument("nms: boxes, scores and class ids must have the same length");
  }
  std::vector<std::size_t> order(boxes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&scores](std::size_t i, std::size_t j) { return scores[i] > scores[j]; });
  std::vector<std::size_t> kept;
  std::vector<char> removed(boxes.size(), 0);
  for (std::size_t a = 0; a < order.size(); ++a) {
    const std::size_t i = order[a];
    if (removed[i]) continue;
    kept.push_back(i);
    for (std::size_t b = a + 1; b < order.size(); ++b) {
      const std::size_t j = order[b];
      if (removed[j]) continue;
      if (class_ids && (*class_ids)[i] != (*class_ids)[j]) continue;
      if (iou(boxes[i], boxes[j]) > iou_threshold) removed[j] = 1;
    }
  }
  return kept;
}

double maskIou(const std::uint8_t* a, const std::uint8_t* b, std::size_t count) {
  std::size_t inter = 0;
  std::size_t uni = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const bool x = a[k] != 0;
    const bool y = b[k] != 0;
    inter += x && y;
    uni += x || y;
  }
  return uni == 0 ? 0.0 : static_cast<double>(inter) / static_cast<double>(uni);
}

}  // namespace downstream_perception
