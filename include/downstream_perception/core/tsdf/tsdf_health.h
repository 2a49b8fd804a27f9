// The lesson's health check of a TSDF. Where the field crosses zero, a clean surface has
// |grad D| = 1/mu, i.e. |grad (D mu)| = 1 per metre. Inconsistent observations move it: drift
// below mu averages into one slightly flatter surface (0.93 for a 2-voxel shift in the gtest),
// drift beyond mu leaves two shells, a gradient far from 1 where they end, and two zero
// crossings within mu along a grid line (a doubled surface: pose drift's fingerprint, or a
// genuinely thin object such as a table top).
#pragma once

#include <cstddef>

#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {

struct TsdfHealth {
  /// Neighbouring observed voxel pairs with a sign change, along an axis within 54.7 degrees of
  /// the surface normal there (|grad_axis| >= |grad| / sqrt 3).
  std::size_t crossings = 0;
  double mean_gradient_ratio = 0.0;    ///< mean |grad (D mu)| there (1 = healthy)
  double low_gradient_fraction = 0.0;  ///< share of crossings with |grad (D mu)| < 0.5
  std::size_t double_crossings = 0;    ///< + - + or - + - within mu along an axis
};

TsdfHealth tsdfHealth(const TsdfMap& map);

}  // namespace downstream_perception
