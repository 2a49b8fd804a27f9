// Shared by the tracker gtests: a metric detection of class 0.
#pragma once

#include "downstream_perception/core/tracking/tracker.h"

namespace downstream_perception {
namespace test {

inline Detection at(double x, double y, int truth, double score = 0.9) {
  Detection d;
  d.x = x;
  d.y = y;
  d.score = score;
  d.truth_id = truth;
  d.class_id = 0;
  return d;
}

}  // namespace test
}  // namespace downstream_perception
