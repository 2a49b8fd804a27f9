#include <boost/math/distributions/chi_squared.hpp>

#include <stdexcept>
#include <string>

#include "downstream_perception/core/tracking/kalman.h"

namespace downstream_perception {

double chiSquareQuantile(int dof, double confidence) {
  if (dof < 1 || !(confidence > 0.0 && confidence < 1.0)) {
    throw std::invalid_argument("chi-square quantile needs dof >= 1 and 0 < confidence < 1, got " +
                                std::to_string(dof) + ", " + std::to_string(confidence));
  }
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), confidence);
}

}  // namespace downstream_perception
