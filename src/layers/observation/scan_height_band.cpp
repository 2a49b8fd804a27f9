#include "downstream_perception/layers/observation/scan_height_band.h"

#include <cmath>
#include <limits>

namespace downstream_perception {

ScanPrefilterStats prefilterScanRanges(std::vector<float>* ranges, double angle_min,
                                       double angle_increment, double range_max,
                                       bool costmap2d_inf_is_valid, double no_return_range_m,
                                       const ScanHeightModel& model, const ScanHeightBand& band) {
  ScanPrefilterStats stats;
  const bool level = model.zx == 0.0 && model.zy == 0.0;
  for (std::size_t k = 0; k < ranges->size(); ++k) {
    float& r = (*ranges)[k];
    if (r == std::numeric_limits<float>::infinity() && costmap2d_inf_is_valid) {
      r = static_cast<float>(range_max - kCostmap2dInfEpsilonM);
      ++stats.inf_substituted;
    }
    double distance = 0.0;
    if (std::isfinite(r) && r > 0.0f) {
      distance = r;
    } else if (r == std::numeric_limits<float>::infinity()) {
      distance = no_return_range_m;
    } else {
      continue;
    }
    double z = model.origin_z;
    if (!level) {
      const double a = angle_min + static_cast<double>(k) * angle_increment;
      z += distance * (model.zx * std::cos(a) + model.zy * std::sin(a));
    }
    if (z < band.min_z || z > band.max_z) {
      r = std::numeric_limits<float>::quiet_NaN();
      ++stats.outside_band;
    }
  }
  return stats;
}

}  // namespace downstream_perception
