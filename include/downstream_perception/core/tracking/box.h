// Axis-aligned image boxes: IoU, greedy NMS, and IoU of binary masks.
//
// Boxes use continuous pixel coordinates (x_min, y_min) - (x_max, y_max), area
// (x_max - x_min) * (y_max - y_min), as vision_msgs' and the lesson's examples do:
// (10,10)-(60,60) vs (30,30)-(80,80) -> 900 / 4100 = 0.220.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace downstream_perception {

struct Box {
  double x_min = 0.0;
  double y_min = 0.0;
  double x_max = 0.0;
  double y_max = 0.0;

  double width() const { return x_max - x_min; }
  double height() const { return y_max - y_min; }
  double area() const { return width() * height(); }
  double centerX() const { return 0.5 * (x_min + x_max); }
  double centerY() const { return 0.5 * (y_min + y_max); }
  static Box fromCenter(double cx, double cy, double w, double h) {
    return {cx - 0.5 * w, cy - 0.5 * h, cx + 0.5 * w, cy + 0.5 * h};
  }
  /// Empty if finite with x_min <= x_max and y_min <= y_max, else the reason.
  std::string validate() const;
};

/// Intersection over union; 0 for disjoint boxes (each overlap side clamped at 0) and when the
/// union is empty.
double iou(const Box& a, const Box& b);

/// Greedy non-maximum suppression: repeatedly keep the highest-scoring box and drop every
/// remaining box whose IoU with it exceeds `iou_threshold`. With `class_ids` (same length as
/// boxes), boxes only suppress boxes of their own class. Returns the kept indices, best first.
/// Ties in score keep the lower index first (stable).
std::vector<std::size_t> nms(const std::vector<Box>& boxes, const std::vector<double>& scores,
                             double iou_threshold, const std::vector<int>* class_ids = nullptr);

/// IoU of two binary masks of `count` cells (non-zero = foreground); 0 if both are empty.
double maskIou(const std::uint8_t* a, const std::uint8_t* b, std::size_t count);

}  // namespace downstream_perception
